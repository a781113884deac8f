"""Fixed vocabularies of the cobots app."""

from django.db import models

from hrc.engine.taskconfig import DEVICE_KINDS


class DriverKind(models.TextChoices):
    """Which driver talks to the cobot."""

    # A gateway with the simulated backend (hrc_gateway/sim/), a stand-in for URSim + URUA.
    SIMULATED = "simulated", "Simulated (OPC UA simulator)"
    # A Universal Robots controller behind a gateway with the ur-rtde backend (hrc_gateway/ur/).
    UR = "ur", "Universal Robots (OPC UA + RTDE)"


class CredentialsKind(models.TextChoices):
    """Where a driver finds the cobot's credentials: never the worker's environment or files,
    which every organisation's cobots would share."""

    # The endpoint needs no credentials (the simulator, a lab network).
    NONE = "none", "No credentials"
    # A named secret of the cobot's own organisation (CredentialsSecret), decrypted at connect time.
    SECRET = "secret", "A named secret of the organisation"


class ControlCommand(models.TextChoices):
    """What a person may ask of a cobot from its page or the API (hrc.cobots.control).

    Nothing here clears a protective or emergency stop: a person does that at the cell.
    """

    # Powers the arm on and releases the brakes (URUA's PowerOn).
    POWER_ON = "power-on", "Power on"
    # Releases the brakes of an arm powered on to Idle.
    BRAKE_RELEASE = "brake-release", "Release the brakes"
    POWER_OFF = "power-off", "Power off"
    # Selects a program by name (arguments: {"program": name}); nothing plays yet.
    LOAD_PROGRAM = "load-program", "Load a program"
    # Plays the loaded program, or resumes a paused one.
    START_PROGRAM = "start-program", "Start the program"
    PAUSE_PROGRAM = "pause-program", "Pause the program"
    STOP_PROGRAM = "stop-program", "Stop the program"


class CommandOutcome(models.TextChoices):
    """What came of a control command."""

    # Sent to the cobot, no answer yet; it holds the cobot against another command.
    RUNNING = "running", "Running"
    OK = "ok", "Done"
    # Not carried out: a case was using the cobot, or the cobot said no (its message says why).
    REFUSED = "refused", "Refused"
    # The cobot could not be reached or did not answer in time: it may not have happened.
    FAILED = "failed", "Failed"


# The kinds of device a cell may have: the prefixes of the device calls a task can make
# (hrc.engine.taskconfig.DEVICE_CALLS), so a call and a device of its kind always meet.
DEVICE_KIND_CHOICES = [(kind, kind.replace("-", " ").capitalize()) for kind in DEVICE_KINDS]
