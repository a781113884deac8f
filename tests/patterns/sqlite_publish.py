"""Run as `python -m tests.patterns.sqlite_publish` on the embedded SQLite (DATABASE_URL unset): an
engineer publishes a pattern whose check takes seconds while, on another thread with its own
connection, a writer saves a row. Prints one JSON object: how long the check takes alone, and
how long the other write waited. test_publish_sqlite.py checks it."""

from __future__ import annotations

import json
import threading
import time
from typing import Any

import django

django.setup()

from django.db import connection, connections  # noqa: E402

from bench.nets import generate  # noqa: E402
from hrc.database import ensure_migrated  # noqa: E402
from hrc.engine.check import report_of  # noqa: E402
from hrc.organisations.choices import Role  # noqa: E402
from hrc.patterns import services  # noqa: E402
from tests import factories  # noqa: E402

# A net whose soundness check takes about two seconds on one core (bench/nets.py).
SLOW_TO_CHECK = generate("choices-3", 300)


def main() -> dict[str, Any]:
    assert connection.vendor == "sqlite", connection.vendor
    ensure_migrated(migrate_sqlite=True)
    organisation = factories.make_organisation()
    engineer = factories.make_member(organisation, Role.ENGINEER)
    pattern = services.create_pattern(
        organisation, name="slow to check", created_by=engineer, draft=SLOW_TO_CHECK
    )
    started = time.perf_counter()
    report_of(SLOW_TO_CHECK)
    check_seconds = time.perf_counter() - started

    publishing = threading.Event()
    published: list[int] = []

    def publish() -> None:
        try:
            publishing.set()
            published.append(services.publish_pattern(pattern, published_by=engineer).number)
        finally:
            connections.close_all()

    thread = threading.Thread(target=publish)
    thread.start()
    publishing.wait()
    time.sleep(check_seconds / 4)  # the publish is inside its check now
    started = time.perf_counter()
    factories.make_organisation()  # any write: an operator's completion, a job's lease
    write_seconds = time.perf_counter() - started
    thread.join()
    return {"check": check_seconds, "write": write_seconds, "published": published}


if __name__ == "__main__":
    print(json.dumps(main()))
