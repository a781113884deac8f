/**
 * Auto-layout in actor lanes, done by the server (POST /api/patterns/layout/).
 * On the canvas the new positions are applied as one command that moves and
 * resizes what is there, so one undo restores the drawing as it was.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type CommandStack from "diagram-js/lib/command/CommandStack";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { CommandContext } from "diagram-js/lib/command/CommandStack";
import type { Shape } from "diagram-js/lib/model/Types";

import type { Api } from "../../api";
import type { PatternDocument } from "../../model/document";
import { hasLayout, toSnapshot } from "../../model/snapshot";
import { isLane, isNode, type RootObject } from "../../core/elements";
import type PatternImporter from "../../core/PatternImporter";
import type PatternModeling from "../modeling/PatternModeling";

export default class AutoLayout {
  static $inject = ["config.api", "patternImporter", "commandStack"];

  constructor(
    private readonly api: Api,
    private readonly importer: PatternImporter,
    private readonly commandStack: CommandStack,
  ) {
    commandStack.registerHandler("layout.apply", LayoutApplyHandler);
  }

  /** The document laid out by the server; refuses an answer that still lacks positions. */
  async layoutOf(document: PatternDocument): Promise<PatternDocument> {
    const laidOut = await this.api.layout(document);
    if (!hasLayout(laidOut)) throw new Error("The layout service answered without a position for every element.");
    return laidOut;
  }

  /** Lays out what is drawn, as one undoable step. */
  async layout(): Promise<void> {
    const laidOut = await this.layoutOf(this.importer.document());
    this.commandStack.execute("layout.apply", { document: laidOut });
  }
}

class LayoutApplyHandler {
  static $inject = ["elementRegistry", "modeling", "canvas"];

  constructor(
    private readonly elementRegistry: ElementRegistry,
    private readonly modeling: PatternModeling,
    private readonly canvas: Canvas,
  ) {}

  preExecute(context: CommandContext): void {
    const snapshot = toSnapshot(context.document as PatternDocument);
    const root = this.canvas.getRootElement() as Shape;
    this.modeling.updateData(root, {}, { width: Math.max(snapshot.width, (root.businessObject as RootObject).width) });
    for (const lane of snapshot.lanes) {
      const shape = this.elementRegistry.get(lane.actor.id) as Shape | undefined;
      if (!shape || !isLane(shape)) continue;
      this.modeling.resizeShape(shape, { x: 0, y: lane.y, width: snapshot.width, height: lane.height }, undefined, { free: true });
    }
    for (const node of snapshot.nodes) {
      const shape = this.elementRegistry.get(node.data.id) as Shape | undefined;
      if (!shape || !isNode(shape)) continue;
      const delta = { x: Math.round(node.x - shape.width / 2 - shape.x), y: Math.round(node.y - shape.height / 2 - shape.y) };
      if (delta.x || delta.y) this.modeling.moveShape(shape, delta);
    }
  }
}
