"""The router of every app's api/urls.py: detail routes take an id written in ASCII digits.

DRF's default lookup, `[^/.]+`, lets "²" or "٣" through to the view, where str.isdigit()
says yes and int() says no (a 500). Here anything but 1 to 18 ASCII digits (a bigint) is no
route at all, so it falls through to the API's JSON 404 (hrc.api.views.api_not_found); it
also keeps /api/cells/stop/ apart from /api/cells/{id}/.
"""

from rest_framework.routers import SimpleRouter

# The lookup of a primary key; a viewset that looks up by something else sets its own
# `lookup_value_regex`.
ID_REGEX = r"[0-9]{1,18}"


class IdRouter(SimpleRouter):
    def __init__(self, trailing_slash: bool = True) -> None:
        super().__init__(trailing_slash=trailing_slash)
        self._default_value_pattern = ID_REGEX
