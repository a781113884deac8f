/**
 * A silent transition's `timer` key: an ISO 8601 duration in days, hours,
 * minutes and seconds (PT30S, PT5M, P1DT2H, PT0.5S), the rule of the engine's
 * taskconfig.parse_duration. Years and months are refused: their length varies.
 */

const DURATION = /^P(?:(\d+)D)?(?:T(?:(\d+)H)?(?:(\d+)M)?(?:(\d+(?:\.\d+)?)S)?)?$/;
const UNIT_MS = { d: 86_400_000, h: 3_600_000, min: 60_000, s: 1000 } as const;
export const DURATION_EXAMPLES = "PT30S, PT5M, P1DT2H";

/** The duration in milliseconds. Throws an Error that says what to write instead. */
export function parseDuration(text: string): number {
  const written = text.trim().toUpperCase();
  if (written.startsWith("P") && /[YMW]/.test(written.split("T")[0])) {
    throw new Error(`${JSON.stringify(text.trim())}: years, months and weeks are not used (a month's length varies); write days, e.g. P30D.`);
  }
  const parts = DURATION.exec(written);
  // "P", "PT" and "P1DT" match the pattern's optional parts but say no duration.
  if (!parts || written === "P" || written.endsWith("T")) {
    throw new Error(`${JSON.stringify(text.trim())} is not an ISO 8601 duration: write days, hours, minutes, seconds, e.g. ${DURATION_EXAMPLES}.`);
  }
  const [, days, hours, minutes, seconds] = parts;
  const ms = Number(days ?? 0) * UNIT_MS.d + Number(hours ?? 0) * UNIT_MS.h + Number(minutes ?? 0) * UNIT_MS.min + Number(seconds ?? 0) * UNIT_MS.s;
  return Math.round(ms);
}

/** The duration as the canvas shows it beside the clock: "1 d 2 h", "5 min", "0.5 s". */
export function durationWords(ms: number): string {
  const words: string[] = [];
  let rest = ms;
  for (const [unit, size] of Object.entries(UNIT_MS)) {
    const whole = unit === "s" ? rest / size : Math.floor(rest / size);
    if (whole > 0) words.push(`${Number(whole.toFixed(3))} ${unit}`);
    rest -= Math.floor(rest / size) * size;
  }
  return words.length ? words.join(" ") : "0 s";
}

/** The transition's timer in words, or null when it has none or one the check will refuse. */
export function timerWords(timer: unknown): string | null {
  if (typeof timer !== "string") return null;
  try {
    return durationWords(parseDuration(timer));
  } catch {
    return null;
  }
}
