/**
 * A prediction on the canvas: the bottleneck task marked (hrc-bottleneck), the other tasks of
 * the typical case's critical path marked lighter (hrc-critical). The Predict panel shows and
 * clears them: when it closes, or the model changes.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";

import type { Prediction } from "../../model/prediction";

export const BOTTLENECK = "hrc-bottleneck";
export const CRITICAL = "hrc-critical";

export default class PredictionMarkers {
  static $inject = ["canvas", "elementRegistry"];

  private marked: [string, string][] = [];

  constructor(
    private readonly canvas: Canvas,
    private readonly elementRegistry: ElementRegistry,
  ) {}

  show(prediction: Prediction): void {
    this.clear();
    const bottleneck = prediction.bottleneck;
    for (const task of new Set(prediction.critical_path.map((step) => step.task))) {
      if (task !== bottleneck) this.mark(task, CRITICAL);
    }
    if (bottleneck !== null) this.mark(bottleneck, BOTTLENECK);
  }

  clear(): void {
    for (const [id, marker] of this.marked) if (this.elementRegistry.get(id)) this.canvas.removeMarker(id, marker);
    this.marked = [];
  }

  private mark(id: string, marker: string): void {
    // A task the draft no longer has (a prediction of an older model) has nothing to mark.
    if (!this.elementRegistry.get(id)) return;
    this.canvas.addMarker(id, marker);
    this.marked.push([id, marker]);
  }
}
