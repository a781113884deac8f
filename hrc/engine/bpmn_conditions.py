"""Conditions of BPMN files, written in JUEL and the like, translated into hrc's expressions.

Camunda and Activiti write `${amount > 1000 && approved}`, Bonita and others
plain `amount > 1000`; both read the process variables. hrc's guards read the
same values as `data.amount`. `translate` rewrites what has a clear meaning
(names, numbers, strings, comparisons, `&&`, `||`, `!` and JUEL's word
operators `eq ne lt gt le ge and or not`), and of XPath, BPMN's default
language, the same plain forms over data objects (`bpmn:getDataObject('approved')`,
`not(...)`, `=`, `true()`); it returns None for anything else (method calls, `empty`,
XPath paths, prose such as "Amount > 1000 €"), which the importer then marks as a
condition to rewrite.
"""

import ast
import re

from hrc.engine.expressions import check

JUEL_LANGUAGES = ("", "juel", "javascript", "groovy", "java", "mvel", "spel", "el")
"""The languages whose comparisons and operators read like JUEL's; others are not translated."""

_TOKEN = re.compile(
    r"""\s*(?:
        (?P<number>\d+(?:\.\d+)?)
      | (?P<string>'[^'\\]*'|"[^"\\]*")
      | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
      | (?P<operator>&&|\|\||==|!=|<=|>=|<|>|!|\(|\))
    )""",
    re.VERBOSE,
)
_WORDS = {
    "eq": "==",
    "ne": "!=",
    "lt": "<",
    "gt": ">",
    "le": "<=",
    "ge": ">=",
    "and": "and",
    "or": "or",
    "not": "not",
    "true": "True",
    "false": "False",
    "null": "None",
}
_OPERATORS = {"&&": "and", "||": "or", "!": "not"}
_WRAPPED = re.compile(r"^\s*[$#]\{(?P<body>.*)\}\s*$", re.DOTALL)


def translate(text: str, language: str | None = None) -> str | None:
    """The guard `text` means over `data`, or None when it does not translate clearly."""
    language = (language or "").strip().lower().rsplit("/", 1)[-1]
    if language == "xpath" or _DATA_OBJECT.search(text):
        text = _from_xpath(text)
    elif language not in JUEL_LANGUAGES:
        return None
    wrapped = _WRAPPED.match(text)
    body = wrapped.group("body") if wrapped else text
    if check(body.strip(), ["data"]) is None:
        return body.strip()  # hrc's own language, as our export writes it
    words = _tokens(body)
    if not words:
        return None
    guard = " ".join(words).replace("not ==", "!=")
    return guard if check(guard, ["data"]) is None else None


# XPath, BPMN's default expression language: the spec's `bpmn:getDataObject('name')` reads a
# data object, as a JUEL name reads a variable.
_DATA_OBJECT = re.compile(
    r"""bpmn:getDataObject\(\s*(?:'([A-Za-z_][A-Za-z0-9_]*)'|"([A-Za-z_][A-Za-z0-9_]*)")\s*\)"""
)
_XPATH_BOOLEAN = re.compile(r"\b(true|false)\(\s*\)")
_XPATH_EQUALS = re.compile(r"(?<![!<>=])=(?!=)")


def _from_xpath(text: str) -> str:
    """An XPath condition in JUEL's spelling, for the few forms whose meaning is plain: data
    objects, `true()`, `not(...)`, `=`, `and`, `or`, comparisons, literals. Anything else
    (paths, other functions) keeps a character `_tokens` refuses."""
    text = _DATA_OBJECT.sub(lambda match: match.group(1) or match.group(2), text)
    text = _XPATH_BOOLEAN.sub(r"\1", text)
    return _XPATH_EQUALS.sub("==", text)


def _tokens(body: str) -> list[str] | None:
    """The expression's tokens in hrc's spelling; None at the first one that has no spelling."""
    words: list[str] = []
    position = 0
    body = body.strip()
    while position < len(body):
        match = _TOKEN.match(body, position)
        if match is None or match.end() == position:
            return None
        position = match.end()
        kind, token = next((k, v) for k, v in match.groupdict().items() if v is not None)
        if kind == "name":
            words.append(_WORDS.get(token, f"data.{token}"))
        elif kind == "operator":
            words.append(_OPERATORS.get(token, token))
        else:
            words.append(token)
    return words


def data_defaults(guard: str) -> dict[str, object]:
    """The case data a translated guard reads, each key with a default of the type it is
    compared with (0, "", None), else false: what a case starts with until its start form
    says otherwise."""
    tree = ast.parse(guard, mode="eval")
    defaults: dict[str, object] = {}
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        operands = [node.left, *node.comparators]
        constants = [o.value for o in operands if isinstance(o, ast.Constant)]
        for operand in operands:
            key = _data_key(operand)
            if key is not None and constants:
                value = constants[0]
                default = type(value)() if isinstance(value, int | float | str) else None
                defaults.setdefault(key, default)
    for node in ast.walk(tree):
        key = _data_key(node)
        if key is not None:
            defaults.setdefault(key, False)
    return defaults


def compared_values(guard: str) -> dict[str, list[object]]:
    """Each data key the guard compares with constants, and those constants in order: the
    answers that steer the choice (`data.clarified == 'yes'` gives clarified: ['yes'])."""
    values: dict[str, list[object]] = {}
    for node in ast.walk(ast.parse(guard, mode="eval")):
        if not isinstance(node, ast.Compare):
            continue
        operands = [node.left, *node.comparators]
        constants = [o.value for o in operands if isinstance(o, ast.Constant)]
        for operand in operands:
            key = _data_key(operand)
            if key is not None:
                found = values.setdefault(key, [])
                found += [value for value in constants if value not in found]
    return values


def _data_key(node: ast.AST) -> str | None:
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        return node.attr if node.value.id == "data" else None
    return None
