// A task's form, built from its JSON Schema (the `form` of /api/work-items/<id>/): big touch
// fields for yes/no, numbers, choices and text; values read back typed.
//
// Only answers are recorded: a yes/no is two choices with neither taken (unless the schema
// gives a default), a choice starts at "Choose…", and a field left alone is left out of the
// result rather than sent as false, "" or 0. A required field left unanswered is named at the
// field before anything is sent (the server refuses it too).

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

export interface RenderedForm {
  /** The answers given, typed; unanswered fields are absent. */
  read(): Record<string, unknown>;
  /** Marks each required field left unanswered at the field; true when there is none. */
  check(): boolean;
}

interface Field {
  name: string;
  required: boolean;
  read: () => unknown;
  problem: HTMLElement;
}

const UNANSWERED = "Answer this before completing.";

/** The form's fields inside `container`. */
export function renderForm(container: HTMLElement, schema: FormSchema | null): RenderedForm {
  container.replaceChildren();
  const required = new Set(schema?.required ?? []);
  const fields: Field[] = [];
  for (const [name, field] of Object.entries(schema?.properties ?? {})) {
    const id = `field-${name}`;
    const row = document.createElement("div");
    row.className = "field";
    const title = (field.title ?? name) + (required.has(name) ? " *" : "");
    let read: () => unknown;
    if (field.enum) {
      row.append(labelFor(id, title));
      read = choice(row, id, name, field);
    } else if (field.type === "boolean") {
      read = yesNo(row, id, name, title, field);
    } else {
      row.append(labelFor(id, title));
      read = entry(row, id, name, field, required.has(name));
    }
    if (field.description) {
      const help = document.createElement("small");
      help.textContent = field.description;
      row.append(help);
    }
    const problem = document.createElement("p");
    problem.className = "errors field-error";
    problem.setAttribute("role", "alert");
    problem.hidden = true;
    row.append(problem);
    container.append(row);
    fields.push({ name, required: required.has(name), read, problem });
  }
  return {
    read() {
      const values: Record<string, unknown> = {};
      for (const field of fields) {
        const value = field.read();
        if (value !== undefined) values[field.name] = value;
      }
      return values;
    },
    check() {
      let answered = true;
      for (const field of fields) {
        const missing = field.required && field.read() === undefined;
        field.problem.textContent = missing ? UNANSWERED : "";
        field.problem.hidden = !missing;
        answered &&= !missing;
      }
      return answered;
    },
  };
}

function labelFor(id: string, text: string): HTMLLabelElement {
  const label = document.createElement("label");
  label.htmlFor = id;
  label.textContent = text;
  return label;
}

/** A drop-down of the schema's values, starting at "Choose…" unless the schema gives a default. */
function choice(row: HTMLElement, id: string, name: string, field: FieldSchema): () => unknown {
  const select = document.createElement("select");
  select.id = id;
  select.name = name;
  const none = document.createElement("option");
  none.value = "";
  none.textContent = "Choose…";
  select.append(none);
  for (const value of field.enum ?? []) {
    const option = document.createElement("option");
    option.value = JSON.stringify(value);
    option.textContent = String(value);
    select.append(option);
  }
  select.value = field.default !== undefined ? JSON.stringify(field.default) : "";
  row.append(select);
  return () => (select.value === "" ? undefined : JSON.parse(select.value));
}

/** Yes and No as two big buttons of one group; neither is taken unless the schema's default says. */
function yesNo(row: HTMLElement, id: string, name: string, title: string, field: FieldSchema): () => unknown {
  row.classList.add("yes-no");
  const group = document.createElement("fieldset");
  group.id = id;
  const legend = document.createElement("legend");
  legend.textContent = title;
  group.append(legend);
  const boxes: HTMLInputElement[] = [];
  for (const [answer, text] of [[true, "Yes"], [false, "No"]] as const) {
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "radio";
    box.name = name;
    box.value = String(answer);
    box.checked = field.default === answer;
    label.append(box, document.createTextNode(text));
    group.append(label);
    boxes.push(box);
  }
  row.append(group);
  return () => {
    const taken = boxes.find((box) => box.checked);
    return taken === undefined ? undefined : taken.value === "true";
  };
}

function entry(row: HTMLElement, id: string, name: string, field: FieldSchema, required: boolean): () => unknown {
  const input = document.createElement("input");
  input.id = id;
  input.name = name;
  const numeric = field.type === "integer" || field.type === "number";
  input.type = numeric ? "number" : "text";
  if (numeric) {
    input.inputMode = field.type === "integer" ? "numeric" : "decimal";
    input.step = field.type === "integer" ? "1" : "any";
    if (field.minimum !== undefined) input.min = String(field.minimum);
    if (field.maximum !== undefined) input.max = String(field.maximum);
  }
  if (field.default !== undefined) input.value = String(field.default);
  input.required = required;
  row.append(input);
  return () => {
    if (input.value.trim() === "") return undefined;
    return numeric ? Number(input.value) : input.value;
  };
}
