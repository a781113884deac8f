/**
 * The token game on the execution net the server compiles (each task split
 * into start and complete, constraints as extra places: pattern-format.md,
 * "Execution semantics"). The editor never derives the semantics itself; it
 * fires the net it was given, steps back and forward, and replays a witness.
 */

import { isObject } from "./document";

export type PlaceKind = "flow" | "busy" | "constraint";
export type FiringKind = "start" | "complete" | "silent";

export interface NetPlace {
  id: string;
  label: string;
  tokens: number;
  kind: PlaceKind;
  /** The pattern element the place belongs to: the flow place itself, the running task, the constraint's tasks. */
  of: string[];
}

export interface NetTransition {
  id: string;
  label: string;
  kind: FiringKind;
  task: string;
  /** The actor who performs the task; null for a silent step. */
  performer: string | null;
  /** Places emptied when it fires, after its input is taken (a `cancels` key; `running:t` cancels task t). */
  resets: string[];
}

export interface ExecutionNet {
  places: NetPlace[];
  transitions: NetTransition[];
  /** Arcs as [from, to]; a repeated arc means weight 2. */
  arcs: [string, string][];
}

/** Reads the server's answer, accepting the small variations of field names a JSON API may have. */
export function readExecutionNet(value: unknown): ExecutionNet {
  if (!isObject(value) || !Array.isArray(value.places) || !Array.isArray(value.transitions)) {
    throw new Error("The server's execution net has no places or transitions.");
  }
  const initial = isObject(value.initial) ? value.initial : null;
  const places = value.places.filter(isObject).map((place): NetPlace => {
    const id = String(place.id);
    const kind = (["flow", "busy", "constraint"].includes(String(place.kind)) ? place.kind : guessKind(id)) as PlaceKind;
    const tokens = Number((initial ? initial[id] : undefined) ?? place.tokens ?? place.initial ?? 0);
    return { id, label: String(place.label ?? id), tokens: Number.isFinite(tokens) ? tokens : 0, kind, of: ofList(place.of, id, kind) };
  });
  const transitions = value.transitions.filter(isObject).map((transition): NetTransition => {
    const id = String(transition.id);
    const kind = (["start", "complete", "silent"].includes(String(transition.kind)) ? transition.kind : id.includes(":") ? id.split(":")[0] : "silent") as FiringKind;
    const task = String(transition.task ?? (id.includes(":") ? id.split(":").slice(1).join(":") : id));
    const performer = typeof transition.performer === "string" ? transition.performer : null;
    const resets = Array.isArray(transition.resets) ? transition.resets.map(String) : [];
    return { id, label: String(transition.label ?? (kind === "silent" ? task : `${kind} ${task}`)), kind, task, performer, resets };
  });
  const arcs = (Array.isArray(value.arcs) ? value.arcs : []).flatMap((arc): [string, string][] => {
    if (Array.isArray(arc) && arc.length >= 2) {
      const weight = arc.length > 2 && Number.isInteger(arc[2]) ? (arc[2] as number) : 1;
      return Array.from({ length: weight }, () => [String(arc[0]), String(arc[1])] as [string, string]);
    }
    if (isObject(arc)) {
      const weight = Number.isInteger(arc.weight) ? (arc.weight as number) : 1;
      return Array.from({ length: weight }, () => [String(arc.source ?? arc.from), String(arc.target ?? arc.to)] as [string, string]);
    }
    return [];
  });
  return { places, transitions, arcs };
}

function guessKind(id: string): PlaceKind {
  if (id.startsWith("running:")) return "busy";
  return /^(time|func-start|func-done):/.test(id) ? "constraint" : "flow";
}

function ofList(of: unknown, id: string, kind: PlaceKind): string[] {
  if (Array.isArray(of)) return of.map(String);
  // A constraint place names its constraint: {constraint, type, role, from, to}.
  if (isObject(of) && typeof of.from === "string" && typeof of.to === "string") return [of.from, of.to];
  if (typeof of === "string" && of) return [of];
  if (kind === "busy") return [id.slice("running:".length)];
  if (kind === "constraint") return id.slice(id.indexOf(":") + 1).split(">");
  return [id];
}

export type Marking = Map<string, number>;

/** The token game: a marking, the firings that led to it, and the ones undone (to step forward again). */
export class TokenGame {
  readonly net: ExecutionNet;
  marking: Marking;
  readonly history: NetTransition[] = [];
  future: NetTransition[] = [];
  private readonly pre = new Map<string, Map<string, number>>();
  private readonly post = new Map<string, Map<string, number>>();
  private readonly byId: Map<string, NetTransition>;
  /** Per firing in `history`, the tokens its resets took, so a step back puts them back. */
  private readonly taken: Marking[] = [];

  constructor(net: ExecutionNet) {
    this.net = net;
    this.byId = new Map(net.transitions.map((t) => [t.id, t]));
    for (const [from, to] of net.arcs) {
      if (this.byId.has(to)) add(this.pre, to, from);
      else if (this.byId.has(from)) add(this.post, from, to);
    }
    this.marking = this.initialMarking();
  }

  initialMarking(): Marking {
    return new Map(this.net.places.filter((place) => place.tokens > 0).map((place) => [place.id, place.tokens]));
  }

  tokens(place: string): number {
    return this.marking.get(place) ?? 0;
  }

  isEnabled(transition: NetTransition): boolean {
    for (const [place, weight] of this.pre.get(transition.id) ?? []) {
      if (this.tokens(place) < weight) return false;
    }
    return true;
  }

  enabled(): NetTransition[] {
    return this.net.transitions.filter((transition) => this.isEnabled(transition));
  }

  /** Fires a transition; a new firing forgets the steps that were undone. Throws when it is not enabled. */
  fire(id: string): NetTransition {
    const transition = this.apply(id);
    this.future = [];
    return transition;
  }

  /** Undoes the last firing; false at the start. */
  back(): boolean {
    const last = this.history.pop();
    if (!last) return false;
    this.unfire(last, this.taken.pop() ?? new Map<string, number>());
    this.future.unshift(last);
    return true;
  }

  /** Fires the next undone (or queued) firing again; false when there is none or it is not enabled. */
  forward(): boolean {
    const next = this.future[0];
    if (!next || !this.isEnabled(next)) return false;
    this.future.shift();
    this.apply(next.id);
    return true;
  }

  reset(): void {
    this.marking = this.initialMarking();
    this.history.length = 0;
    this.taken.length = 0;
    this.future = [];
  }

  /** Fires one enabled transition chosen by `random` (0 ≤ r < 1); null when nothing is enabled. */
  fireRandom(random: () => number = Math.random): NetTransition | null {
    const enabled = this.enabled();
    if (enabled.length === 0) return null;
    return this.fire(enabled[Math.min(enabled.length - 1, Math.floor(random() * enabled.length))].id);
  }

  /** What a click on a pattern transition fires: a silent one itself, a task its completion if running, else its start. */
  firingFor(task: string): NetTransition | null {
    const candidates = this.net.transitions.filter((t) => t.task === task && this.isEnabled(t));
    const order: FiringKind[] = ["silent", "complete", "start"];
    return order.map((kind) => candidates.find((t) => t.kind === kind)).find((t) => t !== undefined) ?? null;
  }

  /**
   * Why a click on `task` fires nothing though its flow is there: the constraint
   * places its next firing (start, or completion while it runs) lacks. Empty when
   * it can fire, or when it also waits for tokens of the flow.
   */
  heldBack(task: string): NetPlace[] {
    const kind: FiringKind = this.isRunning(task) ? "complete" : "start";
    const firing = this.net.transitions.find((t) => t.task === task && t.kind === kind);
    if (!firing || this.isEnabled(firing)) return [];
    const missing = [...(this.pre.get(firing.id) ?? [])].filter(([place, weight]) => this.tokens(place) < weight);
    const places = missing.map(([id]) => this.net.places.find((place) => place.id === id));
    return places.every((place) => place?.kind === "constraint") ? (places as NetPlace[]) : [];
  }

  /** The actor who performs a pattern task, as the execution net says; null for a silent step. */
  performerOf(task: string): string | null {
    return this.net.transitions.find((t) => t.task === task)?.performer ?? null;
  }

  /** Whether a pattern task is running (its busy place holds a token). */
  isRunning(task: string): boolean {
    return this.net.places.some((place) => place.kind === "busy" && place.of.includes(task) && this.tokens(place.id) > 0);
  }

  /** Restarts and queues a firing sequence (a witness) to be stepped through with forward(). */
  load(labels: string[]): void {
    this.reset();
    this.future = labels.map((label) => {
      const transition = this.byLabel(label);
      if (!transition) throw new Error(`The witness names ${label}, which is not in the execution net.`);
      return transition;
    });
  }

  byLabel(label: string): NetTransition | undefined {
    const found = this.net.transitions.find((t) => t.label === label || t.id === label);
    if (found) return found;
    const [kind, ...rest] = label.split(" ");
    return this.byId.get(`${kind}:${rest.join(" ")}`);
  }

  private apply(id: string): NetTransition {
    const transition = this.byId.get(id);
    if (!transition) throw new Error(`There is no transition ${id} in the execution net.`);
    if (!this.isEnabled(transition)) throw new Error(`${transition.label} is not enabled.`);
    for (const [place, weight] of this.pre.get(id) ?? []) this.bump(place, -weight);
    const taken: Marking = new Map();
    for (const place of transition.resets) {
      const tokens = this.tokens(place);
      if (tokens > 0) taken.set(place, tokens);
      this.bump(place, -tokens);
    }
    for (const [place, weight] of this.post.get(id) ?? []) this.bump(place, weight);
    this.history.push(transition);
    this.taken.push(taken);
    return transition;
  }

  /** Takes a firing back: its output, then what its resets took, then its input. */
  private unfire(transition: NetTransition, taken: Marking): void {
    for (const [place, weight] of this.post.get(transition.id) ?? []) this.bump(place, -weight);
    for (const [place, tokens] of taken) this.bump(place, tokens);
    for (const [place, weight] of this.pre.get(transition.id) ?? []) this.bump(place, weight);
  }

  private bump(place: string, delta: number): void {
    const tokens = this.tokens(place) + delta;
    if (tokens === 0) this.marking.delete(place);
    else this.marking.set(place, tokens);
  }
}

function add(arcs: Map<string, Map<string, number>>, transition: string, place: string): void {
  const weights = arcs.get(transition) ?? new Map<string, number>();
  weights.set(place, (weights.get(place) ?? 0) + 1);
  arcs.set(transition, weights);
}

/**
 * Why a task is held back, in the drawing's words: which constraint and which
 * other actor's task it waits for. `name` turns a task id into its label.
 */
export function heldBackWords(game: TokenGame, task: string, name: (id: string) => string): string {
  const reasons = game.heldBack(task).map((place) => {
    const role = place.id.slice(0, place.id.indexOf(":"));
    const other = place.of.find((id) => id !== task) ?? place.of[0];
    const actor = game.performerOf(other);
    const whose = actor ? `${actor}'s ${name(other)}` : name(other);
    const [from, to] = place.of;
    if (role === "time") return `the time constraint ${name(from)} → ${name(to)}: it waits for ${whose} to complete`;
    if (role === "func-start") return `the func constraint with ${name(other)}: it starts only while ${whose} runs`;
    return `the func constraint with ${name(other)}: it completes only after ${whose} has completed`;
  });
  if (reasons.length === 0) return "";
  const verb = game.isRunning(task) ? "cannot complete yet" : "cannot start yet";
  return `${name(task)} ${verb}, held back by ${reasons.join("; and by ")}.`;
}
