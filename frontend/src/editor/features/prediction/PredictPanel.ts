/**
 * The Predict panel beside the canvas: how many cases, how many at once, the people of each
 * operator lane, the seed and the times the engineer gives tasks (TaskTimes), each checked
 * as it is typed; the server simulates the draft (POST /api/patterns/predict/) and the panel
 * shows the cycle time, each lane's load, the bottleneck, the typical case's critical path,
 * the times it had to assume and the cases that got stuck. Compare sets the draft beside one
 * of the pattern's published versions, predicted under the same options. The bottleneck is
 * marked on the canvas (PredictionMarkers) while the panel is open and the model is the one
 * predicted.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Selection from "diagram-js/lib/features/selection/Selection";

import { addElement, element } from "../../../shared/dom";
import { problemOf } from "../../../shared/http";
import type { Api, PredictRequest, VersionSummary } from "../../api";
import type PatternImporter from "../../core/PatternImporter";
import {
  bottleneckName,
  comparisonRows,
  formatRate,
  formatSeconds,
  formatShare,
  type Prediction,
  type PredictionAnswer,
  type TaskDuration,
  utilisationWords,
} from "../../model/prediction";
import { peopleKey, type Problems, readOptions } from "../../model/predictoptions";
import { numberField, showError } from "../properties/fields";
import type PredictionMarkers from "./PredictionMarkers";
import TaskTimes from "./TaskTimes";

export default class PredictPanel {
  static $inject = ["eventBus", "config.shell", "config.api", "config.pattern", "patternImporter", "predictionMarkers", "elementRegistry", "selection", "canvas"];

  readonly section: HTMLElement;
  readonly results: HTMLElement;
  private readonly status: HTMLElement;
  private readonly form: HTMLFormElement;
  private readonly people: HTMLElement;
  private readonly times: TaskTimes;
  private readonly versionSelect: HTMLSelectElement;
  private readonly compareButton: HTMLButtonElement;
  private readonly fields: Record<"cases" | "parallel" | "seed", HTMLInputElement>;
  private readonly peopleByActor = new Map<string, string>();
  /** Counts the model's changes: an answer for an older model is shown as such, and marks nothing. */
  private generation = 0;
  private busy = false;
  answer: PredictionAnswer | null = null;
  private answerGeneration = -1;

  constructor(
    private readonly eventBus: EventBus,
    shell: { side: HTMLElement },
    private readonly api: Api,
    private readonly pattern: { id: number | null },
    private readonly importer: PatternImporter,
    private readonly markers: PredictionMarkers,
    private readonly elementRegistry: ElementRegistry,
    private readonly selection: Selection,
    private readonly canvas: Canvas,
  ) {
    this.section = element("section", { class: "hrc-predict", id: "hrc-predict", "aria-label": "Prediction" });
    this.section.hidden = true;
    shell.side.prepend(this.section);
    addElement(this.section, "h2", "", "Predict");
    addElement(this.section, "p", "hrc-hint", "Simulates many cases of the draft as drawn: task times measured in earlier versions' cases where there are some.");
    const form = (this.form = addElement(this.section, "form", "hrc-predict-options"));
    // The server judges the ranges and says which option is wrong; the panel shows its words.
    form.noValidate = true;
    this.fields = {
      cases: optionField(form, "Cases", "cases", 1000, 1, 10000),
      parallel: optionField(form, "Cases at once", "parallel", 1, 1, 1000),
      seed: optionField(form, "Seed", "seed", 0, 0, 2 ** 31 - 1),
    };
    this.people = addElement(form, "fieldset", "hrc-predict-people");
    this.times = new TaskTimes(form);
    addElement(form, "button", { type: "submit", class: "primary" }, "Predict");
    form.addEventListener("submit", (event) => {
      event.preventDefault();
      void this.predict();
    });
    // Said as it is typed, not on leaving the field: a message appearing then would move the button being clicked.
    form.addEventListener("input", (event) => this.showProblems(this.read().problems, event.target));
    const compare = addElement(this.section, "div", "hrc-predict-compare");
    const label = addElement(compare, "label", "hrc-field");
    addElement(label, "span", "hrc-field-label", "Published version");
    this.versionSelect = addElement(label, "select");
    this.compareButton = addElement(compare, "button", { type: "button" }, "Compare");
    this.compareButton.addEventListener("click", () => void this.predict(Number(this.versionSelect.value)));
    this.status = addElement(this.section, "p", { class: "hrc-predict-status", role: "status" });
    this.results = addElement(this.section, "div", "hrc-predict-results");

    eventBus.on(["commandStack.changed", "import.done"], () => this.modelChanged());
    eventBus.on("diagram.clear", () => this.markers.clear());
  }

  get open(): boolean {
    return !this.section.hidden;
  }

  toggle(): void {
    if (this.open) this.close();
    else void this.show();
  }

  async show(): Promise<void> {
    this.section.hidden = false;
    this.eventBus.fire("prediction.toggled", { open: true });
    this.refreshFields();
    this.section.scrollIntoView?.({ block: "nearest" });
    this.fields.cases.focus();
    if (this.answer && this.answerGeneration === this.generation) this.markers.show(this.answer.prediction);
    await this.loadVersions();
  }

  close(): void {
    this.section.hidden = true;
    this.markers.clear();
    this.eventBus.fire("prediction.toggled", { open: false });
  }

  /** Posts the draft, with `compareVersion` when set; shows the answer or the server's refusal. */
  async predict(compareVersion?: number): Promise<void> {
    if (this.busy) return;
    const body = this.request(compareVersion);
    if (body === null) return;
    const generation = this.generation;
    this.busy = true;
    this.section.setAttribute("aria-busy", "true");
    this.status.textContent = compareVersion ? "Predicting the draft and the version…" : "Predicting…";
    this.status.classList.remove("hrc-error");
    this.status.setAttribute("role", "status");
    try {
      const answer = await this.api.predict(body);
      this.answer = answer;
      this.answerGeneration = generation;
      this.status.textContent = "";
      this.times.showSources(answer.durations);
      this.render(answer, generation === this.generation);
      if (generation === this.generation && this.open) this.markers.show(answer.prediction);
    } catch (error) {
      this.fail(`The prediction failed: ${problemOf(error)}`);
    } finally {
      this.busy = false;
      this.section.removeAttribute("aria-busy");
    }
  }

  /** The request for the draft (and the version to compare it with); null, with the problems shown, when a field is wrong. */
  private request(compareVersion?: number): PredictRequest | null {
    const { options, problems } = this.read();
    const wrong = this.showProblems(problems);
    if (wrong) {
      this.fail("Nothing was sent: correct the marked fields.");
      wrong.closest("details")?.setAttribute("open", "");
      wrong.focus();
      return null;
    }
    const body: PredictRequest = { document: this.importer.document(), options };
    if (this.pattern.id !== null) body.pattern = this.pattern.id;
    if (compareVersion) body.compare_version = compareVersion;
    return body;
  }

  private read(): ReturnType<typeof readOptions> {
    const people: Record<string, string> = {};
    for (const input of this.people.querySelectorAll<HTMLInputElement>("input[data-actor]")) people[input.dataset.actor as string] = input.value;
    const { cases, parallel, seed } = this.fields;
    return readOptions({ cases: cases.value, parallel: parallel.value, seed: seed.value, people, times: this.times.times() });
  }

  /**
   * Puts each problem beside its field; answers the first wrong field, null when none is.
   * While `typed` is being typed in, an empty field other than it is left alone: a time's
   * fields start empty when its kind is chosen.
   */
  private showProblems(problems: Problems, typed?: EventTarget | null): HTMLInputElement | null {
    let first: HTMLInputElement | null = null;
    for (const input of this.form.querySelectorAll<HTMLInputElement>("input[data-option]")) {
      if (typed !== undefined && input !== typed && input.value === "") continue;
      const problem = problems[input.dataset.option as string] ?? "";
      showError(input, problem);
      if (problem) first ??= input;
    }
    return first;
  }

  private fail(message: string): void {
    this.status.textContent = message;
    this.status.classList.add("hrc-error");
    this.status.setAttribute("role", "alert");
  }

  private modelChanged(): void {
    this.generation += 1;
    this.markers.clear();
    if (this.results.firstChild && !this.results.querySelector(".hrc-predict-stale")) {
      this.results.prepend(element("p", "hrc-predict-stale hrc-warning", "The model changed since this prediction: predict again."));
    }
    if (this.open) this.refreshFields();
  }

  private refreshFields(): void {
    this.refreshPeople();
    this.times.refresh(this.importer.document());
  }

  /** One field per operator lane for its persons, keeping what was typed for a lane still there. */
  private refreshPeople(): void {
    for (const input of this.people.querySelectorAll<HTMLInputElement>("input[data-actor]")) this.peopleByActor.set(input.dataset.actor as string, input.value);
    const operators = this.importer.document().actors.filter((actor) => actor.type === "operator");
    this.people.replaceChildren();
    this.people.hidden = operators.length === 0;
    addElement(this.people, "legend", "hrc-field-label", "Persons per operator lane");
    for (const actor of operators) {
      const input = optionField(this.people, String(actor.id), peopleKey(actor.id), 1, 1, 1000);
      input.dataset.actor = String(actor.id);
      input.value = this.peopleByActor.get(String(actor.id)) ?? "1";
    }
  }

  private async loadVersions(): Promise<void> {
    const compare = this.compareButton.parentElement as HTMLElement;
    if (this.pattern.id === null) {
      compare.hidden = true;
      return;
    }
    let versions: VersionSummary[];
    try {
      versions = await this.api.versions(this.pattern.id);
    } catch (error) {
      this.fail(`The published versions could not be read: ${problemOf(error)}`);
      return;
    }
    const chosen = this.versionSelect.value;
    this.versionSelect.replaceChildren(...versions.map((version) => element("option", { value: String(version.id) }, `Version ${version.number}${version.retired_at ? " (retired)" : ""}`)));
    if (versions.some((version) => String(version.id) === chosen)) this.versionSelect.value = chosen;
    compare.hidden = false;
    this.versionSelect.disabled = this.compareButton.disabled = versions.length === 0;
    if (versions.length === 0) this.versionSelect.replaceChildren(element("option", { value: "" }, "None published yet"));
  }

  private render(answer: PredictionAnswer, current: boolean): void {
    const prediction = answer.prediction;
    const parts: Node[] = [];
    if (!current) parts.push(element("p", "hrc-predict-stale hrc-warning", "The model changed while this was predicted: predict again."));
    parts.push(...this.summary(prediction));
    parts.push(...this.lanes(prediction));
    parts.push(...this.bottleneck(prediction));
    parts.push(...this.criticalPath(prediction));
    parts.push(...this.assumed(prediction, answer.durations));
    if (answer.compared) parts.push(...this.comparison(prediction, answer.compared.prediction, answer.compared.version.number));
    this.results.replaceChildren(...parts);
  }

  private summary(prediction: Prediction): Node[] {
    const nodes: Node[] = [element("h3", "", "Cycle time")];
    const cycle = prediction.cycle_time;
    const list = element("dl", "hrc-predict-figures");
    const figure = (term: string, value: string, key: string) => list.append(element("dt", "", term), element("dd", { "data-figure": key }, value));
    if (cycle) {
      figure("Median (p50)", formatSeconds(cycle.p50), "p50");
      figure("p90", formatSeconds(cycle.p90), "p90");
      figure("p99", formatSeconds(cycle.p99), "p99");
    }
    figure("Throughput", formatRate(prediction.throughput_per_hour), "throughput");
    figure("Cases", `${prediction.completed} of ${prediction.cases} completed, ${prediction.parallel} at once`, "cases");
    nodes.push(list);
    if (prediction.stuck_count > 0) {
      const why = prediction.stuck[0]?.why;
      nodes.push(element("p", { class: "hrc-predict-stuck hrc-warning", role: "alert" }, `${prediction.stuck_count} case${prediction.stuck_count === 1 ? "" : "s"} got stuck${why ? `: ${why}` : "."}`));
    }
    return nodes;
  }

  private lanes(prediction: Prediction): Node[] {
    const list = element("ul", "hrc-predict-lanes");
    for (const load of prediction.actors) {
      const item = addElement(list, "li", { "data-actor": load.actor });
      const people = load.kind === "operator" ? (load.people === null ? ", any number of persons" : `, ${load.people} person${load.people === 1 ? "" : "s"}`) : "";
      addElement(item, "span", "hrc-predict-lane", `${load.actor} (${load.kind}${people})`);
      const meter = addElement(item, "meter", { min: "0", max: "1", value: String(Math.min(1, load.utilisation)), "aria-label": `${load.actor} utilisation` });
      meter.title = utilisationWords(load);
      addElement(item, "span", "hrc-predict-share", utilisationWords(load));
      addElement(item, "span", "hrc-hint", `waits ${formatSeconds(load.waiting_per_case)} a case`);
    }
    return [element("h3", "", "Utilisation per lane"), list];
  }

  private bottleneck(prediction: Prediction): Node[] {
    const name = bottleneckName(prediction);
    if (name === null || prediction.bottleneck === null) return [element("h3", "", "Bottleneck"), element("p", "hrc-hint", "None: no task spent time on a completed case's critical path.")];
    const id = prediction.bottleneck;
    const task = prediction.tasks.find((load) => load.task === id);
    const words = element("p", { class: "hrc-predict-bottleneck", "data-task": id }, element("strong", "", name));
    if (task) words.append(` (${task.actor}): ${formatShare(task.critical_share)} of a cycle on the critical path, ${formatSeconds(task.critical_wait_seconds)} of it waiting.`);
    const shape = this.elementRegistry.get(id);
    if (shape) {
      const show = addElement(words, "button", { type: "button" }, "Show");
      show.addEventListener("click", () => {
        this.selection.select(shape);
        this.canvas.scrollToElement(shape as never);
      });
    }
    return [element("h3", "", "Bottleneck"), words];
  }

  private criticalPath(prediction: Prediction): Node[] {
    if (!prediction.critical_path.length) return [];
    const list = element("ol", "hrc-predict-path");
    for (const step of prediction.critical_path) {
      const waited = step.waited > 0 ? `waits ${formatSeconds(step.waited)}, ` : "";
      addElement(list, "li", { "data-task": step.task }, `${step.label.trim() || step.task} (${step.actor}): ${waited}${formatSeconds(step.worked)}`);
    }
    return [element("h3", "", "Critical path of a typical case"), list];
  }

  private assumed(prediction: Prediction, durations: Record<string, TaskDuration>): Node[] {
    if (!prediction.assumed.length) return [];
    const list = element("ul", "hrc-predict-assumed");
    for (const id of prediction.assumed) {
      const duration = durations[id];
      addElement(list, "li", { "data-task": id }, `${duration?.label.trim() || id}: ${duration?.describe ?? "assumed"}`);
    }
    const hint = element("p", "hrc-hint", "No measurement and no given time: these are guesses. Give the tasks a time, or run the pattern to measure them, for a prediction to trust.");
    return [element("h3", "", "Assumed times"), hint, list];
  }

  private comparison(draft: Prediction, version: Prediction, number: number): Node[] {
    const table = element("table", "hrc-predict-comparison");
    const head = addElement(addElement(table, "thead"), "tr");
    for (const text of ["", "Draft", `Version ${number}`, "Difference"]) addElement(head, "th", { scope: "col" }, text);
    const body = addElement(table, "tbody");
    let group = "";
    for (const row of comparisonRows(draft, version)) {
      if (row.group === "utilisation" && group !== row.group) {
        addElement(addElement(body, "tr", "hrc-predict-group"), "th", { scope: "rowgroup", colspan: "4" }, "Utilisation per lane");
      }
      group = row.group;
      const line = addElement(body, "tr", { "data-row": row.key, class: `hrc-predict-row-${row.group}` });
      addElement(line, "th", { scope: "row" }, row.label);
      addElement(line, "td", "", row.draft);
      addElement(line, "td", "", row.version);
      const difference = addElement(line, "td", "", row.difference);
      if (row.better !== null) difference.className = row.better ? "hrc-better" : "hrc-worse";
    }
    return [element("h3", "", `Draft vs version ${number}`), table];
  }
}

/** A whole-number option's input, keyed for its problem (predictoptions.ts); the server's check has the last word on its range. */
function optionField(parent: HTMLElement, label: string, key: string, value: number, minimum: number, maximum: number): HTMLInputElement {
  const input = numberField(parent, label, String(value), { min: minimum, max: maximum });
  input.dataset.option = key;
  return input;
}
