"""What each task does when a case runs it: the `task` key of a transition, and guards and messages.

A transition of an `hrc-pattern/1` document may carry, beside the formal model:

- `"task"` on a task (a transition with a performer):
  - operator tasks: `instructions` (text), `form` (a JSON Schema object the
    completion's data must satisfy; the data is stored as the operator gave
    it: a required field has no value until answered, and a field's
    `default` is only what the tablet shows filled in on an optional field);
  - cobot tasks, either a program step
    `"step": {"program": "Coexistence_PickAndPlace", "number": 2, "workspace": 0, "poses": [[x, y, z, rx, ry, rz]]}`
    or a device call `"device": {"call": "part-detection.scan", "args": {}}`;
    a cobot task with neither runs step 1 of its actor's program (the actor's
    `"program"` key); a step that names no program, neither itself nor through
    its actor, is a `task-config` error: there is no default program;
  - any task: `outputs` (`{"case key": "expression over result and data"}`;
    without it the whole result is stored under the task's id), `timeout`
    (seconds) and `retries` (automatic retries of a cobot or device task).
- `"guard"` on a silent transition: an expression over `data`; a silent
  transition fires at once only when its guard holds.
- `"message"` on a silent transition: `{"name": "...", "correlation": {"key": "expression"}}`;
  it fires when a matching message arrives (POST /api/messages/, or one a case
  sent), never by itself.
- `"send"` on a task (sent when it completes) or a silent transition (sent when
  it fires): `{"name": "...", "correlation": {"key": value}, "payload": {"key": value}}`;
  a message that correlates like one from outside, to another case or to
  another process of the same case.
- `"timer"` on a silent transition: an ISO 8601 duration (`"PT5M"`); it fires
  once it has been enabled that long without interruption, never by itself
  before; not together with a guard or a message.
- `"cancels"` on a silent transition: the ids of places and tasks of its own
  process that it empties when it fires (a running task is cancelled).

Message correlation and send expressions read `case` (its `id` and
`reference`) besides `data`: `=case.id` keeps a message inside its case.

An actor may carry `"device": "<kind>"` (a cobot actor only): a device actor, whose lane holds
device calls of that kind only (a linear axis beside the cobots); DEVICE_KINDS are the calls'
prefixes.

And the document itself may carry `"data"`: a JSON object every case's data
starts with (the use case's settings: poses, spots, task lists); the data a
case is started with is laid over it, key by key.

Configuration values are literals or expressions (a string starting with "=",
see expressions.py), resolved against the case data when the task starts.
"""

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any, Final, Literal

from hrc.engine import expressions
from hrc.engine.issues import Issue, error
from hrc.engine.model import Actor, Pattern, Process, Transition
from hrc.engine.wording import Names, sentence

TaskKind = Literal["operator", "step", "device"]

DEFAULT_TIMEOUT: Final = 120.0
DEFAULT_RETRIES: Final = 3
POSE_LENGTH: Final = 6
MAX_POSES: Final = 2  # Double24–35 hold two poses

# Device calls an automated task can make: the gateway method under Devices/,
# its arguments in order, and the names its outputs get in the result.
DEVICE_CALLS: Final[Mapping[str, tuple[str, tuple[str, ...], tuple[str, ...]]]] = {
    "linear-axis.move": ("Devices/LinearAxis/Move", ("direction", "duration_ms"), ()),
    "part-detection.scan": ("Devices/PartDetection/Scan", (), ("detected", "pose")),
    "inspection.inspect": ("Devices/Inspection/Inspect", ("spot",), ("result",)),
    "display.show": ("Devices/Display/Show", ("text",), ()),
    "recognition.gesture": ("Devices/Recognition/Gesture", ("gesture",), ("detected",)),
    "recognition.face": ("Devices/Recognition/Face", (), ("authorized",)),
    "recognition.screws": ("Devices/Recognition/Screws", ("expected",), ("found",)),
    "place-position.check": ("Devices/PlacePosition/Check", (), ("free",)),
    "place-position.wait": ("Devices/PlacePosition/WaitUntilFree", ("timeout_ms",), ("free",)),
}

# The kinds of device (a device actor's `"device"` key, a registered device's kind): the
# calls' prefixes, "linear-axis" for "linear-axis.move".
DEVICE_KINDS: Final = tuple(sorted({call.split(".")[0] for call in DEVICE_CALLS}))

# How a space constraint interrupts the cobot (its "interrupt" key); pause by default.
INTERRUPT_MODES: Final = ("pause", "slow")
# The "interrupt" modes per pair of actor types (the pair sorted), the first the default:
# beside an operator a cobot pauses or slows; of two cobots the later step waits for the
# area or pauses the running one; two operators have no choice (the second is refused).
SPACE_MODES: Final[dict[tuple[str, str], tuple[str, ...]]] = {
    ("cobot", "operator"): INTERRUPT_MODES,
    ("cobot", "cobot"): ("wait", "pause"),
    ("operator", "operator"): ("wait",),
}

# Names expressions may use: case data everywhere, a task's result in its outputs, the case
# itself (id, reference) in what messages carry and match, so a case can address its own.
DATA_NAMES: Final = frozenset({"data"})
OUTPUT_NAMES: Final = frozenset({"data", "result"})
MESSAGE_NAMES: Final = frozenset({"data", "case"})


@dataclass(frozen=True)
class StepConfig:
    program: str
    number: Any
    workspace: Any = 0
    poses: Any = ()


@dataclass(frozen=True)
class DeviceConfig:
    call: str
    args: Mapping[str, Any] = field(default_factory=dict)

    @property
    def method(self) -> str:
        return DEVICE_CALLS[self.call][0]

    @property
    def argument_names(self) -> tuple[str, ...]:
        return DEVICE_CALLS[self.call][1]

    @property
    def output_names(self) -> tuple[str, ...]:
        return DEVICE_CALLS[self.call][2]


@dataclass(frozen=True)
class TaskConfig:
    kind: TaskKind
    instructions: str = ""
    form: Mapping[str, Any] | None = None
    step: StepConfig | None = None
    device: DeviceConfig | None = None
    outputs: Mapping[str, str] | None = None
    timeout: float = DEFAULT_TIMEOUT
    retries: int = DEFAULT_RETRIES


class ConfigError(ValueError):
    """A task, guard or message configuration is wrong; the message names the transition."""

    def __init__(self, transition: str, message: str) -> None:
        super().__init__(f"{transition}: {message}")
        self.transition = transition
        self.problem = message


def task_config(pattern: Pattern, transition: Transition) -> TaskConfig:
    """The configuration of a task; raises ConfigError when it is malformed."""
    raw = transition.extra.get("task", {})
    t = transition.id
    if not isinstance(raw, Mapping):
        raise ConfigError(t, "'task' must be an object.")
    actor = pattern.actor(transition.performer or "")
    common = _common(t, raw)
    if actor is None or actor.type == "operator":
        form = raw.get("form")
        if form is not None and (not isinstance(form, Mapping) or form.get("type") != "object"):
            raise ConfigError(t, '\'form\' must be a JSON Schema object with "type": "object".')
        for key in ("step", "device"):
            if key in raw:
                raise ConfigError(t, f"an operator task has no '{key}'; only cobot tasks do.")
        return TaskConfig("operator", form=form, **common)
    if "step" in raw and "device" in raw:
        raise ConfigError(t, "a cobot task runs either a 'step' or a 'device' call, not both.")
    if "device" in actor.extra:
        return TaskConfig("device", device=_device_actor_call(t, raw, actor), **common)
    if "device" in raw:
        return TaskConfig("device", device=_device(t, raw["device"]), **common)
    actor_program = actor.extra.get("program")
    return TaskConfig("step", step=_step(t, raw.get("step", {}), actor, actor_program), **common)


def _common(t: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    instructions = raw.get("instructions", "")
    if not isinstance(instructions, str):
        raise ConfigError(t, "'instructions' must be text.")
    outputs = raw.get("outputs")
    if outputs is not None:
        if not isinstance(outputs, Mapping) or not all(
            isinstance(v, str) for v in outputs.values()
        ):
            raise ConfigError(t, "'outputs' must map case data keys to expressions.")
        for key, text in outputs.items():
            _check_expression(t, f"output {key!r}", text, OUTPUT_NAMES)
    timeout = raw.get("timeout", DEFAULT_TIMEOUT)
    if (
        isinstance(timeout, bool)
        or not isinstance(timeout, int | float)
        or not 0 < timeout <= 86_400
    ):
        raise ConfigError(t, "'timeout' must be a number of seconds between 0 and 86400.")
    retries = raw.get("retries", DEFAULT_RETRIES)
    if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= 20:
        raise ConfigError(t, "'retries' must be a whole number from 0 to 20.")
    return {
        "instructions": instructions,
        "outputs": outputs,
        "timeout": float(timeout),
        "retries": retries,
    }


def _step(t: str, raw: object, actor: Actor, actor_program: object) -> StepConfig:
    if not isinstance(raw, Mapping):
        raise ConfigError(t, "'step' must be an object.")
    program = raw.get("program", actor_program)
    if program is None:
        # No default: a cobot running another pattern's program by surprise is a hazard.
        raise ConfigError(
            t,
            f"the cobot task names no program: give its 'step' a 'program', or its actor "
            f'{actor.id!r} a "program" key.',
        )
    if not isinstance(program, str) or not program:
        raise ConfigError(t, "the step's 'program' must be a program name.")
    number = raw.get("number", 1)
    workspace = raw.get("workspace", 0)
    poses = raw.get("poses", [])
    for name, value in (("number", number), ("workspace", workspace)):
        if not expressions.is_expression(value) and (
            isinstance(value, bool) or not isinstance(value, int) or value < 0
        ):
            raise ConfigError(
                t, f"the step's '{name}' must be a whole number ≥ 0 or an expression."
            )
        _check_value(t, f"step {name}", value)
    if expressions.is_expression(poses):
        _check_value(t, "step poses", poses)
    elif not isinstance(poses, list) or len(poses) > MAX_POSES:
        raise ConfigError(t, f"the step's 'poses' must be a list of at most {MAX_POSES} poses.")
    else:
        for pose in poses:
            _check_pose(t, pose)
    return StepConfig(program, number, workspace, poses)


def _check_pose(t: str, pose: object) -> None:
    if expressions.is_expression(pose):
        _check_value(t, "a pose", pose)
        return
    if not isinstance(pose, list) or len(pose) != POSE_LENGTH:
        raise ConfigError(t, f"each pose is a list of {POSE_LENGTH} numbers (x, y, z, rx, ry, rz).")
    for value in pose:
        if expressions.is_expression(value):
            _check_value(t, "a pose value", value)
        elif isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(t, f"pose values are numbers, not {value!r}.")


def _device(t: str, raw: object) -> DeviceConfig:
    # The isinstance check first: `in` on a dict raises TypeError for a list or object.
    if (
        not isinstance(raw, Mapping)
        or not isinstance(raw.get("call"), str)
        or raw["call"] not in DEVICE_CALLS
    ):
        raise ConfigError(t, f"'device' needs a 'call', one of {', '.join(DEVICE_CALLS)}.")
    call = str(raw["call"])
    args = raw.get("args", {})
    expected = DEVICE_CALLS[call][1]
    if not isinstance(args, Mapping) or set(args) != set(expected):
        wanted = ", ".join(expected) or "none"
        raise ConfigError(t, f"the device call {call} takes the arguments: {wanted}.")
    for name, value in args.items():
        _check_value(t, f"argument {name!r}", value)
    return DeviceConfig(call, args)


def _device_actor_call(t: str, raw: Mapping[str, Any], actor: Actor) -> DeviceConfig:
    """A task of a device actor's lane: a call of the actor's kind, nothing else."""
    kind = device_kind_of(actor)
    if kind is None:
        raise ConfigError(
            t, f"its actor {actor.id!r} has device {actor.extra['device']!r}; it must be one of "
            f"{', '.join(DEVICE_KINDS)}.",
        )  # fmt: skip
    if "device" not in raw:
        raise ConfigError(
            t, f"the device actor {actor.id!r} runs device calls only: give the task a "
            f"'device' call of {kind}.",
        )  # fmt: skip
    config = _device(t, raw["device"])
    if config.call.split(".")[0] != kind:
        raise ConfigError(
            t, f"the device actor {actor.id!r} is a {kind}; it cannot run {config.call}.",
        )  # fmt: skip
    return config


def _wrong_device_actor(actor: Actor) -> str:
    if actor.type != "cobot":
        return f"The actor {actor.id} is an {actor.type}; only a cobot actor is a device actor."
    return (
        f"The actor {actor.id} has device {actor.extra['device']!r}; it must be one of "
        f"{', '.join(DEVICE_KINDS)}."
    )


def device_kind_of(actor: Actor) -> str | None:
    """The kind of device a device actor stands for (its "device" key); None for another actor
    or an unknown kind."""
    kind = actor.extra.get("device")
    return kind if actor.type == "cobot" and kind in DEVICE_KINDS else None


def device_kinds_called(pattern: Pattern) -> dict[str, set[str]]:
    """The kinds of device each cobot actor's lane calls (device actors left out: their lane is
    their own device's); a task whose configuration is malformed calls none."""
    called: dict[str, set[str]] = {}
    for _, transition in pattern.transitions():
        actor = pattern.actor(transition.performer or "")
        if actor is None or actor.type != "cobot" or "device" in actor.extra:
            continue
        try:
            config = task_config(pattern, transition)
        except ConfigError:
            continue
        if config.device is not None:
            called.setdefault(actor.id, set()).add(config.device.call.split(".")[0])
    return called


def _check_value(t: str, what: str, value: object, names: frozenset[str] = DATA_NAMES) -> None:
    if expressions.is_expression(value):
        _check_expression(t, what, str(value)[1:], names)


def _check_expression(t: str, what: str, text: str, names: frozenset[str]) -> None:
    problem = expressions.check(text, names)
    if problem is not None:
        raise ConfigError(t, f"{what}: {problem}")


@dataclass(frozen=True)
class MessageConfig:
    name: str
    correlation: Mapping[str, str]


@dataclass(frozen=True)
class SendConfig:
    """A message a transition sends: its values are literals or "=expressions" (MESSAGE_NAMES)."""

    name: str
    correlation: Mapping[str, Any]
    payload: Mapping[str, Any]


def guard_of(transition: Transition) -> str | None:
    """The guard expression of a silent transition, None when it has none."""
    guard = transition.extra.get("guard")
    if guard is None:
        return None
    if not isinstance(guard, str) or not guard.strip():
        raise ConfigError(transition.id, "'guard' must be an expression.")
    _check_expression(transition.id, "guard", guard, DATA_NAMES)
    return guard


def message_of(transition: Transition) -> MessageConfig | None:
    """What message a silent transition waits for, None when it waits for none."""
    raw = transition.extra.get("message")
    if raw is None:
        return None
    t = transition.id
    if not isinstance(raw, Mapping) or not isinstance(raw.get("name"), str) or not raw["name"]:
        raise ConfigError(t, "'message' needs a 'name'.")
    correlation = raw.get("correlation", {})
    if not isinstance(correlation, Mapping) or not all(
        isinstance(v, str) for v in correlation.values()
    ):
        raise ConfigError(
            t, "the message's 'correlation' maps keys to expressions over data and case."
        )
    for key, text in correlation.items():
        _check_expression(t, f"correlation {key!r}", text, MESSAGE_NAMES)
    return MessageConfig(raw["name"], correlation)


def send_of(transition: Transition) -> SendConfig | None:
    """What message a transition sends when it completes or fires, None when it sends none."""
    raw = transition.extra.get("send")
    if raw is None:
        return None
    t = transition.id
    if not isinstance(raw, Mapping):
        raise ConfigError(t, "'send' must be an object with a 'name'.")
    unknown = sorted(set(raw) - {"name", "correlation", "payload"})
    if unknown:
        raise ConfigError(t, f"'send' has no key {unknown[0]!r} (name, correlation, payload).")
    if not isinstance(raw.get("name"), str) or not raw["name"].strip():
        raise ConfigError(t, "'send' needs a 'name': the message's name.")
    parts = {key: raw.get(key, {}) for key in ("correlation", "payload")}
    for key, values in parts.items():
        if not isinstance(values, Mapping):
            raise ConfigError(t, f"the 'send' {key!r} must map keys to values or expressions.")
        for name, value in values.items():
            _check_nested(t, f"send {key} {name!r}", value)
    return SendConfig(raw["name"], parts["correlation"], parts["payload"])


# PnW, or PnDTnHnMnS with any part left out; a part may have a fraction (PT0.5S, P1,5D).
_NUMBER = r"(\d+(?:[.,]\d+)?)"
_DURATION = re.compile(
    rf"P(?:{_NUMBER}W|(?:{_NUMBER}D)?(?:T(?=\d)(?:{_NUMBER}H)?(?:{_NUMBER}M)?(?:{_NUMBER}S)?)?)"
)
_YEARS_OR_MONTHS = re.compile(r"P[^T]*[YM].*")
_MILLISECONDS = (7 * 86_400_000, 86_400_000, 3_600_000, 60_000, 1000)  # W, D, H, M, S
MAX_TIMER_MS: Final = 366 * 86_400_000


def parse_duration(text: str) -> int:
    """An ISO 8601 duration (`PT5M`, `P1DT2H`, `PT0.5S`, `P2W`) in milliseconds.

    Raises ValueError with a message a person can act on: years and months are
    refused, having no fixed length, and so is anything longer than a year."""
    written = text.strip().upper()
    match = _DURATION.fullmatch(written)
    if match is None or not any(match.groups()):
        if _YEARS_OR_MONTHS.fullmatch(written):
            raise ValueError(
                f"{text!r} counts years or months, which have no fixed length; "
                "write the duration in weeks, days, hours, minutes and seconds (P30D)."
            )
        raise ValueError(
            f"{text!r} is not an ISO 8601 duration such as PT5M (5 minutes), PT30S or P1DT2H."
        )
    total = sum(
        (
            Decimal(part.replace(",", ".")) * unit
            for part, unit in zip(match.groups(), _MILLISECONDS, strict=True)
            if part is not None
        ),
        Decimal(0),
    )
    if total > MAX_TIMER_MS:
        raise ValueError(f"{text!r} is longer than a year; a timer waits at most P366D.")
    return int(total.to_integral_value())


def timer_of(transition: Transition) -> int | None:
    """How long a silent transition waits once enabled, in milliseconds; None without a timer."""
    raw = transition.extra.get("timer")
    if raw is None:
        return None
    if not isinstance(raw, str):
        raise ConfigError(transition.id, "'timer' must be an ISO 8601 duration such as \"PT5M\".")
    try:
        return parse_duration(raw)
    except ValueError as problem:
        raise ConfigError(transition.id, f"'timer': {problem}") from None


def cancels_of(process: Process, transition: Transition) -> tuple[str, ...]:
    """The places and tasks of `process` that a silent transition empties when it fires,
    as written; () without `cancels`.

    Raises ConfigError for a value that is no list of ids, or an id that is no
    place or transition of the process. A silent transition may be named too
    (an importer may list a whole region); it holds nothing, so that changes nothing.
    """
    raw = transition.extra.get("cancels")
    if raw is None:
        return ()
    t = transition.id
    if not isinstance(raw, list) or not all(isinstance(node, str) for node in raw):
        raise ConfigError(t, "'cancels' must be a list of place and task ids.")
    nodes = {p.id for p in process.places} | {n.id for n in process.transitions}
    foreign = [node for node in raw if node not in nodes]
    if foreign:
        raise ConfigError(
            t,
            f"'cancels' names {', '.join(repr(n) for n in foreign)}, which "
            f"{'is' if len(foreign) == 1 else 'are'} no place or task of its process "
            f"{process.id}: a transition cancels work of its own process only.",
        )
    return tuple(dict.fromkeys(raw))


def _check_nested(t: str, what: str, value: object) -> None:
    """A send value's expressions, also inside lists and objects, as resolve() will find them."""
    if isinstance(value, list):
        for item in value:
            _check_nested(t, what, item)
    elif isinstance(value, Mapping):
        for item in value.values():
            _check_nested(t, what, item)
    else:
        _check_value(t, what, value, MESSAGE_NAMES)


def initial_data(pattern: Pattern) -> dict[str, Any]:
    """The data every case of the pattern starts with: its `data` object, {} without one.

    Raises ConfigError (naming "data") when it is not a JSON object.
    """
    raw = pattern.extra.get("data", {})
    if not isinstance(raw, Mapping) or not all(isinstance(key, str) for key in raw):
        raise ConfigError("data", "the pattern's 'data', what each case starts with, must be a JSON object.")  # fmt: skip
    return dict(raw)


def space_modes(pattern: Pattern, first: str, second: str) -> tuple[str, ...]:
    """The "interrupt" modes a space constraint between these tasks may have, the default
    first; () when either is not a task of an operator or a cobot."""
    performers = {t.id: t.performer for _, t in pattern.transitions()}
    actors = [pattern.actor(performers.get(task) or "") for task in (first, second)]
    kinds = sorted(actor.type for actor in actors if actor is not None)
    return SPACE_MODES.get((kinds[0], kinds[1]), ()) if len(kinds) == 2 else ()


def _device_end(pattern: Pattern, tasks: list[str]) -> str | None:
    """The device actor performing one of `tasks`, if one does."""
    for task in tasks:
        transition = pattern.transition(task)
        actor = pattern.actor(transition.performer or "") if transition else None
        if actor is not None and "device" in actor.extra:
            return actor.id
    return None


# The keys only a silent transition may carry.
SILENT_KEYS: Final = ("guard", "message", "timer", "cancels")


def _check_silent(process: Process, transition: Transition) -> None:
    if "task" in transition.extra:
        raise ConfigError(transition.id, "a silent transition runs no 'task'.")
    send_of(transition)
    cancels_of(process, transition)
    guard, message = guard_of(transition), message_of(transition)
    if guard is not None and message is not None:
        raise ConfigError(
            transition.id,
            "a transition waits for a message or has a guard, not both: "
            "put the guard on a silent transition after it.",
        )
    if timer_of(transition) is not None and (guard is not None or message is not None):
        raise ConfigError(
            transition.id,
            f"a transition waits for a timer or {'a message' if message else 'has a guard'}, "
            "not both: put the other on a silent transition of its own.",
        )


def config_issues(pattern: Pattern) -> list[Issue]:
    """Every malformed task, guard, message, timer or cancels configuration, as `task-config` errors."""
    issues = []
    names = Names(pattern)
    try:
        initial_data(pattern)
    except ConfigError as problem:
        issues.append(error("task-config", str(problem)))
    for process, transition in pattern.transitions():
        try:
            if transition.is_task:
                for key in SILENT_KEYS:
                    if key in transition.extra:
                        raise ConfigError(transition.id, f"only silent transitions have a '{key}'.")
                task_config(pattern, transition)
                send_of(transition)
            else:
                _check_silent(process, transition)
        except ConfigError as problem:
            where = sentence(names.node(transition.id))
            issues.append(error("task-config", f"{where}: {problem.problem}", transition.id))
    for actor in pattern.actors:
        if "device" in actor.extra and device_kind_of(actor) is None:
            issues.append(error("task-config", _wrong_device_actor(actor)))
    for constraint in pattern.constraints:
        if constraint.type == "space" and (device := _device_end(pattern, constraint.elements)):
            # A call cannot be paused or slowed, and a space constraint does not hold one back.
            issues.append(
                error(
                    "task-config",
                    f"The space constraint {names.name(constraint.source)} → "
                    f"{names.name(constraint.target)} ends at a call of the device actor "
                    f"{device!r}: a device call is neither paused nor kept waiting for a shared "
                    "area. Order it with a time constraint instead.",
                    constraint.source,
                    constraint.target,
                )
            )
            continue
        modes = space_modes(pattern, constraint.source, constraint.target)
        mode = constraint.extra.get("interrupt", modes[0] if modes else "pause")
        if constraint.type == "space" and modes and mode not in modes:
            issues.append(
                error(
                    "task-config",
                    f"The space constraint {names.name(constraint.source)} → "
                    f"{names.name(constraint.target)} has "
                    f"interrupt {mode!r}; it must be one of {', '.join(modes)}.",
                    constraint.source,
                    constraint.target,
                )
            )
    return issues
