/**
 * A task's configuration (its `task` key): instructions for everyone; a form
 * for an operator's task; a program step or a device call for a cobot's.
 */

import type { Shape } from "diagram-js/lib/model/Types";

import { type Extra, isObject } from "../../model/document";
import {
  DEVICE_CALLS,
  FIELD_TYPES,
  type FormField,
  fieldsOfForm,
  formatPoses,
  formOfFields,
  isExpression,
  parsePoses,
  parseWhole,
  taskKind,
  withKind,
} from "../../model/taskconfig";
import type { ActorType } from "../../model/document";
import type { TransitionObject } from "../../core/elements";
import type PatternModeling from "../modeling/PatternModeling";
import { addElement } from "../../../shared/dom";
import { button, checkbox, field, heading, note, select } from "./fields";

export function taskSection(
  parent: HTMLElement,
  shape: Shape,
  actorType: ActorType | undefined,
  modeling: PatternModeling,
  deviceCalls: Record<string, string[]> = DEVICE_CALLS,
): void {
  const object = shape.businessObject as TransitionObject;
  const task: Extra = isObject(object.data.task) ? object.data.task : {};
  const set = (next: Extra) => modeling.updateData(shape, { task: Object.keys(next).length ? next : undefined });
  const setKey = (key: string, value: unknown) => {
    const next = { ...task };
    if (value === undefined || value === "") delete next[key];
    else next[key] = value;
    set(next);
  };
  heading(parent, actorType === "cobot" ? "Cobot task" : "Operator task");
  field(parent, { label: "Instructions", value: String(task.instructions ?? ""), multiline: true, commit: (text) => setKey("instructions", text.trim() || undefined) });
  const kind = taskKind(task, actorType);
  if (kind === "operator") formEditor(parent, task, setKey);
  else {
    select(parent, "Runs", kind, [["step", "a program step"], ["device", "a device call (automated task)"]], (value) => set(withKind(task, value as "step" | "device")));
    if (kind === "step") stepEditor(parent, task, setKey);
    else deviceEditor(parent, task, setKey, deviceCalls);
  }
  field(parent, { label: "Timeout (s)", value: task.timeout === undefined ? "" : String(task.timeout), placeholder: "120", commit: (text) => setKey("timeout", text.trim() ? positive(text, "The timeout") : undefined) });
  if (kind !== "operator") field(parent, { label: "Automatic retries", value: task.retries === undefined ? "" : String(task.retries), placeholder: "3", commit: (text) => setKey("retries", text.trim() ? whole(text, "Retries") : undefined) });
}

function stepEditor(parent: HTMLElement, task: Extra, setKey: (key: string, value: unknown) => void): void {
  const step: Extra = isObject(task.step) ? task.step : {};
  const setStep = (key: string, value: unknown) => {
    const next = { ...step };
    if (value === undefined) delete next[key];
    else next[key] = value;
    setKey("step", next);
  };
  field(parent, { label: "Program", value: String(step.program ?? ""), placeholder: "the actor's program", commit: (text) => setStep("program", text.trim() || undefined) });
  field(parent, { label: "Step number", value: String(step.number ?? 1), hint: "A whole number, or =expression over data", commit: (text) => setStep("number", parseWhole(text, "number")) });
  field(parent, { label: "Workspace", value: String(step.workspace ?? 0), hint: "A whole number, or =expression over data", commit: (text) => setStep("workspace", parseWhole(text, "workspace")) });
  const fromExpression = typeof step.poses === "string";
  select(parent, "Poses", fromExpression ? "expression" : "listed", [["listed", "listed here, one a line"], ["expression", "one expression gives the list"]], (mode) =>
    setStep("poses", mode === "expression" ? "=data.poses" : []),
  );
  if (fromExpression) {
    field(parent, { label: "Poses expression", value: String(step.poses), hint: "An expression over data giving a list of poses, e.g. =data.poses", commit: (text) => {
      if (!isExpression(text.trim())) throw new Error("An expression starts with =.");
      setStep("poses", text.trim());
    } });
  } else {
    field(parent, {
      label: "Pose list",
      value: formatPoses(step.poses),
      multiline: true,
      placeholder: "0.1, 0.2, 0.05, 0, 0, 0",
      hint: "One pose a line: x, y, z, rx, ry, rz, or =expression for that pose (e.g. =data.pick_pose).",
      commit: (text) => setStep("poses", parsePoses(text)),
    });
  }
}

function deviceEditor(parent: HTMLElement, task: Extra, setKey: (key: string, value: unknown) => void, calls: Record<string, string[]>): void {
  const device: Extra = isObject(task.device) ? task.device : {};
  const call = typeof device.call === "string" && device.call in calls ? device.call : Object.keys(calls)[0];
  const args: Extra = isObject(device.args) ? device.args : {};
  select(parent, "Device call", call, Object.keys(calls).map((name) => [name, name]), (value) =>
    setKey("device", { ...device, call: value, args: Object.fromEntries(calls[value].map((name) => [name, args[name] ?? ""])) }),
  );
  for (const name of calls[call]) {
    const value = args[name];
    field(parent, {
      label: `Argument ${name}`,
      value: value === undefined ? "" : typeof value === "string" ? value : JSON.stringify(value),
      hint: "A value (number, text) or =expression",
      commit: (text) => setKey("device", { ...device, call, args: { ...args, [name]: literal(text) } }),
    });
  }
  if (calls[call].length === 0) note(parent, `${call} takes no arguments.`);
}

function formEditor(parent: HTMLElement, task: Extra, setKey: (key: string, value: unknown) => void): void {
  const fields = fieldsOfForm(task.form);
  addElement(parent, "h4", "").textContent = "Form fields the operator fills in";
  const save = (next: FormField[]) => setKey("form", formOfFields(next, task.form));
  fields.forEach((formField, index) => {
    const row = addElement(parent, "div", "hrc-form-row");
    const update = (change: Partial<FormField>) => save(fields.map((f, i) => (i === index ? { ...f, ...change } : f)));
    field(row, { label: "Name", value: formField.name, commit: (text) => update({ name: text.trim() }) });
    field(row, { label: "Title", value: formField.title, commit: (text) => update({ title: text.trim() }) });
    select(row, "Type", formField.type, FIELD_TYPES.map((type) => [type, type]), (type) => update({ type: type as FormField["type"] }));
    checkbox(row, "required", formField.required, (required) => update({ required }));
    button(row, "Remove field", () => save(fields.filter((_, i) => i !== index)));
  });
  button(parent, "Add a form field", () => {
    let n = fields.length + 1;
    while (fields.some((f) => f.name === `field${n}`)) n += 1;
    save([...fields, { name: `field${n}`, type: "string", title: "", required: false }]);
  });
}

function literal(text: string): unknown {
  const trimmed = text.trim();
  if (isExpression(trimmed) || trimmed === "") return trimmed;
  const number = Number(trimmed);
  return Number.isFinite(number) ? number : trimmed;
}

function positive(text: string, what: string): number {
  const value = Number(text);
  if (!Number.isFinite(value) || value <= 0 || value > 86400) throw new Error(`${what} is a number of seconds between 0 and 86400.`);
  return value;
}

function whole(text: string, what: string): number {
  const value = Number(text);
  if (!Number.isInteger(value) || value < 0 || value > 20) throw new Error(`${what} is a whole number from 0 to 20.`);
  return value;
}
