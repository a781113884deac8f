/** The palette: tools, the three node kinds and the two kinds of actor lane. */

import type Palette from "diagram-js/lib/features/palette/Palette";
import type Create from "diagram-js/lib/features/create/Create";
import type HandTool from "diagram-js/lib/features/hand-tool/HandTool";
import type LassoTool from "diagram-js/lib/features/lasso-tool/LassoTool";
import type GlobalConnect from "diagram-js/lib/features/global-connect/GlobalConnect";
import type Dragging from "diagram-js/lib/features/dragging/Dragging";
import type EventBus from "diagram-js/lib/core/EventBus";

import type { ActorType } from "../../model/document";
import type { NodeObject } from "../../core/elements";
import type PatternElementFactory from "../../core/PatternElementFactory";
import type PatternModeling from "../modeling/PatternModeling";
import { entryHtml } from "./icons";

const LANE_DRAG = "lane.drag";

type Entry = { group: string; title: string; html: string; action: Record<string, (event: Event) => void> };

export default class PaletteProvider {
  static $inject = ["palette", "create", "elementFactory", "handTool", "lassoTool", "globalConnect", "modeling", "dragging", "eventBus"];

  constructor(
    palette: Palette,
    private readonly create: Create,
    private readonly elementFactory: PatternElementFactory,
    private readonly handTool: HandTool,
    private readonly lassoTool: LassoTool,
    private readonly globalConnect: GlobalConnect,
    private readonly modeling: PatternModeling,
    private readonly dragging: Dragging,
    eventBus: EventBus,
  ) {
    palette.registerProvider(this);
    // A lane tool dragged and let go over the canvas adds the lane, as a click does.
    eventBus.on(`${LANE_DRAG}.end`, (event: { hover?: unknown; context: { type: ActorType } }) => {
      if (event.hover) this.modeling.addLane(event.context.type);
    });
  }

  getPaletteEntries(): Record<string, Entry> {
    return {
      "hand-tool": this.tool("Hand tool: pan the canvas (H)", "hand", (event) => this.handTool.activateHand(event)),
      "lasso-tool": this.tool("Lasso: select several elements (L)", "lasso", (event) => this.lassoTool.activateSelection(event as MouseEvent)),
      "global-connect-tool": this.tool("Arc: connect a place and a transition (C)", "arc", (event) => this.globalConnect.start(event, undefined)),
      "create.place": this.node("Place", "place", { kind: "place", process: "", data: { id: "" } }),
      "create.task": this.node("Task (drop it in an actor's lane)", "task", { kind: "transition", process: "", silent: false, data: { id: "", label: "" } }),
      "create.silent": this.node("Silent transition (split or join)", "silent", { kind: "transition", process: "", silent: true, data: { id: "" } }),
      "create.cobot-lane": this.lane("Cobot lane", "cobot"),
      "create.operator-lane": this.lane("Operator lane", "operator"),
    };
  }

  private tool(title: string, icon: string, start: (event: Event) => void): Entry {
    return { group: "tools", title, html: entryHtml(icon), action: { click: start } };
  }

  private node(title: string, icon: string, template: NodeObject): Entry {
    const start = (event: Event) => {
      const object = structuredClone(template);
      const shape = this.elementFactory.createShape({ businessObject: object });
      this.create.start(event, shape, { hints: { editLabel: true } });
    };
    return { group: "nodes", title, html: entryHtml(icon), action: { click: start, dragstart: start } };
  }

  private lane(title: string, type: ActorType): Entry {
    const drag = (event: Event) => this.dragging.init(event as MouseEvent, LANE_DRAG, { data: { context: { type } } });
    return { group: "lanes", title, html: entryHtml(type), action: { click: () => this.modeling.addLane(type), dragstart: drag } };
  }
}
