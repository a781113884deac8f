/**
 * Appending: the natural next node right of the selected one, joined by an
 * arc — a task after a place (in the place's lane), a place after a
 * transition. The context pad and the A key use it.
 */

import type AutoPlace from "diagram-js/lib/features/auto-place/AutoPlace";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { Shape } from "diagram-js/lib/model/Types";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import { asTRBL, getMid } from "diagram-js/lib/layout/LayoutUtil";

import { centre, isNode, laneAt, nodeObject, type NodeObject } from "../../core/elements";
import type PatternElementFactory from "../../core/PatternElementFactory";
import { newTaskRefusal } from "../../model/rules";
import type LaneBehavior from "../lanes/LaneBehavior";
import type LabelEditing from "../label-editing/LabelEditing";
import type Refusals from "../rules/Refusals";
import { placeInLane } from "./placement";

export type AppendKind = "place" | "task" | "silent";

export default class Append {
  static $inject = ["eventBus", "autoPlace", "elementFactory", "laneBehavior", "refusals", "labelEditing", "elementRegistry"];

  constructor(
    eventBus: EventBus,
    private readonly autoPlace: AutoPlace,
    private readonly elementFactory: PatternElementFactory,
    private readonly laneBehavior: LaneBehavior,
    private readonly refusals: Refusals,
    private readonly labelEditing: LabelEditing,
    private readonly elementRegistry: ElementRegistry,
  ) {
    // Right of the source, in the source's lane; below or above when that spot is taken
    // (a split's second branch), never across the lane's border.
    eventBus.on("autoPlace", 1500, (event: { source: Shape; shape: Shape }) => {
      const { source, shape } = event;
      const position = { x: asTRBL(source).right + 60 + shape.width / 2, y: getMid(source).y };
      const lane = laneAt(this.laneBehavior.lanes(), centre(source).y);
      const taken = (this.elementRegistry.filter(isNode) as Shape[]).filter((node) => node !== shape);
      return placeInLane(position, shape, lane, taken);
    });
  }

  /** The kind appended by default: a task after a place, a place after a transition. */
  defaultKind(source: Shape): AppendKind {
    return nodeObject(source).kind === "place" ? "task" : "place";
  }

  /** Appends and returns the new node (selected; a task opens its label), or null with the reason shown. */
  append(source: Shape, kind: AppendKind = this.defaultKind(source)): Shape | null {
    if (!isNode(source)) return null;
    const from = nodeObject(source).kind;
    if ((from === "place") === (kind === "place")) {
      this.refusals.refuse(from === "place" ? "After a place comes a transition: append a task or a silent transition." : "After a transition comes a place.");
      return null;
    }
    if (kind === "task") {
      const lanes = this.laneBehavior.lanes();
      const reason = newTaskRefusal(laneAt(lanes, centre(source).y)?.id ?? null, lanes.length);
      if (reason) {
        this.refusals.refuse(reason);
        return null;
      }
    }
    const template: NodeObject =
      kind === "place"
        ? { kind: "place", process: "", data: { id: "" } }
        : { kind: "transition", process: "", silent: kind === "silent", data: { id: "" } };
    const shape = this.elementFactory.createShape({ businessObject: template });
    const appended = this.autoPlace.append(source, shape, { connection: { businessObject: { kind: "arc" } } }) as Shape;
    if (kind === "task") this.labelEditing.activate(appended);
    return appended;
  }
}
