"""The expression language: what it computes, what it refuses, and what its errors say."""

import operator
import re
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from hrc.engine.expressions import (
    Expression,
    ExpressionError,
    check,
    evaluate,
    is_expression,
    parse,
    resolve,
)

CASE: dict[str, Any] = {
    "data": {
        "count": 3,
        "name": "gear",
        "ok": True,
        "missing": None,
        "part": {"pose": [0.1, 0.2, 0.3], "kind": "gear", "weight": 2.5},
        "parts": [{"id": "p1", "ok": True}, {"id": "p2", "ok": False}],
        "tags": ["fragile", "heavy"],
    },
    "result": {"status": "done", "grip": 40},
}


def value(text: str, names: dict[str, Any] = CASE) -> Any:
    return evaluate(text, names)


def error(text: str, names: dict[str, Any] = CASE) -> str:
    with pytest.raises(ExpressionError) as raised:
        evaluate(text, names)
    return str(raised.value)


# What it computes


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("42", 42),
        ("-2.5", -2.5),
        ("'gear'", "gear"),
        ('"gear"', "gear"),
        ("True", True),
        ("False", False),
        ("None", None),
        ("true", True),
        ("false", False),
        ("null", None),
    ],
)
def test_literals_include_python_and_json_spellings(text: str, expected: object) -> None:
    assert value(text) == expected
    assert type(value(text)) is type(expected)


def test_json_constants_win_over_names_of_the_same_spelling() -> None:
    assert value("true", {"true": 0}) is True


def test_lists_tuples_and_dicts_hold_expressions() -> None:
    assert value("[data.count, 1 + 1]") == [3, 2]
    assert value("(data.count, 'x')") == (3, "x")
    assert value("{'n': data.count, data.name: 1}") == {"n": 3, "gear": 1}


def test_a_name_is_read_from_the_mapping() -> None:
    assert value("result") == {"status": "done", "grip": 40}


def test_attribute_access_reads_nested_dict_keys() -> None:
    assert value("data.part.kind") == "gear"
    assert value("result.status") == "done"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('data["count"]', 3),
        ("data.part.pose[0]", 0.1),
        ("data.part.pose[-1]", 0.3),
        ("data.parts[1].id", "p2"),
        ("data.part.pose[1:]", [0.2, 0.3]),
        ("data.part.pose[:-1]", [0.1, 0.2]),
        ("data.part.pose[::2]", [0.1, 0.3]),
        ("data.tags[data.count - 2]", "heavy"),
        ("data.name[0]", "g"),
        ("(1, 2, 3)[1]", 2),
        ("{'a': 1}['a']", 1),
    ],
)
def test_subscripts_take_keys_indexes_and_slices(text: str, expected: object) -> None:
    assert value(text) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("7 + 2", 9),
        ("7 - 2", 5),
        ("7 * 2", 14),
        ("7 / 2", 3.5),
        ("7 // 2", 3),
        ("-7 // 2", -4),
        ("7 % 3", 1),
        ("-7 % 3", 2),
        ("2 ** 10", 1024),
        ("2 ** -1", 0.5),
        ("2 ** 0.5", 2**0.5),
        ("1 + 2 * 3 ** 2", 19),
        ("'ab' + 'c'", "abc"),
        ("'ab' * 3", "ababab"),
        ("[0] * 3", [0, 0, 0]),
        ("data.tags + ['new']", ["fragile", "heavy", "new"]),
        ("result.grip / 2 + data.part.weight", 22.5),
    ],
)
def test_arithmetic_follows_python(text: str, expected: object) -> None:
    assert value(text) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [("-data.count", -3), ("+data.count", 3), ("not data.ok", False), ("not data.missing", True)],
)
def test_unary_operators(text: str, expected: object) -> None:
    assert value(text) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("data.count == 3", True),
        ("data.count != 3", False),
        ("data.count < 3", False),
        ("data.count <= 3", True),
        ("data.count > 2", True),
        ("data.count >= 4", False),
        ("1 < data.count < 5", True),
        ("1 < data.count < 2", False),
        ("3 == data.count == 3.0", True),
        ("'heavy' in data.tags", True),
        ("'light' not in data.tags", True),
        ("'ea' in 'gear'", True),
        ("'pose' in data.part", True),
        ("data.missing is None", True),
        ("data.missing is not None", False),
        ("data.count is not null", True),
    ],
)
def test_comparisons_including_chains_membership_and_none(text: str, expected: bool) -> None:
    assert value(text) is expected


def test_a_chain_stops_at_the_first_false_comparison_like_python() -> None:
    # 'x' < 1 would fail if the chain went on after 5 < 1.
    assert value("5 < 1 < 'x'") is False


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("data.count and data.name", "gear"),
        ("0 and data.name", 0),
        ("data.missing or 'default'", "default"),
        ("data.count or 'default'", 3),
        ("'' or [] or 0", 0),
        ("1 and 2 and 3", 3),
    ],
)
def test_and_or_return_an_operand_as_python_does(text: str, expected: object) -> None:
    assert value(text) == expected


def test_and_or_short_circuit_so_the_right_side_is_not_evaluated() -> None:
    assert value("data.missing is None or data.missing.pose") is True
    assert value("false and nowhere.at_all") is False
    assert value("'pose' in data and data.pose[0] > 0") is False


def test_the_conditional_expression_evaluates_only_the_chosen_branch() -> None:
    assert value("'heavy' if data.part.weight > 2 else 'light'") == "heavy"
    assert value("data.part.pose if data.ok else nowhere") == [0.1, 0.2, 0.3]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("len(data.tags)", 2),
        ("len(data.name)", 4),
        ("min(data.part.pose)", 0.1),
        ("min(3, 1, 2)", 1),
        ("max(data.count, 10)", 10),
        ("abs(-2.5)", 2.5),
        ("round(2.567, 1)", 2.6),
        ("round(2.5)", 2),
        ("int('12')", 12),
        ("int(2.9)", 2),
        ("float('1.5')", 1.5),
        ("str(data.count)", "3"),
        ("bool(data.tags)", True),
        ("sum(data.part.pose) > 0.59", True),
        ("any([false, data.ok])", True),
        ("all([data.ok, data.missing])", False),
        ("sorted(data.tags + ['a'])", ["a", "fragile", "heavy"]),
    ],
)
def test_the_allowed_functions(text: str, expected: object) -> None:
    assert value(text) == expected


# Guards over case data, as a pattern writes them


@pytest.mark.parametrize(
    ("guard", "expected"),
    [
        ("result.status == 'done' and data.part.weight < 5", True),
        ("data.parts[0].ok and not data.parts[1].ok", True),
        ("len(data.parts) >= 2 and data.part.kind in ['gear', 'shaft']", True),
        ("all([data.ok, result.grip > 50])", False),
        ("data.part.pose[2] - data.part.pose[0] > 0.1", True),
    ],
)
def test_guards_over_nested_case_data(guard: str, expected: bool) -> None:
    assert bool(value(guard)) is expected


# The "=" convention for configuration values


def test_only_strings_starting_with_equals_are_expressions() -> None:
    assert is_expression("=data.count")
    assert not is_expression("data.count")
    assert not is_expression(3)
    assert not is_expression(["=data.count"])


def test_resolve_evaluates_expressions_inside_nested_lists_and_dicts() -> None:
    parameters = {
        "pose": [0.1, "=data.part.pose[1]", {"z": "=data.part.pose[2] + 1"}],
        "speed": 0.5,
        "label": "gear",
        "grip": "=result.grip",
        "frame": ("base", "=data.name"),
    }

    assert resolve(parameters, CASE) == {
        "pose": [0.1, 0.2, {"z": 1.3}],
        "speed": 0.5,
        "label": "gear",
        "grip": 40,
        "frame": ("base", "gear"),
    }


def test_resolve_leaves_dict_keys_and_non_strings_alone() -> None:
    assert resolve({"=data.count": None, "n": 1}, CASE) == {"=data.count": None, "n": 1}


def test_a_literal_string_starting_with_equals_is_written_as_a_string_expression() -> None:
    assert resolve("='=x'", CASE) == "=x"


def test_resolve_allows_a_blank_after_the_equals_sign() -> None:
    assert resolve("= data.count + 1", CASE) == 4


def test_resolve_reports_a_failing_expression() -> None:
    with pytest.raises(ExpressionError, match="data has no key 'nope'"):
        resolve({"pose": [1, "=data.nope"]}, CASE)


# Parsing ahead of time


def test_parse_returns_the_same_expression_for_the_same_text() -> None:
    assert parse("data.count + 1") is parse("data.count + 1")
    assert parse("data.count") == Expression("data.count")


def test_names_are_the_top_level_names_read_not_functions_or_constants() -> None:
    expression = parse("len(data.tags) > limit and result.ok is not null or true")

    assert expression.names() == frozenset({"data", "limit", "result"})


def test_an_expression_evaluates_many_times_over_different_names() -> None:
    expression = parse("n * 2")

    assert [expression.evaluate({"n": n}) for n in (1, 2, 3)] == [2, 4, 6]


def test_check_accepts_an_expression_over_allowed_names() -> None:
    assert check("data.count > 1 and result.ok", ["data", "result"]) is None


def test_check_reports_a_name_that_will_not_be_given() -> None:
    problem = check("data.count > limit", ["data", "result"])

    assert isinstance(problem, ExpressionError)
    assert str(problem) == "unknown name 'limit' in \"data.count > limit\" (names: data, result)"


def test_check_reports_a_syntax_error_without_raising() -> None:
    problem = check("data.count >", ["data"])

    assert isinstance(problem, ExpressionError)
    assert "invalid syntax" in str(problem)


def test_a_refused_construct_fails_at_parse_before_any_case_runs() -> None:
    with pytest.raises(ExpressionError, match="lambdas are not allowed"):
        parse("data.ok or (lambda: 1)")


# What the messages say


def test_a_syntax_error_names_the_text_and_the_column() -> None:
    assert error("data.count >") == (
        '"data.count >" is not a valid expression: invalid syntax at column 13'
    )
    assert error("data.count > > 1").endswith("at column 14")


def test_an_unknown_name_lists_the_names_there_are() -> None:
    assert error("foo + 1", {"data": {}, "result": {}}) == (
        "unknown name 'foo' in \"foo + 1\" (names: data, result)"
    )


def test_a_missing_key_names_the_path() -> None:
    assert error("data.part.pose.x == 1") == (
        "data.part.pose is list, not a dict, so it has no key 'x' in \"data.part.pose.x == 1\""
    )
    assert error("data.part.colour") == "data.part has no key 'colour' in \"data.part.colour\""
    assert error("data['nope']") == "data has no key 'nope' in \"data['nope']\""


def test_an_index_out_of_range_names_the_path() -> None:
    assert error("data.parts[5].id") == 'data.parts has no index 5 in "data.parts[5].id"'


def test_an_index_of_the_wrong_type_names_the_path() -> None:
    assert error("data.tags['a']").startswith("data.tags is list, which cannot be indexed by str")
    assert error("data.count[0]").startswith("data.count is int, which has no keys or indexes")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("data.name < 1", "'<' between str and int in \"data.name < 1\""),
        ("1 in data.name", "'in' between int and str"),
        ("data.name + 1", "'+' between str and int"),
        ("data.tags - 1", "'-' between list and int"),
        ("-data.name", "'-' on str"),
        ("data.count / 0", "'/' by zero in \"data.count / 0\""),
        ("1 // 0", "'//' by zero"),
        ("1 % 0", "'%' by zero"),
        ("0 ** -1", "'**' by zero"),
        ("'2' ** 2", "'**' between str and int"),
        ("len(data.count)", "len(): object of type 'int' has no len()"),
        ("int('x')", "int(): invalid literal"),
        ("max([])", "max(): "),
        ("sorted([1, 'a'])", "sorted(): '<' not supported"),
        ("{[1]: 2}", "unhashable type: 'list'"),
    ],
)
def test_run_time_type_errors_name_the_operation_and_the_expression(
    text: str, message: str
) -> None:
    problem = error(text)

    assert message in problem
    assert f'"{text}"' in problem


# Refusals: nothing outside the whitelist runs


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("__import__('os')", "function calls other than len, min, max"),
        ("__import__('os').system('true')", "function calls other than len"),
        ("().__class__", "dunder attributes are not allowed ('.__class__')"),
        ("().__class__.__bases__[0].__subclasses__()", "not allowed"),
        ("data.__class__", "dunder attributes are not allowed ('.__class__')"),
        ("__builtins__", "dunder names are not allowed ('__builtins__')"),
        ("data.name.upper()", "function calls other than len"),
        ("open('/etc/passwd')", "function calls other than len"),
        ("getattr(data, 'x')", "function calls other than len"),
        ("(lambda: 1)()", "function calls other than len"),
        ("lambda: 1", "lambdas are not allowed"),
        ("[x for x in data.tags]", "comprehensions are not allowed"),
        ("{x for x in data.tags}", "comprehensions are not allowed"),
        ("{x: 1 for x in data.tags}", "comprehensions are not allowed"),
        ("sum(x for x in [1])", "comprehensions are not allowed"),
        ("(x := 1)", "assignment expressions (:=) are not allowed"),
        ("f'{data}'", "f-strings are not allowed"),
        ("{1, 2}", "set literals are not allowed"),
        ("max(*data.tags)", "star arguments (*x) are not allowed"),
        ("{**data}", "dict unpacking (**x) is not allowed"),
        ("sorted(data.tags, key=len)", "keyword arguments are not allowed"),
        ("sum([[1]], [])", "sum takes exactly one argument"),
        ("data.count is 3", "'is' and 'is not' are allowed only as 'is None'"),
        ("1 << 40", "bitwise and matrix operators"),
        ("1 | 2", "bitwise and matrix operators"),
        ("~1", "bitwise and matrix operators"),
        ("1j", "complex literals are not allowed"),
        ("b'x'", "bytes literals are not allowed"),
        ("...", "ellipsis literals are not allowed"),
        ("await data", "await and yield are not allowed"),
    ],
)
def test_constructs_outside_the_whitelist_are_refused_by_name(text: str, message: str) -> None:
    with pytest.raises(ExpressionError) as raised:
        parse(text)

    assert message in str(raised.value)
    assert f'"{text}"' in str(raised.value)


@pytest.mark.parametrize(
    "text",
    [
        "2 ** 65",
        "10 ** 64 ** 2",
        "1000001 ** 2",
        "(10 ** 6) ** 64 ** 64",
        "2 ** 100.0",
    ],
)
def test_huge_powers_are_refused(text: str) -> None:
    assert "'**' is limited to |base| ≤ 1000000 and |exponent| ≤ 64" in error(text)


def test_powers_within_the_limits_work() -> None:
    assert value("1000000 ** 64") == 10**384
    assert value("(-2) ** -64") == 2**-64


def test_a_fractional_power_of_a_negative_number_is_refused_not_complex() -> None:
    assert "not a real number" in error("(-8) ** 0.5")


@pytest.mark.parametrize(
    "text",
    [
        "'a' * 10001",
        "10001 * 'a'",
        "[0] * 10001",
        "(0, 0) * 5001",
        "[[0] * 10000] * 10000",
        "[data.tags] * 5000",
        "'ab' * 10 ** 20",
    ],
)
def test_huge_repetition_is_refused_also_through_nesting(text: str) -> None:
    assert "repetition beyond 10000 elements or characters is not allowed" in error(text)


def test_repetition_up_to_the_limit_works() -> None:
    assert len(value("'a' * 10000")) == 10_000
    assert value("[1, 2] * 0") == []


def test_string_formatting_with_percent_is_refused() -> None:
    assert "'%' formatting of strings is not allowed" in error("'%999999999d' % 1")


def test_attributes_of_anything_but_dicts_stay_hidden() -> None:
    assert error("data.name.upper") == (
        "data.name is str, not a dict, so it has no key 'upper' in \"data.name.upper\""
    )
    assert "is tuple, not a dict" in error("(1, 2).count")


def test_very_long_text_is_refused_before_parsing() -> None:
    text = "1 + " * 300 + "1"

    with pytest.raises(
        ExpressionError, match=r"longer than 1000 characters are not allowed \(1201\)"
    ):
        parse(text)


def test_text_of_exactly_the_limit_is_accepted() -> None:
    text = "1" * 1000

    assert parse(text).evaluate({}) == int(text)


@pytest.mark.parametrize("text", ["-" * 40 + "1", "[" * 40 + "]" * 40, "(((" + "a." * 40 + "b)))"])
def test_deep_nesting_is_refused(text: str) -> None:
    with pytest.raises(ExpressionError, match="nesting deeper than 32 is not allowed"):
        parse(text)


def test_nesting_up_to_the_limit_is_accepted() -> None:
    assert value("-" * 30 + "1") == 1


def test_parenthesis_nesting_beyond_the_parser_is_a_syntax_error() -> None:
    with pytest.raises(ExpressionError, match="too many nested parentheses"):
        parse("(" * 300 + ")" * 300)


def test_no_builtins_leak_into_names() -> None:
    assert "unknown name 'len'" in error("len", {})
    assert "unknown name 'print'" in error("print", {})


# Agreement with Python's own arithmetic

_OPERATORS: dict[str, Callable[[Any, Any], Any]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": operator.truediv,
    "//": operator.floordiv,
    "%": operator.mod,
}
Tree = int | tuple[str, Any, Any]


def _powers() -> st.SearchStrategy[Tree]:
    return st.tuples(st.just("**"), st.integers(-50, 50), st.integers(0, 4))


_trees: st.SearchStrategy[Tree] = st.recursive(
    st.integers(-(10**6), 10**6) | _powers(),
    lambda inner: st.tuples(st.sampled_from(sorted(_OPERATORS)), inner, inner),
    max_leaves=12,
)


def _text(tree: Tree) -> str:
    if isinstance(tree, int):
        return f"({tree})"
    symbol, left, right = tree
    return f"({_text(left)} {symbol} {_text(right)})"


def _python(tree: Tree) -> Any:
    """What Python computes for the tree, without ever evaluating text."""
    if isinstance(tree, int):
        return tree
    symbol, left, right = tree
    function = operator.pow if symbol == "**" else _OPERATORS[symbol]
    return function(_python(left), _python(right))


@given(_trees)
def test_arithmetic_over_ints_agrees_with_python(tree: Tree) -> None:
    text = _text(tree)
    try:
        expected = _python(tree)
    except ZeroDivisionError:
        with pytest.raises(ExpressionError, match="by zero"):
            evaluate(text, {})
        return
    except OverflowError:
        with pytest.raises(ExpressionError, match="overflows"):
            evaluate(text, {})
        return

    assert evaluate(text, {}) == expected


def test_error_messages_quote_the_text_exactly() -> None:
    text = "data.part.colour"
    assert re.search(r'in "data\.part\.colour"$', error(text))
