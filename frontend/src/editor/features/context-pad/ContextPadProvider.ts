/**
 * The context pad of a selected element: append the next node, draw an arc
 * or a constraint of each kind, add or take a token, edit the label, delete.
 */

import type ContextPad from "diagram-js/lib/features/context-pad/ContextPad";
import type Connect from "diagram-js/lib/features/connect/Connect";
import type Rules from "diagram-js/lib/features/rules/Rules";
import type Canvas from "diagram-js/lib/core/Canvas";
import type { Element, Shape } from "diagram-js/lib/model/Types";

import { CONSTRAINT_TYPES } from "../../model/document";
import { isLane, isNode, isTask, nodeObject, type PlaceObject } from "../../core/elements";
import type ConnectMode from "../constraints/ConnectMode";
import type LabelEditing from "../label-editing/LabelEditing";
import type PatternModeling from "../modeling/PatternModeling";
import { entryHtml } from "../palette/icons";
import type Append from "./Append";
import type { AppendKind } from "./Append";

type Action = (event: MouseEvent, element: Element) => void;
type Entry = { group: string; title: string; html: string; action: Record<string, Action> };

export default class ContextPadProvider {
  static $inject = ["contextPad", "connect", "connectMode", "modeling", "rules", "append", "labelEditing", "canvas"];

  constructor(
    contextPad: ContextPad,
    private readonly connect: Connect,
    private readonly connectMode: ConnectMode,
    private readonly modeling: PatternModeling,
    private readonly rules: Rules,
    private readonly append: Append,
    private readonly labelEditing: LabelEditing,
    private readonly canvas: Canvas,
  ) {
    contextPad.registerProvider(this as never);
  }

  getContextPadEntries(element: Element): Record<string, Entry> {
    const entries: Record<string, Entry> = {};
    if (isNode(element)) {
      const shape = element as Shape;
      const kind = nodeObject(shape).kind;
      if (kind === "place") {
        entries["append.task"] = this.appendEntry("Append task (A)", "task", shape, "task");
        entries["append.silent"] = this.appendEntry("Append silent transition", "silent", shape, "silent");
      } else entries["append.place"] = this.appendEntry("Append place (A)", "place", shape, "place");
      entries.connect = this.connectEntry("Connect with an arc", "arc", "arc");
      if (isTask(shape)) {
        for (const type of CONSTRAINT_TYPES) entries[`constraint.${type}`] = this.connectEntry(`Add a ${type} constraint to a task of another actor`, type, type);
      }
      if (kind === "place") {
        const tokens = (nodeObject(shape) as PlaceObject).data.tokens ?? 0;
        entries["token.add"] = this.entry("edit", "Add an initial token", "token-add", () => this.modeling.updateData(shape, { tokens: tokens + 1 }));
        if (tokens > 0) entries["token.remove"] = this.entry("edit", "Take an initial token away", "token-remove", () => this.modeling.updateData(shape, { tokens: tokens > 1 ? tokens - 1 : undefined }));
      }
    }
    if (isNode(element) || isLane(element)) {
      entries["edit-label"] = this.entry("edit", "Edit the label (E)", "label", () => this.labelEditing.activate(element as Shape));
    }
    entries.delete = this.entry("edit", "Delete (Del)", "delete", () => {
      const allowed = this.rules.allowed("elements.delete", { elements: [element] });
      if (Array.isArray(allowed) && allowed.length) this.modeling.removeElements(allowed);
    });
    return entries;
  }

  private entry(group: string, title: string, icon: string, run: () => void): Entry {
    const click = () => {
      run();
      // Pressing on the pad (outside the canvas, not focusable) left the focus on the page:
      // give the keys back to the canvas now, unless a field (a new task's label) took them.
      // Not on a timer: the browser handles a key pressed right after the click before timers.
      if (document.activeElement === document.body) this.canvas.focus();
    };
    return { group, title, html: entryHtml(icon), action: { click } };
  }

  private appendEntry(title: string, icon: string, source: Shape, kind: AppendKind): Entry {
    return this.entry("append", title, icon, () => this.append.append(source, kind));
  }

  private connectEntry(title: string, icon: string, kind: ConnectMode["kind"]): Entry {
    const start: Action = (event, element) => {
      this.connectMode.kind = kind;
      this.connect.start(event, element as Shape);
    };
    return { group: "connect", title, html: entryHtml(icon), action: { click: start, dragstart: start } };
  }
}
