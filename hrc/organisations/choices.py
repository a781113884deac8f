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


class AdminAction(models.TextChoices):
    """What an organisation's admin did; each write of the administration pages and API is one."""

    PERSON_ADDED = "person_added", "Added a person"
    # The invited person chose their password through the invitation link (they are the actor).
    INVITATION_ACCEPTED = "invitation_accepted", "Accepted the invitation"
    ROLE_CHANGED = "role_changed", "Changed a role"
    TEAMS_CHANGED = "teams_changed", "Changed a person's teams"
    PERSON_DEACTIVATED = "person_deactivated", "Deactivated a person"
    # A new one-time password was set; the record never holds the password.
    PASSWORD_RESET = "password_reset", "Reset a password"
    TEAM_CREATED = "team_created", "Created a team"
    TEAM_CHANGED = "team_changed", "Changed a team"
    TEAM_DELETED = "team_deleted", "Deleted a team"
    CELL_CREATED = "cell_created", "Created a cell"
    CELL_CHANGED = "cell_changed", "Changed a cell"
    CELL_DELETED = "cell_deleted", "Deleted a cell"
    COBOT_REGISTERED = "cobot_registered", "Registered a cobot"
    COBOT_CHANGED = "cobot_changed", "Changed a cobot"
