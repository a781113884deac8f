"""An engine worker: `python -m hrc.engine.worker PARENT_PID`, the check off a server's threads.

It reads one request per line on stdin, `{"document": …, "seconds": s or null,
"markings": n}`, and answers each with the check's report as one JSON line on
stdout. It ends when stdin closes, and (Linux) when its parent dies however it
dies, so a server killed outright leaves no worker behind. The server side is
hrc.patterns.engine_workers.
"""

from __future__ import annotations

import ctypes
import json
import os
import signal
import sys

from hrc.engine.budget import Budget
from hrc.engine.check import report_of

_PR_SET_PDEATHSIG = 1


def main(parent: int) -> None:
    _die_with(parent)
    for line in sys.stdin:
        request = json.loads(line)
        budget = Budget(max_markings=int(request["markings"]), seconds=request["seconds"])
        sys.stdout.write(json.dumps(report_of(request["document"], budget)) + "\n")
        sys.stdout.flush()


def _die_with(parent: int) -> None:
    """SIGKILL this process when the parent dies; exits now if it already has."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:  # the parent died before the line above
        sys.exit(0)


if __name__ == "__main__":
    main(int(sys.argv[1]))
