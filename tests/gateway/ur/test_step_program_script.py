"""hrc_step_program.script agrees with protocol.py, urua.py, the fake and REGISTERS.md.

There is no URScript interpreter here, so the script is parsed: its blocks
must close, every hrc_ function it calls must exist, and the registers,
outcome codes and constants it uses must be the ones the gateway and its docs
name. A typo in a register number would otherwise reach a robot untested.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from hrc_gateway import urua
from hrc_gateway.ur import protocol
from tests.gateway.fake_ur.controller import SEEN_TOKENS

FOLDER = Path(protocol.__file__).parent
SCRIPT = (FOLDER / "hrc_step_program.script").read_text()
REGISTERS_MD = (FOLDER / "REGISTERS.md").read_text()


def code_lines() -> list[tuple[int, str]]:
    """(indentation, statement) for every line of code, comments removed."""
    lines = []
    for raw in SCRIPT.splitlines():
        code = raw.split("#", 1)[0].rstrip()
        if code.strip():
            lines.append((len(code) - len(code.lstrip()), code.strip()))
    return lines


def registers(function: str) -> set[int]:
    """Register numbers passed to a URScript register function, `42 + j` read as 42–46."""
    numbers: set[int] = set()
    for argument in re.findall(rf"\b{function}\((\d+(?: \+ j)?)", SCRIPT):
        base = int(argument.split()[0])
        numbers |= set(range(base, base + protocol.DATA_CHUNK)) if "+ j" in argument else {base}
    return numbers


def function_body(name: str) -> str:
    match = re.search(rf"^def {name}\(.*?^end$", SCRIPT, re.MULTILINE | re.DOTALL)
    assert match is not None, f"{name} is not defined at the top level"
    return match[0]


def test_every_block_is_closed_by_an_end_at_its_own_indentation() -> None:
    open_blocks: list[tuple[int, str]] = []
    for indent, code in code_lines():
        keyword = code.split()[0].rstrip(":")
        if keyword in ("elif", "else"):
            assert open_blocks[-1:] == [(indent, "if")], code
        elif keyword == "end":
            assert open_blocks, "an end without a block"
            assert open_blocks.pop()[0] == indent, (
                f"end at indentation {indent} closes another block"
            )
        elif keyword in ("def", "if", "while"):
            assert code.endswith(":"), code
            open_blocks.append((indent, keyword))
    assert open_blocks == []


def test_every_hrc_function_called_is_defined_and_there_are_no_threads() -> None:
    defined = set(re.findall(r"^\s*def (hrc_\w+)\(", SCRIPT, re.MULTILINE))
    called = set(re.findall(r"\b(hrc_\w+)\(", SCRIPT)) - defined

    assert called == set()
    assert {"hrc_step_1", "hrc_step_2", "hrc_step_3", "hrc_dispatch", "hrc_run_frame"} <= defined
    assert not re.search(r"^\s*thread\b", SCRIPT, re.MULTILINE)


def test_the_script_uses_exactly_the_protocols_registers() -> None:
    assert registers("read_input_integer_register") == {
        protocol.IN_SEQ,
        protocol.IN_KIND,
        protocol.IN_ARG,
        protocol.IN_WORKSPACE,
        protocol.IN_ATTEMPT,
    }
    assert registers("read_input_float_register") == set(protocol.IN_VALUES) | {protocol.IN_STEP_ID}
    assert registers("write_output_integer_register") == {
        protocol.OUT_ACK,
        protocol.OUT_OUTCOME,
        protocol.OUT_ATTEMPT,
        protocol.OUT_STEP,
        protocol.OUT_STATUS,
        protocol.OUT_PROTOCOL,
    }
    assert registers("write_output_float_register") == {protocol.OUT_STEP_ID}
    assert set(protocol.OUTPUT_INTS) >= registers("write_output_integer_register")


def test_a_run_frame_echoes_first_and_the_loop_acknowledges_the_frame_last() -> None:
    run = function_body("hrc_run_frame")
    assert f"write_output_integer_register({protocol.OUT_ACK}," not in run
    for register in (protocol.OUT_OUTCOME, protocol.OUT_ATTEMPT, protocol.OUT_STEP):
        assert f"write_output_integer_register({register}," in run
    loop = SCRIPT[SCRIPT.index("while True:") :]
    assert loop.index("hrc_run_frame()") < loop.index(
        f"write_output_integer_register({protocol.OUT_ACK}, hrc_seq)"
    )


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("HRC_PROTOCOL", protocol.PROTOCOL_VERSION),
        ("HRC_SEEN", SEEN_TOKENS),
        ("HRC_OUTCOME_NONE", urua.OUTCOME_NONE),
        ("HRC_OUTCOME_RAN", urua.OUTCOME_RAN),
        ("HRC_OUTCOME_DUPLICATE", urua.OUTCOME_DUPLICATE),
        ("HRC_OUTCOME_STALE", urua.OUTCOME_STALE),
        ("HRC_OUTCOME_UNKNOWN_STEP", urua.OUTCOME_UNKNOWN_STEP),
        ("HRC_OUTCOME_BAD_WORKSPACE", urua.OUTCOME_BAD_WORKSPACE),
    ],
)
def test_the_scripts_constants_match_the_gateway_and_the_fake(name: str, value: int) -> None:
    assert re.search(rf"^{name} = (\d+)", SCRIPT, re.MULTILINE)[1] == str(value)  # type: ignore[index]


def test_registers_md_documents_every_register_the_script_uses() -> None:
    documented = REGISTERS_MD.replace("–", "-")
    for direction, kind, function in (
        ("input", "int", "read_input_integer_register"),
        ("output", "int", "write_output_integer_register"),
        ("output", "double", "write_output_float_register"),
    ):
        for number in registers(function):
            assert f"| {direction} {kind} {number} |" in documented, (direction, kind, number)
    assert "| input double 42-46 |" in documented
    assert f"protocol version, {protocol.PROTOCOL_VERSION}" in documented
