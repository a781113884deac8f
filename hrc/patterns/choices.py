"""Fixed vocabularies of the patterns app."""

from django.db import models


class DocumentFormat(models.TextChoices):
    """The file formats a pattern is imported from and exported to."""

    # hrc-pattern/1 (shared/pattern-format.md): the whole model, layout and task configuration kept.
    JSON = "json", "hrc-pattern/1 (JSON)"
    # PNML, the Petri net exchange standard: the nets travel, actors and constraints as tool data.
    PNML = "pnml", "PNML (XML)"
    # BPMN 2.0 (Dijkman, Dumas and Ouyang's mapping): tasks in lanes, gateways, a diagram for other tools.
    BPMN = "bpmn", "BPMN 2.0 (XML)"
