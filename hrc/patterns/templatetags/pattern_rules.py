"""What a published version's page says about rules added since it was published."""

from typing import Any

from django import template

from hrc.patterns.models import PatternVersion
from hrc.patterns.selectors import rules_a_new_version_must_fix

register = template.Library()


@register.inclusion_tag("patterns/_must_fix.html")
def must_fix(version: PatternVersion) -> dict[str, Any]:
    """The heading "A new version must fix" and each broken rule's message; nothing when none is."""
    return {"issues": [issue.as_dict() for issue in rules_a_new_version_must_fix(version)]}
