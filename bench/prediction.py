"""`make bench` (seventh part): the prediction (hrc.engine.prediction) against real runs.

Each use case of hrc/patterns/examples/use_cases/ runs --rounds rounds on bench/use_cases.py's
rig (scratch PostgreSQL database, private redis, real Celery workers, simulated OPC UA
gateways at --time-scale), each round one case, or one per case variant at once, with every
operator task timed by OPERATOR_TIME (run_pattern's `durations`: drawn from the run's seeded
random source). Measured, in simulated seconds (wall seconds over the time scale): each
case's cycle, and each cobot's utilisation, the time its steps held it (task-started →
task-completed, merged) over the rounds' spans (sums over rounds: the prediction's is over all
its cases, and a mean of rounds would weigh a short case as much as a long one).

Three predictions of each use case, with the simulator's plant for cobot steps and device
calls and the same cases in flight:

- predicted: PREDICTED_CASES cases, from the distributions alone;
- calibrated: the same, with the runtime's costs, which the prediction does not model,
  measured in the same run: the hop from a task's offer to its start (the median over the
  run's tasks: a lease, a doorbell, a tablet's poll), the scenario's handover before each
  task's work (a shared area is entered after it, as at run time); and, added to every
  task, what a step's handshake and a device call's round trip take beyond the plant's time
  (the means of real minus planned over the steps and calls no space constraint
  interrupted), and what an operator's task took beyond its drawn time (the mean of its
  times less OPERATOR_TIME's mean);
- replayed: the calibrated one over the run's own cases, with the run's draws instead of
  its own: each operator task's times in start order, each cobot's device answers in call
  order.

Why replayed: over a handful of cases, chance alone moves the real p50 far (use case 3's
loop runs as long as the part detection finds parts: the p50 of five cases may lie anywhere
between 20 and 130 s). With the run's draws, the prediction is compared case for case: the
steps' plans, the queues, the constraints and the costs, not two samples of chance. The
verdicts (10 % on the cycle p50, 5 points on each cobot's utilisation) are the replayed
prediction's; the others are printed beside the real p50's 90 % bootstrap interval, what
chance allows them.

The speed row: SPEED_CASES cases of the largest use case (by tasks) predicted, CPU seconds and
events, against a bare heapq event loop pushing and popping the same number of events in the
same run. Results: bench/results/prediction-<UTC>.json (and -latest.json), and a table.
"""

from __future__ import annotations

import argparse
import heapq
import json
import random
import signal
import statistics
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Final, cast

from bench import use_cases
from bench.report import load_average, print_load, settings_json, write_results
from bench.runtime_rig import RESULTS_DIR
from bench.use_cases import CASE_TIMEOUT, case_times, rig, use_case_files
from hrc.engine import read_pattern
from hrc.engine.durations import Duration, Triangular
from hrc.engine.prediction import Scenario, case_variants, predict
from hrc.engine.prediction_report import Prediction
from hrc.engine.runtime import CaseNet
from hrc_gateway.sim.timing import WAIT_PLACE, SimulatedPlant

# Every operator task's time, simulated seconds: the order of the cobots' steps, so that the
# tasks, not the hops between them, make most of a cycle at the time scales run here.
OPERATOR_TIME: Final = Triangular(2.0, 4.0, 8.0)
PREDICTED_CASES: Final = 400
SPEED_CASES: Final = 10_000
CYCLE_TOLERANCE: Final = 0.10
UTILISATION_TOLERANCE: Final = 0.05


@dataclass(frozen=True)
class Settings:
    time_scale: float = 0.1
    rounds: int = 5
    workers: int = use_cases.WORKERS
    only: tuple[str, ...] = ()
    quick: bool = False
    speed_cases: int = SPEED_CASES
    results_dir: Path = field(default=RESULTS_DIR, compare=False)


QUICK: dict[str, Any] = {"time_scale": 0.05, "rounds": 2, "speed_cases": 2000}


@dataclass(frozen=True)
class Calibration:
    """The runtime's own costs, measured in the real run (simulated seconds), that the
    prediction leaves out: the hop from a task's offer to its start (the median over the run's
    tasks), what a step's handshake and a device call's round trip take beyond the plant's
    time (the means of real minus planned over the run's steps, and over its device calls),
    and what an operator's task took beyond its drawn time (the tablet's poll, the commit:
    the mean of its times less OPERATOR_TIME's mean)."""

    hop: float = 0.0
    step: float = 0.0
    call: float = 0.0
    operator: float = 0.0


@dataclass(frozen=True)
class Draws:
    """What chance decided in the real run, for a prediction to take instead of drawing its own:
    each operator task's times (simulated seconds, in start order), and each cobot's device
    answers, by (actor, method), in call order."""

    operator_times: Mapping[str, Sequence[float]]
    answers: Mapping[tuple[str, str], Sequence[Mapping[str, Any]]]


class _CalibratedPlant:
    """The simulator's plant with the calibration's costs added to every command it times, and
    the run's device answers where `draws` gives them (its odds once they run out)."""

    def __init__(self, calibration: Calibration, draws: Draws | None = None) -> None:
        self._plant = SimulatedPlant()
        self._calibration = calibration
        self._answers = {key: iter(answers) for key, answers in (draws.answers if draws else {}).items()}  # fmt: skip

    def seconds(self, cobot: str, command: Mapping[str, Any], at: float) -> float | None:
        seconds = self._plant.seconds(cobot, command, at)
        if seconds is None:
            return None
        cost = self._calibration.step if "program" in command else self._calibration.call
        return seconds + cost

    def answer(
        self, cobot: str, command: Mapping[str, Any], rng: random.Random, at: float
    ) -> Mapping[str, Any] | None:
        recorded = next(self._answers.get((_actor(cobot), command["method"]), iter(())), None)
        if recorded is None:
            return self._plant.answer(cobot, command, rng, at)
        self._plant.saw(cobot, command, recorded, at)
        return recorded


class _Replayed:
    """An operator task's times as the run took them, one per start; `then` once they run out
    (a prediction whose cases went another way than the run's)."""

    def __init__(self, times: Sequence[float], then: Duration) -> None:
        self._times = iter(times)
        self._then = then
        self.mean = then.mean

    def sample(self, rng: random.Random) -> float:
        taken = next(self._times, None)
        return self._then.sample(rng) if taken is None else taken


def _actor(resource: str) -> str:
    """The actor of a prediction's resource key ("c", or "c.place-position" for its device)."""
    return resource.split(".", 1)[0]


def operator_durations(
    net: CaseNet, calibration: Calibration = Calibration(), draws: Draws | None = None
) -> dict[str, Duration]:
    """OPERATOR_TIME for every operator task of the pattern, shifted by the calibration's
    operator cost; the run's times (which hold that cost) where `draws` gives them."""
    shift = calibration.operator
    time = Triangular(*(value + shift for value in (OPERATOR_TIME.low, OPERATOR_TIME.mode, OPERATOR_TIME.high)))  # fmt: skip
    types = {actor.id: actor.type for actor in net.pattern.actors}
    durations: dict[str, Duration] = {}
    for _, transition in net.pattern.transitions():
        if transition.performer and types.get(transition.performer) == "operator":
            taken = draws.operator_times.get(transition.id) if draws else None
            # A duck-typed Duration: the engine only samples it.
            replayed = _Replayed(taken, time) if taken else None
            durations[transition.id] = cast(Duration, replayed) if replayed else time
    return durations


def predicted(
    net: CaseNet, per_round: int, cases: int, calibration: Calibration = Calibration(),
    draws: Draws | None = None,
) -> Prediction:  # fmt: skip
    scenario = _scenario(net, per_round, cases, calibration, draws)
    return predict(net, scenario, plant=lambda: _CalibratedPlant(calibration, draws))


def _scenario(
    net: CaseNet, per_round: int, cases: int, calibration: Calibration = Calibration(),
    draws: Draws | None = None,
) -> Scenario:  # fmt: skip
    return Scenario(
        cases=cases, parallel=per_round, seed=1,
        durations=operator_durations(net, calibration, draws),
        people={actor.id: None for actor in net.pattern.actors if actor.type == "operator"},
        handover=calibration.hop,
    )  # fmt: skip


# The real run ----------------------------------------------------------------------------------


def task_runs(case_ids: Sequence[int]) -> list[tuple[datetime, datetime, datetime, Any]]:
    """Each task run of the cases: (task-offered, task-started, task-completed, work item), in
    start order."""
    from hrc.cases.choices import EventType
    from hrc.cases.models import CaseEvent

    offered: dict[int, datetime] = {}
    began: dict[int, datetime] = {}
    runs: list[tuple[datetime, datetime, datetime, Any]] = []
    events = CaseEvent.objects.filter(
        case_id__in=case_ids, work_item__isnull=False,
        type__in=[EventType.TASK_OFFERED, EventType.TASK_STARTED, EventType.TASK_COMPLETED],
    ).select_related("work_item__job__cobot")  # fmt: skip
    for event in events.order_by("at", "seq"):
        item = event.work_item
        assert item is not None  # filtered so
        if event.type == EventType.TASK_OFFERED:
            offered[item.pk] = event.at
        elif event.type == EventType.TASK_STARTED:
            began[item.pk] = event.at
        elif item.pk in began:
            start = began.pop(item.pk)
            runs.append((offered.pop(item.pk, start), start, event.at, item))
    return sorted(runs, key=lambda run: run[1])


def cobot_busy(simulation: Any, case_ids: Sequence[int]) -> tuple[float, dict[str, float]]:
    """The cases' span (first started → last ended), and within it each cobot's busy seconds:
    the time its steps held it (task-started → task-completed, merged), as the prediction
    counts a cobot busy."""
    from hrc.analytics.metrics import covered_seconds
    from hrc.cases.models import Case

    cases = Case.objects.filter(pk__in=case_ids)
    window = (min(c.started_at for c in cases), max(c.ended_at or c.started_at for c in cases))
    span = (window[1] - window[0]).total_seconds()
    busy: dict[str, list[Any]] = {}
    suffix = f"-{simulation.organisation.slug}"
    for _, start, end, item in task_runs(case_ids):
        job = getattr(item, "job", None)
        if job is not None and job.device_id is None and job.cobot is not None:
            busy.setdefault(job.cobot.name.removesuffix(suffix), []).append((start, end))
    return span, {actor: covered_seconds(spans, window) for actor, spans in busy.items()}


def recorded(case_ids: Sequence[int], scale: float, suffix: str) -> tuple[Draws, Calibration]:
    """The run's draws, and its runtime costs: the hop from a task's offer to its start, and its
    steps' and device calls' costs beyond the plant's times. A cobot is named as in the
    prediction: its name without the organisation's `suffix`."""
    from hrc.cases.choices import WorkItemKind
    from hrc.cases.models import Interruption

    # A step a space constraint paused or slowed took longer for it: not a cost of the runtime.
    interrupted = set(Interruption.objects.filter(case_id__in=case_ids).values_list("work_item_id", flat=True))  # fmt: skip
    operator_times: dict[str, list[float]] = {}
    answers: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    costs: dict[str, list[float]] = {"step": [], "call": []}
    hops: list[float] = []
    plant = SimulatedPlant()  # the plan of each cobot's steps, in the order they ran
    for offered, started, completed, item in task_runs(case_ids):
        start, end = started.timestamp() / scale, completed.timestamp() / scale
        hops.append(start - offered.timestamp() / scale)
        if item.kind == WorkItemKind.OPERATOR:
            operator_times.setdefault(item.task, []).append(end - start)
            continue
        job = item.job
        cobot = job.cobot.name.removesuffix(suffix) if job.cobot else item.actor
        command = job.command
        if "method" in command and job.result:
            answers.setdefault((cobot, command["method"]), []).append(job.result)
        if command.get("method") == WAIT_PLACE:
            continue  # how long it waits is the sensor's, not a cost of the runtime
        planned = plant.seconds(cobot, command, start)
        if planned is not None and item.pk not in interrupted:
            costs["step" if "program" in command else "call"].append(end - start - planned)
    # The mean, not the median: a cobot's utilisation adds its steps' times up.
    step, call = (statistics.fmean(costs[kind]) if costs[kind] else 0.0 for kind in ("step", "call"))  # fmt: skip
    # The median: a task that waited its turn on a busy cobot waited for what the prediction
    # models; most start as soon as the runtime lets them.
    hop = statistics.median(hops) if hops else 0.0
    took = [t for times in operator_times.values() for t in times]
    operator = statistics.fmean(took) - OPERATOR_TIME.mean if took else 0.0
    return Draws(operator_times, answers), Calibration(hop, step, call, operator)


def measure_use_case(
    path: Path, workdir: Path, settings: Settings, progress: Callable[[str], None]
) -> dict[str, Any]:
    from hrc.cases.simulation import Simulation

    document = json.loads(path.read_text())
    net = CaseNet(read_pattern(document))
    per_round = max(len(case_variants(document.get("simulation"), net)), 1)
    folder = workdir / path.stem
    folder.mkdir()
    case_ids: list[int] = []
    rounds: list[tuple[float, dict[str, float]]] = []
    with Simulation(
        document, folder, time_scale=settings.time_scale, inline=False, seed=7,
        durations=operator_durations(net),
    ) as simulation:  # fmt: skip
        for number in range(settings.rounds):
            progress(f"{path.stem}: round {number + 1} of {settings.rounds} ...")
            with simulation.running():
                ids = simulation.start_cases(per_round)
                ended = simulation.wait(ids, timeout=CASE_TIMEOUT)
            case_ids += ids
            rounds.append(cobot_busy(simulation, ids))
            if not ended:
                break
        suffix = f"-{simulation.organisation.slug}"
        draws, costs = recorded(case_ids, settings.time_scale, suffix)
        cases = [case_times(case_id) for case_id in case_ids]
    return compare(path, document, net, per_round, settings, cases, rounds, draws, costs)


def compare(
    path: Path, document: Mapping[str, Any], net: CaseNet, per_round: int, settings: Settings,
    cases: Sequence[Mapping[str, Any]], rounds: Sequence[tuple[float, Mapping[str, float]]], draws: Draws,
    costs: Calibration,
) -> dict[str, Any]:  # fmt: skip
    """The real run's figures beside the three predictions': plain; calibrated (the runtime's
    costs added); and replayed (calibrated, with the run's own draws, over its cases)."""
    scale = settings.time_scale
    done = [case for case in cases if case["completed"]]
    real: dict[str, Any] = {"cases": len(cases), "completed": len(done)}
    row: dict[str, Any] = {"file": path.name, "name": document["name"], "real": real}
    if not done:
        return row
    hop = costs.hop
    cobots = sorted({actor for _, busy in rounds for actor in busy})
    span = sum(seconds for seconds, _ in rounds)
    cycles = [case["cycle_s"] / scale for case in done]
    real |= {
        "cycle_p50": statistics.median(cycles),
        "cycle_p50_interval": median_interval(cycles),
        "busy_p50": statistics.median(case["busy_s"] for case in done) / scale,
        "hop": hop,
        "step_cost": costs.step,
        "call_cost": costs.call,
        "utilisation": {
            a: sum(busy.get(a, 0.0) for _, busy in rounds) / span if span else 0.0 for a in cobots
        },
    }
    for name, hop_added, prediction in (
        ("predicted", 0.0, predicted(net, per_round, PREDICTED_CASES)),
        ("calibrated", hop, predicted(net, per_round, PREDICTED_CASES, costs)),
        ("replayed", hop, predicted(net, per_round, len(cases), costs, draws)),
    ):
        cycle = prediction.cycle_time.p50 if prediction.cycle_time else None
        utilisation = cobot_shares(prediction, hop_added)
        errors = {a: utilisation.get(a, 0.0) - real["utilisation"][a] for a in cobots}
        cycle_error = None if cycle is None else cycle / real["cycle_p50"] - 1
        low, high = real["cycle_p50_interval"]
        row[name] = {
            "cycle_p50": cycle, "cycle_error": cycle_error, "utilisation": utilisation,
            "utilisation_error_points": {a: e * 100 for a, e in errors.items()},
            "stuck": prediction.stuck_count,
            "cycle_ok": cycle_error is not None and abs(cycle_error) <= CYCLE_TOLERANCE,
            "cycle_in_interval": cycle is not None and low <= cycle <= high,
            "utilisation_ok": all(abs(e) <= UTILISATION_TOLERANCE for e in errors.values()),
        }  # fmt: skip
    return row


def cobot_shares(prediction: Prediction, hop: float) -> dict[str, float]:
    """Each cobot's predicted utilisation, less the handover (`hop`) before each of its steps'
    work: the time between two tasks, which holds no cobot at run time."""
    return {
        load.actor: max(load.busy_seconds - hop * load.work_items, 0.0) / load.busy_seconds * load.utilisation
        if load.busy_seconds > 0 else 0.0
        for load in prediction.actors if load.kind == "cobot"
    }  # fmt: skip


def median_interval(values: Sequence[float], draws: int = 2000) -> tuple[float, float]:
    """The 90 % bootstrap interval of the median of `values`: how far the real cycle's p50
    could be from the pattern's own, by chance alone, over so few cases."""
    rng = random.Random(0)
    medians = sorted(statistics.median(rng.choices(values, k=len(values))) for _ in range(draws))
    return medians[int(0.05 * draws)], medians[int(0.95 * draws) - 1]


# The speed row ---------------------------------------------------------------------------------


def speed(cases: int) -> dict[str, Any]:
    """The largest use case (by tasks), `cases` cases predicted, against a bare event loop."""
    documents = [json.loads(path.read_text()) for path in use_case_files()]
    nets = [CaseNet(read_pattern(document)) for document in documents]
    net = max(nets, key=lambda n: sum(1 for _, t in n.pattern.transitions() if t.performer))
    per_round = max(len(case_variants(net.pattern.extra.get("simulation"), net)), 1)
    scenario = _scenario(net, per_round, cases)
    began = time.process_time()
    prediction = predict(net, scenario, plant=SimulatedPlant)  # as the product predicts
    seconds = time.process_time() - began
    floor = _bare_event_loop(prediction.events)
    return {
        "use_case": net.pattern.name,
        "tasks": sum(1 for _, t in net.pattern.transitions() if t.performer),
        "cases": cases,
        "events": prediction.events,
        "seconds": seconds,
        "floor_seconds": floor,
        "ratio": seconds / floor if floor else None,
    }


def _bare_event_loop(events: int) -> float:
    """CPU seconds to push and pop `events` timed events through a heap, 100 in flight."""
    rng = random.Random(0)
    heap = [(rng.random(), index) for index in range(100)]
    heapq.heapify(heap)
    began = time.process_time()
    for index in range(events):
        at, _ = heapq.heappop(heap)
        heapq.heappush(heap, (at + rng.random(), index))
    return time.process_time() - began


# Report ----------------------------------------------------------------------------------------


def run(settings: Settings, progress: Callable[[str], None] = print) -> dict[str, Any]:
    from bench.runtime import machine

    files = use_case_files(settings.only)
    load_before = load_average()
    with rig(use_cases.Settings(workers=settings.workers), progress) as workdir:
        host = machine()
        results = [measure_use_case(path, workdir, settings, progress) for path in files]
    progress(f"speed: {settings.speed_cases} cases ...")
    report = {
        "benchmark": "prediction",
        "when": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": host,
        "load_average": {"before": load_before, "after": load_average()},
        "settings": settings_json(settings),
        "operator_time": OPERATOR_TIME.as_dict(),
        "predicted_cases": PREDICTED_CASES,
        "use_cases": results,
        "speed": speed(settings.speed_cases),
    }
    write_results(settings.results_dir, "prediction", report)
    return report


def print_table(report: Mapping[str, Any]) -> None:
    settings = report["settings"]
    print(
        f"\nPrediction against real runs: {settings['rounds']} round(s) each at time scale "
        f"{settings['time_scale']:g}; simulated seconds. Predicted and calibrated (+ the run's hop "
        f"per task, step and call costs): {report['predicted_cases']} cases each; replayed: the "
        "calibrated one over the run's cases with the run's operator times and device answers. "
        "The real p50's 90 % interval is what chance alone allows over so few cases."
    )
    print(f"{'use case':34} {'cases':>5} {'cycle':>7} {'90 % interval':>15} {'pred.':>7} {'err %':>6} "
          f"{'calib.':>7} {'err %':>6} {'replay':>7} {'err %':>6}  {'hop/step/call':>14}  "
          "cobot utilisation real / calib. / replay (err points)")  # fmt: skip
    for row in report["use_cases"]:
        real = row["real"]
        label = row["file"].removesuffix(".json").replace("_", " ")
        cases = f"{real['completed']}/{real['cases']}"
        if not real["completed"]:
            print(f"{label:34} {cases:>5}  no case completed")
            continue
        plain, calibrated, replayed = row["predicted"], row["calibrated"], row["replayed"]
        low, high = real["cycle_p50_interval"]
        cobots = "; ".join(
            f"{actor} {share * 100:.0f}/{calibrated['utilisation'].get(actor, 0) * 100:.0f}"
            f"/{replayed['utilisation'].get(actor, 0) * 100:.0f} "
            f"({calibrated['utilisation_error_points'][actor]:+.1f}/{replayed['utilisation_error_points'][actor]:+.1f})"
            for actor, share in real["utilisation"].items()
        )  # fmt: skip
        costs = f"{real['hop']:.2f}/{real['step_cost']:.2f}/{real['call_cost']:.2f}"
        verdict = "ok" if replayed["cycle_ok"] and replayed["utilisation_ok"] else "MISS"
        print(f"{label:34} {cases:>5} {real['cycle_p50']:7.1f} {f'{low:.1f}–{high:.1f}':>15} "
              f"{_figure(plain['cycle_p50'])} {_percent(plain['cycle_error'])} "
              f"{_figure(calibrated['cycle_p50'])} {_percent(calibrated['cycle_error'])} "
              f"{_figure(replayed['cycle_p50'])} {_percent(replayed['cycle_error'])}  "
              f"{costs:>14}  {cobots}  {verdict}")  # fmt: skip
    s = report["speed"]
    print(f"speed: {s['cases']} cases of {s['use_case']} ({s['tasks']} tasks): {s['seconds']:.2f} s "
          f"CPU, {s['events']} events; a bare heapq loop over as many events {s['floor_seconds']:.3f} s "
          f"(× {s['ratio']:.0f})")  # fmt: skip
    print_load(report)


def _figure(value: float | None) -> str:
    return f"{value:7.1f}" if value is not None else f"{'-':>7}"


def _percent(value: float | None) -> str:
    return f"{value * 100:+6.1f}" if value is not None else f"{'-':>6}"


def parse_args(argv: Sequence[str] | None = None) -> Settings:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help=f"a small run: {QUICK}")
    use_cases.add_run_options(parser, rounds=Settings.rounds)
    arguments = parser.parse_args(argv)
    settings = replace(Settings(), quick=arguments.quick, results_dir=arguments.results_dir)
    if arguments.quick:
        settings = replace(settings, **QUICK)
    result: Settings = use_cases.apply_run_options(parser, arguments, settings, ("rounds",))
    return result


def main(argv: Sequence[str] | None = None) -> None:
    settings = parse_args(argv)
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    report = run(settings, progress=lambda line: print(line, file=sys.stderr, flush=True))
    print_table(report)


if __name__ == "__main__":
    main()
