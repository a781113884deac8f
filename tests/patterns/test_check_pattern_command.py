"""`manage.py check_pattern`, run as a person or a script would: a real subprocess."""

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES_DIR = ROOT / "hrc" / "patterns" / "examples"
ASSEMBLY = EXAMPLES_DIR / "synch_1o1c_assembly.json"
REPORT_KEYS = {"path", "valid", "patterns", "sound", "errors", "warnings"}


def run_check(*args: str | Path) -> subprocess.CompletedProcess[str]:
    env = {
        **os.environ,
        "DJANGO_SETTINGS_MODULE": "hrc.settings.test",
        # Nothing listens here: a command that touched the database would fail.
        "DATABASE_URL": "postgres://nobody@127.0.0.1:9/none",
    }
    return subprocess.run(
        [sys.executable, "manage.py", "check_pattern", *map(str, args)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def json_lines(stdout: str) -> list[dict[str, Any]]:
    return [json.loads(line) for line in stdout.splitlines()]


def assembly_with(tmp_path: Path, **changes: Any) -> Path:
    """The synchronized assembly example with top-level keys replaced, written to tmp_path."""
    document = {**json.loads(ASSEMBLY.read_text(encoding="utf-8")), **changes}
    path = tmp_path / "changed.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    return path


def same_performer(tmp_path: Path) -> Path:
    """tc1 and tc3 are both the cobot's: the constraint breaks constraint-same-performer."""
    return assembly_with(tmp_path, constraints=[{"from": "tc1", "to": "tc3", "type": "time"}])


def test_json_reports_a_valid_example_and_exits_0() -> None:
    result = run_check("--json", ASSEMBLY)

    assert result.returncode == 0, result.stderr
    [report] = json_lines(result.stdout)
    assert set(report) == REPORT_KEYS
    assert report["path"] == str(ASSEMBLY)
    assert report["valid"] is True
    assert report["sound"] is True
    assert "synchronized" in report["patterns"]
    assert report["errors"] == []


def test_json_prints_one_line_per_file_in_the_order_given() -> None:
    paths = sorted(EXAMPLES_DIR.glob("*.json"), reverse=True)

    result = run_check("--json", *paths)

    assert result.returncode == 0, result.stderr
    assert [report["path"] for report in json_lines(result.stdout)] == [str(p) for p in paths]


def test_json_reports_files_that_are_not_the_format_as_invalid(tmp_path: Path) -> None:
    not_json = tmp_path / "not.json"
    not_json.write_text("{ this is not json", encoding="utf-8")
    other_format = tmp_path / "other.json"
    other_format.write_text('{"format": "bpmn/2"}', encoding="utf-8")

    result = run_check("--json", not_json, other_format)

    assert result.returncode == 1, result.stderr
    reports = json_lines(result.stdout)
    assert [report["path"] for report in reports] == [str(not_json), str(other_format)]
    for report in reports:
        assert set(report) == REPORT_KEYS
        assert (report["valid"], report["sound"], report["patterns"]) == (False, None, [])
        assert report["errors"]
        assert {error["code"] for error in report["errors"]} == {"format"}
        assert all(set(error) == {"code", "message", "elements"} for error in report["errors"])


def test_json_reports_a_broken_rule_with_its_code_and_elements(tmp_path: Path) -> None:
    path = same_performer(tmp_path)

    result = run_check("--json", ASSEMBLY, path)

    assert result.returncode == 1, result.stderr
    good, bad = json_lines(result.stdout)
    assert good["valid"] is True
    assert bad["valid"] is False
    [error] = [e for e in bad["errors"] if e["code"] == "constraint-same-performer"]
    assert {"tc1", "tc3"} <= set(error["elements"])


def test_human_output_gives_a_headline_per_valid_file() -> None:
    result = run_check(ASSEMBLY)

    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0] == f"{ASSEMBLY}: valid · synchronized · sound"


def test_human_output_lists_each_error_with_code_and_elements(tmp_path: Path) -> None:
    path = same_performer(tmp_path)

    result = run_check(path)

    assert result.returncode == 1, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == f"{path}: INVALID"
    [line] = [line for line in lines if line.startswith("  error [constraint-same-performer] ")]
    assert line.endswith("(elements: tc1, tc3)") or line.endswith("(elements: tc3, tc1)")


def test_human_output_shows_the_firing_sequence_of_an_unsound_model(tmp_path: Path) -> None:
    # tc2 must wait for to2, which waits for tc3, which follows tc2: nothing can finish.
    cycle = [
        {"from": "to2", "to": "tc2", "type": "time"},
        {"from": "tc3", "to": "to2", "type": "time"},
    ]
    path = assembly_with(tmp_path, constraints=cycle)

    result = run_check(path)

    assert result.returncode == 1, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == f"{path}: INVALID"
    witnessed = [
        following
        for line, following in zip(lines, [*lines[1:], ""], strict=True)
        if line.startswith("  error [unsound] ") and following.startswith("    firing sequence: ")
    ]
    assert witnessed, result.stdout


def test_a_missing_file_exits_2_and_the_other_files_are_still_reported(tmp_path: Path) -> None:
    missing = tmp_path / "missing.json"
    invalid = same_performer(tmp_path)

    result = run_check("--json", missing, ASSEMBLY, invalid)

    assert result.returncode == 2
    assert str(missing) in result.stderr
    assert "Traceback" not in result.stderr
    assert [r["path"] for r in json_lines(result.stdout)] == [str(ASSEMBLY), str(invalid)]


def test_a_directory_is_an_unreadable_file(tmp_path: Path) -> None:
    result = run_check(tmp_path)

    assert result.returncode == 2
    assert str(tmp_path) in result.stderr
    assert "Traceback" not in result.stderr
    assert result.stdout == ""


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a file whatever its permissions")
def test_a_file_without_read_permission_is_an_unreadable_file(tmp_path: Path) -> None:
    path = tmp_path / "secret.json"
    path.write_text(ASSEMBLY.read_text(encoding="utf-8"), encoding="utf-8")
    path.chmod(0)

    result = run_check("--json", path)

    assert result.returncode == 2
    assert str(path) in result.stderr
    assert "Traceback" not in result.stderr


def test_no_files_is_a_usage_error() -> None:
    result = run_check("--json")

    assert result.returncode == 2
    assert "usage:" in result.stderr
    assert "Traceback" not in result.stderr
    assert result.stdout == ""
