/** Form controls for the editor's panels: each commits on change and shows its own error. */

import { addElement } from "../../../shared/dom";

export interface FieldOptions {
  label: string;
  value: string;
  /** Applies the text; throws an Error whose message is shown under the field. */
  commit?: (value: string) => void;
  multiline?: boolean;
  placeholder?: string;
  hint?: string;
  type?: string;
}

let fieldCount = 0;

/**
 * A labelled control in its `.hrc-field`; the hint and the error describe it without being
 * part of its name. Returns the element the error goes in.
 */
export function labelled(parent: HTMLElement, text: string, control: HTMLElement, hint?: string): HTMLElement {
  fieldCount += 1;
  const id = `hrc-field-${fieldCount}`;
  const wrapper = addElement(parent, "div", "hrc-field");
  const label = addElement(wrapper, "label", "hrc-field-label");
  label.htmlFor = id;
  label.textContent = text;
  control.id = id;
  wrapper.appendChild(control);
  const described: string[] = [];
  if (hint) {
    const small = addElement(wrapper, "small", "hrc-hint");
    small.id = `${id}-hint`;
    small.textContent = hint;
    described.push(small.id);
  }
  const error = addElement(wrapper, "span", "hrc-field-error");
  error.id = `${id}-error`;
  error.setAttribute("role", "alert");
  described.push(error.id);
  control.setAttribute("aria-describedby", described.join(" "));
  return error;
}

export function field(parent: HTMLElement, options: FieldOptions): HTMLInputElement | HTMLTextAreaElement {
  const input = options.multiline ? document.createElement("textarea") : document.createElement("input");
  if (input instanceof HTMLInputElement) input.type = options.type ?? "text";
  input.value = options.value;
  if (options.placeholder) input.placeholder = options.placeholder;
  const error = labelled(parent, options.label, input, options.hint);
  if (!options.commit) input.readOnly = true;
  else input.addEventListener("change", () => run(error, () => options.commit?.(input.value)));
  return input;
}

/** A number input whose value the caller reads and checks, saying what is wrong with `showError`; its bounds only guide the spinner. */
export function numberField(parent: HTMLElement, label: string, value: string, bounds: { min: number; max?: number; step?: string }): HTMLInputElement {
  const input = document.createElement("input");
  input.type = "number";
  input.min = String(bounds.min);
  if (bounds.max !== undefined) input.max = String(bounds.max);
  input.step = bounds.step ?? "1";
  input.inputMode = input.step === "1" ? "numeric" : "decimal";
  input.value = value;
  labelled(parent, label, input);
  return input;
}

/** Shows `message` as the field's error ("" clears it). */
export function showError(control: HTMLElement, message: string): void {
  const error = control.closest(".hrc-field")?.querySelector(".hrc-field-error");
  if (error) error.textContent = message;
}

export function select(parent: HTMLElement, label: string, value: string, choices: [string, string][], commit?: (value: string) => void): HTMLSelectElement {
  const input = document.createElement("select");
  for (const [choice, text] of choices) {
    const option = addElement(input, "option", "");
    option.value = choice;
    option.textContent = text;
  }
  input.value = value;
  input.disabled = !commit;
  const error = labelled(parent, label, input);
  input.addEventListener("change", () => run(error, () => commit?.(input.value)));
  return input;
}

export function checkbox(parent: HTMLElement, label: string, checked: boolean, commit: (checked: boolean) => void): HTMLInputElement {
  const wrapper = addElement(parent, "label", "hrc-check-field");
  const input = document.createElement("input");
  input.type = "checkbox";
  input.checked = checked;
  wrapper.append(input, ` ${label}`);
  input.addEventListener("change", () => commit(input.checked));
  return input;
}

export function heading(parent: HTMLElement, text: string): void {
  addElement(parent, "h3", "").textContent = text;
}

export function note(parent: HTMLElement, text: string): HTMLElement {
  const node = addElement(parent, "p", "hrc-note");
  node.textContent = text;
  return node;
}

export function button(parent: HTMLElement, text: string, run: () => void): HTMLButtonElement {
  const node = addElement(parent, "button", "");
  node.type = "button";
  node.textContent = text;
  node.addEventListener("click", run);
  return node;
}

function run(error: HTMLElement, apply: () => void): void {
  try {
    apply();
    error.textContent = "";
  } catch (problem) {
    error.textContent = (problem as Error).message;
  }
}
