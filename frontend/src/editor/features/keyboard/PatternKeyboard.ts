/**
 * Keys a modeler user expects, beside diagram-js' own (Ctrl+Z/Y undo/redo,
 * Ctrl+C/V copy/paste, Del, arrows, Ctrl +/-): Ctrl+A select all, E edit the
 * label, A append the next node, H hand, L lasso, C connect.
 */

import type Keyboard from "diagram-js/lib/features/keyboard/Keyboard";
import type EditorActions from "diagram-js/lib/features/editor-actions/EditorActions";
import type Selection from "diagram-js/lib/features/selection/Selection";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type HandTool from "diagram-js/lib/features/hand-tool/HandTool";
import type LassoTool from "diagram-js/lib/features/lasso-tool/LassoTool";
import type GlobalConnect from "diagram-js/lib/features/global-connect/GlobalConnect";
import type { Shape } from "diagram-js/lib/model/Types";
import { hasModifier, isCmd, isKey } from "diagram-js/lib/features/keyboard/KeyboardUtil";

import { isLane, isNode, objectOf } from "../../core/elements";
import type Append from "../context-pad/Append";
import type LabelEditing from "../label-editing/LabelEditing";

const KEYS: Record<string, string> = { a: "appendNext", e: "editLabel", h: "handTool", l: "lassoTool", c: "globalConnectTool" };

export default class PatternKeyboard {
  static $inject = ["keyboard", "editorActions", "selection", "elementRegistry", "handTool", "lassoTool", "globalConnect", "append", "labelEditing"];

  constructor(
    keyboard: Keyboard,
    editorActions: EditorActions,
    private readonly selection: Selection,
    elementRegistry: ElementRegistry,
    handTool: HandTool,
    lassoTool: LassoTool,
    globalConnect: GlobalConnect,
    private readonly append: Append,
    private readonly labelEditing: LabelEditing,
  ) {
    editorActions.register({
      selectAll: () => this.selection.select(elementRegistry.filter((element) => objectOf(element)?.kind !== "root" && !isLane(element))),
      editLabel: () => {
        const only = this.single();
        if (only && (isNode(only) || isLane(only))) this.labelEditing.activate(only);
      },
      appendNext: () => this.appendNext(),
      handTool: () => handTool.toggle(),
      lassoTool: () => lassoTool.toggle(),
      globalConnectTool: () => globalConnect.toggle(),
    });
    keyboard.addListener((context: { keyEvent: KeyboardEvent }) => {
      const event = context.keyEvent;
      if (isCmd(event) && isKey(["a", "A"], event)) {
        editorActions.trigger("selectAll", {});
        return true;
      }
      const action = KEYS[event.key.toLowerCase()];
      if (!action || hasModifier(event)) return;
      editorActions.trigger(action, {});
      return true;
    });
  }

  private single(): Shape | null {
    const selected = this.selection.get() as Shape[];
    return selected.length === 1 ? selected[0] : null;
  }

  private appendNext(): void {
    const source = this.single();
    if (source && isNode(source)) this.append.append(source);
  }
}
