"""Content negotiation that leaves `?format=` to the view.

DRF reads `?format=` as "pick the renderer named so" and answers 404 when none
is; our import and export endpoints use it for the document format
(`json` | `pnml`) and answer an unknown one with a 400 that says what is allowed.
"""

from typing import Any

from rest_framework.negotiation import DefaultContentNegotiation
from rest_framework.settings import api_settings


class _SettingsWithoutFormatOverride:
    """DRF's settings, except that no query parameter overrides the renderer."""

    URL_FORMAT_OVERRIDE = None

    def __getattr__(self, name: str) -> Any:
        return getattr(api_settings, name)


class FormatParameterForViews(DefaultContentNegotiation):
    settings = _SettingsWithoutFormatOverride()  # type: ignore[assignment]
