"""Is the database ready for a management command: reachable and migrated.

A fresh clone has no `var/` and so no SQLite file; a new PostgreSQL database has
no tables. Without this check a command that needs the database ends in a
traceback ("unable to open database file", "relation … does not exist").
"""

from __future__ import annotations

from pathlib import Path

import psycopg
from django.core.management import call_command
from django.core.management.base import CommandError
from django.db import DEFAULT_DB_ALIAS, DatabaseError, connections
from django.db.backends.base.base import BaseDatabaseWrapper
from django.db.migrations.executor import MigrationExecutor

MIGRATE = ".venv/bin/python manage.py migrate"
PROBE_TIMEOUT_SECONDS = 5


def ensure_migrated(*, migrate_sqlite: bool = False, alias: str = DEFAULT_DB_ALIAS) -> None:
    """Raises CommandError with one line saying what to run when the database is not ready.

    With `migrate_sqlite`, a SQLite database (the embedded default) is created and
    migrated here instead: a scratch tool the README runs right after cloning may do
    that by itself, while a shared PostgreSQL database is migrated by a person.
    """
    connection = connections[alias]
    if connection.vendor == "sqlite" and migrate_sqlite:
        Path(connection.settings_dict["NAME"]).parent.mkdir(parents=True, exist_ok=True)
    if connection.vendor == "postgresql":
        _reach_postgresql(connection)
    try:
        executor = MigrationExecutor(connection)
        pending = executor.migration_plan(executor.loader.graph.leaf_nodes())
    except DatabaseError as error:
        first_line = str(error).splitlines()[0] if str(error) else type(error).__name__
        where = _where(connection.vendor, connection.settings_dict["NAME"])
        hint = (
            f"does its folder exist? Then run `{MIGRATE}`"
            if connection.vendor == "sqlite"
            else "is it running, and does DATABASE_URL name it?"
        )
        raise CommandError(f"Cannot open {where} ({first_line}); {hint}") from None
    if not pending:
        return
    if connection.vendor == "sqlite" and migrate_sqlite:
        call_command("migrate", interactive=False, verbosity=0, database=alias)
        return
    where = _where(connection.vendor, connection.settings_dict["NAME"])
    raise CommandError(
        f"{where[:1].upper()}{where[1:]} is not migrated ({len(pending)} migration(s) to apply): run `{MIGRATE}` first."
    )


def _reach_postgresql(connection: BaseDatabaseWrapper) -> None:
    """Raises CommandError naming why the PostgreSQL server does not answer.

    Through the pool an unreachable server is only "couldn't get a connection" after
    HRC_DB_POOL_TIMEOUT, its log repeating the cause; one plain connection says it at once.
    """
    try:
        psycopg.connect(
            **connection.get_connection_params(), connect_timeout=PROBE_TIMEOUT_SECONDS
        ).close()
    except psycopg.Error as error:
        first_line = str(error).splitlines()[0] if str(error) else type(error).__name__
        where = _where(connection.vendor, connection.settings_dict["NAME"])
        raise CommandError(
            f"Cannot open {where} ({first_line}); is it running, and does DATABASE_URL name it?"
        ) from None


def _where(vendor: str, name: object) -> str:
    return f"the SQLite database {name}" if vendor == "sqlite" else f"the {vendor} database {name}"
