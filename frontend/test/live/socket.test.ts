import { describe, expect, it } from "vitest";
import { backoff, GAP_WAIT_MS, LiveSocket, type SocketLike } from "../../src/live/socket";
import { LiveStore } from "../../src/live/store";
import { itemDelta, snapshot } from "./fixtures";

class FakeTimers {
  now = 0;
  private timers: Array<{ at: number; callback: () => void; id: number }> = [];
  private next = 1;
  set = (callback: () => void, ms: number): number => {
    const id = this.next++;
    this.timers.push({ at: this.now + ms, callback, id });
    return id;
  };
  clear = (id: unknown): void => {
    this.timers = this.timers.filter((timer) => timer.id !== id);
  };
  advance(ms: number): void {
    this.now += ms;
    for (const timer of [...this.timers].sort((a, b) => a.at - b.at)) {
      if (timer.at <= this.now && this.timers.includes(timer)) {
        this.clear(timer.id);
        timer.callback();
      }
    }
  }
}

// A stand-in for the browser's WebSocket object, driven by the test (the server side is tested
// over real sockets in tests/live/ and tests/browser/).
class ScriptedSocket implements SocketLike {
  onopen: ((event: Event) => void) | null = null;
  onmessage: ((event: MessageEvent) => void) | null = null;
  onclose: ((event: CloseEvent) => void) | null = null;
  sent: string[] = [];
  closed = false;
  send(data: string): void {
    this.sent.push(data);
  }
  close(): void {
    this.closed = true;
  }
  deliver(event: unknown): void {
    this.onmessage?.({ data: JSON.stringify(event) } as MessageEvent);
  }
  drop(code = 1006): void {
    this.onclose?.({ code, reason: "" } as CloseEvent);
  }
}

function setUp() {
  const timers = new FakeTimers();
  const sockets: ScriptedSocket[] = [];
  const statuses: string[] = [];
  const store = new LiveStore();
  const live = new LiveSocket({
    url: "ws://tablet/ws/live/",
    store,
    open: () => {
      const socket = new ScriptedSocket();
      sockets.push(socket);
      return socket;
    },
    onStatus: (status) => statuses.push(status),
    setTimer: timers.set,
    clearTimer: timers.clear,
    random: () => 0.5,
  });
  live.start();
  return { timers, sockets, statuses, store, live };
}

describe("gap detection", () => {
  it("asks for a snapshot when a missing delta does not come in time", () => {
    const { timers, sockets, store, live } = setUp();
    sockets[0].deliver(snapshot());
    sockets[0].deliver(itemDelta(4, { state: "running" }));
    timers.advance(GAP_WAIT_MS - 1);
    expect(sockets[0].sent).toEqual([]);
    timers.advance(1);
    expect(sockets[0].sent).toEqual([JSON.stringify({ type: "resync" })]);
    expect(live.resyncs).toBe(1);
    expect(store.hasHoles()).toBe(false);
  });

  it("does not resynchronise when the late delta arrives within the wait", () => {
    const { timers, sockets } = setUp();
    sockets[0].deliver(snapshot());
    sockets[0].deliver(itemDelta(4, { state: "running" }));
    sockets[0].deliver(itemDelta(3, { state: "claimed" }));
    timers.advance(GAP_WAIT_MS * 2);
    expect(sockets[0].sent).toEqual([]);
  });
});

describe("reconnecting", () => {
  it("backs off from half a second, doubling to ten", () => {
    expect([0, 1, 2, 3, 4, 5, 9].map((n) => backoff(n, () => 0.5))).toEqual([500, 1000, 2000, 4000, 8000, 10000, 10000]);
  });

  it("reconnects after a lost socket and is live again once the snapshot arrives", () => {
    const { timers, sockets, statuses, store } = setUp();
    sockets[0].deliver(snapshot());
    expect(statuses[statuses.length - 1]).toBe("live");
    sockets[0].drop();
    expect(statuses[statuses.length - 1]).toBe("reconnecting");
    timers.advance(499);
    expect(sockets.length).toBe(1);
    timers.advance(1);
    expect(sockets.length).toBe(2);
    sockets[1].drop();
    timers.advance(999);
    expect(sockets.length).toBe(2);
    timers.advance(1);
    expect(sockets.length).toBe(3);
    sockets[2].deliver(snapshot({ cases: [{ id: 10, seq: 8, status: "running", name: "", cobots: [] }] }));
    expect(statuses[statuses.length - 1]).toBe("live");
    expect(store.state!.cases.get(10)!.seq).toBe(8);
    sockets[2].drop();
    timers.advance(500); // the back-off starts over after a good connection
    expect(sockets.length).toBe(4);
  });

  it("stops trying when the server refuses", () => {
    const { timers, sockets, statuses } = setUp();
    sockets[0].deliver({ type: "refused", reason: "Sign in first." });
    sockets[0].drop(4401);
    timers.advance(60_000);
    expect(sockets.length).toBe(1);
    expect(statuses[statuses.length - 1]).toBe("refused");
  });
});
