"""`manage.py demo` (what `make demo` runs): migrate, load the demo organisation and the examples,
start two simulated cobots, the background work and the web server; Ctrl-C stops them all.

Without REDIS_URL jobs, the sweeper and the cobot monitor run inside the web
server (hrc.embedded); with it, a Celery worker with beat and `live_cobots`
run beside it. DATABASE_URL chooses the database as everywhere (SQLite under
var/ when unset). The personas' passwords are generated on every run and
printed once, at the end of start-up; --keep-passwords leaves existing ones.
Once everything serves, the demo prepares its simulated cobots as a person
at the pendant would and starts a few use cases through the server
(hrc.demo.plant), unless --no-cases.
"""

from __future__ import annotations

import signal
from pathlib import Path
from types import FrameType
from typing import Any

import redis
from django.conf import settings
from django.core.management import call_command
from django.core.management.base import BaseCommand, CommandError, CommandParser
from django.db import OperationalError

from hrc.demo import library, organisation, plant
from hrc.demo.organisation import DEMO_COBOTS, PERSONAS
from hrc.demo.runner import Demo, DemoFailed, Plan

# The line scripts and tests wait for: everything is up once it is printed.
SERVING = "hrc demo serving"
# What the banner says of each cobot the demo powered on.
PREPARED = (
    "powered on and brakes released, as a person at the pendant would; hrc loads each step's "
    "program"
)
# (page, path, who uses it) for the start-up banner.
PAGES = (
    ("tablet", "/tablet/", "operators"),
    ("editor", "/patterns/", "engineers, admins"),
    ("supervisor", "/cases/", "engineers, admins"),
    ("incidents", "/incidents/", "engineers, admins"),
    ("analytics", "/analytics/", "engineers, admins"),
    ("administration", "/organisation/people/", "the admin"),
    ("API", "/api/docs/", "anyone signed in; machines with a token"),
)


class Command(BaseCommand):
    help = (
        "Runs the demo: migrates, loads the demo organisation and the example patterns, starts "
        "two simulated cobots, the background work and the web server, and prints the users' "
        "passwords and the URLs. Ctrl-C stops everything it started."
    )

    def add_arguments(self, parser: CommandParser) -> None:
        parser.add_argument("--addr", default="127.0.0.1", help="Web server address.")
        parser.add_argument("--port", type=int, default=8000, help="Web server port (8000).")
        parser.add_argument(
            "--cobot-ports",
            default=",".join(str(cobot.port) for cobot in DEMO_COBOTS),
            help="The simulated cobots' OPC UA ports on loopback, comma-separated (4841,4842).",
        )
        parser.add_argument(
            "--time-scale",
            type=float,
            default=1.0,
            help="The simulated cobots' speed: 1 is real time, 0.1 ten times faster.",
        )
        parser.add_argument(
            "--keep-passwords",
            action="store_true",
            help="Leave the passwords of demo users who have one (they are not printed).",
        )
        parser.add_argument(
            "--no-cases",
            action="store_true",
            help="Start no use-case cases (the cobots are still powered on).",
        )
        parser.add_argument(
            "--logs", type=Path, default=settings.VAR_DIR / "demo", help="Folder for the logs."
        )

    def handle(self, *args: Any, **options: Any) -> None:
        plan = Plan(
            address=options["addr"],
            port=options["port"],
            cobot_ports=_cobot_ports(options["cobot_ports"]),
            time_scale=_time_scale(options["time_scale"]),
            redis=bool(settings.REDIS_URL),
            logs=options["logs"].resolve(),
        )
        _check_free(plan)
        if settings.REDIS_URL:
            _check_redis(settings.REDIS_URL)
        # SIGTERM ends the demo as Ctrl-C does: through the `finally` that stops the children.
        # SIGINT too, even when started with it ignored (a background job of a script).
        signal.signal(signal.SIGTERM, _interrupt)
        signal.signal(signal.SIGINT, _interrupt)
        database = settings.DATABASES["default"]
        if "sqlite" in database["ENGINE"]:  # the embedded default lives in var/, made here
            Path(database["NAME"]).parent.mkdir(parents=True, exist_ok=True)
        self.say(f"Database: {_database()}; migrating")
        try:
            call_command("migrate", interactive=False, verbosity=0)
        except OperationalError as error:
            raise CommandError(
                f"The database does not answer ({error}). Start it, or unset DATABASE_URL to run "
                "the demo on SQLite under var/."
            ) from None
        demo_organisation = self.load(plan, options["keep_passwords"])
        demo = Demo(plan)
        failure: DemoFailed | None = None
        try:
            demo.start(self.say)
            preparations = self.prepare(plan)
            started = self.start_cases(plan, demo_organisation, options["no_cases"])
            self.banner(plan, demo_organisation, preparations, started)
            demo.serve(stop=lambda: False)
        except KeyboardInterrupt:
            self.say("Stopping the demo")
        except DemoFailed as error:
            failure = error
        finally:
            # Let nothing interrupt the stopping: a second Ctrl-C would leave orphans.
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            demo.stop()
        if failure is not None:
            raise CommandError(f"{failure}\nEverything the demo started has been stopped.")
        self.say("Stopped; every process the demo started has ended.")

    def say(self, line: str) -> None:
        self.stdout.write(line)
        self.stdout.flush()

    def load(self, plan: Plan, keep_passwords: bool) -> organisation.DemoOrganisation:
        endpoints = {
            cobot.name: cobot.endpoint(port=plan.cobot_ports[cobot.name]) for cobot in DEMO_COBOTS
        }
        demo = organisation.provision(endpoints=endpoints, keep_passwords=keep_passwords)
        results = library.load_examples(
            demo.organisation, demo.users["engineer"], library.EXAMPLES_DIR, demo.team, demo.cobots
        )
        for loaded in results:
            if loaded.refused is not None:
                self.stderr.write(f"  {loaded.file}: not loaded: {loaded.refused}")
        published = sum(loaded.refused is None for loaded in results)
        self.say(f"{demo.organisation.name}: {published} example patterns published")
        return demo

    def prepare(self, plan: Plan) -> list[plant.Preparation]:
        self.say("Powering the simulated cobots on and releasing their brakes")
        endpoints = {
            cobot.name: cobot.endpoint(port=plan.cobot_ports[cobot.name]) for cobot in DEMO_COBOTS
        }
        return plant.prepare_cobots(endpoints)

    def start_cases(
        self, plan: Plan, demo: organisation.DemoOrganisation, no_cases: bool
    ) -> list[str]:
        """Starts the use cases through the server; returns the banner's lines about them."""
        if no_cases:
            return ["Cases: none started (--no-cases); start one from a pattern in the editor"]
        password = demo.passwords["engineer"]
        if password is None:
            return [
                "Cases: none started: the engineer kept their password (--keep-passwords), "
                "which the demo does not know; start one from a pattern in the editor"
            ]
        cobot_ids = {cobot.name: cobot.pk for cobot in demo.cobots}
        try:
            started = plant.start_cases(plan.url, "engineer", password, cobot_ids)
        except plant.CasesNotStarted as error:
            self.stderr.write(f"The use cases did not start: {error}")
            return [f"Cases: none started ({error}); start one from a pattern in the editor"]
        lines = ["Cases started by engineer, for the operators' tablets and the cobots:"]
        lines += [f"  {c.pattern}: case {c.case}  {plan.url}/cases/{c.case}/" for c in started]
        return lines

    def banner(
        self,
        plan: Plan,
        demo: organisation.DemoOrganisation,
        preparations: list[plant.Preparation],
        cases: list[str],
    ) -> None:
        url = plan.url
        lines = ["", self.style.SUCCESS(f"{demo.organisation.name} at {url}/accounts/login/")]
        lines += organisation.credential_lines(demo)
        lines += ["Where each persona begins:"]
        for persona in PERSONAS:
            pages = "  ".join(f"{url}{path}" for path in persona.pages)
            lines.append(f"  {persona.username:<10} {pages}")
        lines += ["Pages:"]
        lines += [f"  {name:<10} {url}{path:<12} {who}" for name, path, who in PAGES]
        cobots = ", ".join(
            f"{c.name} opc.tcp://127.0.0.1:{plan.cobot_ports[c.name]}" for c in demo.cobots
        )
        lines.append(f"Simulated cobots: {cobots}")
        prepared = [p.cobot for p in preparations if p.problem is None]
        if prepared:
            lines.append(f"{', '.join(prepared)}: {PREPARED}")
        lines += [
            self.style.WARNING(f"{p.cobot}: not prepared: {p.problem}")
            for p in preparations
            if p.problem is not None
        ]
        lines += cases
        if plan.redis:
            lines.append("Jobs: a Celery worker with beat, and the cobot monitor, on REDIS_URL")
        else:
            lines.append("Jobs: on threads of the web server (no REDIS_URL; embedded mode)")
        lines += [f"Logs: {plan.logs}", "", f"{SERVING} {url}/ (Ctrl-C stops it)"]
        self.say("\n".join(lines))


def _interrupt(signum: int, frame: FrameType | None) -> None:
    # The first signal stops the demo; any that follows (make passes SIGTERM on to its
    # group, a second Ctrl-C) is ignored from here on, not only once the `finally` runs:
    # one arriving in between would cut the stopping short and leave orphans.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise KeyboardInterrupt


def _cobot_ports(value: str) -> dict[str, int]:
    parts = [part.strip() for part in value.split(",")]
    if len(parts) != len(DEMO_COBOTS) or not all(
        part.isascii() and part.isdigit() for part in parts
    ):
        raise CommandError(
            f"--cobot-ports needs {len(DEMO_COBOTS)} port numbers separated by a comma, got {value!r}."
        )
    ports = [int(part) for part in parts]
    if len(set(ports)) != len(ports) or not all(0 < port < 65536 for port in ports):
        raise CommandError(f"--cobot-ports must be different ports within 1..65535, got {value!r}.")
    return {cobot.name: port for cobot, port in zip(DEMO_COBOTS, ports, strict=True)}


def _time_scale(value: float) -> float:
    if value < 0:
        raise CommandError(f"--time-scale must be 0 or more, not {value}.")
    return value


def _check_free(plan: Plan) -> None:
    taken = plan.taken_ports()
    if taken:
        raise CommandError(
            f"In use: {', '.join(taken)}. Is another demo running? Stop it, or choose other "
            "ports with --port and --cobot-ports."
        )


def _check_redis(url: str) -> None:
    try:
        redis.Redis.from_url(url, socket_connect_timeout=3).ping()
    except redis.RedisError as error:
        raise CommandError(
            f"REDIS_URL is set but Redis does not answer there ({error}). Start Redis, or unset "
            "REDIS_URL to run the demo on its embedded defaults."
        ) from None


def _database() -> str:
    database = settings.DATABASES["default"]
    if "sqlite" in database["ENGINE"]:
        return f"SQLite {database['NAME']}"
    return f"PostgreSQL {database['NAME']} on {database.get('HOST') or 'localhost'}"
