"""Published versions compiled for running, once per process (versions never change)."""

from functools import lru_cache

from hrc.engine.document import read_pattern
from hrc.engine.runtime import CaseNet
from hrc.patterns.models import PatternVersion


def case_net(version: PatternVersion) -> CaseNet:
    return _compiled(version.pk, version)


@lru_cache(maxsize=256)
def _compiled(version_id: int, version: PatternVersion) -> CaseNet:
    # Keyed by id: a version's document is immutable, so its compiled net is too.
    return CaseNet(read_pattern(version.document))
