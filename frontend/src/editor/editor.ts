/**
 * The pattern editor: diagram-js with the pattern's core and features. Open a
 * document with open(); read the drawn model back with document().
 */

import Diagram from "diagram-js";
import BendpointsModule from "diagram-js/lib/features/bendpoints";
import CopyPasteModule from "diagram-js/lib/features/copy-paste";
import MoveModule from "diagram-js/lib/features/move";
import OutlineModule from "diagram-js/lib/features/outline";
import OverlaysModule from "diagram-js/lib/features/overlays";
import ResizeModule from "diagram-js/lib/features/resize";
import SelectionModule from "diagram-js/lib/features/selection";
import SnappingModule from "diagram-js/lib/features/snapping";
import MoveCanvasModule from "diagram-js/lib/navigation/movecanvas";
import ZoomScrollModule from "diagram-js/lib/navigation/zoomscroll";
import KeyboardMoveModule from "diagram-js/lib/navigation/keyboard-move";
import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type { Shape } from "diagram-js/lib/model/Types";

import type { Api } from "./api";
import CoreModule from "./core";
import { isLane, isNode } from "./core/elements";
import type PatternImporter from "./core/PatternImporter";
import CancellationModule from "./features/cancellation";
import CheckingModule from "./features/checking";
import ConstraintsModule from "./features/constraints";
import ContextPadModule from "./features/context-pad";
import CopyModule from "./features/copy";
import FilesModule from "./features/files";
import KeyboardModule from "./features/keyboard";
import LabelEditingModule from "./features/label-editing";
import LanesModule from "./features/lanes";
import LayoutModule from "./features/layout";
import ModelingModule from "./features/modeling";
import PaletteModule from "./features/palette";
import PredictionModule from "./features/prediction";
import PropertiesModule from "./features/properties";
import RulesModule from "./features/rules";
import TokenGameModule from "./features/token-game";
import type AutoLayout from "./features/layout/AutoLayout";
import { hasLayout } from "./model/snapshot";
import { DEVICE_CALLS } from "./model/taskconfig";
import type { PatternDocument } from "./model/document";

/** Where the editor's panels go, and what it talks to. */
export interface EditorOptions {
  canvas: HTMLElement;
  toolbar: HTMLElement;
  side: HTMLElement;
  api: Api;
  /** The pattern being edited; null for a new one not saved yet. */
  pattern: { id: number | null; name: string; canWrite: boolean; organisation?: number };
  /** Check with the server as the model changes (off in the bench's static page). */
  liveChecking?: boolean;
  /** The device calls a cobot task can make; the server's list when the page gives one. */
  deviceCalls?: Record<string, string[]>;
}

export const MODULES = [
  CoreModule,
  ModelingModule,
  MoveModule,
  SelectionModule,
  OutlineModule,
  OverlaysModule,
  ResizeModule,
  BendpointsModule,
  SnappingModule,
  CopyPasteModule,
  MoveCanvasModule,
  ZoomScrollModule,
  KeyboardMoveModule,
  RulesModule,
  LanesModule,
  PaletteModule,
  ContextPadModule,
  ConstraintsModule,
  CancellationModule,
  LabelEditingModule,
  KeyboardModule,
  CopyModule,
  CheckingModule,
  TokenGameModule,
  PredictionModule,
  PropertiesModule,
  FilesModule,
  LayoutModule,
];

export class PatternEditor {
  readonly diagram: Diagram;

  constructor(readonly options: EditorOptions) {
    this.diagram = new Diagram({
      // autoFocus: keys reach the canvas again after a click on the palette or the context pad.
      canvas: { container: options.canvas, autoFocus: true },
      keyboard: { bind: true },
      modules: MODULES,
      shell: { toolbar: options.toolbar, side: options.side },
      api: options.api,
      pattern: options.pattern,
      liveChecking: options.liveChecking ?? true,
      deviceCalls: options.deviceCalls ?? DEVICE_CALLS,
    } as never);
    this.get<{ on(event: string, callback: () => void): void }>("eventBus").on("editor.fit", () => this.fit());
  }

  get<T>(name: string): T {
    return this.diagram.get<T>(name);
  }

  /** Shows a document: laid out by the server first when it has no layout yet. Returns what could not be drawn. */
  async open(document: PatternDocument): Promise<string[]> {
    const laidOut = hasLayout(document) ? document : await this.get<AutoLayout>("autoLayout").layoutOf(document);
    const dropped = this.get<PatternImporter>("patternImporter").importDocument(laidOut);
    this.fit();
    return dropped;
  }

  /** Shows the whole drawing, leaving the palette's strip on the left free. */
  fit(): void {
    const canvas = this.get<Canvas>("canvas");
    const size = canvas.getSize();
    const shapes = this.get<ElementRegistry>("elementRegistry").filter((element) => isNode(element) || isLane(element)) as Shape[];
    const right = Math.max(1000, ...shapes.map((shape) => shape.x + shape.width));
    const bottom = Math.max(360, ...shapes.map((shape) => shape.y + shape.height + 20));
    const left = 80;
    const scale = Math.min(1.4, (size.width - left - 20) / right, (size.height - 40) / bottom);
    canvas.viewbox({ x: -left / scale, y: -20 / scale, width: size.width / scale, height: size.height / scale });
  }

  document(): PatternDocument {
    return this.get<PatternImporter>("patternImporter").document();
  }
}
