"""URUA's address space, built in an asyncua server, and the typed door to its values.

Node ids follow URUA (prototype-artefacts §1.1): the root object is
`ns=2;s=<cobot>`; its members are `ns=2;s=/<cobot>/<path>`, except the
separately manifested sub-objects Axes, Tcp and Register, whose own ids have
no leading slash (`ns=2;s=<cobot>/Axes`) while their children have one.

Unlike URUA every variable has a fixed type (vectors are Double arrays, not
their text form), so a client that writes the wrong type gets
BadTypeMismatch instead of silently changing the node's type.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from asyncua import Node, Server, ua

from hrc_gateway import urua
from hrc_gateway.backend import MethodHandler, Value

# Sub-objects URUA manifested separately: their own node id has no leading slash.
_SEPARATE_OBJECTS = frozenset({"Axes", "Tcp", "Register"})

AXES = tuple(f"Axis{n}" for n in range(1, 7))


def _urua_variables() -> dict[str, Value]:
    """Every URUA variable (§1.2) with its initial value; the value fixes the type."""
    variables: dict[str, Value] = {
        "SerialNumber": "",
        "RobotModel": "",
        urua.STATE_CURRENT_PROGRAM: "",
        "State/RobotState": "",
        urua.STATE_ROBOT_MODE: "Disconnected",
        "State/JointMode": "",
        urua.STATE_SAFETY_MODE: urua.SAFETY_NORMAL,
        "State/ToolMode": "",
        urua.STATE_PROGRAM_STATE: urua.PROGRAM_STOPPED,
        "State/SpeedScaling": 1.0,
        "State/Remote": False,
        "State/OperationalMode": "",
        "State/Override": 100.0,
        urua.STATE_LAST_ERROR: "",
        urua.STATE_HEARTBEAT: 0,
        "SafetyBoard/MainVoltage": 0.0,
        "SafetyBoard/RobotVoltage": 0.0,
        "SafetyBoard/RobotCurrent": 0.0,
        "Programs/Programs": [],
        "Axes/ActualMomentum/AxisMomentum": 0.0,
    }
    vectors = {
        "Axes/ActualPositions": "AxisPositions",
        "Axes/ActualVelocities": "AxisVelocities",
        "Axes/ActualCurrents": "AxisCurrents",
        "Axes/ActualVoltage": "AxisVoltage",
        "Tcp/ActualPose": "TCPPose",
        "Tcp/ActualSpeed": "TCPSpeed",
        "Tcp/ActualForce": "TCPForce",
    }
    for folder, vector in vectors.items():
        variables[f"{folder}/{vector}"] = [0.0] * 6
        for axis in AXES:
            variables[f"{folder}/{axis}"] = 0.0
    for direction in ("Inputs", "Outputs"):
        for name in urua.all_register_names():
            initial: Value = {"Bit": False, "Int": 0, "Double": 0.0}[urua.register_kind(name)]
            variables[urua.register_path(direction, name)] = initial
    return variables


URUA_VARIABLES: Mapping[str, Value] = _urua_variables()
# What a client may write among URUA's variables besides the input registers.
URUA_WRITABLE = frozenset({"State/Override"})
# URUA variables whose initial value does not show their type (an empty list).
_DECLARED_TYPES = {"Programs/Programs": "String"}


def variant_type_of(value: Value) -> ua.VariantType:
    """The OPC UA type a value is served as: bool Boolean, int Int32, float Double, str String."""
    sample: object = value[0] if isinstance(value, list) and value else value
    if isinstance(sample, bool):
        return ua.VariantType.Boolean
    if isinstance(sample, int):
        return ua.VariantType.Int32
    if isinstance(sample, float):
        return ua.VariantType.Double
    if isinstance(sample, str):
        return ua.VariantType.String
    if isinstance(value, list):  # an empty list of no declared type
        return ua.VariantType.Double
    raise TypeError(f"Cannot serve a {type(value).__name__} over OPC UA")


@dataclass
class Variable:
    node_id: ua.NodeId
    vtype: ua.VariantType
    is_array: bool
    writable: bool


class AddressSpace:
    """The cobot's nodes in one asyncua server, addressed by path under the root."""

    def __init__(self, server: Server, cobot: str) -> None:
        self.server = server
        self.cobot = cobot
        self.variables: dict[str, Variable] = {}
        self._nodes: dict[str, Node] = {}
        self._last: dict[str, Value] = {}

    def node_id(self, path: str) -> ua.NodeId:
        if path in _SEPARATE_OBJECTS:
            return ua.NodeId(f"{self.cobot}/{path}", urua.NAMESPACE_INDEX)
        return ua.NodeId.from_string(urua.node_id(self.cobot, path))

    async def build(self) -> None:
        """Creates the root object and every URUA variable (methods come from the server)."""
        objects = self.server.nodes.objects
        root_id = ua.NodeId(self.cobot, urua.NAMESPACE_INDEX)
        self._nodes[""] = await objects.add_object(
            root_id, ua.QualifiedName(self.cobot, urua.NAMESPACE_INDEX)
        )
        for path, value in URUA_VARIABLES.items():
            await self.add_variable(
                path, value, writable=path in URUA_WRITABLE, vtype=_DECLARED_TYPES.get(path)
            )

    async def folder(self, path: str) -> Node:
        """The object at `path`, created (with its parents) when missing."""
        if path in self._nodes:
            return self._nodes[path]
        parent_path, _, name = path.rpartition("/")
        parent = await self.folder(parent_path)
        node = await parent.add_object(
            self.node_id(path), ua.QualifiedName(name, urua.NAMESPACE_INDEX)
        )
        self._nodes[path] = node
        return node

    async def add_variable(
        self, path: str, value: Value, *, writable: bool = False, vtype: str | None = None
    ) -> None:
        """A variable typed by `vtype` (a VariantType name) or else by its value."""
        parent_path, _, name = path.rpartition("/")
        parent = await self.folder(parent_path)
        is_array = isinstance(value, list)
        variant_type = ua.VariantType[vtype] if vtype else variant_type_of(value)
        node = await parent.add_variable(
            self.node_id(path),
            ua.QualifiedName(name, urua.NAMESPACE_INDEX),
            ua.Variant(value, variant_type, is_array=is_array),
            varianttype=variant_type,
        )
        if writable:
            # Straight into the address space: client-facing writes are the server's to check.
            level = ua.DataValue(
                ua.Variant(
                    ua.AccessLevel.CurrentRead.mask | ua.AccessLevel.CurrentWrite.mask,
                    ua.VariantType.Byte,
                )
            )
            for attribute in (ua.AttributeIds.AccessLevel, ua.AttributeIds.UserAccessLevel):
                await self.server.write_attribute_value(node.nodeid, level, attribute)
        self.variables[path] = Variable(node.nodeid, variant_type, is_array, writable)
        self._last[path] = value

    async def add_method(
        self,
        path: str,
        handler: MethodHandler,
        inputs: Sequence[tuple[str, str]] = (),
        outputs: Sequence[tuple[str, str]] = (),
    ) -> None:
        """A method node; `handler` is already wrapped by the server (statuses, LastError)."""
        parent_path, _, name = path.rpartition("/")
        parent = await self.folder(parent_path)
        await parent.add_method(
            self.node_id(path),
            ua.QualifiedName(name, urua.NAMESPACE_INDEX),
            handler,
            [_argument(arg_name, type_name) for arg_name, type_name in inputs],
            [_argument(arg_name, type_name) for arg_name, type_name in outputs],
        )

    async def delete(self, path: str) -> None:
        """Removes an object and everything under it (programs that disappeared)."""
        node = self._nodes.pop(path, None)
        if node is not None:
            await self.server.delete_nodes([node], recursive=True)

    def path_of(self, node_id: ua.NodeId) -> str | None:
        """The path of a variable by node id; None for anything else."""
        if node_id.NamespaceIndex != urua.NAMESPACE_INDEX or not isinstance(
            node_id.Identifier, str
        ):
            return None
        prefix = f"/{self.cobot}/"
        if node_id.Identifier.startswith(prefix):
            path = node_id.Identifier[len(prefix) :]
            return path if path in self.variables else None
        return None

    async def publish(self, changes: Mapping[str, Value]) -> None:
        """Writes the values that changed; subscribers see them at once (publishing interval 0)."""
        now = dt.datetime.now(dt.UTC)
        for path, value in changes.items():
            variable = self.variables.get(path)
            if variable is None:
                raise KeyError(f"The gateway serves no variable {path!r}")
            if self._last.get(path) == value:
                continue
            self._last[path] = value
            data = ua.DataValue(
                ua.Variant(_as_served(value, variable), variable.vtype, is_array=variable.is_array),
                SourceTimestamp=now,
                ServerTimestamp=now,
            )
            await self.server.write_attribute_value(variable.node_id, data)

    def value(self, path: str) -> Value:
        """The last value published at `path`."""
        return self._last[path]


def _as_served(value: Value, variable: Variable) -> Value:
    # A backend may publish 1 for a Double; the node keeps its type.
    if variable.vtype == ua.VariantType.Double and not variable.is_array:
        return float(value)  # type: ignore[arg-type]
    if variable.vtype == ua.VariantType.Double and isinstance(value, list):
        return [float(v) for v in value]
    return value


def _argument(name: str, type_name: str) -> ua.Argument:
    argument = ua.Argument()
    argument.Name = name
    vtype = ua.VariantType[type_name.removesuffix("[]")]
    argument.DataType = ua.NodeId(vtype.value)
    argument.ValueRank = 1 if type_name.endswith("[]") else -1
    if type_name.endswith("[]"):
        argument.ArrayDimensions = [0]
    return argument
