"""Fixed vocabularies of the organisations app."""

from django.db import models


class Role(models.TextChoices):
    """What a member may do inside their organisation."""

    # Manages the organisation: people, teams, cobots; may also do all an engineer does.
    ADMIN = "admin", "Admin"
    # Models, checks and publishes collaboration patterns; configures cobots.
    ENGINEER = "engineer", "Engineer"
    # Works on the shop floor: sees and performs tasks; reads models, never changes them.
    OPERATOR = "operator", "Operator"


# Roles allowed to change the organisation's models and cobots.
WRITER_ROLES: frozenset[str] = frozenset({Role.ADMIN, Role.ENGINEER})
