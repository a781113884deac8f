"""pm4py's Woflan on our execution net, in a child process with a time limit.

pm4py is AGPL and installed for the benchmark only (requirements/bench-lock.txt):
it is imported in the child process alone, never in the parent and never by
anything under hrc/. The child gets a plain description of the net (`NetSpec`,
built from the engine's execution net by `net_spec`), so both checkers decide
exactly the same net.

Why a child process: Woflan takes minutes on some 200-transition nets and
cannot be interrupted from inside, so the parent waits a bounded time and
kills the child. The clock starts once the child has imported pm4py and built
the net (about a second of import that is no part of Woflan's work), so the
time and the limit are Woflan's `apply` alone.
"""

import contextlib
import multiprocessing
import os
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any, TypedDict

from hrc.engine.petri import Net

# Importing pm4py and building its net takes ~1 s; this bounds a child that hangs before Woflan.
STARTUP_TIMEOUT = 60.0


class TransitionSpec(TypedDict):
    id: str
    pre: list[tuple[str, int]]
    post: list[tuple[str, int]]


class NetSpec(TypedDict):
    """A net as plain data, picklable into the child without importing hrc there."""

    places: list[str]
    transitions: list[TransitionSpec]
    initial: dict[str, int]
    final: dict[str, int]


@dataclass(frozen=True)
class WoflanResult:
    seconds: float | None
    """Woflan's `apply` alone; None when it did not finish."""
    sound: bool | None
    """Woflan's verdict; None when it timed out or failed."""
    timed_out: bool = False
    error: str | None = None


def net_spec(net: Net) -> NetSpec:
    """The execution net for Woflan: every transition visible and labelled with its id.

    The final marking is `net.final` with nothing on the constraint places
    (`net.ignored`). Woflan has no notion of places that proper completion
    ignores; for the benchmark families every constraint place is emptied in
    every complete run (t_b consumes what t_a produced), so this asks Woflan
    the same question our checker answers.
    """
    return {
        "places": list(net.places),
        "transitions": [
            {"id": t.id, "pre": list(t.pre), "post": list(t.post)} for t in net.transitions
        ],
        "initial": dict(net.initial),
        "final": dict(net.final),
    }


def _build(spec: NetSpec) -> tuple[Any, Any, Any]:
    """The pm4py PetriNet, initial and final marking for a spec (runs in the child)."""
    from pm4py.objects.petri_net.obj import Marking, PetriNet
    from pm4py.objects.petri_net.utils import petri_utils

    net = PetriNet("execution-net")
    places = {}
    for place_id in spec["places"]:
        place = PetriNet.Place(place_id)
        net.places.add(place)
        places[place_id] = place
    for transition_spec in spec["transitions"]:
        transition = PetriNet.Transition(transition_spec["id"], transition_spec["id"])
        net.transitions.add(transition)
        for place_id, weight in transition_spec["pre"]:
            petri_utils.add_arc_from_to(places[place_id], transition, net, weight=weight)
        for place_id, weight in transition_spec["post"]:
            petri_utils.add_arc_from_to(transition, places[place_id], net, weight=weight)
    initial = Marking({places[p]: n for p, n in spec["initial"].items()})
    final = Marking({places[p]: n for p, n in spec["final"].items()})
    return net, initial, final


def _child(spec: NetSpec, conn: Connection) -> None:
    """Child process: import pm4py, build the net, say ready, run Woflan, send the verdict."""
    # pm4py prints diagnostics and an AGPL banner at exit; keep them out of the table.
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    try:
        from pm4py.algo.analysis.woflan import algorithm as woflan

        net, initial, final = _build(spec)
        conn.send(("ready",))
        began = time.perf_counter()
        verdict = woflan.apply(
            net,
            initial,
            final,
            parameters={"return_asap_when_not_sound": True, "print_diagnostics": False},
        )
        conn.send(("done", time.perf_counter() - began, bool(verdict)))
    except Exception as exc:  # reported to the parent, which records it instead of crashing
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()


def run_woflan(spec: NetSpec, timeout: float) -> WoflanResult:
    """Woflan's verdict and time on one net; killed after `timeout` seconds of Woflan."""
    # spawn, not fork: the child starts clean, so pm4py never shares memory
    # (or the parent's tracemalloc state) with the process we measure.
    context = multiprocessing.get_context("spawn")
    receiver, sender = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(spec, sender), daemon=True)
    process.start()
    sender.close()
    try:
        message = _receive(receiver, STARTUP_TIMEOUT)
        if message is None:
            return WoflanResult(None, None, error="pm4py did not start in time")
        if message[0] == "error":
            return WoflanResult(None, None, error=message[1])
        message = _receive(receiver, timeout)
        if message is None:
            return WoflanResult(None, None, timed_out=True)
        if message[0] == "error":
            return WoflanResult(None, None, error=message[1])
        _, seconds, sound = message
        return WoflanResult(seconds, sound)
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join(5)


def _receive(conn: Connection, timeout: float) -> tuple[Any, ...] | None:
    """The next message, or None if none came in time or the child died without one."""
    with contextlib.suppress(EOFError, OSError):
        if conn.poll(timeout):
            message: tuple[Any, ...] = conn.recv()
            return message
    return None
