"""What a service refuses, each kind with the HTTP status and the machine code it answers.

Services raise these and views let them through: `hrc.api.exceptions` turns them
into the API's JSON and `hrc.middleware.RefusalMiddleware` into the pages' answer.
Nothing of hrc is imported here, so every app may raise them.
"""

from __future__ import annotations

from typing import Any


class Refusal(Exception):
    """A request refused for a reason the client can act on; never a bug.

    `extra` is what the API's body carries besides `detail` and `code` (a check's
    report, the recorded command). `status` may be given per refusal where one
    kind answers several (a cobot unreachable is 503, one that took too long 504).
    """

    status: int = 400
    code: str = "refused"

    def __init__(
        self, message: str, *, status: int | None = None, extra: dict[str, Any] | None = None
    ) -> None:
        super().__init__(message)
        if status is not None:
            self.status = status
        self.extra: dict[str, Any] = dict(extra or {})

    def body(self) -> dict[str, Any]:
        """The API's answer: `{"detail": message, "code": code, ...extra}`."""
        return {"detail": str(self), "code": self.code, **self.extra}

    def headers(self) -> dict[str, str]:
        """Headers the answer carries, page or API."""
        return {}


class Invalid(Refusal):
    """The input is wrong (400); the message names what. `fields` holds the messages by field
    (DRF's shape, `{"name": ["message"]}`), so a form can show each at its field."""

    status = 400
    code = "invalid"

    def __init__(
        self,
        message: str,
        fields: dict[str, list[str]] | None = None,
        *,
        extra: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(message, extra=extra)
        self.fields = fields or {}

    @classmethod
    def at(cls, field: str, message: str) -> Invalid:
        """The refusal of one field's value (`data.batch`, `actor_mapping.o`)."""
        return cls(message, {field: [message]})

    def body(self) -> dict[str, Any]:
        body = super().body()
        if self.fields:
            body["fields"] = self.fields
        return body


class NotAllowed(Refusal):
    """Not this user's to do (403)."""

    status = 403
    code = "not-allowed"


class NotFound(Refusal):
    """Not there, or not in the user's organisations (404): an outsider learns nothing."""

    status = 404
    code = "not-found"

    def body(self) -> dict[str, Any]:
        # Only the detail, as every other 404 of the API: the wall looks the same from outside.
        return {"detail": str(self)}


class Conflict(Refusal):
    """The thing has moved on (409): completed by someone else, ended, withdrawn, stopped."""

    status = 409
    code = "conflict"


class Busy(Refusal):
    """Every slot of a shared resource is taken (429); the client tries again after `retry_after` s."""

    status = 429
    code = "busy"

    def __init__(self, message: str, *, retry_after: int) -> None:
        super().__init__(message)
        self.retry_after = retry_after

    def headers(self) -> dict[str, str]:
        return {"Retry-After": str(self.retry_after)}
