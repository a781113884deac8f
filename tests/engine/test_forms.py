"""An operator's answers checked against their task's form (hrc.engine.forms)."""

from typing import Any

from hrc.engine.forms import answer_period, example_answers, form_problems

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


# What a simulated operator answers (the same rule as run_pattern --simulate's) --------------

ANSWERED: dict[str, Any] = {
    "type": "object",
    "required": ["position", "last", "count", "verdict", "note", "size"],
    "properties": {
        "position": {"enum": ["top", "bottom"], "examples": ["bottom", "top", "top"]},
        "last": {"type": "boolean", "default": False},
        "count": {"type": "integer", "minimum": 3},
        "verdict": {"enum": ["OK", "NOK"]},
        "note": {"type": "string"},
        "size": {"type": "object", "required": ["w"], "properties": {"w": {"examples": [1, 2]}}},
        "optional": {"type": "string", "examples": ["never entered"]},
    },
}


def test_a_simulated_operator_answers_the_examples_in_turn_else_a_default_choice_or_type() -> None:
    answers = [example_answers(ANSWERED, n) for n in range(4)]

    assert [a["position"] for a in answers] == ["bottom", "top", "top", "bottom"]
    assert [a["size"] for a in answers] == [{"w": 1}, {"w": 2}, {"w": 1}, {"w": 2}]
    assert answers[0] == {
        "position": "bottom",
        "last": False,
        "count": 3,
        "verdict": "OK",
        "note": "ok",
        "size": {"w": 1},
    }
    assert example_answers(None) == {} == example_answers({"type": "object"})


def test_the_answers_repeat_after_the_least_common_multiple_of_the_examples() -> None:
    assert answer_period(ANSWERED) == 6
    assert all(example_answers(ANSWERED, n) == example_answers(ANSWERED, n + 6) for n in range(6))
    assert example_answers(ANSWERED, 1) != example_answers(ANSWERED, 4)
    assert answer_period(None) == 1 == answer_period(FORM)
