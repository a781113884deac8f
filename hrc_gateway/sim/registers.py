"""The controller's register file: input and output Bit64–127, Int0–47, Double0–47."""

from __future__ import annotations

import asyncio
from collections.abc import Mapping
from typing import Any

from hrc_gateway import urua
from hrc_gateway.backend import RegisterValue, Value

_DEFAULTS: Mapping[str, RegisterValue] = {"Bit": False, "Int": 0, "Double": 0.0}


def _initial() -> dict[str, RegisterValue]:
    return {name: _DEFAULTS[urua.register_kind(name)] for name in urua.all_register_names()}


class RegisterFile:
    """Inputs are written by clients (through the gateway), outputs by the running program.

    Waiters wake on every input write, so a program waiting for Bit64 sees it
    in the same event-loop turn as the write.
    """

    def __init__(self) -> None:
        self.inputs = _initial()
        self.outputs = _initial()
        self._input_written = asyncio.Condition()

    async def write_inputs(self, values: Mapping[str, RegisterValue]) -> dict[str, Value]:
        """Applies `values` in order; returns the published paths and values of the inputs written.

        Raises urua.RegisterError, before applying anything, for a name or
        value no register holds.
        """
        coerced = {name: urua.coerce_register_value(name, value) for name, value in values.items()}
        self.inputs.update(coerced)
        async with self._input_written:
            self._input_written.notify_all()
        return {urua.register_path("Inputs", name): value for name, value in coerced.items()}

    def write_outputs(self, values: Mapping[str, RegisterValue]) -> dict[str, Value]:
        """Sets output registers (the program's writes); returns their paths and values."""
        coerced = {name: urua.coerce_register_value(name, value) for name, value in values.items()}
        self.outputs.update(coerced)
        return {urua.register_path("Outputs", name): value for name, value in coerced.items()}

    async def wait_input(self, name: str, value: RegisterValue) -> None:
        """Returns once input `name` holds `value` (at once if it already does)."""
        async with self._input_written:
            await self._input_written.wait_for(lambda: self.inputs[name] == value)

    def published_values(self) -> dict[str, Value]:
        """Every register, inputs and outputs, by path."""
        values: dict[str, Value] = {}
        for direction, registers in (("Inputs", self.inputs), ("Outputs", self.outputs)):
            for name, value in registers.items():
                values[urua.register_path(direction, name)] = value
        return values

    def to_dict(self) -> dict[str, Any]:
        return {"inputs": dict(self.inputs), "outputs": dict(self.outputs)}

    def restore(self, data: Mapping[str, Any]) -> None:
        """Takes the values saved by to_dict; urua.RegisterError/KeyError/TypeError if malformed."""
        inputs, outputs = _initial(), _initial()
        for saved, target in ((data["inputs"], inputs), (data["outputs"], outputs)):
            for name, value in dict(saved).items():
                target[name] = urua.coerce_register_value(name, value)
        self.inputs, self.outputs = inputs, outputs
