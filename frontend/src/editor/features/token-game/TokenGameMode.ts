/**
 * The token game on the canvas: the server compiles the execution net
 * (POST /api/patterns/execution-net/); here tokens move on it. A click on a
 * task starts it, or completes it when it runs; a silent transition fires on
 * a click. Back and forward step through the firings; a witness from the
 * check is replayed the same way. Editing is off while the game runs.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Overlays from "diagram-js/lib/features/overlays/Overlays";
import type { Connection, Shape } from "diagram-js/lib/model/Types";

import type { Api } from "../../api";
import { heldBackWords, type NetTransition, readExecutionNet, TokenGame } from "../../model/net";
import { isConstraint, isNode, objectOf } from "../../core/elements";
import { listOfNames, quotedName } from "../../model/words";
import type PatternImporter from "../../core/PatternImporter";

const OVERLAY = "hrc-game";
const MARKERS = ["hrc-enabled", "hrc-running", "hrc-fired", "hrc-stuck", "hrc-held", "hrc-awaited"];

export interface Replay {
  labels: string[];
  elements: string[];
}

export default class TokenGameMode {
  static $inject = ["eventBus", "config.api", "patternImporter", "elementRegistry", "canvas", "overlays"];

  game: TokenGame | null = null;
  replaying: Replay | null = null;
  showConstraintPlaces = false;
  private runner: ReturnType<typeof setInterval> | undefined;

  constructor(
    private readonly eventBus: EventBus,
    private readonly api: Api,
    private readonly importer: PatternImporter,
    private readonly elementRegistry: ElementRegistry,
    private readonly canvas: Canvas,
    private readonly overlays: Overlays,
  ) {
    eventBus.on("element.click", 3000, (event: { element: Shape }) => {
      if (!this.game) return;
      if (isNode(event.element)) this.fireTask(event.element.id);
      return false;
    });
    eventBus.on("element.dblclick", 3000, () => (this.game ? false : undefined));
    eventBus.on("diagram.clear", () => this.stop());
  }

  get active(): boolean {
    return this.game !== null;
  }

  async start(): Promise<void> {
    this.stop();
    const net = readExecutionNet(await this.api.executionNet(this.importer.document()));
    this.game = new TokenGame(net);
    this.canvas.getContainer().classList.add("hrc-playing");
    this.eventBus.fire("tokenGame.started", {});
    this.render();
  }

  /** Restarts the game and queues a witness; forward() steps through it. */
  async replay(labels: string[], elements: string[]): Promise<void> {
    await this.start();
    (this.game as TokenGame).load(labels);
    this.replaying = { labels, elements };
    this.render();
  }

  stop(): void {
    clearInterval(this.runner);
    if (!this.game) return;
    this.game = null;
    this.replaying = null;
    this.clearMarks();
    for (const shape of this.elementRegistry.filter(isNode)) {
      delete (shape as Shape).gameTokens;
      this.eventBus.fire("element.changed", { element: shape });
    }
    this.canvas.getContainer().classList.remove("hrc-playing");
    this.eventBus.fire("tokenGame.stopped", {});
  }

  /**
   * What a click on a node does: fire the task's completion, its start, or the
   * silent transition; a task a constraint holds back says why instead.
   */
  fireTask(id: string): NetTransition | null {
    const game = this.game;
    const firing = game?.firingFor(id) ?? null;
    if (game && !firing) this.explainHeldBack(game, id);
    if (!game || !firing) return null;
    game.fire(firing.id);
    this.replaying = null;
    this.render();
    return firing;
  }

  /** The task's name as drawn: its label in quotes, its id where it has none. */
  nameOf(id: string): string {
    const data = (objectOf(this.elementRegistry.get(id)) as { data?: { label?: string } } | undefined)?.data;
    return quotedName(id, data?.label);
  }

  private explainHeldBack(game: TokenGame, task: string): void {
    const words = heldBackWords(game, task, (id) => this.nameOf(id));
    if (!words) return;
    this.render();
    for (const place of game.heldBack(task)) {
      for (const other of place.of) if (other !== task && this.elementRegistry.get(other)) this.mark(other, "hrc-awaited");
    }
    this.mark(task, "hrc-held");
    this.eventBus.fire("tokenGame.changed", { caption: words });
  }

  back(): void {
    if (this.game?.back()) this.render();
  }

  forward(): void {
    if (this.game?.forward()) this.render();
  }

  reset(): void {
    if (!this.game) return;
    const replay = this.replaying;
    this.game.reset();
    if (replay) this.game.load(replay.labels);
    this.render();
  }

  /** Fires random enabled transitions, one every `everyMs`, until none is enabled or `steps` were fired. */
  runRandomly(steps = 50, everyMs = 250): void {
    clearInterval(this.runner);
    let left = steps;
    this.runner = setInterval(() => {
      const fired = this.game?.fireRandom() ?? null;
      this.replaying = null;
      this.render();
      left -= 1;
      if (!fired || left <= 0) clearInterval(this.runner);
    }, everyMs);
  }

  toggleConstraintPlaces(show: boolean): void {
    this.showConstraintPlaces = show;
    this.render();
  }

  /** The caption for the bar: what just fired, what can fire, or where a witness ends. */
  caption(): string {
    const game = this.game;
    if (!game) return "";
    const last = game.history[game.history.length - 1];
    if (this.replaying) {
      const done = game.history.length;
      const total = done + game.future.length;
      if (game.future.length === 0) {
        const steps = this.replaying.labels.map((label) => this.stepWords(label)).join(", ");
        return `Witness replayed (${done} of ${total}): ${steps || "from the start"}. Nothing more can happen for ${listOfNames(this.replaying.elements, (id) => this.nameOf(id), 6)}.`;
      }
      return `Witness step ${done} of ${total}${last ? `: ${this.firingWords(last)}` : ""}. Next: ${this.firingWords(game.future[0])}.`;
    }
    const enabled = game.enabled();
    const lastWords = last ? `Fired: ${this.firingWords(last)}. ` : "";
    if (enabled.length === 0) return `${lastWords}Nothing can fire.`;
    return `${lastWords}Can fire: ${enabled.map((t) => this.firingWords(t)).join(", ")}.`;
  }

  /** A witness step (`start tc1`, `t1`) as the drawing says it: `start “Pick insert”`. */
  stepWords(label: string): string {
    const [kind, ...rest] = label.split(" ");
    if ((kind === "start" || kind === "complete") && rest.length) return `${kind} ${this.nameOf(rest.join(" "))}`;
    return this.nameOf(label);
  }

  /** A firing as the drawing says it: `start “Pick insert”`. */
  firingWords(transition: NetTransition): string {
    return transition.kind === "silent" ? this.nameOf(transition.task) : `${transition.kind} ${this.nameOf(transition.task)}`;
  }

  private render(): void {
    const game = this.game;
    if (!game) return;
    this.clearMarks();
    for (const place of game.net.places) {
      if (place.kind !== "flow") continue;
      const shape = this.elementRegistry.get(place.of[0] ?? place.id) as Shape | undefined;
      if (!shape) continue;
      shape.gameTokens = game.tokens(place.id);
      this.eventBus.fire("element.changed", { element: shape });
    }
    for (const shape of this.elementRegistry.filter((element) => objectOf(element)?.kind === "transition") as Shape[]) {
      if (game.isRunning(shape.id)) {
        this.mark(shape.id, "hrc-running");
        this.badge(shape.id, "running", "hrc-running-badge", { top: -14, left: 4 });
      }
      if (game.firingFor(shape.id)) this.mark(shape.id, "hrc-enabled");
    }
    const last = game.history[game.history.length - 1];
    if (last && this.elementRegistry.get(last.task)) this.mark(last.task, "hrc-fired");
    if (this.replaying && game.future.length === 0) {
      for (const id of this.replaying.elements) if (this.elementRegistry.get(id)) this.mark(id, "hrc-stuck");
    }
    if (this.showConstraintPlaces) this.showConstraintTokens(game);
    this.eventBus.fire("tokenGame.changed", { caption: this.caption() });
  }

  private showConstraintTokens(game: TokenGame): void {
    const constraints = this.elementRegistry.filter(isConstraint) as Connection[];
    for (const place of game.net.places.filter((p) => p.kind === "constraint")) {
      const [a, b] = place.of;
      const connection = constraints.find((c) => (c.source?.id === a && c.target?.id === b) || (c.source?.id === b && c.target?.id === a));
      if (!connection) continue;
      const tokens = game.tokens(place.id);
      this.badge(connection.id, `${place.label}: ${tokens}`, `hrc-constraint-place${tokens ? " hrc-marked" : ""}`, { top: 10, left: 0 });
    }
  }

  private mark(id: string, marker: string): void {
    this.canvas.addMarker(id, marker);
  }

  private badge(id: string, text: string, className: string, position: { top: number; left: number }): void {
    const html = document.createElement("div");
    html.className = className;
    html.textContent = text;
    this.overlays.add(id, OVERLAY, { position, html });
  }

  private clearMarks(): void {
    this.overlays.remove({ type: OVERLAY });
    for (const element of this.elementRegistry.getAll()) {
      if (objectOf(element)?.kind === "root") continue;
      for (const marker of MARKERS) this.canvas.removeMarker(element.id, marker);
    }
  }
}

