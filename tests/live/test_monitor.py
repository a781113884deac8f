"""The monitor's record of a cobot's display: a text keeps the time it appeared."""

from __future__ import annotations

import time

from hrc.live.monitor import Watched


def _watched() -> Watched:
    return Watched(5, "weld-arm", "opc.tcp://weld:4840", "", organisation=1, cell="weld")


def test_a_display_text_keeps_its_time_while_other_values_change() -> None:
    watched = _watched()
    watched.update(display="Place the part")
    shown_at = watched.state["display_at"]
    time.sleep(0.01)
    watched.update(joints=[0.1] * 6)
    watched.update(display="Place the part")  # the gateway's first notification after a reconnect
    assert watched.state["display_at"] == shown_at
    assert watched.state["at"] > shown_at
    watched.update(display="Take the part")
    assert watched.state["display_at"] > shown_at


def test_a_restarted_monitor_takes_the_text_and_its_time_from_the_last_state() -> None:
    before = _watched()
    before.update(display="Place the part")
    remembered = before.state
    after = _watched()
    after.recall_display(remembered)
    after.update(display="Place the part")
    assert after.state["display_at"] == remembered["display_at"]
