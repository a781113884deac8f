"""Reads of patterns and versions across the organisation wall."""

from django.db.models import Max, QuerySet

from hrc.engine import FormatError, read_pattern
from hrc.engine.issues import Issue
from hrc.engine.model import Pattern
from hrc.engine.rules import check_rules
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from hrc.organisations.selectors import AnyUser, organisations_of, role_in
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


def published_pattern_named(organisation: Organisation, names: list[str]) -> Pattern | None:
    """The pattern of the latest version in service of the organisation's pattern named one of
    `names` (case-insensitive, the first name that finds one wins); None when none does.

    This is how a BPMN call activity finds the pattern it calls: by the called element,
    then by its own name. Only `organisation`'s patterns are looked at (organisations are
    walls), and retired versions are passed over, as they start no new cases.
    """
    in_service = PatternVersion.objects.filter(
        pattern__organisation=organisation, retired_at__isnull=True
    )
    for name in (name.strip() for name in names):
        version = (
            in_service.filter(pattern__name__iexact=name).order_by("-published_at", "-pk").first()
            if name
            else None
        )
        if version is not None:
            return read_pattern(version.document)
    return None


def why_may_not_start(user: AnyUser, version: PatternVersion, *, cell: str = "") -> str | None:
    """Why the user may not start a case of the version (at `cell`, for operators); None when they may.

    The version's start rights name the roles that may start it; operators
    start only at a tablet of one of its start cells, with its default mapping.
    """
    role = role_in(user, version.pattern.organisation_id)
    if role is None:
        return f"You are not a member of {version.pattern.organisation}."
    if version.retired_at is not None:
        return f"{version} is retired: it starts no new cases."
    if role not in version.start_roles:
        return f"{role.label}s may not start cases of {version}."
    if role == Role.OPERATOR and cell not in version.start_cells:
        where = ", ".join(version.start_cells) or "no cell"
        return f"Operators start {version} at the tablet of its cells ({where}), not here."
    return None


def versions_startable_at(user: AnyUser, cell: str) -> list[PatternVersion]:
    """The versions the user may start at the tablet of `cell`: in service, offered there, their role."""
    # Filtered here, not in SQL: SQLite, the embedded default, has no JSON containment.
    candidates = (
        versions_visible_to(user)
        .filter(retired_at__isnull=True)
        .order_by("pattern__name", "-number")
    )
    return [
        version
        for version in candidates
        if cell in version.start_cells and why_may_not_start(user, version, cell=cell) is None
    ]


def rules_a_new_version_must_fix(version: PatternVersion) -> list[Issue]:
    """The rules the version's document breaks today; [] when it keeps every one.

    A version was valid when it was published, so what this finds are rules
    added since. The version keeps running (its cases are never re-checked);
    a new version of the pattern must fix them to be published. The rules are
    linear in the size of the document, cheap enough to run on every page view.
    """
    try:
        return check_rules(read_pattern(version.document))
    except FormatError as exc:
        return list(exc.issues)
