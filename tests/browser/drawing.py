"""Drawing in the pattern editor with the mouse and the keyboard, as a person aims: positions come
from what is on screen. Shared by the editor's tests and the tests that walk the product."""

from typing import Any

from playwright.sync_api import FloatRect, Page, expect

# The server checks a moment after the model stops changing (LiveChecker, 600 ms).
CHECKED = 15_000


def open_editor(page: Page, url: str) -> None:
    page.goto(url)
    expect(page.locator("#hrc-editor")).to_have_attribute("data-ready", "true")


def pattern_badge(page: Page) -> Any:
    return page.get_by_label("Pattern class")


def element_box(page: Page, element_id: str) -> FloatRect:
    """The element's box on screen: its hit area, which is the shape's bounds."""
    box = page.locator(f'[data-element-id="{element_id}"] .djs-hit').first.bounding_box()
    assert box is not None, f"{element_id} is not on the canvas"
    return box


def centre_of(page: Page, element_id: str) -> tuple[float, float]:
    box = element_box(page, element_id)
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def near(box: FloatRect, other: FloatRect) -> bool:
    return abs(box["x"] - other["x"]) < 2 and abs(box["y"] - other["y"]) < 2


def click_element(page: Page, element_id: str) -> None:
    page.mouse.click(*centre_of(page, element_id))


def select_element(page: Page, element_id: str) -> None:
    """Clicks the element until it is selected. diagram-js swallows the first click for 0.4 s
    after a drag ends (the drag's ghost click; a loaded machine runs that timer late), so a
    click right after drawing an arc can select nothing; a second one comes a second later,
    never a double click."""
    selected = page.locator(f'.djs-element.selected[data-element-id="{element_id}"]')
    for _ in range(3):
        click_element(page, element_id)
        try:
            expect(selected).to_have_count(1, timeout=1000)
            return
        except AssertionError:
            continue
    expect(selected).to_have_count(1)


def drop_tool(page: Page, tool: str, x: float, y: float) -> None:
    """Takes a node from the palette and drops it at (x, y)."""
    page.get_by_role("button", name=tool, exact=True).click()
    page.mouse.move(x, y, steps=6)
    page.mouse.down()
    page.mouse.up()


def pad_action(page: Page, action: str) -> None:
    page.locator(f'.djs-context-pad.open [data-action="{action}"]').click()


def connect(page: Page, source: str, target: str, action: str = "connect") -> None:
    """From the source's context pad, draws an arc (or a constraint) to the target."""
    select_element(page, source)
    pad_action(page, action)
    x, y = centre_of(page, target)
    page.mouse.move(x, y, steps=8)
    page.mouse.down()
    page.mouse.up()


def append_node(page: Page, label: str = "") -> None:
    """Appends the next node to the selected one with the A key; a task gets its label typed."""
    selected = page.get_by_role("region", name="Properties").get_by_label("Id")
    before = selected.input_value()
    page.keyboard.press("a")
    expect(selected).not_to_have_value(before)
    if label:
        field = page.locator(".hrc-label-input")
        expect(field).to_be_focused()
        page.keyboard.type(label)
        page.keyboard.press("Enter")
        expect(field).to_have_count(0)
