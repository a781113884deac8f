"""An operator's answers checked against their task's form (hrc.engine.forms)."""

from hrc.engine.forms import form_problems

FORM = {
    "type": "object",
    "properties": {
        "count": {"type": "integer", "minimum": 0},
        "part": {
            "type": "object",
            "properties": {"serial": {"type": "string"}},
            "required": ["serial"],
        },
    },
    "required": ["count", "ok"],
}


def test_answers_the_form_accepts_have_no_problems() -> None:
    assert form_problems(FORM, {"count": 3, "ok": True}) == {}


def test_a_task_without_a_form_accepts_anything() -> None:
    assert form_problems(None, {"anything": 1}) == {}


def test_each_missing_required_answer_is_named_by_its_own_field() -> None:
    assert form_problems(FORM, {"ok": True, "part": {}}) == {
        "count": ["an answer is required"],
        "part.serial": ["an answer is required"],
    }


def test_a_wrong_answer_is_reported_at_its_field_with_the_schema_s_message() -> None:
    problems = form_problems(FORM, {"count": -1, "ok": True})
    assert list(problems) == ["count"]
    assert "minimum" in problems["count"][0]


def test_an_answer_that_is_not_an_object_is_reported_against_the_form() -> None:
    assert list(form_problems(FORM, [])) == ["the form"]  # type: ignore[arg-type]
