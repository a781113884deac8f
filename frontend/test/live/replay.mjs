// Replays captured events through the tablet's store (tests/live/test_event_stream.py bundles
// this with esbuild and runs it with node): reads {"events": [snapshot, ...deltas]} on stdin,
// prints the state the store ends with.
import { readFileSync } from "node:fs";
import { asSnapshot, LiveStore } from "../../src/live/store";

const input = JSON.parse(readFileSync(0, "utf8"));
const store = new LiveStore();
const outcomes = input.events.map((event) => store.apply(event));
process.stdout.write(
  JSON.stringify({ state: store.state ? asSnapshot(store.state) : null, holes: store.hasHoles(), outcomes }),
);
