// @vitest-environment jsdom
import { describe, expect, it } from "vitest";

import { renderForm } from "../../src/tablet/form";

const SCHEMA = {
  type: "object",
  required: ["seated", "quality"],
  properties: {
    seated: { type: "boolean", title: "Part seated?" },
    quality: { enum: ["OK", "NOK"], title: "Quality" },
    note: { type: "string", title: "Note" },
    checked: { type: "boolean", title: "Checked twice" },
    count: { type: "integer", title: "Count" },
  },
};

function form() {
  const container = document.createElement("div");
  document.body.replaceChildren(container);
  return { container, rendered: renderForm(container, SCHEMA) };
}

describe("a task's form records only answers", () => {
  it("offers yes and no with neither taken, and a choice that starts empty", () => {
    const { container, rendered } = form();
    const radios = container.querySelectorAll<HTMLInputElement>('input[name="seated"]');
    expect(Array.from(radios, (radio) => radio.checked)).toEqual([false, false]);
    expect(container.querySelector<HTMLSelectElement>('select[name="quality"]')?.value).toBe("");
    expect(rendered.read()).toEqual({});
  });

  it("names each unanswered required field at the field and sends nothing", () => {
    const { container, rendered } = form();
    expect(rendered.check()).toBe(false);
    const problems = Array.from(container.querySelectorAll<HTMLElement>(".field-error"), (p) => p.hidden ? "" : p.textContent);
    expect(problems).toEqual(["Answer this before completing.", "Answer this before completing.", "", "", ""]);
  });

  it("reads exactly what was answered, a No as false", () => {
    const { container, rendered } = form();
    container.querySelector<HTMLInputElement>('input[name="seated"][value="false"]')!.checked = true;
    const quality = container.querySelector<HTMLSelectElement>('select[name="quality"]')!;
    quality.value = JSON.stringify("NOK");
    expect(rendered.check()).toBe(true);
    expect(rendered.read()).toEqual({ seated: false, quality: "NOK" });
  });

  it("takes the schema's default as an answer given", () => {
    const container = document.createElement("div");
    const rendered = renderForm(container, { properties: { ok: { type: "boolean", default: true }, q: { enum: [1, 2], default: 2 } } });
    expect(rendered.read()).toEqual({ ok: true, q: 2 });
  });
});
