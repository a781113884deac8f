/**
 * The Predict panel's task times: one group per task of the draft, with its lane, where the
 * last prediction took its time from, and the time the engineer gives it (fixed, triangular
 * or lognormal), or none. What was typed stays, by task id, while the draft keeps the task.
 */

import { addElement, element } from "../../../shared/dom";
import type { PatternDocument } from "../../model/document";
import type { TaskDuration } from "../../model/prediction";
import { TIME_FIELDS, TIME_KINDS, type TimeEntry, type TimeKind, timeKey, timeSource } from "../../model/predictoptions";
import { numberField, select } from "../properties/fields";

interface Task {
  id: string;
  label: string;
  actor: string;
}

export default class TaskTimes {
  private readonly details: HTMLDetailsElement;
  private readonly summary: HTMLElement;
  private readonly list: HTMLElement;
  private readonly entries = new Map<string, TimeEntry>();
  private sources: Record<string, TaskDuration> = {};

  constructor(parent: HTMLElement) {
    this.details = addElement(parent, "details", "hrc-predict-times");
    this.summary = addElement(this.details, "summary", "hrc-field-label");
    addElement(this.details, "p", "hrc-hint", "A time given here replaces the measured one, the program's and the default.");
    this.list = addElement(this.details, "div");
    this.count();
  }

  /** A group per task of `document`; a task's typed time stays while the draft has the task. */
  refresh(document: PatternDocument): void {
    const tasks = tasksOf(document);
    const ids = new Set(tasks.map((task) => task.id));
    for (const id of this.entries.keys()) if (!ids.has(id)) this.entries.delete(id);
    this.details.hidden = tasks.length === 0;
    this.list.replaceChildren(...tasks.map((task) => this.group(task)));
    this.count();
  }

  /** Shows where the prediction that answered `durations` took each task's time from. */
  showSources(durations: Record<string, TaskDuration>): void {
    this.sources = durations;
    for (const line of this.list.querySelectorAll<HTMLElement>(".hrc-predict-source")) this.source(line);
  }

  /** Each task's time as typed. */
  times(): Record<string, TimeEntry> {
    return Object.fromEntries(this.entries);
  }

  private group(task: Task): HTMLElement {
    const group = element("fieldset", { class: "hrc-predict-task", "data-task": task.id });
    addElement(group, "legend", "", `${task.label} (${task.actor})`);
    this.source(addElement(group, "p", { class: "hrc-hint hrc-predict-source", "data-task": task.id }));
    const entry = this.entries.get(task.id) ?? { kind: "", values: {} };
    const values = element("div", "hrc-predict-time-values");
    select(group, "Time", entry.kind, TIME_KINDS, (kind) => {
      entry.kind = kind as TimeKind;
      this.entries.set(task.id, entry);
      this.fields(values, task.id, entry);
      this.count();
    });
    group.append(values);
    this.fields(values, task.id, entry);
    return group;
  }

  /** The fields of the entry's kind, each keeping its text in the entry as it is typed. */
  private fields(parent: HTMLElement, task: string, entry: TimeEntry): void {
    parent.replaceChildren();
    if (entry.kind === "") return;
    for (const [field, label] of TIME_FIELDS[entry.kind]) {
      const input = numberField(parent, label, entry.values[field] ?? "", { min: 0, step: "any" });
      input.dataset.option = timeKey(task, field);
      input.addEventListener("input", () => (entry.values[field] = input.value));
    }
  }

  private source(line: HTMLElement): void {
    const duration = this.sources[line.dataset.task as string];
    line.textContent = duration ? timeSource(duration) : "";
  }

  private count(): void {
    const given = [...this.entries.values()].filter((entry) => entry.kind !== "").length;
    this.summary.textContent = given ? `Task times (${given} given)` : "Task times";
  }
}

/** The draft's tasks (its transitions with a performer), in the order drawn. */
function tasksOf(document: PatternDocument): Task[] {
  return document.processes.flatMap((process) =>
    process.transitions.filter((transition) => transition.performer).map((transition) => ({ id: transition.id, label: transition.label?.trim() || transition.id, actor: transition.performer as string })),
  );
}
