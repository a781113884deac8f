"""What the tests ask PostgreSQL itself about the test database."""

from __future__ import annotations

from django.db import connection


def sessions_opened() -> int:
    """Sessions ever opened on the test database (each counted by its backend, at the latest
    when it ends)."""
    with connection.cursor() as cursor:
        cursor.execute("SELECT sessions FROM pg_stat_database WHERE datname = current_database()")
        return int(cursor.fetchone()[0])
