"""Published versions compiled for running, once per process (versions never change)."""

import threading
from collections import OrderedDict
from collections.abc import Callable

from hrc.cases.models import Case
from hrc.engine.document import read_pattern
from hrc.engine.runtime import CaseNet
from hrc.engine.taskconfig import ConfigError
from hrc.errors import Invalid
from hrc.patterns.models import PatternVersion

# Compiled versions kept per process, the least recently used dropped first.
KEPT = 256

_compiled: OrderedDict[int, CaseNet] = OrderedDict()
_guard = threading.Lock()


def case_net(version: PatternVersion) -> CaseNet:
    """The version compiled; raises Invalid when its task configuration cannot run.

    (Publishing checks the configuration, so only a version published before
    that check existed can fail here.)
    """
    return _net(version.pk, lambda: version)


def net_of(case: Case) -> CaseNet:
    """The case's version compiled (case_net), its row read only the first time in a process:
    a case locked on the hot path is read without its version's document."""
    return _net(case.version_id, lambda: case.version)


def compiled_net(version_id: int) -> CaseNet | None:
    """The version compiled if this process has compiled it already, else None: never a query
    (what a case event's broadcast reads, inside the transaction that recorded it)."""
    with _guard:
        return _compiled.get(version_id)


def _net(version_id: int, version: Callable[[], PatternVersion]) -> CaseNet:
    # Keyed by id: a version's document is immutable, so its compiled net is too.
    with _guard:
        net = _compiled.get(version_id)
        if net is not None:
            _compiled.move_to_end(version_id)
            return net
    read = version()
    try:
        net = CaseNet(read_pattern(read.document))
    except ConfigError as problem:
        raise Invalid(f"{read} cannot run: {problem}") from None
    with _guard:
        _compiled[version_id] = net
        while len(_compiled) > KEPT:
            _compiled.popitem(last=False)
    return net
