"""How an administration record's detail reads on the pages: "role: operator; teams: Crew"."""

from typing import Any

from django import template

register = template.Library()


@register.filter
def record_detail(detail: dict[str, Any]) -> str:
    """The record's values as a line; lists joined by commas, yes/no for flags, – for nothing."""
    return "; ".join(f"{key.replace('_', ' ')}: {_value(value)}" for key, value in detail.items())


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, list):
        return ", ".join(str(v) for v in value) or "–"
    return str(value) if value not in (None, "") else "–"
