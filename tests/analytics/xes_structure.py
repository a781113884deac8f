"""A check of an XES document against the structure of IEEE 1849-2016's XML schema.

Parsed with defusedxml. The order of a log's children (extensions, globals,
classifiers, attributes, traces), that every attribute has a key and a value
of its type (xs:dateTime, xs:long, xs:double, xs:boolean), that classifier
keys are declared global and that each prefixed key belongs to a declared
extension. Returns the root for the test to read further.
"""

from __future__ import annotations

import datetime as dt
from xml.etree.ElementTree import Element

from defusedxml.ElementTree import fromstring

NS = "{http://www.xes-standard.org/}"
ATTRIBUTE_TAGS = {"string", "date", "int", "float", "boolean", "id", "list"}
LOG_ORDER = ["extension", "global", "classifier", "attribute", "trace"]


def tag(element: Element) -> str:
    assert element.tag.startswith(NS), f"{element.tag} is outside the XES namespace"
    return element.tag[len(NS) :]


def check_xes(text: str | bytes) -> Element:
    root: Element = fromstring(text)
    assert tag(root) == "log"
    float(root.attrib["xes.version"])  # xs:decimal
    prefixes = set()
    globals_: dict[str, set[str]] = {}
    stage = 0
    for child in root:
        kind = tag(child)
        group = "attribute" if kind in ATTRIBUTE_TAGS else kind
        assert group in LOG_ORDER, f"a log holds no <{kind}>"
        assert LOG_ORDER.index(group) >= stage, f"<{kind}> comes too late in the log"
        stage = LOG_ORDER.index(group)
        if kind == "extension":
            assert {"name", "prefix", "uri"} <= set(child.attrib)
            prefixes.add(child.attrib["prefix"])
        elif kind == "global":
            assert child.attrib["scope"] in {"trace", "event"}
            globals_[child.attrib["scope"]] = {_attribute(a, prefixes) for a in child}
        elif kind == "classifier":
            for key in child.attrib["keys"].split():
                assert key in globals_.get("event", set()), f"classifier key {key} is not global"
        elif kind == "trace":
            _trace(child, prefixes, globals_)
        else:
            _attribute(child, prefixes)
    return root


def _trace(trace: Element, prefixes: set[str], globals_: dict[str, set[str]]) -> None:
    keys, seen_event = set(), False
    for child in trace:
        if tag(child) == "event":
            seen_event = True
            event_keys = {_attribute(a, prefixes) for a in child}
            missing = globals_.get("event", set()) - event_keys
            assert not missing, f"an event lacks the global attributes {missing}"
        else:
            assert not seen_event, "a trace's attributes come before its events"
            key = _attribute(child, prefixes)
            assert key not in keys, f"the trace has {key} twice"
            keys.add(key)
    assert globals_.get("trace", set()) <= keys


def _attribute(element: Element, prefixes: set[str]) -> str:
    kind = tag(element)
    assert kind in ATTRIBUTE_TAGS, f"<{kind}> is not an attribute"
    key, value = element.attrib["key"], element.attrib["value"]
    if ":" in key:
        assert key.split(":")[0] in prefixes, f"{key}'s prefix is no declared extension"
    if kind == "date":
        moment = dt.datetime.fromisoformat(value)
        assert moment.tzinfo is not None, f"{value} has no time zone"
    elif kind == "int":
        assert -(2**63) <= int(value) < 2**63
    elif kind == "float":
        float(value)
    elif kind == "boolean":
        assert value in {"true", "false"}
    return key
