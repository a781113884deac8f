/**
 * Editing a label in place: an input over the element (double-click, the E
 * key, or right after a task is dropped); Enter or leaving the field keeps
 * the text as one undoable command, Escape drops it.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type EventBus from "diagram-js/lib/core/EventBus";
import type { Shape } from "diagram-js/lib/model/Types";

import { isLane, isNode, isTask, objectOf } from "../../core/elements";
import type PatternModeling from "../modeling/PatternModeling";

export default class LabelEditing {
  static $inject = ["eventBus", "canvas", "modeling"];

  /** The open field and the element whose label it edits; null while none is open. */
  private editing: { input: HTMLInputElement; shape: Shape } | null = null;

  constructor(
    eventBus: EventBus,
    private readonly canvas: Canvas,
    private readonly modeling: PatternModeling,
  ) {
    eventBus.on("element.dblclick", (event: { element: Shape }) => {
      if (isNode(event.element) || isLane(event.element)) this.activate(event.element);
    });
    // A task taken from the palette asks for its label at once (not a pasted one: it has one).
    eventBus.on("create.end", 500, (event: { context: { shape?: Shape; canExecute?: unknown; hints?: { editLabel?: boolean } } }) => {
      const { shape, canExecute, hints } = event.context;
      if (shape && canExecute && hints?.editLabel && isTask(shape)) setTimeout(() => this.activate(shape));
    });
    eventBus.on(["diagram.clear", "canvas.viewbox.changing", "drag.init"], () => this.finish(true));
  }

  isActive(): boolean {
    return this.editing !== null;
  }

  activate(shape: Shape): void {
    this.finish(true);
    const object = objectOf(shape) as { data?: { label?: unknown } } | undefined;
    if (!object?.data) return;
    const box = this.screenBox(shape);
    const input = document.createElement("input");
    input.className = "hrc-label-input";
    input.setAttribute("aria-label", `Label of ${shape.id}`);
    input.value = typeof object.data.label === "string" ? object.data.label : "";
    Object.assign(input.style, { left: `${box.x}px`, top: `${box.y}px`, width: `${Math.max(120, box.width)}px` });
    input.addEventListener("keydown", (event) => {
      event.stopPropagation();
      if (event.key === "Enter") this.finish(false);
      if (event.key === "Escape") this.finish(true);
    });
    input.addEventListener("blur", () => this.finish(false));
    this.canvas.getContainer().appendChild(input);
    this.editing = { input, shape };
    input.focus();
    input.select();
  }

  /** Closes the field; keeps the text unless cancelled and unchanged text changes nothing. */
  finish(cancel: boolean): void {
    if (!this.editing) return;
    const { input, shape } = this.editing;
    this.editing = null;
    input.remove();
    const object = objectOf(shape) as { data: { label?: unknown } };
    const before = typeof object.data.label === "string" ? object.data.label : "";
    if (!cancel && input.value.trim() !== before) this.modeling.updateLabel(shape, input.value);
    this.canvas.focus();
  }

  /** Where the label goes on screen: over a task, under a place, on a lane's header. */
  private screenBox(shape: Shape): { x: number; y: number; width: number } {
    const viewbox = this.canvas.viewbox();
    const scale = viewbox.scale;
    const toScreen = (x: number, y: number) => ({ x: (x - viewbox.x) * scale, y: (y - viewbox.y) * scale });
    if (isLane(shape)) return { ...toScreen(shape.x + 40, shape.y + 4), width: 200 };
    const below = !isTask(shape);
    const point = toScreen(shape.x + shape.width / 2 - 60, below ? shape.y + shape.height + 2 : shape.y + shape.height / 2 - 12);
    return { ...point, width: Math.max(120, shape.width * scale) };
  }
}
