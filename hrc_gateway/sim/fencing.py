"""What the step programs remember so a redelivered step does no harm (urua.py's fencing).

A step request carries a token (step id, attempt). The log keeps, per step
id, the highest attempt seen and the attempts that ran: a token that ran is
acknowledged as a duplicate, a lower attempt than one seen is stale. Token
(0, 0) is a prototype client's "no token" and is never remembered.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

from hrc_gateway import urua
from hrc_gateway.backend import Value
from hrc_gateway.sim.registers import RegisterFile

NO_TOKEN: Final = (0, 0)
# Step ids remembered; the oldest are forgotten first. A cell runs far fewer
# steps between two restarts of its processes, and the file stays small.
REMEMBERED_STEP_IDS: Final = 10_000
# Entries of Simulator/ExecutedSteps kept (the newest): the whole list goes out
# on every change, so it stays short; Executions counts them all.
LISTED_EXECUTIONS: Final = 100


@dataclass(frozen=True)
class StepRequest:
    """One step as the program read it from the input registers when Bit64 rose."""

    token: tuple[int, int]
    step: int
    workspace: int
    poses: tuple[float, ...]  # Double24–35: pose 0 (x, y, z, rx, ry, rz), then pose 1

    @classmethod
    def read(cls, registers: RegisterFile) -> StepRequest:
        inputs = registers.inputs
        return cls(
            token=(int(inputs[urua.FENCE_STEP]), int(inputs[urua.FENCE_ATTEMPT])),
            step=int(inputs[urua.STEP]),
            workspace=int(inputs[urua.WORKSPACE]),
            poses=tuple(float(inputs[name]) for name in urua.POSE_REGISTERS),
        )

    @property
    def pose(self) -> tuple[float, ...]:
        return self.poses[:6]

    @property
    def second_pose(self) -> tuple[float, ...]:
        return self.poses[6:]

    def to_dict(self) -> dict[str, Any]:
        return {
            "token": list(self.token),
            "step": self.step,
            "workspace": self.workspace,
            "poses": list(self.poses),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> StepRequest:
        token = tuple(int(t) for t in data["token"])
        poses = tuple(float(p) for p in data["poses"])
        if len(token) != 2 or len(poses) != len(urua.POSE_REGISTERS):
            raise ValueError("not a saved step request")
        if not all(math.isfinite(p) for p in poses):
            raise ValueError("a saved pose is not finite")
        return cls(token, int(data["step"]), int(data["workspace"]), poses)


class ExecutionLog:
    """Which tokens ran, the highest attempt seen per step id, and how many steps ran."""

    def __init__(self) -> None:
        self._seen: OrderedDict[int, tuple[int, set[int]]] = OrderedDict()
        self.executions = 0
        self.executed: list[str] = []
        # Entries [step id, attempt, ran 0/1] not yet in the journal file. The
        # memory of step ids grows with every step, so it is appended to a
        # journal instead of being rewritten whole at every save.
        self._unjournaled: list[list[int]] = []

    def verdict(self, token: tuple[int, int]) -> int | None:
        """OUTCOME_DUPLICATE or OUTCOME_STALE when the token must not run; None when it may."""
        if token == NO_TOKEN or token[0] not in self._seen:
            return None
        highest, ran = self._seen[token[0]]
        if token[1] in ran:
            return urua.OUTCOME_DUPLICATE
        if token[1] < highest:
            return urua.OUTCOME_STALE
        return None

    def saw(self, token: tuple[int, int]) -> None:
        """Remembers a token the program judged (ran or refused): older attempts are stale now."""
        self._remember(token, ran=False)

    def ran(self, request: StepRequest, program: str) -> None:
        """Counts a step that is about to run."""
        self._remember(request.token, ran=True)
        self.executions += 1
        step_id, attempt = request.token
        self.executed.append(f"{step_id}.{attempt} step={request.step} program={program}")
        del self.executed[:-LISTED_EXECUTIONS]

    def _remember(self, token: tuple[int, int], *, ran: bool) -> None:
        if token == NO_TOKEN:
            return
        step_id, attempt = token
        self._unjournaled.append([step_id, attempt, int(ran)])
        self._replay(step_id, attempt, ran=ran)

    def _replay(self, step_id: int, attempt: int, *, ran: bool) -> None:
        highest, attempts = self._seen.pop(step_id, (attempt, set()))
        if ran:
            attempts.add(attempt)
        self._seen[step_id] = (max(highest, attempt), attempts)
        while len(self._seen) > REMEMBERED_STEP_IDS:
            self._seen.popitem(last=False)

    def published_values(self) -> dict[str, Value]:
        return {
            "Simulator/Executions": self.executions,
            "Simulator/ExecutedSteps": list(self.executed),
        }

    def take_journal(self) -> list[list[int]]:
        """The entries to append to the journal since the last call."""
        entries, self._unjournaled = self._unjournaled, []
        return entries

    def compacted_journal(self) -> list[list[int]]:
        """Entries that rebuild exactly what is remembered now (to rewrite a long journal)."""
        entries = []
        for step_id, (highest, ran) in self._seen.items():
            entries.append([step_id, highest, 0])
            entries.extend([step_id, attempt, 1] for attempt in sorted(ran))
        return entries

    def to_dict(self) -> dict[str, Any]:
        """The counters for the state snapshot; the step ids live in the journal."""
        return {"executions": self.executions, "executed": list(self.executed)}

    def restore(self, data: Mapping[str, Any], journal: Iterable[Sequence[int]] = ()) -> None:
        """Takes what to_dict saved and the journal; ValueError/KeyError/TypeError when malformed."""
        executed = [str(entry) for entry in data["executed"]]
        executions = int(data["executions"])
        if executions < 0:
            raise ValueError("a negative execution count")
        self._seen = OrderedDict()
        for step_id, attempt, ran in journal:
            self._replay(int(step_id), int(attempt), ran=bool(ran))
        self.executions, self.executed = executions, executed
