/**
 * Draws the pattern: places as circles with their tokens, tasks as boxes in
 * their actor's colours, silent transitions as black bars (a clock and its
 * duration under a timer's, a lightning bolt beside one that cancels), actors
 * as lanes (cobots and operators look different), arcs as arrows and
 * constraints as dashed lines, one colour and marker per kind.
 */

import BaseRenderer from "diagram-js/lib/draw/BaseRenderer";
import type EventBus from "diagram-js/lib/core/EventBus";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import { type Element, LANE_HEADER, laneObject, nodeObject, objectOf, type ConstraintObject, type PlaceObject, type TransitionObject } from "./elements";
import { svg, textBlock } from "./svg";
import { cancelsOf } from "../model/cancels";
import { timerWords } from "../model/timers";

export const CONSTRAINT_STYLE: Record<string, { colour: string; dash: string; start: string; end: string; meaning: string }> = {
  time: { colour: "#1f5fbf", dash: "7 4", start: "", end: "arrow", meaning: "the second task starts after the first completes" },
  space: { colour: "#c2410c", dash: "2 4", start: "diamond", end: "diamond", meaning: "both may work in a shared area; the cobot yields" },
  func: { colour: "#7e22ce", dash: "10 3 2 3", start: "dot", end: "dot", meaning: "the two run together; one supports the other" },
};

const ACTOR_STYLE = {
  cobot: { fill: "#e6eef8", band: "#c9dcf2", stroke: "#3b6ea8", task: "#dbe8f7", word: "COBOT" },
  operator: { fill: "#fbf4e4", band: "#f3e0b5", stroke: "#a8731f", task: "#fdf0d2", word: "OPERATOR" },
} as const;

export default class PatternRenderer extends BaseRenderer {
  static $inject = ["eventBus", "elementRegistry"];

  constructor(
    eventBus: EventBus,
    private readonly elementRegistry: ElementRegistry,
  ) {
    super(eventBus, 1500);
  }

  canRender(element: NonNullable<Element>): boolean {
    const kind = objectOf(element)?.kind;
    return kind !== undefined && kind !== "root";
  }

  drawShape(parent: SVGElement, shape: Shape): SVGElement {
    const object = objectOf(shape);
    if (object?.kind === "lane") return this.drawLane(parent, shape);
    if (object?.kind === "place") return this.drawPlace(parent, shape);
    return object?.kind === "transition" && object.silent ? this.drawSilent(parent, shape) : this.drawTask(parent, shape);
  }

  drawConnection(parent: SVGElement, connection: Connection): SVGElement {
    const points = connection.waypoints.map((p) => `${p.x},${p.y}`).join(" ");
    const object = objectOf(connection);
    if (object?.kind !== "constraint") {
      this.ensureMarker(parent, "arc", "#1b1f24", "arrow");
      return svg("polyline", { points, class: "hrc-arc", fill: "none", stroke: "#1b1f24", "stroke-width": 1.5, "marker-end": "url(#hrc-marker-arc-arrow)" }, parent);
    }
    return this.drawConstraint(parent, connection, object, points);
  }

  getShapePath(shape: Shape): string {
    const { x, y, width, height } = shape;
    if (objectOf(shape)?.kind === "place") {
      const r = width / 2;
      return `M${x + r},${y} a${r},${r} 0 1,1 0,${2 * r} a${r},${r} 0 1,1 0,${-2 * r}z`;
    }
    return `M${x},${y}h${width}v${height}h${-width}z`;
  }

  getConnectionPath(connection: Connection): string {
    return connection.waypoints.map((p, index) => `${index ? "L" : "M"}${p.x},${p.y}`).join("");
  }

  private drawPlace(parent: SVGElement, shape: Shape): SVGElement {
    const object = nodeObject(shape) as PlaceObject;
    const r = shape.width / 2;
    const circle = svg("circle", { cx: r, cy: r, r, class: "hrc-place", fill: "#fff", stroke: "#1b1f24", "stroke-width": 2 }, parent);
    const tokens = typeof shape.gameTokens === "number" ? shape.gameTokens : (object.data.tokens ?? 0);
    drawTokens(parent, tokens, r);
    textBlock(parent, object.data.label || object.data.id, r, shape.height + 11, { width: 110, size: 11, className: "hrc-text hrc-node-label", maxLines: 2 });
    return circle;
  }

  private drawTask(parent: SVGElement, shape: Shape): SVGElement {
    const object = nodeObject(shape) as TransitionObject;
    const style = ACTOR_STYLE[this.actorType(object.data.performer)];
    const box = svg("rect", { x: 0, y: 0, width: shape.width, height: shape.height, rx: 8, class: "hrc-task", fill: style.task, stroke: style.stroke, "stroke-width": 2 }, parent);
    textBlock(parent, object.data.label || "", shape.width / 2, shape.height / 2 + 4, { width: shape.width - 10, size: 12, className: "hrc-text hrc-task-label" });
    const id = svg("text", { x: 4, y: 11, "font-size": 10, class: "hrc-text hrc-id" }, parent);
    id.textContent = object.data.id;
    drawActorGlyph(parent, this.actorType(object.data.performer), shape.width - 14, 9, style.stroke);
    return box;
  }

  private drawSilent(parent: SVGElement, shape: Shape): SVGElement {
    const object = nodeObject(shape);
    const bar = svg("rect", { x: 0, y: 0, width: shape.width, height: shape.height, class: "hrc-silent", fill: "#1b1f24", stroke: "#1b1f24" }, parent);
    textBlock(parent, object.data.label || object.data.id, shape.width / 2, -9, { width: 90, size: 11, className: "hrc-text hrc-node-label", maxLines: 1 });
    const timer = timerWords(object.data.timer);
    if (timer) drawTimer(parent, shape, timer);
    const cancels = cancelsOf(object.data);
    if (cancels.length) drawCancels(parent, shape, cancels);
    return bar;
  }

  private drawLane(parent: SVGElement, shape: Shape): SVGElement {
    const actor = laneObject(shape).data;
    const style = ACTOR_STYLE[actor.type === "cobot" ? "cobot" : "operator"];
    const body = svg("rect", { x: 0, y: 0, width: shape.width, height: shape.height, class: `hrc-lane hrc-lane-${actor.type}`, fill: style.fill, stroke: style.stroke, "stroke-opacity": 0.45 }, parent);
    svg("rect", { x: 0, y: 0, width: LANE_HEADER, height: shape.height, class: "hrc-lane-header", fill: style.band, stroke: style.stroke, "stroke-opacity": 0.45 }, parent);
    const middle = shape.height / 2;
    const label = svg("text", { x: LANE_HEADER / 2, y: middle, transform: `rotate(-90 ${LANE_HEADER / 2} ${middle})`, "text-anchor": "middle", "dominant-baseline": "middle", "font-size": 12, class: "hrc-text hrc-lane-label" }, parent);
    const name = typeof actor.label === "string" && actor.label ? `${actor.id} · ${actor.label}` : actor.id;
    label.textContent = `${style.word} ${name}`;
    return body;
  }

  private drawConstraint(parent: SVGElement, connection: Connection, object: ConstraintObject, points: string): SVGElement {
    const type = object.data.type in CONSTRAINT_STYLE ? object.data.type : "time";
    const style = CONSTRAINT_STYLE[type];
    const attrs: Record<string, string | number> = { points, class: `hrc-constraint hrc-constraint-${type}`, fill: "none", stroke: style.colour, "stroke-width": 2, "stroke-dasharray": style.dash };
    if (style.start) attrs["marker-start"] = `url(#${this.ensureMarker(parent, type, style.colour, style.start)})`;
    if (style.end) attrs["marker-end"] = `url(#${this.ensureMarker(parent, type, style.colour, style.end)})`;
    const line = svg("polyline", attrs, parent);
    const title = svg("title", {}, line);
    title.textContent = `${type} constraint ${connection.source?.id ?? ""} → ${connection.target?.id ?? ""}: ${style.meaning}`;
    return line;
  }

  private actorType(performer: string | undefined): "cobot" | "operator" {
    const lane = performer ? this.elementRegistry.get(performer) : undefined;
    const object = objectOf(lane);
    return object?.kind === "lane" && object.data.type === "cobot" ? "cobot" : "operator";
  }

  /** One marker per kind and shape, made in the canvas' own <defs> the first time it is needed. */
  private ensureMarker(parent: SVGElement, kind: string, colour: string, shape: string): string {
    const id = `hrc-marker-${kind}-${shape}`;
    const root = parent.ownerSVGElement;
    if (!root || root.querySelector(`#${id}`)) return id;
    const defs = root.querySelector("defs.hrc-defs") ?? svg("defs", { class: "hrc-defs" }, root);
    const marker = svg("marker", { id, viewBox: "0 0 12 12", refX: shape === "arrow" ? 11 : 6, refY: 6, markerWidth: 9, markerHeight: 9, orient: "auto-start-reverse", markerUnits: "userSpaceOnUse" }, defs);
    if (shape === "arrow") svg("path", { d: "M1,1 L11,6 L1,11 z", fill: colour }, marker);
    else if (shape === "diamond") svg("path", { d: "M1,6 L6,1 L11,6 L6,11 z", fill: "#fff", stroke: colour, "stroke-width": 1.5 }, marker);
    else svg("circle", { cx: 6, cy: 6, r: 4, fill: colour }, marker);
    return id;
  }
}

function drawTokens(parent: SVGElement, tokens: number, r: number): void {
  if (tokens <= 0) return;
  const spots: Record<number, [number, number][]> = {
    1: [[0, 0]],
    2: [[-6, 0], [6, 0]],
    3: [[0, -6], [-6, 5], [6, 5]],
    4: [[-6, -6], [6, -6], [-6, 6], [6, 6]],
  };
  if (tokens <= 4) {
    for (const [dx, dy] of spots[tokens]) svg("circle", { cx: r + dx, cy: r + dy, r: 4, class: "hrc-token", fill: "#1b1f24" }, parent);
    return;
  }
  const count = svg("text", { x: r, y: r + 1, "text-anchor": "middle", "dominant-baseline": "middle", "font-size": 14, "font-weight": 700, class: "hrc-text hrc-token-count" }, parent);
  count.textContent = String(tokens);
}

/** A clock under the bar, its duration beneath; the tooltip says when the transition fires. */
function drawTimer(parent: SVGElement, shape: Shape, words: string): void {
  const x = shape.width / 2;
  const y = shape.height + 11;
  const clock = svg("g", { class: "hrc-timer-mark", fill: "#fff", stroke: "#1b1f24", "stroke-width": 1.5 }, parent);
  svg("circle", { cx: x, cy: y, r: 8 }, clock);
  svg("path", { d: `M${x},${y - 5} V${y} L${x + 4},${y + 2}`, fill: "none", "stroke-linecap": "round" }, clock);
  svg("title", {}, clock).textContent = `Timer: fires once enabled for ${words} without interruption`;
  const text = svg("text", { x, y: y + 20, "text-anchor": "middle", "font-size": 11, class: "hrc-text hrc-timer-duration" }, parent);
  text.textContent = words;
}

/** A lightning bolt at the bar's top right; the tooltip names what it cancels. */
function drawCancels(parent: SVGElement, shape: Shape, cancels: string[]): void {
  const mark = svg("g", { class: "hrc-cancels-mark", transform: `translate(${shape.width + 2} 0)` }, parent);
  svg("path", { d: "M7,0 L1,9 H5 L3,17 L11,6 H7 L9,0 z", fill: "#b42318", stroke: "#fff", "stroke-width": 0.8, "stroke-linejoin": "round" }, mark);
  svg("title", {}, mark).textContent = `Cancels ${cancels.join(", ")} when it fires`;
}

/** A small robot arm for cobots, a person for operators. */
function drawActorGlyph(parent: SVGElement, type: "cobot" | "operator", x: number, y: number, colour: string): void {
  const glyph = svg("g", { class: `hrc-glyph hrc-glyph-${type}`, transform: `translate(${x} ${y})`, fill: "none", stroke: colour, "stroke-width": 1.6 }, parent);
  if (type === "cobot") {
    svg("path", { d: "M0,9 h8 M4,9 V5 L8,1 L10,3", "stroke-linecap": "round" }, glyph);
    svg("circle", { cx: 4, cy: 5, r: 1.3, fill: colour }, glyph);
  } else {
    svg("circle", { cx: 5, cy: 2.5, r: 2.3 }, glyph);
    svg("path", { d: "M0.5,10 C1,6 9,6 9.5,10", "stroke-linecap": "round" }, glyph);
  }
}
