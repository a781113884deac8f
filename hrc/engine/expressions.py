"""A small, safe expression language over case data: guards on transitions, task outputs
mapped into case data, cobot step parameters taken from case data, the messages a case
sends and the correlation of those it waits for (these read `case` too, see taskconfig.py).

Expressions use Python's expression syntax. They are parsed with `ast.parse(mode="eval")`
and interpreted here over a whitelist of node types; no text is ever given to eval, exec
or compile.

    literals       1  2.5  "text"  True False None, and JSON's true false null
    containers     [a, b]  (a, b)  {"key": value}
    names          looked up in the mapping given to `evaluate` (true/false/null win)
    keys           data.part.pose is data["part"]["pose"] (on dicts only); data["x"]
    indexes        data.poses[0]  data.poses[-1]  data.poses[1:3]  data.poses[i:]  "text"[0]
    arithmetic     + - * / // % **  (% on numbers only: no string formatting)
    logic          not, and, or (short-circuit, returning an operand as Python does);
                   a if condition else b
    comparisons    == != < <= > >= in, not in, chained; `is` only as `is None`/`is not None`
    functions      len min max abs round int float str bool sum any all sorted
                   (positional arguments only; sum takes one argument)

Limits, so that a published pattern cannot stall the server: text ≤ 1000 characters,
nesting ≤ 32 expression nodes deep, `**` only for |base| ≤ 1e6 and |exponent| ≤ 64,
repetition (`"ab" * n`, `[x] * n`) only up to 10 000 elements or characters, counted
through nested lists and dicts, with strings counted by their characters.

Configuration values (`resolve`): a string starting with "=" is an expression whose text
is the rest after the "="; anything else is a literal. So "=data.pose[1]" reads case data
and "pose" is the string pose. A literal string that itself starts with "=" is written as
an expression of a string literal: "='=x'" resolves to the string "=x".

Every failure, at parse time or at run time, raises ExpressionError; its message says what
is wrong and quotes the expression text.
"""

import ast
import functools
import operator
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

MAX_LENGTH = 1000
MAX_DEPTH = 32
MAX_BASE = 1_000_000
MAX_EXPONENT = 64
MAX_REPEAT = 10_000

# JSON spellings, so that people who write case data as JSON can write guards the same way.
CONSTANTS: Mapping[str, object] = {"true": True, "false": False, "null": None}


class ExpressionError(ValueError):
    """An expression that cannot be parsed, is not allowed, or fails on the given names."""


class _Fault(Exception):
    """A run-time failure inside the interpreter; `Expression.evaluate` adds the text."""

    def __init__(self, message: str, hint: str = "") -> None:
        super().__init__(message)
        self.message, self.hint = message, hint


def _kind(value: object) -> str:
    return type(value).__name__


def _size(value: object, limit: int) -> int:
    """Characters or elements in value, counted through nested containers; stops past limit.

    Counted through nesting because `[[0] * 10000] * 10000` is only 10 000 references but
    becomes 10^8 elements as soon as it is printed, compared or summed."""
    if isinstance(value, str):
        return len(value)
    if not isinstance(value, list | tuple | dict):
        return 1
    total = len(value)
    for item in value.values() if isinstance(value, dict) else value:
        if total > limit:
            break
        total += _size(item, limit - total)
    return total


def _multiply(left: Any, right: Any) -> Any:
    for sequence, count in ((left, right), (right, left)):
        if (
            isinstance(sequence, str | list | tuple)
            and isinstance(count, int)
            and count * _size(sequence, MAX_REPEAT) > MAX_REPEAT
        ):
            raise _Fault(f"repetition beyond {MAX_REPEAT} elements or characters is not allowed")
    return left * right


def _power(base: Any, exponent: Any) -> Any:
    if not (isinstance(base, int | float) and isinstance(exponent, int | float)):
        raise TypeError  # reported by _binary as "'**' between …"
    if abs(base) > MAX_BASE or abs(exponent) > MAX_EXPONENT:
        raise _Fault(f"'**' is limited to |base| ≤ {MAX_BASE} and |exponent| ≤ {MAX_EXPONENT}")
    result = base**exponent
    if isinstance(result, complex):
        raise _Fault("'**' of a negative number to a fractional power is not a real number")
    return result


def _modulo(left: Any, right: Any) -> Any:
    # "%s" % x is string formatting: "%999999999d" would build a gigabyte string.
    if isinstance(left, str):
        raise _Fault("'%' formatting of strings is not allowed")
    return left % right


# fmt: off
# The whitelists, laid out as tables so that a reviewer sees everything that is allowed at once.
FUNCTIONS: Mapping[str, Callable[..., Any]] = {
    "len": len, "min": min, "max": max, "abs": abs, "round": round, "int": int, "float": float,
    "str": str, "bool": bool, "sum": sum, "any": any, "all": all, "sorted": sorted,
}
_Op = tuple[str, Callable[[Any, Any], Any]]
BINARY: Mapping[type[ast.AST], _Op] = {
    ast.Add: ("+", operator.add), ast.Sub: ("-", operator.sub), ast.Mult: ("*", _multiply),
    ast.Div: ("/", operator.truediv), ast.FloorDiv: ("//", operator.floordiv),
    ast.Mod: ("%", _modulo), ast.Pow: ("**", _power),
}
UNARY: Mapping[type[ast.AST], tuple[str, Callable[[Any], Any]]] = {
    ast.USub: ("-", operator.neg), ast.UAdd: ("+", operator.pos), ast.Not: ("not", operator.not_),
}
COMPARE: Mapping[type[ast.AST], _Op] = {
    ast.Eq: ("==", operator.eq), ast.NotEq: ("!=", operator.ne),
    ast.Lt: ("<", operator.lt), ast.LtE: ("<=", operator.le),
    ast.Gt: (">", operator.gt), ast.GtE: (">=", operator.ge),
    ast.In: ("in", lambda a, b: a in b), ast.NotIn: ("not in", lambda a, b: a not in b),
    ast.Is: ("is", operator.is_), ast.IsNot: ("is not", operator.is_not),
}
# fmt: on
_ALLOWED = (
    *(ast.Constant, ast.Name, ast.List, ast.Tuple, ast.Dict, ast.Attribute, ast.Subscript),
    *(ast.Slice, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp, ast.Call),
)
_LEAVES = (ast.expr_context, ast.boolop, ast.cmpop)  # checked through their parent
# Constructs people reach for, refused by their everyday name rather than "ListComp".
_REFUSED: Mapping[type[ast.AST], str] = {
    ast.Lambda: "lambdas",
    **dict.fromkeys((ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp), "comprehensions"),
    ast.NamedExpr: "assignment expressions (:=)",
    ast.JoinedStr: "f-strings",
    ast.Starred: "star arguments (*x)",
    ast.Set: "set literals",
    **dict.fromkeys((ast.Await, ast.Yield, ast.YieldFrom), "await and yield"),
}


def _is_dunder(name: str) -> bool:
    return name.startswith("__")


def _refusal(node: ast.AST) -> str | None:
    """What is wrong with node itself (not its children), or None when it is allowed."""
    if isinstance(node, _LEAVES) or type(node) in BINARY or type(node) in UNARY:
        return None
    if isinstance(node, ast.operator | ast.unaryop):
        return "bitwise and matrix operators (<< >> & | ^ ~ @) are not allowed"
    if not isinstance(node, _ALLOWED):
        return f"{_REFUSED.get(type(node), type(node).__name__)} are not allowed"
    if isinstance(node, ast.Constant) and not isinstance(node.value, int | float | str | None):
        return f"{_kind(node.value)} literals are not allowed"
    if isinstance(node, ast.Name) and _is_dunder(node.id):
        return f"dunder names are not allowed ({node.id!r})"
    if isinstance(node, ast.Attribute) and _is_dunder(node.attr):
        return f"dunder attributes are not allowed ('.{node.attr}')"
    if isinstance(node, ast.Dict) and None in node.keys:
        return "dict unpacking (**x) is not allowed"
    if isinstance(node, ast.Compare) and not all(
        _is_none(right)
        for op, right in zip(node.ops, node.comparators, strict=True)
        if isinstance(op, ast.Is | ast.IsNot)
    ):
        return "'is' and 'is not' are allowed only as 'is None' and 'is not None'"
    if isinstance(node, ast.Call):
        if not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS):
            called = ast.unparse(node.func)
            return f"function calls other than {', '.join(FUNCTIONS)} are not allowed ({called!r})"
        if node.keywords:
            return "keyword arguments are not allowed"
        # sum(lists, []) would concatenate quadratically, past the repetition cap.
        if node.func.id == "sum" and len(node.args) != 1:
            return "sum takes exactly one argument"
    return None


def _is_none(node: ast.expr) -> bool:
    return (isinstance(node, ast.Constant) and node.value is None) or (
        isinstance(node, ast.Name) and node.id == "null"
    )


def _check(node: ast.AST, text: str, depth: int) -> None:
    if depth > MAX_DEPTH:
        raise ExpressionError(f'nesting deeper than {MAX_DEPTH} is not allowed in "{text}"')
    if problem := _refusal(node):
        raise ExpressionError(f'{problem} in "{text}"')
    for child in ast.iter_child_nodes(node):
        _check(child, text, depth + isinstance(child, ast.expr))


def _syntax_tree(text: str) -> ast.Expression:
    """The checked tree of text; raises ExpressionError on bad syntax or a refused construct."""
    if len(text) > MAX_LENGTH:
        shown = text[:40]
        raise ExpressionError(
            f'expressions longer than {MAX_LENGTH} characters are not allowed ({len(text)}): "{shown}…"'
        )
    # Like eval(), allow leading blanks ("= data.x"), which ast.parse calls an indent.
    source = text.lstrip(" \t")
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        # Python 3.11 gives offset 0 for errors at the end of the text.
        column = (exc.offset or len(source) + 1) + len(text) - len(source)
        where = f" at column {column}" if exc.lineno is not None else ""
        raise ExpressionError(f'"{text}" is not a valid expression: {exc.msg}{where}') from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise ExpressionError(f'"{text}" is not a valid expression: {exc}') from None
    _check(tree.body, text, 1)
    return tree


@dataclass(frozen=True)
class Expression:
    """A parsed expression that passed the whitelist; constructing one raises ExpressionError
    otherwise. Equal when the text is equal. Prefer `parse`, which caches."""

    text: str
    _tree: ast.Expression = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_tree", _syntax_tree(self.text))

    def names(self) -> frozenset[str]:
        """The names the expression reads from the mapping (not true/false/null, not functions)."""
        nodes = list(ast.walk(self._tree))
        called = {id(node.func) for node in nodes if isinstance(node, ast.Call)}
        return frozenset(
            node.id
            for node in nodes
            if isinstance(node, ast.Name) and id(node) not in called and node.id not in CONSTANTS
        )

    def evaluate(self, names: Mapping[str, Any]) -> Any:
        """The value of the expression over names; raises ExpressionError if evaluation fails."""
        try:
            return _value(self._tree.body, names)
        except _Fault as fault:
            raise ExpressionError(f'{fault.message} in "{self.text}"{fault.hint}') from None
        except (TypeError, ValueError, ArithmeticError, LookupError, RecursionError) as exc:
            # Python's own words, for what the cases in _value do not phrase themselves.
            raise ExpressionError(f'{exc} in "{self.text}"') from exc


def _value(node: ast.expr, names: Mapping[str, Any]) -> Any:
    match node:
        case ast.Constant(value=value):
            return value
        case ast.Name(id=name):
            return _name(name, names)
        case ast.List(elts=items) | ast.Tuple(elts=items):
            values = [_value(item, names) for item in items]
            return values if isinstance(node, ast.List) else tuple(values)
        case ast.Dict(keys=keys, values=values):
            pairs = zip(keys, values, strict=True)
            return {_value(k, names): _value(v, names) for k, v in pairs if k is not None}
        case ast.Attribute(value=inner, attr=key):
            return _key(_value(inner, names), key, inner)
        case ast.Subscript(value=inner, slice=index):
            return _item(_value(inner, names), _index(index, names), inner)
        case ast.BinOp(left=left, op=op, right=right):
            return _binary(op, _value(left, names), _value(right, names))
        case ast.UnaryOp(op=op, operand=operand):
            return _unary(op, _value(operand, names))
        case ast.BoolOp(op=op, values=operands):
            return _boolean(isinstance(op, ast.Or), operands, names)
        case ast.Compare(left=left, ops=ops, comparators=rights):
            return _compare(_value(left, names), ops, rights, names)
        case ast.IfExp(test=test, body=body, orelse=orelse):
            return _value(body if _value(test, names) else orelse, names)
        case ast.Call(func=ast.Name(id=function), args=args):
            return _call(function, [_value(arg, names) for arg in args])
    raise AssertionError(f"unchecked node {ast.dump(node)}")  # _check refuses everything else


def _name(name: str, names: Mapping[str, Any]) -> Any:
    if name in CONSTANTS:
        return CONSTANTS[name]
    try:
        return names[name]
    except KeyError:
        known = ", ".join(sorted(map(str, names)))
        raise _Fault(f"unknown name {name!r}", f" (names: {known})") from None


def _key(container: Any, key: str, node: ast.expr) -> Any:
    """container.key, which reads a key of a dict; other objects' attributes stay hidden."""
    if not isinstance(container, Mapping):
        path = ast.unparse(node)
        raise _Fault(f"{path} is {_kind(container)}, not a dict, so it has no key {key!r}")
    return _item(container, key, node)


def _item(container: Any, index: Any, node: ast.expr) -> Any:
    if not isinstance(container, Mapping | list | tuple | str):
        raise _Fault(f"{ast.unparse(node)} is {_kind(container)}, which has no keys or indexes")
    try:
        return container[index]
    except KeyError:
        raise _Fault(f"{ast.unparse(node)} has no key {index!r}") from None
    except IndexError:
        raise _Fault(f"{ast.unparse(node)} has no index {index!r}") from None
    except TypeError:
        path, kind = ast.unparse(node), _kind(container)
        raise _Fault(f"{path} is {kind}, which cannot be indexed by {_kind(index)}") from None


def _index(node: ast.expr, names: Mapping[str, Any]) -> Any:
    if not isinstance(node, ast.Slice):
        return _value(node, names)
    parts = (node.lower, node.upper, node.step)
    return slice(*(None if part is None else _value(part, names) for part in parts))


def _binary(op: ast.operator, left: Any, right: Any) -> Any:
    symbol, function = BINARY[type(op)]
    try:
        return function(left, right)
    except TypeError:
        raise _Fault(f"'{symbol}' between {_kind(left)} and {_kind(right)}") from None
    except ZeroDivisionError:
        raise _Fault(f"'{symbol}' by zero") from None
    except OverflowError:
        raise _Fault(f"'{symbol}' overflows") from None


def _unary(op: ast.unaryop, operand: Any) -> Any:
    symbol, function = UNARY[type(op)]
    try:
        return function(operand)
    except TypeError:
        raise _Fault(f"'{symbol}' on {_kind(operand)}") from None


def _boolean(is_or: bool, operands: list[ast.expr], names: Mapping[str, Any]) -> Any:
    """Python's and/or: the first operand that decides the result, else the last one."""
    result = None
    for operand in operands:
        result = _value(operand, names)
        if bool(result) == is_or:
            return result
    return result


def _compare(
    left: Any, ops: list[ast.cmpop], rights: list[ast.expr], names: Mapping[str, Any]
) -> bool:
    for op, node in zip(ops, rights, strict=True):
        right = _value(node, names)  # evaluated only as far as the chain needs, as Python does
        symbol, test = COMPARE[type(op)]
        try:
            if not test(left, right):
                return False
        except TypeError:
            raise _Fault(f"'{symbol}' between {_kind(left)} and {_kind(right)}") from None
        left = right
    return True


def _call(function: str, args: list[Any]) -> Any:
    try:
        return FUNCTIONS[function](*args)
    except (TypeError, ValueError, OverflowError) as exc:
        raise _Fault(f"{function}(): {exc}") from None


@functools.lru_cache(maxsize=1024)
def parse(text: str) -> Expression:
    """The checked expression for text (cached); raises ExpressionError before any case runs."""
    return Expression(text)


def evaluate(text: str, names: Mapping[str, Any]) -> Any:
    """parse(text).evaluate(names)."""
    return parse(text).evaluate(names)


def is_expression(value: object) -> bool:
    """Whether a configuration value is an expression: a string that starts with "="."""
    return isinstance(value, str) and value.startswith("=")


def resolve(value: Any, names: Mapping[str, Any]) -> Any:
    """value with every "=..." string, also inside lists, tuples and dict values, evaluated.

    Other values, and dict keys, are returned as they are."""
    if is_expression(value):
        return evaluate(value[1:], names)
    if isinstance(value, list | tuple):
        return type(value)(resolve(item, names) for item in value)
    if isinstance(value, dict):
        return {key: resolve(item, names) for key, item in value.items()}
    return value


def check(text: str, allowed_names: Iterable[str]) -> ExpressionError | None:
    """The first thing wrong with text where only allowed_names will be given, or None."""
    try:
        expression = parse(text)
    except ExpressionError as error:
        return error
    allowed = set(allowed_names)
    unknown = sorted(expression.names() - allowed)
    if unknown:
        known = ", ".join(sorted(allowed))
        return ExpressionError(f'unknown name {unknown[0]!r} in "{text}" (names: {known})')
    return None
