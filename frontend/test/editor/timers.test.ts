import { expect, test } from "vitest";

import { durationWords, parseDuration, timerWords } from "../../src/editor/model/timers";

test("a timer is an ISO 8601 duration in weeks, days, hours, minutes and seconds", () => {
  expect(parseDuration("PT30S")).toBe(30_000);
  expect(parseDuration("PT5M")).toBe(300_000);
  expect(parseDuration("P1DT2H")).toBe(93_600_000);
  expect(parseDuration("PT0.5S")).toBe(500);
  expect(parseDuration("P1,5D")).toBe(129_600_000);
  expect(parseDuration(" pt1h30m ")).toBe(5_400_000);
  expect(parseDuration("P2W")).toBe(1_209_600_000);
  expect(parseDuration("PT0S")).toBe(0);
});

test("years and months are refused as ambiguous, with what to write instead", () => {
  for (const text of ["P1Y", "P2M", "P1Y2M3DT4H"]) {
    expect(() => parseDuration(text), text).toThrowError(/counts years or months, which have no fixed length; write the duration in weeks, days, hours, minutes and seconds \(P30D\)\.$/);
  }
  // M after the T is minutes.
  expect(parseDuration("P1DT2M")).toBe(86_520_000);
});

test("anything else is not a duration, and the message gives examples", () => {
  for (const text of ["", "P", "PT", "P1DT", "5M", "PT5", "PT5M30", "T5M", "PT-5S", "P1W2D", "5 minutes"]) {
    expect(() => parseDuration(text), text).toThrowError(/is not an ISO 8601 duration such as PT5M \(5 minutes\), PT30S or P1DT2H\.$/);
  }
});

test("a timer waits at most a year", () => {
  expect(parseDuration("P366D")).toBe(366 * 86_400_000);
  expect(() => parseDuration("P367D")).toThrowError('"P367D" is longer than a year; a timer waits at most P366D.');
});

test("the canvas words a duration by its units, largest first", () => {
  expect(durationWords(93_600_000)).toBe("1 d 2 h");
  expect(durationWords(300_000)).toBe("5 min");
  expect(durationWords(90_500)).toBe("1 min 30.5 s");
  expect(durationWords(0)).toBe("0 s");
  expect(timerWords("PT0.5S")).toBe("0.5 s");
  expect(timerWords("P2W")).toBe("14 d");
  expect(timerWords("P1M")).toBeNull();
  expect(timerWords(30)).toBeNull();
});
