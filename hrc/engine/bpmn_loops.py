"""Standard loops and multi-instance activities: a step back after the activity, or copies of it.

A loop whose condition translates gets it as the guard of the step back;
a multi-instance task with a literal count up to MAX_COPIES becomes that many
copies (`bpmn_net.FlowNet` builds both). Anything else is imported once, with
a `rewrite` key saying what to draw.
"""

import xml.etree.ElementTree as ET

from hrc.engine.bpmn_conditions import translate
from hrc.engine.bpmn_net import FlowNode
from hrc.engine.bpmn_xml import children, text_of

MAX_COPIES = 20
"""Multi-instance copies made at import; a larger cardinality is imported once, to rewrite."""


def mark_loops(element: ET.Element, node: FlowNode) -> None:
    """Reads the activity's loop or multi-instance marker into the node (`loop`, `copies`, `rewrite`)."""
    what = node.describe()
    loop = next(iter(children(element, "standardLoopCharacteristics")), None)
    if loop is not None:
        condition = next(iter(children(loop, "loopCondition")), None)
        text = text_of(condition)
        guard = (
            translate(text, condition.get("language") if condition is not None else None)
            if text
            else None
        )
        if guard is not None:
            node.loop = {"guard": guard}
        else:
            node.loop = {
                "rewrite": f"The {what} loops "
                + (
                    f"while {text[:200]!r}, which did not translate"
                    if text
                    else "without a condition"
                )
                + ": write the guard of repeating it."
            }
    multiple = next(iter(children(element, "multiInstanceLoopCharacteristics")), None)
    if multiple is None:
        return
    cardinality = text_of(next(iter(children(multiple, "loopCardinality")), None))
    sequential = multiple.get("isSequential") == "true"
    if cardinality.isdigit() and 1 <= int(cardinality) <= MAX_COPIES and node.kind != "begin":
        node.copies = (int(cardinality), sequential)
        return
    collection = next((v for k, v in multiple.attrib.items() if k.endswith("collection")), None)
    if cardinality:
        how = f"{cardinality[:200]!r} times"
    elif collection:
        how = f"once per item of {collection[:200]!r}"
    else:
        how = "a number of times known only at run time"
    node.keys["rewrite"] = (
        f"The {what} runs {how} ({'in sequence' if sequential else 'in parallel'}): it is "
        "imported once; draw its copies."
    )
