"""The benchmark's generators and a tiny run (without Woflan: it would start pm4py's machinery)."""

import json
from pathlib import Path

import pytest

from bench import nets
from bench.run import main
from bench.woflan import net_spec
from hrc.engine import check_document, read_pattern
from hrc.engine.execution import build_execution_net


@pytest.mark.parametrize("size", nets.SIZES)
@pytest.mark.parametrize("family", nets.FAMILIES)
def test_generated_document_is_valid_with_the_requested_transitions(family: str, size: int) -> None:
    document = nets.generate(family, size)
    pattern = read_pattern(document)

    assert sum(len(process.transitions) for process in pattern.processes) == size
    report = check_document(document)
    # The only error a generated net may have is the deadlock lanes-dead is built to have.
    expected = set() if nets.EXPECTED_SOUND[family] else {"unsound"}
    assert {issue.code for issue in report.errors} == expected
    assert report.sound is nets.EXPECTED_SOUND[family]


@pytest.mark.parametrize("family", ["lanes", "lanes-dead"])
def test_lanes_are_synchronized(family: str) -> None:
    document = nets.generate(family, 20)

    assert "synchronized" in check_document(document).patterns
    assert all(constraint["type"] == "time" for constraint in document["constraints"])


def test_woflan_gets_one_place_initial_and_final_markings() -> None:
    # Woflan refuses anything else; constraint places stay out of the final marking.
    net = build_execution_net(read_pattern(nets.generate("lanes", 20)))
    spec = net_spec(net)

    assert len(spec["initial"]) == 1
    assert len(spec["final"]) == 1
    assert len(spec["transitions"]) == len(net.transitions)
    assert not set(spec["final"]) & net.ignored


def test_quick_run_writes_well_formed_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["--quick", "--runs", "1", "--results-dir", str(tmp_path)]) == 0

    latest = json.loads((tmp_path / "soundness-latest.json").read_text(encoding="utf-8"))
    stamped = [
        path for path in tmp_path.glob("soundness-*.json") if path.name != "soundness-latest.json"
    ]
    assert len(stamped) == 1
    assert json.loads(stamped[0].read_text(encoding="utf-8")) == latest
    assert {"python", "cpu_count", "platform"} <= set(latest["machine"])
    rows = latest["nets"]
    assert [(row["family"], row["transitions"]) for row in rows] == [
        (family, 20) for family in nets.FAMILIES
    ]
    for row in rows:
        assert row["woflan"] is None
        assert row["ours"]["seconds"] > 0
        assert row["floor_seconds"] > 0
        assert row["ours"]["sound"] is row["expected_sound"]
        assert row["flags"] == []
    assert rows[-1]["ours"]["witness"] is True
    assert "lanes-dead-20" in capsys.readouterr().out
