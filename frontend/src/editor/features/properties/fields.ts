/** Form controls for the properties panel: each commits on change and shows its own error. */

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

export function field(parent: HTMLElement, options: FieldOptions): HTMLInputElement | HTMLTextAreaElement {
  const wrapper = add(parent, "label", "hrc-field");
  add(wrapper, "span", "hrc-field-label").textContent = options.label;
  const input = options.multiline ? document.createElement("textarea") : document.createElement("input");
  if (input instanceof HTMLInputElement) input.type = options.type ?? "text";
  input.value = options.value;
  if (options.placeholder) input.placeholder = options.placeholder;
  wrapper.appendChild(input);
  if (options.hint) add(wrapper, "small", "hrc-hint").textContent = options.hint;
  const error = add(wrapper, "span", "hrc-field-error");
  error.setAttribute("role", "alert");
  if (!options.commit) input.readOnly = true;
  else input.addEventListener("change", () => run(error, () => options.commit?.(input.value)));
  return input;
}

export function select(parent: HTMLElement, label: string, value: string, choices: [string, string][], commit?: (value: string) => void): HTMLSelectElement {
  const wrapper = add(parent, "label", "hrc-field");
  add(wrapper, "span", "hrc-field-label").textContent = label;
  const input = document.createElement("select");
  for (const [choice, text] of choices) {
    const option = add(input, "option", "") as HTMLOptionElement;
    option.value = choice;
    option.textContent = text;
  }
  input.value = value;
  input.disabled = !commit;
  wrapper.appendChild(input);
  const error = add(wrapper, "span", "hrc-field-error");
  error.setAttribute("role", "alert");
  input.addEventListener("change", () => run(error, () => commit?.(input.value)));
  return input;
}

export function checkbox(parent: HTMLElement, label: string, checked: boolean, commit: (checked: boolean) => void): HTMLInputElement {
  const wrapper = add(parent, "label", "hrc-check-field");
  const input = document.createElement("input");
  input.type = "checkbox";
  input.checked = checked;
  wrapper.append(input, ` ${label}`);
  input.addEventListener("change", () => commit(input.checked));
  return input;
}

export function heading(parent: HTMLElement, text: string): void {
  add(parent, "h3", "").textContent = text;
}

export function note(parent: HTMLElement, text: string): void {
  add(parent, "p", "hrc-note").textContent = text;
}

export function button(parent: HTMLElement, text: string, run: () => void): HTMLButtonElement {
  const node = add(parent, "button", "") as HTMLButtonElement;
  node.type = "button";
  node.textContent = text;
  node.addEventListener("click", run);
  return node;
}

export function add(parent: HTMLElement, tag: string, className: string): HTMLElement {
  const node = document.createElement(tag);
  if (className) node.className = className;
  parent.appendChild(node);
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
