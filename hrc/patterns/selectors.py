"""Reads of patterns and versions across the organisation wall."""

from django.db.models import Max, QuerySet

from hrc.organisations.selectors import AnyUser, organisations_of
from hrc.patterns.models import PatternModel, PatternVersion


def patterns_visible_to(user: AnyUser) -> QuerySet[PatternModel]:
    """The patterns of the user's organisations, with `latest_version` (None if unpublished)."""
    return (
        PatternModel.objects.filter(organisation__in=organisations_of(user))
        .select_related("organisation", "created_by")
        .annotate(latest_version=Max("versions__number"))
    )


def versions_visible_to(user: AnyUser) -> QuerySet[PatternVersion]:
    """The published versions of the user's organisations' patterns, newest first per pattern."""
    return PatternVersion.objects.filter(
        pattern__organisation__in=organisations_of(user)
    ).select_related("pattern", "published_by")


def versions_of(pattern: PatternModel) -> QuerySet[PatternVersion]:
    """One pattern's versions, newest first."""
    return pattern.versions.select_related("pattern", "published_by").order_by("-number")


def latest_version(pattern: PatternModel) -> PatternVersion | None:
    return versions_of(pattern).first()
