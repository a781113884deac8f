import { describe, expect, test } from "vitest";

import { placeInLane } from "../../src/editor/features/context-pad/placement";

const task = { width: 100, height: 60 };
// A lane 200 px high from y = 100; a task's centre may lie between 150 and 250.
const lane = { x: 0, y: 100, width: 1000, height: 200 };

describe("placing an appended node", () => {
  test("goes right of its source when the spot is free", () => {
    expect(placeInLane({ x: 300, y: 150 }, task, lane, [])).toEqual({ x: 300, y: 150 });
  });

  test("a second branch goes below the first, inside the lane", () => {
    const first = { x: 250, y: 120, width: 100, height: 60 };
    const placed = placeInLane({ x: 300, y: 150 }, task, lane, [first]);
    expect(placed.x).toBe(300);
    expect(placed.y).toBeGreaterThan(150);
    expect(placed.y + task.height / 2).toBeLessThanOrEqual(lane.y + lane.height);
  });

  test("a lane with no room below or above puts it further right, never across the border", () => {
    const narrow = { x: 0, y: 100, width: 1000, height: 110 };
    const first = { x: 250, y: 125, width: 100, height: 60 };
    const placed = placeInLane({ x: 300, y: 155 }, task, narrow, [first]);
    expect(placed.x).toBeGreaterThan(300);
    expect(placed.y - task.height / 2).toBeGreaterThanOrEqual(narrow.y);
    expect(placed.y + task.height / 2).toBeLessThanOrEqual(narrow.y + narrow.height);
  });
});
