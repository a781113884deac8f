/**
 * The properties of the selected element beside the canvas, or of the
 * pattern when nothing is selected. Every change is a command (undoable).
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Selection from "diagram-js/lib/features/selection/Selection";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import { PATTERN_NAMES, type ActorType } from "../../model/document";
import { SPACE_MODES, SPACE_MODE_WORDS, actorPair } from "../../model/taskconfig";
import { idProblem } from "../../model/ids";
import { performerRefusal } from "../../model/rules";
import { CONSTRAINT_TYPES } from "../../model/document";
import { quotedName } from "../../model/words";
import { DURATION_EXAMPLES, parseDuration } from "../../model/timers";
import { cancelsOf, parseCancels } from "../../model/cancels";

const MESSAGE_EXAMPLE = '{"name": "sync1", "correlation": {"case": "=case.id"}, "payload": {"cycle": "=data.cycle"}}';
import { isLane, isNode, lanesTopDown, laneObject, nodeObject, objectOf, type ConstraintObject, type PatternObject, type RootObject } from "../../core/elements";
import type PatternElementFactory from "../../core/PatternElementFactory";
import type PatternModeling from "../modeling/PatternModeling";
import { addElement } from "../../../shared/dom";
import { button, field, heading, note, select } from "./fields";
import { taskSection } from "./TaskSection";

type Element = Shape | Connection;

export default class PropertiesPanel {
  static $inject = ["eventBus", "config.shell", "selection", "elementRegistry", "canvas", "modeling", "elementFactory", "config.deviceCalls"];

  readonly panel: HTMLElement;

  constructor(
    eventBus: EventBus,
    shell: { side: HTMLElement },
    private readonly selection: Selection,
    private readonly elementRegistry: ElementRegistry,
    private readonly canvas: Canvas,
    private readonly modeling: PatternModeling,
    private readonly elementFactory: PatternElementFactory,
    private readonly deviceCalls: Record<string, string[]>,
  ) {
    this.panel = addElement(shell.side, "section", "hrc-properties");
    this.panel.setAttribute("aria-label", "Properties");
    eventBus.on(["selection.changed", "import.done", "commandStack.changed"], () => this.render());
  }

  render(): void {
    const selected = this.selection.get() as Element[];
    this.panel.replaceChildren();
    const element = selected.length === 1 ? selected[0] : null;
    const object = objectOf(element);
    if (selected.length > 1) {
      note(this.panel, `${selected.length} elements selected.`);
      return;
    }
    if (!element || !object || object.kind === "root") return this.patternSection();
    if (object.kind === "place" || object.kind === "transition") this.nodeSection(element as Shape, object);
    else if (object.kind === "lane") this.laneSection(element as Shape);
    else if (object.kind === "constraint") this.constraintSection(element as Connection, object);
    else this.arcSection(element as Connection);
  }

  private patternSection(): void {
    const root = this.canvas.getRootElement() as Shape;
    const object = objectOf(root) as RootObject | undefined;
    if (!object) return;
    heading(this.panel, "Pattern");
    select(this.panel, "Declared pattern", String(object.data.declared_pattern ?? ""), [["", "none (classify only)"], ...PATTERN_NAMES.map((name): [string, string] => [name, name])], (value) =>
      this.modeling.updateData(root, { declared_pattern: value || undefined }),
    );
    object.processes.forEach((process, index) => {
      field(this.panel, {
        label: `Workpiece of net ${String(process.id)}`,
        value: String(process.workpiece ?? ""),
        commit: (text) => {
          const processes = object.processes.map((p, i) => (i === index ? { ...p, workpiece: text.trim() || undefined } : p));
          this.modeling.updateData(root, {}, { processes: processes.map((p) => JSON.parse(JSON.stringify(p))) });
        },
      });
    });
    note(this.panel, "Select an element to see its properties. Drop tasks in an actor's lane; join two tasks of different actors with a constraint from the task's context pad.");
  }

  private nodeSection(shape: Shape, object: PatternObject & { kind: "place" | "transition" }): void {
    const silent = object.kind === "transition" && object.silent;
    heading(this.panel, object.kind === "place" ? "Place" : silent ? "Silent transition" : "Task");
    if (typeof object.data.rewrite === "string") this.rewriteNote(shape, object.data.rewrite);
    this.idField(shape);
    field(this.panel, { label: "Label", value: String(object.data.label ?? ""), commit: (text) => this.modeling.updateLabel(shape, text) });
    if (object.kind === "place") {
      field(this.panel, { label: "Initial tokens", type: "number", value: String(object.data.tokens ?? 0), commit: (text) => {
        const tokens = Number(text);
        if (!Number.isInteger(tokens) || tokens < 0) throw new Error("Tokens are a whole number ≥ 0.");
        this.modeling.updateData(shape, { tokens: tokens || undefined });
      } });
      return;
    }
    if (silent) {
      field(this.panel, { label: "Guard", value: String(object.data.guard ?? ""), hint: "Fires only when this expression over data holds, e.g. data.count > 3", commit: (text) => this.modeling.updateData(shape, { guard: text.trim() || undefined }) });
      this.messageField(shape, "message", "Waits for a message", '{"name": "sync1", "correlation": {"case": "=case.id"}}');
      this.messageField(shape, "send", "Sends a message when it fires", MESSAGE_EXAMPLE);
      this.timerField(shape, object.data.timer);
      this.cancelsField(shape, object.process, object.data);
      return;
    }
    const performer = String(object.data.performer ?? "");
    const lanes = this.elementRegistry.filter(isLane) as Shape[];
    select(this.panel, "Actor", performer, lanes.map((lane): [string, string] => [lane.id, `${laneObject(lane).data.type} ${lane.id}`]), (actor) => {
      const reason = performerRefusal(shape.id, actor, this.constraints(), (task) => (objectOf(this.elementRegistry.get(task)) as { data?: { performer?: string } } | undefined)?.data?.performer);
      if (reason) throw new Error(reason);
      const lane = this.elementRegistry.get(actor) as Shape;
      const y = lane.y + lane.height / 2 - (shape.y + shape.height / 2);
      this.modeling.moveElements([shape], { x: 0, y: Math.round(y) });
    });
    const actor = this.elementRegistry.get(performer);
    taskSection(this.panel, shape, actor && isLane(actor) ? laneObject(actor).data.type : undefined, this.modeling, this.deviceCalls);
    this.messageField(shape, "send", "Sends a message when it completes", MESSAGE_EXAMPLE);
  }

  /** A message key (`message` or `send`) as JSON text: its name, correlation and payload are
   * checked by the server's check, which names what is wrong; here only that it is an object. */
  private messageField(shape: Shape, key: "message" | "send", label: string, example: string): void {
    const object = objectOf(shape) as { data?: Record<string, unknown> } | undefined;
    const value = object?.data?.[key];
    field(this.panel, { label, value: value === undefined ? "" : JSON.stringify(value), hint: `JSON, e.g. ${example}`, commit: (text) => {
      if (!text.trim()) {
        this.modeling.updateData(shape, { [key]: undefined });
        return;
      }
      let parsed: unknown;
      try {
        parsed = JSON.parse(text);
      } catch {
        throw new Error("Not JSON: write an object such as the example.");
      }
      if (typeof parsed !== "object" || parsed === null || Array.isArray(parsed)) throw new Error("Write an object with a \"name\", such as the example.");
      this.modeling.updateData(shape, { [key]: parsed });
    } });
  }

  /** What an import could not translate, until the engineer says they rewrote it: the check
   * holds the model back as a draft (`to-rewrite`) while the key is there. */
  private rewriteNote(shape: Shape, text: string): void {
    const box = addElement(this.panel, "div", { class: "hrc-rewrite", role: "note", "aria-label": "To rewrite" });
    addElement(box, "h4", "").textContent = "To rewrite";
    addElement(box, "p", "hrc-rewrite-text").textContent = text;
    const done = button(box, "Rewritten", () => this.modeling.updateData(shape, { rewrite: undefined }));
    done.title = "You rewrote this as the note asks: the note goes, and with it the check's error";
  }

  private timerField(shape: Shape, timer: unknown): void {
    field(this.panel, {
      label: "Timer",
      value: typeof timer === "string" ? timer : "",
      placeholder: "no timer",
      hint: `Fires once enabled this long without interruption: an ISO 8601 duration, e.g. ${DURATION_EXAMPLES}`,
      commit: (text) => {
        const written = text.trim().toUpperCase();
        if (written) parseDuration(written);
        this.modeling.updateData(shape, { timer: written || undefined });
      },
    });
  }

  private cancelsField(shape: Shape, process: string, data: Record<string, unknown>): void {
    field(this.panel, {
      label: "Cancels",
      value: cancelsOf(data).join(", "),
      placeholder: "nothing",
      hint: "Places and tasks of this net it empties when it fires (running tasks are cancelled): their ids, e.g. p3, tc2",
      commit: (text) => {
        const ids = parseCancels(text, process, (id) => this.processOf(id));
        this.modeling.updateData(shape, { cancels: ids.length ? ids : undefined });
      },
    });
  }

  /** The process of the node with this id; undefined when no node has it. */
  private processOf(id: string): string | undefined {
    const element = this.elementRegistry.get(id);
    return isNode(element) ? nodeObject(element).process : undefined;
  }

  private laneSection(shape: Shape): void {
    const object = laneObject(shape);
    heading(this.panel, object.data.type === "cobot" ? "Cobot (actor)" : "Operator (actor)");
    this.idField(shape);
    field(this.panel, { label: "Name", value: String(object.data.label ?? ""), commit: (text) => this.modeling.updateLabel(shape, text) });
    select(this.panel, "Kind", object.data.type, [["operator", "operator (a person)"], ["cobot", "cobot"]], (type) => this.modeling.updateData(shape, { type }));
    if (object.data.type === "cobot") {
      field(this.panel, { label: "Default program", value: String(object.data.program ?? ""), placeholder: "needed unless each step names one", commit: (text) => this.modeling.updateData(shape, { program: text.trim() || undefined }) });
    }
    const root = objectOf(this.canvas.getRootElement() as Shape) as RootObject;
    select(this.panel, "Net (process)", object.process ?? "", root.processes.map((p): [string, string] => [String(p.id), String(p.id)]), (process) => this.modeling.updateData(shape, {}, { process }));
    const lanes = lanesTopDown(this.elementRegistry.getAll());
    const index = lanes.indexOf(shape);
    button(this.panel, "Move lane up", () => this.modeling.moveLane(shape, -1)).disabled = index <= 0;
    button(this.panel, "Move lane down", () => this.modeling.moveLane(shape, 1)).disabled = index === lanes.length - 1;
  }

  private constraintSection(connection: Connection, object: ConstraintObject): void {
    heading(this.panel, "Constraint");
    const name = (element: Connection["source"]) => {
      const data = (objectOf(element) as { data?: { label?: string } } | undefined)?.data;
      return element ? quotedName(element.id, data?.label) : "?";
    };
    const words = note(this.panel, `${name(connection.source)} → ${name(connection.target)} (${object.data.type})`);
    words.classList.add("hrc-constraint-ends");
    const reverse = button(this.panel, "Reverse", () => this.modeling.reverseConstraint(connection));
    reverse.title = "Swap the two tasks: the constraint then runs the other way";
    select(this.panel, "Kind", object.data.type, CONSTRAINT_TYPES.map((type): [string, string] => [type, type]), (type) => this.modeling.updateData(connection, { type, interrupt: type === "space" ? object.data.interrupt : undefined }));
    if (object.data.type === "space") this.spaceModeSection(connection, object);
  }

  /** The space constraint's mode, offered as its pair of actors allows (cobot and operator, two
   * cobots, two operators); the default is left unwritten. */
  private spaceModeSection(connection: Connection, object: ConstraintObject): void {
    const kinds = [connection.source, connection.target].map((task) => this.actorKind(task));
    if (kinds[0] === undefined || kinds[1] === undefined) return;
    const pair = actorPair(kinds[0], kinds[1]);
    const [fallback, ...others] = SPACE_MODES[pair];
    const words = SPACE_MODE_WORDS[pair];
    const choices = [fallback, ...others].map((mode): [string, string] => [mode, words.modes[mode]]);
    select(this.panel, words.question, String(object.data.interrupt ?? fallback), choices, (mode) => this.modeling.updateData(connection, { interrupt: mode === fallback ? undefined : mode }));
  }

  /** The kind of actor whose lane the task is in; undefined for a split/join. */
  private actorKind(task: Connection["source"]): ActorType | undefined {
    const performer = (objectOf(task) as { data?: { performer?: string } } | undefined)?.data?.performer;
    const lane = performer ? this.elementRegistry.get(performer) : undefined;
    return lane && isLane(lane) ? laneObject(lane).data.type : undefined;
  }

  private arcSection(connection: Connection): void {
    heading(this.panel, "Arc");
    note(this.panel, `From ${connection.source?.id} to ${connection.target?.id}.`);
  }

  private idField(shape: Shape): void {
    field(this.panel, {
      label: "Id",
      value: shape.id,
      commit: (text) => {
        const id = text.trim();
        if (id === shape.id) return;
        const problem = idProblem(id, this.elementFactory.isTaken);
        if (problem) throw new Error(problem);
        this.modeling.updateId(shape, id);
      },
    });
  }

  private constraints(): { from: string; to: string; type: string }[] {
    return this.elementRegistry
      .filter((element) => objectOf(element)?.kind === "constraint")
      .map((element) => {
        const c = element as Connection;
        return { from: String(c.source?.id), to: String(c.target?.id), type: (objectOf(c) as ConstraintObject).data.type };
      });
  }
}
