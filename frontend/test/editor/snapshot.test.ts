import { describe, expect, test } from "vitest";

import { emptyDocument, readDocument } from "../../src/editor/model/document";
import { hasLayout, LANE_HEIGHT, toDocument, toSnapshot } from "../../src/editor/model/snapshot";
import { example } from "./helpers";

function laidOut() {
  const document = example("synch_1o1c_assembly");
  document.processes[0].places.forEach((place, index) => (place.layout = { x: 60 + index * 80, y: index % 2 ? 200 : 60 }));
  document.processes[0].transitions.forEach((transition, index) => (transition.layout = { x: 100 + index * 90, y: transition.performer === "o" ? 220 : 70 }));
  document.layout = { lanes: [{ actor: "c", y: 0, height: 150 }, { actor: "o", y: 150, height: 150 }], width: 1200, height: 300, sizes: { place: { width: 36 } } };
  return document;
}

describe("the canvas snapshot of a document", () => {
  test("a document with layout goes to the canvas and back unchanged", () => {
    const document = laidOut();
    document.processes[0].transitions[2].task = { step: { number: 3 } };
    document.constraints[0].interrupt = "slow";
    expect(toDocument(toSnapshot(readDocument(document)))).toEqual(document);
  });

  test("nodes keep their centres and lanes their bands", () => {
    const snapshot = toSnapshot(laidOut());
    expect(snapshot.lanes.map((lane) => [lane.actor.id, lane.process, lane.y, lane.height])).toEqual([
      ["c", "N", 0, 150],
      ["o", "N", 150, 150],
    ]);
    expect(snapshot.nodes.find((node) => node.data.id === "to1")).toMatchObject({ kind: "transition", process: "N", x: 100 + 5 * 90, y: 220 });
    expect(snapshot.arcs).toHaveLength(16);
    expect(snapshot.width).toBe(1200);
  });

  test("a document is drawn as it is only when every actor has a lane and every node a centre", () => {
    expect(hasLayout(laidOut())).toBe(true);
    expect(hasLayout(example("synch_1o1c_assembly"))).toBe(false);
    const missing = laidOut();
    delete missing.processes[0].places[3].layout;
    expect(hasLayout(missing)).toBe(false);
    const noLane = laidOut();
    (noLane.layout as { lanes: unknown[] }).lanes.pop();
    expect(hasLayout(noLane)).toBe(false);
  });

  test("an actor without a lane gets one under the others", () => {
    const document = laidOut();
    document.actors.push({ id: "c2", type: "cobot" });
    expect(toSnapshot(document).lanes[2]).toMatchObject({ y: 300, height: LANE_HEIGHT, process: null });
  });

  test("a process lists its lanes' actors: new ones appended, those moved to another net dropped", () => {
    const snapshot = toSnapshot(laidOut());
    snapshot.processes.push({ id: "N2", actors: [] });
    snapshot.lanes.push({ actor: { id: "c2", type: "cobot" }, process: "N", y: 300, height: 150 });
    snapshot.lanes[0].process = "N2";
    const document = toDocument(snapshot);
    expect(document.processes.map((process) => [process.id, process.actors])).toEqual([
      ["N", ["o", "c2"]],
      ["N2", ["c"]],
    ]);
    expect(document.actors.map((actor) => actor.id)).toEqual(["c", "o", "c2"]);
  });

  test("an empty model becomes a document with one empty net", () => {
    const document = toDocument(toSnapshot(emptyDocument("Fresh")));
    expect(document).toMatchObject({ format: "hrc-pattern/1", name: "Fresh", actors: [], constraints: [] });
    expect(document.processes).toEqual([{ id: "N", workpiece: "workpiece", actors: [], places: [], transitions: [], arcs: [] }]);
  });
});
