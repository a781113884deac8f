"""What case services refuse, each with the HTTP status the API answers."""


class CaseError(Exception):
    status = 400


class Invalid(CaseError):
    """The input is wrong (400); the message names what. `fields` holds the messages by field
    (DRF's shape, `{"name": ["message"]}`), so a form can show each at its field."""

    status = 400

    def __init__(self, message: str, fields: dict[str, list[str]] | None = None) -> None:
        super().__init__(message)
        self.fields = fields or {}

    @classmethod
    def at(cls, field: str, message: str) -> "Invalid":
        """The refusal of one field's value (`data.batch`, `actor_mapping.o`)."""
        return cls(message, {field: [message]})


class NotAllowed(CaseError):
    """Not this user's to do (403)."""

    status = 403


class NotFound(CaseError):
    """Not there, or not in the user's organisations (404): an outsider learns nothing."""

    status = 404


class Conflict(CaseError):
    """The case or work item has moved on (409): completed by someone else, ended, withdrawn."""

    status = 409
