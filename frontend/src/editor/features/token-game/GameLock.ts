/**
 * While the token game runs the model stands still: every editing rule says
 * no, and the keys step the game instead (Ctrl+Z back, Ctrl+Y forward, Esc stops).
 */

import RuleProvider from "diagram-js/lib/features/rules/RuleProvider";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Keyboard from "diagram-js/lib/features/keyboard/Keyboard";
import { isRedo, isUndo } from "diagram-js/lib/features/keyboard/KeyboardUtil";

import type TokenGameMode from "./TokenGameMode";

const EDITS = [
  "shape.create",
  "elements.create",
  "elements.move",
  "shape.resize",
  "connection.start",
  "connection.create",
  "connection.reconnect",
  "connection.updateWaypoints",
  "elements.delete",
  "element.copy",
];

export default class GameLock extends RuleProvider {
  static $inject = ["eventBus", "tokenGame", "keyboard"];

  constructor(
    eventBus: EventBus,
    private readonly tokenGame: TokenGameMode,
    keyboard: Keyboard,
  ) {
    super(eventBus);
    keyboard.addListener(3000, (context: { keyEvent: KeyboardEvent }) => {
      if (!this.tokenGame.active) return;
      const event = context.keyEvent;
      if (isUndo(event)) this.tokenGame.back();
      else if (isRedo(event)) this.tokenGame.forward();
      else if (event.key === "Escape") this.tokenGame.stop();
      return true;
    });
  }

  init(): void {
    this.addRule(EDITS, 3000, () => (this.tokenGame.active ? false : undefined));
  }
}
