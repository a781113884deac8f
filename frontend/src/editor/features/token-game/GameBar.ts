/** The token game's controls and caption, over the canvas while a game runs. */

import type Canvas from "diagram-js/lib/core/Canvas";
import type EventBus from "diagram-js/lib/core/EventBus";

import type TokenGameMode from "./TokenGameMode";

export default class GameBar {
  static $inject = ["eventBus", "canvas", "tokenGame"];

  readonly bar: HTMLElement;
  private readonly caption: HTMLElement;

  constructor(eventBus: EventBus, canvas: Canvas, tokenGame: TokenGameMode) {
    this.bar = document.createElement("div");
    this.bar.className = "hrc-game-bar";
    this.bar.setAttribute("role", "toolbar");
    this.bar.setAttribute("aria-label", "Token game");
    this.bar.hidden = true;
    const add = (label: string, run: () => void) => {
      const button = document.createElement("button");
      button.type = "button";
      button.textContent = label;
      button.addEventListener("click", run);
      this.bar.appendChild(button);
      return button;
    };
    // Back and forward step through the firings already made: undo and redo, not "fire".
    const undo = add("↶ Undo firing", () => tokenGame.back());
    undo.title = "Take back the last firing";
    const redo = add("Redo firing ↷", () => tokenGame.forward());
    redo.title = "Fire again the firing just undone, or the witness' next step";
    add("Fire randomly", () => tokenGame.runRandomly()).title = "Fire enabled tasks at random until nothing can fire";
    add("Reset", () => tokenGame.reset());
    const toggle = document.createElement("label");
    toggle.innerHTML = '<input type="checkbox"> Constraint places';
    const box = toggle.querySelector("input") as HTMLInputElement;
    box.addEventListener("change", () => tokenGame.toggleConstraintPlaces(box.checked));
    this.bar.appendChild(toggle);
    add("Stop", () => tokenGame.stop());
    this.caption = document.createElement("output");
    this.caption.className = "hrc-game-caption";
    this.caption.setAttribute("aria-live", "polite");
    this.bar.appendChild(this.caption);
    canvas.getContainer().appendChild(this.bar);
    eventBus.on("tokenGame.started", () => (this.bar.hidden = false));
    eventBus.on("tokenGame.stopped", () => {
      this.bar.hidden = true;
      box.checked = false;
    });
    eventBus.on("tokenGame.changed", (event: { caption: string }) => {
      this.caption.textContent = event.caption;
      const game = tokenGame.game;
      undo.disabled = !game || game.history.length === 0;
      redo.disabled = !game || game.future.length === 0;
      redo.textContent = tokenGame.replaying ? "Fire next step ↷" : "Redo firing ↷";
    });
  }
}
