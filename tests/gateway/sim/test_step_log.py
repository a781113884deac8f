"""The simulator's step log: one JSON line per step that ran, next to its state file."""

import json
from pathlib import Path

from hrc_gateway.sim.state import StateFile, read_step_log, step_log_path


def test_steps_are_appended_next_to_the_state_file_and_read_back_in_order(tmp_path: Path) -> None:
    state = StateFile(tmp_path / "arm.json")
    first = {"token": [1, 1], "step": 3, "started": 10.0, "ended": 11.0, "override": 10.0}
    second = {"token": [2, 1], "step": 3, "started": 12.0, "ended": 13.0, "override": 100.0}

    state.append_step(first)
    state.append_step(second)

    assert step_log_path(tmp_path / "arm.json") == tmp_path / "arm.json.steps"
    assert read_step_log(tmp_path / "arm.json") == [first, second]


def test_a_torn_last_line_is_left_out_and_no_log_is_no_steps(tmp_path: Path) -> None:
    assert read_step_log(tmp_path / "arm.json") == []
    whole = json.dumps({"token": [1, 1]})
    (tmp_path / "arm.json.steps").write_text(whole + "\n" + whole[:5], encoding="utf-8")

    assert read_step_log(tmp_path / "arm.json") == [{"token": [1, 1]}]
