import { describe, expect, test } from "vitest";

import { type OptionsInput, readOptions, readTime, timeSource } from "../../src/editor/model/predictoptions";

function input(overrides: Partial<OptionsInput> = {}): OptionsInput {
  return { cases: "1000", parallel: "2", seed: "0", people: {}, times: {}, ...overrides };
}

describe("the options sent with a prediction", () => {
  test("counts, persons per lane and the given times; a task without one is left out", () => {
    const { options, problems } = readOptions(
      input({
        people: { o: "2", o2: "1" },
        times: {
          t1: { kind: "fixed", values: { seconds: "100" } },
          t2: { kind: "triangular", values: { low: "15", mode: "20", high: "40" } },
          t3: { kind: "lognormal", values: { median: "12", p90: "30.5" } },
          t4: { kind: "", values: { seconds: "5" } },
        },
      }),
    );
    expect(problems).toEqual({});
    expect(options).toEqual({
      cases: 1000,
      parallel: 2,
      seed: 0,
      people: { o: 2, o2: 1 },
      durations: {
        t1: { kind: "fixed", seconds: 100 },
        t2: { kind: "triangular", low: 15, mode: 20, high: 40 },
        t3: { kind: "lognormal", median: 12, p90: 30.5 },
      },
    });
  });

  test("a count that is not a whole number is named; its range is the server's to judge", () => {
    const { options, problems } = readOptions(input({ cases: "", parallel: "1.5", seed: "-3", people: { o: "x" } }));
    expect(problems).toEqual({
      cases: "Cases must be a whole number.",
      parallel: "Cases at once must be a whole number.",
      "people:o": "Persons in o must be a whole number.",
    });
    expect(options.seed).toBe(-3);
  });

  test("a wrong time is keyed by its task and field", () => {
    const { options, problems } = readOptions(input({ times: { t1: { kind: "fixed", values: { seconds: "-1" } } } }));
    expect(problems).toEqual({ "time:t1:seconds": "A time cannot be negative." });
    expect(options.durations).toEqual({});
  });
});

describe("a task's time as typed", () => {
  test("empty, not a number or negative: said beside the field", () => {
    expect(readTime({ kind: "fixed", values: {} }).problems).toEqual({ seconds: "Give a time in seconds." });
    expect(readTime({ kind: "fixed", values: { seconds: " " } }).problems).toEqual({ seconds: "Give a time in seconds." });
    expect(readTime({ kind: "triangular", values: { low: "a", mode: "-2", high: "3" } }).problems).toEqual({
      low: "A time is a number of seconds.",
      mode: "A time cannot be negative.",
    });
  });

  test("a triangular time needs low ≤ mode ≤ high", () => {
    expect(readTime({ kind: "triangular", values: { low: "40", mode: "20", high: "15" } })).toEqual({ time: null, problems: { high: "High must not be below low." } });
    expect(readTime({ kind: "triangular", values: { low: "10", mode: "50", high: "40" } }).problems).toEqual({ mode: "Mode must lie between low and high." });
    expect(readTime({ kind: "triangular", values: { low: "0", mode: "0", high: "0" } }).time).toEqual({ kind: "triangular", low: 0, mode: 0, high: 0 });
  });

  test("a lognormal time needs 0 < median ≤ p90", () => {
    expect(readTime({ kind: "lognormal", values: { median: "30", p90: "20" } }).problems).toEqual({ p90: "p90 must not be below the median." });
    expect(readTime({ kind: "lognormal", values: { median: "0", p90: "20" } }).problems).toEqual({ median: "The median must be above 0 s." });
    expect(readTime({ kind: "lognormal", values: { median: "20", p90: "20" } }).time).toEqual({ kind: "lognormal", median: 20, p90: 20 });
  });

  test("not given: no time and nothing wrong, whatever the fields still hold", () => {
    expect(readTime({ kind: "", values: { seconds: "-5" } })).toEqual({ time: null, problems: {} });
  });
});

test("where the last prediction took a task's time from", () => {
  const duration = (source: "given" | "measured" | "program" | "assumed", describe: string) => ({ source, describe, label: "Tape", actor: "o" });
  expect(timeSource(duration("given", "fixed, 100 s"))).toBe("Given by you: fixed, 100 s");
  expect(timeSource(duration("measured", "lognormal, median 12 s (30 runs)"))).toBe("Measured: lognormal, median 12 s (30 runs)");
  expect(timeSource(duration("assumed", "fixed, 10 s (the default)"))).toBe("Assumed: fixed, 10 s (the default)");
});
