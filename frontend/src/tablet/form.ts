// A task's form, built from its JSON Schema (the `form` of /api/work-items/<id>/): big touch
// fields for booleans, numbers, choices and text; values read back typed.
//
// It records only answers. A yes/no is two choices, a choice starts at "Choose…", and a field the
// operator leaves alone is left out of the values (not false, "" or 0). A `default` is shown
// filled in only on an optional field, where leaving it is an answer the operator can see; a
// required field is never filled in for them, default or not, so one tap cannot answer it.

export interface FieldSchema {
  type?: string;
  title?: string;
  description?: string;
  enum?: unknown[];
  minimum?: number;
  maximum?: number;
  default?: unknown;
}

export interface FormSchema {
  type?: string;
  title?: string;
  properties?: Record<string, FieldSchema>;
  required?: string[];
}

/** The fields of a rendered form. */
export interface FormFields {
  /** The answers given, by field: a field left alone is absent. */
  values(): Record<string, unknown>;
  /** Shows "an answer is required" at each required field left alone; true when none is. */
  check(): boolean;
  /** Shows each message at its field (the server's `fields`), clearing the others; returns the
   * messages of names that are no field of the form, for the form's own error line. */
  showErrors(errors: Record<string, string[] | string>): string[];
}

export const REQUIRED_MESSAGE = "an answer is required";

interface Field {
  row: HTMLElement;
  error: HTMLElement;
  required: boolean;
  read: () => unknown;
}

/** The form's fields inside `container`. */
export function buildForm(container: HTMLElement, schema: FormSchema | null): FormFields {
  container.replaceChildren();
  const properties = schema?.properties ?? {};
  const required = new Set(schema?.required ?? []);
  const fields = new Map<string, Field>();
  for (const [name, field] of Object.entries(properties)) {
    const isRequired = required.has(name);
    const prefill = isRequired ? undefined : field.default;
    const row = document.createElement("div");
    row.className = "field";
    row.dataset.field = name;
    const title = (field.title ?? name) + (isRequired ? " *" : "");
    const error = document.createElement("p");
    error.className = "field-error";
    error.id = `field-${name}-error`;
    error.hidden = true;
    let read: () => unknown;
    if (field.enum) read = choice(row, name, title, field.enum, prefill, isRequired);
    else if (field.type === "boolean") read = yesNo(row, name, title, prefill, isRequired);
    else read = input(row, name, title, field, prefill, isRequired);
    row.append(error);
    if (field.description) {
      const help = document.createElement("small");
      help.textContent = field.description;
      row.append(help);
    }
    for (const control of row.querySelectorAll("input, select")) control.setAttribute("aria-describedby", error.id);
    // An answer clears the field's message.
    row.addEventListener("change", () => setError(row, error, ""));
    row.addEventListener("input", () => setError(row, error, ""));
    container.append(row);
    fields.set(name, { row, error, required: isRequired, read });
  }
  return {
    values() {
      const values: Record<string, unknown> = {};
      for (const [name, field] of fields) {
        const value = field.read();
        if (value !== undefined) values[name] = value;
      }
      return values;
    },
    check() {
      let complete = true;
      for (const field of fields.values()) {
        const missing = field.required && field.read() === undefined;
        setError(field.row, field.error, missing ? REQUIRED_MESSAGE : "");
        complete &&= !missing;
      }
      if (!complete) focusFirstError(container);
      return complete;
    },
    showErrors(errors) {
      const rest: string[] = [];
      for (const [name, field] of fields) setError(field.row, field.error, messages(errors[name]).join(" "));
      for (const [name, message] of Object.entries(errors)) {
        if (!fields.has(name)) rest.push(`${name}: ${messages(message).join(" ")}`);
      }
      focusFirstError(container);
      return rest;
    },
  };
}

/** The form's fields inside `container`; returns a function that reads the answers given. */
export function renderForm(container: HTMLElement, schema: FormSchema | null): () => Record<string, unknown> {
  const form = buildForm(container, schema);
  return () => form.values();
}

function choice(row: HTMLElement, name: string, title: string, values: unknown[], prefill: unknown, required: boolean): () => unknown {
  const id = `field-${name}`;
  row.append(labelFor(id, title));
  const select = document.createElement("select");
  select.id = id;
  select.name = name;
  select.required = required;
  const none = document.createElement("option");
  none.value = "";
  none.textContent = "Choose…";
  select.append(none);
  for (const value of values) {
    const option = document.createElement("option");
    option.value = JSON.stringify(value);
    option.textContent = String(value);
    select.append(option);
  }
  select.value = prefill !== undefined && values.some((v) => JSON.stringify(v) === JSON.stringify(prefill)) ? JSON.stringify(prefill) : "";
  row.append(select);
  return () => (select.value === "" ? undefined : (JSON.parse(select.value) as unknown));
}

/** Two choices, Yes and No, as radio buttons: neither is chosen until the operator chooses. */
function yesNo(row: HTMLElement, name: string, title: string, prefill: unknown, required: boolean): () => unknown {
  row.classList.add("yes-no");
  const group = document.createElement("fieldset");
  const legend = document.createElement("legend");
  legend.textContent = title;
  group.append(legend);
  const choices = document.createElement("div");
  choices.className = "choices";
  const radios: HTMLInputElement[] = [];
  for (const [text, value] of [["Yes", true], ["No", false]] as const) {
    const label = document.createElement("label");
    label.className = "choice";
    const radio = document.createElement("input");
    radio.type = "radio";
    radio.name = `field-${name}`;
    radio.value = String(value);
    radio.required = required;
    radio.checked = prefill === value;
    label.append(radio, document.createTextNode(text));
    choices.append(label);
    radios.push(radio);
  }
  group.append(choices);
  row.append(group);
  return () => {
    const chosen = radios.find((radio) => radio.checked);
    return chosen ? chosen.value === "true" : undefined;
  };
}

function input(row: HTMLElement, name: string, title: string, field: FieldSchema, prefill: unknown, required: boolean): () => unknown {
  const id = `field-${name}`;
  row.append(labelFor(id, title));
  const control = document.createElement("input");
  control.id = id;
  control.name = name;
  const numeric = field.type === "integer" || field.type === "number";
  control.type = numeric ? "number" : "text";
  if (numeric) {
    control.inputMode = field.type === "integer" ? "numeric" : "decimal";
    control.step = field.type === "integer" ? "1" : "any";
    if (field.minimum !== undefined) control.min = String(field.minimum);
    if (field.maximum !== undefined) control.max = String(field.maximum);
  }
  if (prefill !== undefined) control.value = String(prefill);
  control.required = required;
  row.append(control);
  return () => {
    if (control.value === "") return undefined;
    return numeric ? Number(control.value) : control.value;
  };
}

function labelFor(id: string, text: string): HTMLLabelElement {
  const label = document.createElement("label");
  label.htmlFor = id;
  label.textContent = text;
  return label;
}

function setError(row: HTMLElement, error: HTMLElement, message: string): void {
  error.textContent = message;
  error.hidden = !message;
  row.classList.toggle("invalid", !!message);
  for (const control of row.querySelectorAll("input, select")) {
    if (message) control.setAttribute("aria-invalid", "true");
    else control.removeAttribute("aria-invalid");
  }
}

function focusFirstError(container: HTMLElement): void {
  container.querySelector<HTMLElement>(".field.invalid input, .field.invalid select")?.focus();
}

function messages(value: string[] | string | undefined): string[] {
  if (value === undefined) return [];
  return Array.isArray(value) ? value.map(String) : [String(value)];
}
