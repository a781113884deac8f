import { describe, expect, test } from "vitest";

import {
  type ActorLoad,
  bottleneckName,
  comparisonRows,
  formatRate,
  formatSeconds,
  formatShare,
  type Prediction,
  utilisationWords,
} from "../../src/editor/model/prediction";

function load(actor: string, utilisation: number, people: number | null = 1): ActorLoad {
  return { actor, kind: "operator", people, utilisation, busy_seconds: 0, held_seconds: 0, interrupted_seconds: 0, waiting_seconds: 0, waiting_per_case: 0, waited: 0, work_items: 0 };
}

function prediction(overrides: Partial<Prediction> = {}): Prediction {
  return {
    cases: 100,
    completed: 100,
    parallel: 1,
    seed: 0,
    cycle_time: { count: 100, mean: 40, p50: 40, p90: 50, p99: 60, min: 30, max: 70 },
    throughput_per_hour: 90,
    span_seconds: 4000,
    actors: [load("o", 0.5), load("c", 0.8)],
    tasks: [
      { task: "t1", label: "Pick insert", actor: "c", runs: 100, mean_duration: 20, mean_wait: 0, critical_seconds: 20, critical_wait_seconds: 0, critical_share: 0.5 },
      { task: "t2", label: " ", actor: "o", runs: 100, mean_duration: 10, mean_wait: 2, critical_seconds: 12, critical_wait_seconds: 2, critical_share: 0.3 },
    ],
    bottleneck: "t1",
    typical_case: 3,
    critical_path: [],
    stuck: [],
    stuck_count: 0,
    events: 400,
    assumed: [],
    ...overrides,
  };
}

describe("durations, shares and rates in words", () => {
  test("seconds read as seconds, minutes or hours by their size", () => {
    expect(formatSeconds(0.4234)).toBe("0.42 s");
    expect(formatSeconds(4.26)).toBe("4.3 s");
    expect(formatSeconds(42.6)).toBe("43 s");
    expect(formatSeconds(245)).toBe("4 min 05 s");
    expect(formatSeconds(3599.6)).toBe("60 min 00 s");
    expect(formatSeconds(7380)).toBe("2 h 03 min");
    expect(formatSeconds(-90)).toBe("−1 min 30 s");
    expect(formatSeconds(Number.NaN)).toBe("–");
  });

  test("a share is a whole percentage, a sliver of one is not rounded to nothing", () => {
    expect(formatShare(0.876)).toBe("88 %");
    expect(formatShare(0)).toBe("0 %");
    expect(formatShare(0.001)).toBe("< 1 %");
    expect(formatShare(1)).toBe("100 %");
  });

  test("throughput keeps the digits that matter", () => {
    expect(formatRate(123.4)).toBe("123 /h");
    expect(formatRate(7.54)).toBe("7.5 /h");
    expect(formatRate(0.254)).toBe("0.25 /h");
  });

  test("a team without a size is busy by people, not by a share", () => {
    expect(utilisationWords({ people: null, utilisation: 1.44 })).toBe("1.4 busy on average");
    expect(utilisationWords({ people: 2, utilisation: 0.5 })).toBe("50 %");
  });

  test("the bottleneck is named by its label, by its id where the label is blank", () => {
    expect(bottleneckName(prediction())).toBe("Pick insert");
    expect(bottleneckName(prediction({ bottleneck: "t2" }))).toBe("t2");
    expect(bottleneckName(prediction({ bottleneck: null }))).toBeNull();
  });
});

describe("the draft beside a published version", () => {
  test("cycle times, throughput, each actor and the bottleneck, with the differences", () => {
    const draft = prediction({ cycle_time: { count: 100, mean: 30, p50: 30, p90: 45, p99: 60, min: 20, max: 70 }, throughput_per_hour: 120, actors: [load("o", 0.6), load("c", 0.8)], bottleneck: "t2" });
    const rows = comparisonRows(draft, prediction());
    const byKey = Object.fromEntries(rows.map((row) => [row.key, row]));
    expect(rows.map((row) => row.key)).toEqual(["p50", "p90", "throughput", "actor:o", "actor:c", "bottleneck"]);
    expect(byKey.p50).toMatchObject({ draft: "30 s", version: "40 s", difference: "−10 s", better: true });
    expect(byKey.p90).toMatchObject({ draft: "45 s", version: "50 s", difference: "−5 s", better: true });
    expect(byKey.throughput).toMatchObject({ draft: "120 /h", version: "90 /h", difference: "+30 /h", better: true });
    expect(byKey["actor:o"]).toMatchObject({ group: "utilisation", label: "o", draft: "60 %", version: "50 %", difference: "+10 pt", better: null });
    expect(byKey["actor:c"]).toMatchObject({ difference: "same" });
    expect(byKey.p50.group).toBe("cycle");
    expect(byKey.bottleneck.group).toBe("bottleneck");
    expect(byKey.bottleneck).toMatchObject({ draft: "t2", version: "Pick insert", difference: "moved" });
  });

  test("a slower draft is worse, and a lane only one side has shows no difference", () => {
    const draft = prediction({ cycle_time: { count: 100, mean: 50, p50: 50, p90: 50, p99: 60, min: 30, max: 70 }, throughput_per_hour: 60, actors: [load("o", 0.5), load("c", 0.8), load("c2", 0.3)] });
    const rows = comparisonRows(draft, prediction({ actors: [load("o", 0.5), load("d", 0.2, 1)] }));
    const byKey = Object.fromEntries(rows.map((row) => [row.key, row]));
    expect(byKey.p50).toMatchObject({ difference: "+10 s", better: false });
    expect(byKey.p90).toMatchObject({ difference: "same", better: null });
    expect(byKey.throughput).toMatchObject({ difference: "−30 /h", better: false });
    expect(rows.map((row) => row.key)).toEqual(["p50", "p90", "throughput", "actor:o", "actor:c", "actor:c2", "actor:d", "bottleneck"]);
    expect(byKey["actor:c2"]).toMatchObject({ draft: "30 %", version: "–", difference: "" });
    expect(byKey["actor:d"]).toMatchObject({ draft: "–", version: "20 %", difference: "" });
    expect(byKey.bottleneck).toMatchObject({ difference: "same" });
  });

  test("a change of less than a point keeps a decimal", () => {
    const rows = comparisonRows(prediction({ actors: [load("o", 0.503)] }), prediction({ actors: [load("o", 0.5)] }));
    expect(rows.find((row) => row.key === "actor:o")?.difference).toBe("+0.3 pt");
  });

  test("no completed case: no cycle time to compare", () => {
    const rows = comparisonRows(prediction({ cycle_time: null, completed: 0 }), prediction());
    expect(rows[0]).toMatchObject({ draft: "–", version: "40 s", difference: "" });
  });

  test("a team without a size differs by people busy", () => {
    const rows = comparisonRows(prediction({ actors: [load("o", 1.5, null)] }), prediction({ actors: [load("o", 1.2, null)] }));
    expect(rows.find((row) => row.key === "actor:o")).toMatchObject({ draft: "1.5 busy on average", version: "1.2 busy on average", difference: "+0.3 busy" });
  });
});
