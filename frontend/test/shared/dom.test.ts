import { afterEach, describe, expect, it } from "vitest";

import { addElement, element, pageConfig, patchChildren } from "../../src/shared/dom";

describe("the DOM helpers", () => {
  afterEach(() => document.body.replaceChildren());

  it("builds an element with a class and text", () => {
    const node = element("p", "empty", "Nothing for you right now.");
    expect(node.outerHTML).toBe('<p class="empty">Nothing for you right now.</p>');
  });

  it("gives an element no class attribute for an empty class", () => {
    expect(element("li", "").outerHTML).toBe("<li></li>");
  });

  it("sets attributes and appends children in order", () => {
    const node = element("td", { class: "detail", "data-seq": "3" }, "before ", element("code", "muted", "x"), " after");
    expect(node.outerHTML).toBe('<td class="detail" data-seq="3">before <code class="muted">x</code> after</td>');
  });

  it("appends the new element to its parent and answers it typed", () => {
    const list = element("ol");
    const button: HTMLButtonElement = addElement(list, "button", { type: "button" }, "Play");
    expect(list.lastChild).toBe(button);
    expect(button.type).toBe("button");
  });

  it("keeps the children that equal the ones wanted and replaces, adds and drops the others", () => {
    const list = element("ul", "", element("li", "", "a"), element("li", "", "b"), element("li", "", "c"));
    const [first, second] = [...list.children];
    patchChildren(list, [element("li", "", "a"), element("li", "", "B")]);
    expect(list.outerHTML).toBe("<ul><li>a</li><li>B</li></ul>");
    expect(list.firstChild).toBe(first); // the same node: a press on it goes on
    expect(list.lastChild).not.toBe(second);
    patchChildren(list, [element("li", "", "a"), element("li", "", "B"), element("li", "", "d")]);
    expect(list.outerHTML).toBe("<ul><li>a</li><li>B</li><li>d</li></ul>");
    expect(list.firstChild).toBe(first);
  });

  it("reads the page's JSON configuration, or null without one", () => {
    const script = document.createElement("script");
    script.type = "application/json";
    script.id = "page-config";
    script.textContent = '{"cell": "A", "user": 3}';
    document.body.append(script);
    expect(pageConfig<{ cell: string; user: number }>("page-config")).toEqual({ cell: "A", user: 3 });
    expect(pageConfig("no-such-config")).toBeNull();
  });
});
