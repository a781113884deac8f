// The live socket: connects, reconnects with back-off, and resynchronises by itself.
//
// Every (re)connection starts with a snapshot from the server. A hole in a
// case's numbers is given GAP_WAIT_MS for the late delta to arrive; then the
// socket asks for a new snapshot. A refusal (close codes 4401, 4403) is final.

import type { LiveEvent } from "./events";
import { LiveStore } from "./store";

export type ConnectionStatus = "connecting" | "live" | "reconnecting" | "refused";

export const GAP_WAIT_MS = 1000;
export const REFUSED_CODES: ReadonlySet<number> = new Set([4401, 4403]);

/** The wait before reconnection attempt `attempt` (0, 1, 2…): doubling from 0.5 s to 10 s, ±20 %. */
export function backoff(attempt: number, random: () => number = Math.random): number {
  const base = Math.min(10_000, 500 * 2 ** attempt);
  return Math.round(base * (0.8 + 0.4 * random()));
}

/** The part of WebSocket the live socket uses (a test passes its own). */
export interface SocketLike {
  onopen: ((event: Event) => void) | null;
  onmessage: ((event: MessageEvent) => void) | null;
  onclose: ((event: CloseEvent) => void) | null;
  send(data: string): void;
  close(code?: number): void;
}

export interface LiveSocketOptions {
  url: string;
  store: LiveStore;
  open?: (url: string) => SocketLike;
  onStatus?: (status: ConnectionStatus, detail: string) => void;
  setTimer?: (callback: () => void, ms: number) => unknown;
  clearTimer?: (timer: unknown) => void;
  random?: () => number;
}

export class LiveSocket {
  status: ConnectionStatus = "connecting";
  attempts = 0;
  resyncs = 0;
  private socket: SocketLike | null = null;
  private gapTimer: unknown = null;
  private retryTimer: unknown = null;
  private stopped = false;
  private readonly options: Required<LiveSocketOptions>;

  constructor(options: LiveSocketOptions) {
    this.options = {
      open: (url) => new WebSocket(url),
      onStatus: () => undefined,
      setTimer: (callback, ms) => setTimeout(callback, ms),
      clearTimer: (timer) => clearTimeout(timer as ReturnType<typeof setTimeout>),
      random: Math.random,
      ...options,
    };
  }

  start(): void {
    this.stopped = false;
    this.connect();
  }

  /** Closes for good (the page is leaving). */
  stop(): void {
    this.stopped = true;
    this.clearTimers();
    this.socket?.close(1000);
  }

  private connect(): void {
    this.setStatus(this.attempts === 0 ? "connecting" : "reconnecting", "");
    const socket = this.options.open(this.options.url);
    this.socket = socket;
    socket.onmessage = (message) => {
      // One event, or the events of one commit in order.
      const data = JSON.parse(String(message.data)) as LiveEvent | LiveEvent[];
      for (const event of Array.isArray(data) ? data : [data]) this.receive(event);
    };
    socket.onclose = (event) => this.closed(event.code, event.reason);
  }

  private receive(event: LiveEvent): void {
    if (event.type === "refused") {
      this.setStatus("refused", event.reason);
      return;
    }
    const outcome = this.options.store.apply(event);
    if (event.type === "snapshot") {
      this.attempts = 0;
      this.clearGapTimer();
      this.setStatus("live", "");
    } else if (outcome === "held" && this.gapTimer === null) {
      this.gapTimer = this.options.setTimer(() => this.gapExpired(), GAP_WAIT_MS);
    } else if (!this.options.store.hasHoles()) {
      this.clearGapTimer();
    }
  }

  private gapExpired(): void {
    this.gapTimer = null;
    if (!this.options.store.hasHoles()) return;
    this.resyncs += 1;
    this.options.store.dropHeld();
    this.socket?.send(JSON.stringify({ type: "resync" }));
  }

  private closed(code: number, reason: string): void {
    this.socket = null;
    this.clearGapTimer();
    if (this.stopped) return;
    if (REFUSED_CODES.has(code)) {
      this.setStatus("refused", this.status === "refused" ? "" : reason);
      return;
    }
    const wait = backoff(this.attempts, this.options.random);
    this.attempts += 1;
    this.setStatus("reconnecting", `retrying in ${Math.round(wait / 100) / 10} s`);
    this.retryTimer = this.options.setTimer(() => {
      this.retryTimer = null;
      if (!this.stopped) this.connect();
    }, wait);
  }

  private setStatus(status: ConnectionStatus, detail: string): void {
    if (this.status === "refused" && status === "refused" && !detail) return;
    this.status = status;
    this.options.onStatus(status, detail);
  }

  private clearGapTimer(): void {
    if (this.gapTimer !== null) this.options.clearTimer(this.gapTimer);
    this.gapTimer = null;
  }

  private clearTimers(): void {
    this.clearGapTimer();
    if (this.retryTimer !== null) this.options.clearTimer(this.retryTimer);
    this.retryTimer = null;
  }
}
