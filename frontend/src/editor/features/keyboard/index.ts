import KeyboardModule from "diagram-js/lib/features/keyboard";
import EditorActionsModule from "diagram-js/lib/features/editor-actions";
import KeyboardMoveSelectionModule from "diagram-js/lib/features/keyboard-move-selection";

import PatternKeyboard from "./PatternKeyboard";

export default {
  __depends__: [KeyboardModule, EditorActionsModule, KeyboardMoveSelectionModule],
  __init__: ["patternKeyboard"],
  patternKeyboard: ["type", PatternKeyboard],
};
