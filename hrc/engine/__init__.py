"""The collaboration-pattern core: pure Python, no Django (a test enforces it).

- `model`: the 7-tuple as frozen dataclasses; `document`: `hrc-pattern/1` in and out;
- `rules`, `classify`: the formal rules and the four patterns;
- `execution`, `petri`: the execution net and its firing rule (used by the runtime);
- `reduction`, `analysis`: soundness by reduced state-space exploration, with witnesses;
- `check`: all of it in one report; `pnml`: PNML import and export;
- `layout`: automatic layout in actor lanes; `bpmn`, `bpmn_net`, `bpmn_export`: BPMN 2.0
  import (Dijkman, Dumas and Ouyang's mapping) and export with a diagram;
- `prediction`: cycle time, load and bottleneck of a pattern, by a simulation of many cases
  over the runtime's firing rule (`prediction_run`, `prediction_state`, `prediction_report`);
  `durations`: task times as distributions, fitted from measured ones.
"""

from hrc.engine.check import CheckReport, check_document, check_pattern
from hrc.engine.document import FORMAT, FormatError, read_pattern, write_pattern

__all__ = [
    "FORMAT",
    "CheckReport",
    "FormatError",
    "check_document",
    "check_pattern",
    "read_pattern",
    "write_pattern",
]
