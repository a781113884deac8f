"""Template filters of the supervisor pages."""

import json
from typing import Any

from django import template

register = template.Library()


@register.filter
def pretty_json(value: Any) -> str:
    """The value as indented JSON with sorted keys, as the page script shows JSON too."""
    return json.dumps(value, indent=2, sort_keys=True, ensure_ascii=False)
