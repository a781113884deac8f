import { describe, expect, it } from "vitest";
import { buildForm, type FormSchema, REQUIRED_MESSAGE } from "../../src/tablet/form";

const SCHEMA: FormSchema = {
  type: "object",
  required: ["seated", "quality", "last"],
  properties: {
    seated: { type: "boolean", title: "Part seated?" },
    quality: { title: "Quality", enum: ["OK", "NOK"] },
    last: { type: "boolean", title: "Last cycle", default: false },
    note: { type: "string", title: "Note" },
    count: { type: "integer", title: "Count" },
    checked: { type: "boolean", title: "Checked" },
    shift: { title: "Shift", enum: ["early", "late"], default: "late" },
  },
};

function render(schema: FormSchema = SCHEMA) {
  const container = document.createElement("div");
  document.body.replaceChildren(container);
  return { container, form: buildForm(container, schema) };
}

const radio = (container: HTMLElement, field: string, answer: "Yes" | "No"): HTMLInputElement =>
  [...container.querySelectorAll<HTMLLabelElement>(`[data-field="${field}"] label.choice`)]
    .find((label) => label.textContent === answer)!
    .querySelector("input")!;

describe("a task's form", () => {
  it("asks a yes/no as two choices, neither chosen, and a choice starting at Choose…", () => {
    const { container } = render();
    const choices = container.querySelectorAll<HTMLInputElement>('[data-field="seated"] input[type="radio"]');
    expect(choices).toHaveLength(2);
    expect([...choices].some((c) => c.checked)).toBe(false);
    expect(container.querySelector('[data-field="seated"] legend')!.textContent).toBe("Part seated? *");
    const quality = container.querySelector<HTMLSelectElement>("#field-quality")!;
    expect(quality.value).toBe("");
    expect(quality.selectedOptions[0].textContent).toBe("Choose…");
    expect(container.querySelectorAll('input[type="checkbox"]')).toHaveLength(0);
  });

  it("records nothing the operator did not enter: optional fields left alone are absent", () => {
    const { form } = render();
    // A required field's default is not filled in; an optional field's is, and is shown.
    expect(form.values()).toEqual({ shift: "late" });
  });

  it("refuses to complete until each required question is answered, with the message at the field", () => {
    const { container, form } = render();
    expect(form.check()).toBe(false);
    for (const field of ["seated", "quality", "last"]) {
      const error = container.querySelector<HTMLElement>(`[data-field="${field}"] .field-error`)!;
      expect(error.hidden).toBe(false);
      expect(error.textContent).toBe(REQUIRED_MESSAGE);
    }
    expect(container.querySelector<HTMLElement>('[data-field="note"] .field-error')!.hidden).toBe(true);

    radio(container, "seated", "No").checked = true;
    radio(container, "last", "Yes").checked = true;
    const quality = container.querySelector<HTMLSelectElement>("#field-quality")!;
    quality.value = JSON.stringify("NOK");
    expect(form.check()).toBe(true);
    expect(container.querySelectorAll(".field.invalid")).toHaveLength(0);
    expect(form.values()).toEqual({ seated: false, quality: "NOK", last: true, shift: "late" });
  });

  it("shows the server's messages at their fields and hands back those of no field", () => {
    const { container, form } = render();
    const rest = form.showErrors({ count: ["0 is less than the minimum of 1"], "the form": "odd" });
    expect(container.querySelector('[data-field="count"] .field-error')!.textContent).toBe(
      "0 is less than the minimum of 1",
    );
    expect(container.querySelector("#field-count")!.getAttribute("aria-invalid")).toBe("true");
    expect(rest).toEqual(["the form: odd"]);
  });

  it("reads numbers typed and leaves an empty one out", () => {
    const { container, form } = render({ type: "object", properties: { count: { type: "integer" } } });
    expect(form.values()).toEqual({});
    container.querySelector<HTMLInputElement>("#field-count")!.value = "12";
    expect(form.values()).toEqual({ count: 12 });
  });
});
