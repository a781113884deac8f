"""A fake dashboard server (PolyScope 5, port 29999) in front of a FakeController.

A greeting line on connect, then one reply line per command line, with the
reply texts UR documents for its dashboard server ("Loading program: x.urp",
"File not found: x.urp", "Starting program", "Powering on", "Brake releasing",
"Robotmode: IDLE", "PLAYING x.urp", "true"/"false", ...). In Local Control it
refuses the commands e-Series reserves for Remote Control. The backend only
relies on the success texts and asks `is in remote control` to explain a
refusal, so the exact refusal wording below matters little.

Every command is recorded in `controller.dashboard_commands`, so a test can
check that the gateway never sent one it must not (`unlock protective stop`).
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable

from tests.gateway.fake_ur.controller import (
    DASHBOARD_ROBOT_MODES,
    DASHBOARD_SAFETY_MODES,
    PAUSED,
    PLAYING,
    PROTECTIVE_STOP,
    STOPPED,
    FakeController,
)
from tests.gateway.fake_ur.loopback import LoopbackServer

GREETING = "Connected: Universal Robots Dashboard Server"
LOCAL_CONTROL_REFUSAL = (
    "Command is not allowed due to safety reasons. Switch your robot to Remote Control "
    "mode to use this command."
)
# Commands e-Series accepts in Remote Control only.
_REMOTE_ONLY = (
    "load ",
    "play",
    "stop",
    "pause",
    "power on",
    "power off",
    "brake release",
    "unlock protective stop",
    "close safety popup",
    "restart safety",
    "shutdown",
)
_PROGRAM_STATES = {STOPPED: "STOPPED", PLAYING: "PLAYING", PAUSED: "PAUSED"}


class FakeDashboardServer(LoopbackServer):
    def __init__(self, controller: FakeController, host: str, port: int = 0) -> None:
        super().__init__(host, port)
        self.controller = controller
        self.silent = False  # accept commands but never answer (a hung PolyScope)
        self.writers: set[asyncio.StreamWriter] = set()

    def drop_connections(self) -> None:
        for writer in list(self.writers):
            writer.close()

    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        if self.refuse:
            writer.close()
            return
        self.writers.add(writer)
        try:
            writer.write(f"{GREETING}\n".encode())
            while line := await reader.readline():
                command = line.decode(errors="replace").strip()
                reply = self.reply(command)
                if command == "quit":
                    writer.write(b"Disconnected\n")
                    break
                if not self.silent:
                    writer.write(f"{reply}\n".encode())
                    await writer.drain()
        except ConnectionError:
            pass
        finally:
            self.writers.discard(writer)
            writer.close()
            with contextlib.suppress(ConnectionError):
                await writer.wait_closed()

    def reply(self, command: str) -> str:
        c = self.controller
        with c.lock:
            c.dashboard_commands.append(command)
            if not c.remote_control and command.startswith(_REMOTE_ONLY):
                return LOCAL_CONTROL_REFUSAL
            verb, _, argument = _split(command)
            handler = self._handlers().get(verb)
            if handler is None:
                return f"could not understand: '{command}'"
            return handler(argument)

    def _handlers(self) -> dict[str, Callable[[str], str]]:
        c = self.controller
        return {
            "load": self._load,
            "play": lambda _: "Starting program" if c.play() else "Failed to execute: play",
            "stop": self._stop,
            "pause": self._pause,
            "power on": _doing(c.power_on, "Powering on"),
            "power off": _doing(c.power_off, "Powering off"),
            "brake release": _doing(c.brake_release, "Brake releasing"),
            "robotmode": lambda _: f"Robotmode: {DASHBOARD_ROBOT_MODES[c.robot_mode]}",
            "safetymode": lambda _: f"Safetymode: {DASHBOARD_SAFETY_MODES[c.safety_mode]}",
            "programState": lambda _: (
                f"{_PROGRAM_STATES.get(c.runtime_state, 'STOPPED')} "
                f"{c.loaded_program or '<unnamed>'}"
            ),
            "get loaded program": lambda _: (
                f"Loaded program: /programs/{c.loaded_program}"
                if c.loaded_program
                else "No program loaded"
            ),
            "running": lambda _: f"Program running: {str(c.runtime_state == PLAYING).lower()}",
            "is in remote control": lambda _: str(c.remote_control).lower(),
            "get operational mode": lambda _: c.operational_mode,
            "set operational mode": self._set_operational_mode,
            "clear operational mode": self._clear_operational_mode,
            "popup": self._popup,
            "close popup": _doing(lambda: setattr(c, "popup_text", None), "closing popup"),
            "addToLog": self._add_to_log,
            "get serial number": lambda _: c.serial_number,
            "get robot model": lambda _: c.robot_model,
            "PolyscopeVersion": lambda _: (
                f"URSoftware {'.'.join(map(str, c.version))} (Jan 10 2022)"
            ),
            "unlock protective stop": self._unlock_protective_stop,
            "close safety popup": lambda _: "closing safety popup",
            "restart safety": lambda _: "Restarting safety",
        }

    def _load(self, name: str) -> str:
        c = self.controller
        file = name.rsplit("/", 1)[-1]
        if file not in c.program_files:
            return f"File not found: {name}"
        c.loaded_program = file
        c.runtime_state = STOPPED
        return f"Loading program: {name}"

    def _stop(self, _: str) -> str:
        self.controller.runtime_state = STOPPED
        return "Stopped"

    def _pause(self, _: str) -> str:
        if self.controller.runtime_state != PLAYING:
            return "Failed to execute: pause"
        self.controller.runtime_state = PAUSED
        return "Pausing program"

    def _set_operational_mode(self, mode: str) -> str:
        if mode not in ("manual", "automatic"):
            return f"Failed setting operational mode to '{mode}'"
        self.controller.operational_mode = mode.upper()
        return f"Operational mode '{mode}' is set"

    def _clear_operational_mode(self, _: str) -> str:
        mode = self.controller.operational_mode.lower()
        return f"No longer controlling the operational mode. Current operational mode: '{mode}'."

    def _popup(self, text: str) -> str:
        self.controller.popup_text = text
        return "showing popup"

    def _add_to_log(self, text: str) -> str:
        if not text:
            return "No log message to add"
        self.controller.log_messages.append(text)
        return "Added log message"

    def _unlock_protective_stop(self, _: str) -> str:
        # Answered as the robot would; the gateway's tests assert it is never sent.
        if self.controller.safety_mode == PROTECTIVE_STOP:
            self.controller.clear_protective_stop()
        return "Protective stop releasing"


def _doing(action: Callable[[], object], reply: str) -> Callable[[str], str]:
    def handler(_: str) -> str:
        action()
        return reply

    return handler


def _split(command: str) -> tuple[str, str, str]:
    """("set operational mode", " ", "manual") for "set operational mode manual"."""
    for verb in (
        "set operational mode",
        "clear operational mode",
        "get operational mode",
        "is in remote control",
        "get loaded program",
        "get serial number",
        "get robot model",
        "power on",
        "power off",
        "brake release",
        "close popup",
        "unlock protective stop",
        "close safety popup",
        "restart safety",
    ):
        if command == verb or command.startswith(verb + " "):
            return verb, " ", command[len(verb) :].strip()
    return command.partition(" ")
