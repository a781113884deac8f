"""Fixed vocabularies of the cobots app."""

from django.db import models


class DriverKind(models.TextChoices):
    """Which driver talks to the cobot."""

    # A gateway with the simulated backend (hrc/cobots/gateway/sim/), a stand-in for URSim + URUA.
    SIMULATED = "simulated", "Simulated (OPC UA simulator)"
    # A Universal Robots controller behind a gateway with the ur-rtde backend (hrc/cobots/gateway/ur/).
    UR = "ur", "Universal Robots (OPC UA + RTDE)"


class CredentialsKind(models.TextChoices):
    """Where a driver finds the cobot's credentials; the secret itself is never in the database."""

    # The endpoint needs no credentials (the simulator, a lab network).
    NONE = "none", "No credentials"
    # Read at connect time from the named environment variable of the worker process.
    ENV = "env", "Environment variable"
    # Read at connect time from a file, e.g. a Docker or Kubernetes secret under /run/secrets/.
    FILE = "file", "File"
