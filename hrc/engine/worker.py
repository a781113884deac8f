"""An engine worker: `python -m hrc.engine.worker`, the check off a server's threads.

It reads one request per line on stdin, `{"document": …, "seconds": s or null,
"markings": n}`, and answers each with the check's report as one JSON line on
stdout. It ends when stdin closes, which its parent's death does too however it
dies (the parent holds the pipe's only writing end), so a server killed outright leaves no
worker behind once the check under way is over. Not PR_SET_PDEATHSIG: that
follows the thread that started the worker, and a server's request threads end.
The server side is hrc.patterns.engine_workers.
"""

from __future__ import annotations

import json
import sys

from hrc.engine.budget import Budget
from hrc.engine.check import report_of


def main() -> None:
    for line in sys.stdin:
        request = json.loads(line)
        budget = Budget(max_markings=int(request["markings"]), seconds=request["seconds"])
        sys.stdout.write(json.dumps(report_of(request["document"], budget)) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
