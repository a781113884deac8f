/**
 * A silent transition's `timer` key: an ISO 8601 duration in weeks, days,
 * hours, minutes and seconds (PT30S, PT5M, P1DT2H, PT0.5S), read by the rule
 * of the engine's taskconfig.parse_duration. Years and months are refused:
 * their length varies.
 */

// PnW, or PnDTnHnMnS with any part left out; a part may have a fraction (PT0.5S, P1,5D).
const NUMBER = String.raw`(\d+(?:[.,]\d+)?)`;
const DURATION = new RegExp(String.raw`^P(?:${NUMBER}W|(?:${NUMBER}D)?(?:T(?=\d)(?:${NUMBER}H)?(?:${NUMBER}M)?(?:${NUMBER}S)?)?)$`);
const YEARS_OR_MONTHS = /^P[^T]*[YM]/;
const PART_MS = [7 * 86_400_000, 86_400_000, 3_600_000, 60_000, 1000]; // W, D, H, M, S
const WORD_UNITS: [string, number][] = [["d", 86_400_000], ["h", 3_600_000], ["min", 60_000], ["s", 1000]];
export const MAX_TIMER_MS = 366 * 86_400_000;
export const DURATION_EXAMPLES = "PT30S, PT5M, P1DT2H";

/** The duration in milliseconds. Throws an Error that says what to write instead. */
export function parseDuration(text: string): number {
  const written = text.trim().toUpperCase();
  const quoted = JSON.stringify(text.trim());
  const parts = DURATION.exec(written)?.slice(1);
  if (!parts?.some((part) => part !== undefined)) {
    if (YEARS_OR_MONTHS.test(written)) {
      throw new Error(`${quoted} counts years or months, which have no fixed length; write the duration in weeks, days, hours, minutes and seconds (P30D).`);
    }
    throw new Error(`${quoted} is not an ISO 8601 duration such as PT5M (5 minutes), PT30S or P1DT2H.`);
  }
  const ms = Math.round(parts.reduce((total, part, index) => total + (part === undefined ? 0 : Number(part.replace(",", ".")) * PART_MS[index]), 0));
  if (ms > MAX_TIMER_MS) throw new Error(`${quoted} is longer than a year; a timer waits at most P366D.`);
  return ms;
}

/** The duration as the canvas shows it beside the clock: "1 d 2 h", "5 min", "0.5 s". */
export function durationWords(ms: number): string {
  const words: string[] = [];
  let rest = ms;
  for (const [unit, size] of WORD_UNITS) {
    const count = unit === "s" ? rest / size : Math.floor(rest / size);
    if (count > 0) words.push(`${Number(count.toFixed(3))} ${unit}`);
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
