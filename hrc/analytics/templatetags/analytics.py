"""Template filters of the analytics pages."""

from django import template

from hrc.cases.views import format_duration

register = template.Library()


@register.filter
def duration(seconds: float | None) -> str:
    """12.3 s, 4 min 05 s, 2 h 03 min; – for nothing measured."""
    return "–" if seconds is None else format_duration(seconds)


@register.filter
def percent(fraction: float | None) -> str:
    """0.423 as 42.3 %; – for nothing measured."""
    return "–" if fraction is None else f"{fraction * 100:.1f} %"


@register.filter
def bar_width(fraction: float | None, full: int = 120) -> str:
    """The width in pixels of a meter showing the fraction of `full`."""
    return "0" if fraction is None else f"{max(0.0, min(fraction, 1.0)) * full:.1f}"
