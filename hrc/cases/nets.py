"""Published versions compiled for running, once per process (versions never change)."""

from functools import lru_cache

from hrc.engine.document import read_pattern
from hrc.engine.runtime import CaseNet
from hrc.engine.taskconfig import ConfigError
from hrc.errors import Invalid
from hrc.patterns.models import PatternVersion


def case_net(version: PatternVersion) -> CaseNet:
    """The version compiled; raises Invalid when its task configuration cannot run.

    (Publishing checks the configuration, so only a version published before
    that check existed can fail here.)
    """
    try:
        return _compiled(version.pk, version)
    except ConfigError as problem:
        raise Invalid(f"{version} cannot run: {problem}") from None


@lru_cache(maxsize=256)
def _compiled(version_id: int, version: PatternVersion) -> CaseNet:
    # Keyed by id: a version's document is immutable, so its compiled net is too.
    return CaseNet(read_pattern(version.document))
