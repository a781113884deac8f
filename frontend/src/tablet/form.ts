// A task's form, built from its JSON Schema (the `form` of /api/work-items/<id>/): big touch
// fields for booleans, numbers, choices and text; values read back typed.

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

/** The form's fields inside `container`; returns a function that reads the values. */
export function renderForm(container: HTMLElement, schema: FormSchema | null): () => Record<string, unknown> {
  container.replaceChildren();
  const properties = schema?.properties ?? {};
  const required = new Set(schema?.required ?? []);
  const readers: Array<[string, () => unknown]> = [];
  for (const [name, field] of Object.entries(properties)) {
    const id = `field-${name}`;
    const row = document.createElement("div");
    row.className = "field";
    const label = document.createElement("label");
    label.htmlFor = id;
    label.textContent = (field.title ?? name) + (required.has(name) ? " *" : "");
    row.append(label);
    let read: () => unknown;
    if (field.enum) {
      const select = document.createElement("select");
      select.id = id;
      select.name = name;
      for (const value of field.enum) {
        const option = document.createElement("option");
        option.value = JSON.stringify(value);
        option.textContent = String(value);
        select.append(option);
      }
      if (field.default !== undefined) select.value = JSON.stringify(field.default);
      row.append(select);
      read = () => JSON.parse(select.value);
    } else if (field.type === "boolean") {
      const box = document.createElement("input");
      box.type = "checkbox";
      box.id = id;
      box.name = name;
      box.checked = field.default === true;
      row.classList.add("check");
      row.prepend(box);
      read = () => box.checked;
    } else {
      const input = document.createElement("input");
      input.id = id;
      input.name = name;
      const numeric = field.type === "integer" || field.type === "number";
      input.type = numeric ? "number" : "text";
      if (numeric) {
        input.inputMode = field.type === "integer" ? "numeric" : "decimal";
        if (field.type === "integer") input.step = "1";
        else input.step = "any";
        if (field.minimum !== undefined) input.min = String(field.minimum);
        if (field.maximum !== undefined) input.max = String(field.maximum);
      }
      if (field.default !== undefined) input.value = String(field.default);
      input.required = required.has(name);
      row.append(input);
      read = () => {
        if (input.value === "") return undefined;
        return numeric ? Number(input.value) : input.value;
      };
    }
    if (field.description) {
      const help = document.createElement("small");
      help.textContent = field.description;
      row.append(help);
    }
    container.append(row);
    readers.push([name, read]);
  }
  return () => {
    const values: Record<string, unknown> = {};
    for (const [name, read] of readers) {
      const value = read();
      if (value !== undefined) values[name] = value;
    }
    return values;
  };
}
