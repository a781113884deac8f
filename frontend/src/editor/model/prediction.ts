/**
 * A prediction as the server sends it (POST /api/patterns/predict/, hrc/engine/prediction_report.py),
 * and what the Predict panel says of it: times and shares in words, and the rows that set a
 * draft beside a published version.
 */

export interface CycleTime {
  count: number;
  mean: number;
  p50: number;
  p90: number;
  p99: number;
  min: number;
  max: number;
}

export interface ActorLoad {
  actor: string;
  kind: "operator" | "cobot" | "device";
  /** Null for a team of unlimited people: then utilisation is the mean number busy. */
  people: number | null;
  utilisation: number;
  busy_seconds: number;
  held_seconds: number;
  interrupted_seconds: number;
  waiting_seconds: number;
  waiting_per_case: number;
  waited: number;
  work_items: number;
}

export interface TaskLoad {
  task: string;
  label: string;
  actor: string;
  runs: number;
  mean_duration: number;
  mean_wait: number;
  critical_seconds: number;
  critical_wait_seconds: number;
  critical_share: number;
}

export interface PathStep {
  task: string;
  label: string;
  actor: string;
  offered: number;
  started: number;
  completed: number;
  waited: number;
  worked: number;
}

export interface StuckCase {
  case: number;
  at: number;
  marking: Record<string, number>;
  why: string;
}

export interface Prediction {
  cases: number;
  completed: number;
  parallel: number;
  seed: number;
  cycle_time: CycleTime | null;
  throughput_per_hour: number;
  span_seconds: number;
  actors: ActorLoad[];
  tasks: TaskLoad[];
  bottleneck: string | null;
  typical_case: number | null;
  critical_path: PathStep[];
  stuck: StuckCase[];
  stuck_count: number;
  events: number;
  assumed: string[];
}

/** Where a task's time came from. */
export interface TaskDuration {
  source: "given" | "measured" | "program" | "assumed";
  label: string;
  actor: string;
  describe: string;
}

/** A task's time as the engineer gives it (duration_from_dict's JSON); a lognormal by its median and p90, which the server converts. */
export type GivenTime =
  | { kind: "fixed"; seconds: number }
  | { kind: "triangular"; low: number; mode: number; high: number }
  | { kind: "lognormal"; median: number; p90: number };

export interface PredictOptions {
  cases?: number;
  parallel?: number;
  seed?: number;
  people?: Record<string, number>;
  /** Task id → its given time. */
  durations?: Record<string, GivenTime>;
  measured?: boolean;
}

export interface PredictionAnswer {
  prediction: Prediction;
  durations: Record<string, TaskDuration>;
  compared: null | {
    version: { id: number; number: number; pattern: number };
    prediction: Prediction;
    durations: Record<string, TaskDuration>;
  };
}

/** "0.42 s", "12.3 s", "4 min 05 s", "2 h 03 min": seconds as a person reads a duration. */
export function formatSeconds(seconds: number): string {
  if (!Number.isFinite(seconds)) return "–";
  const sign = seconds < 0 ? "−" : "";
  const value = Math.abs(seconds);
  if (value < 10) return `${sign}${trimmed(value, value < 1 ? 2 : 1)} s`;
  if (value < 60) return `${sign}${Math.round(value)} s`;
  if (value < 3600) {
    const whole = Math.round(value);
    return `${sign}${Math.floor(whole / 60)} min ${pad(whole % 60)} s`;
  }
  const minutes = Math.round(value / 60);
  return `${sign}${Math.floor(minutes / 60)} h ${pad(minutes % 60)} min`;
}

/** A share (0..1) as a whole percentage: "87 %"; below 1 % but above nothing, "< 1 %". */
export function formatShare(share: number): string {
  if (share > 0 && share < 0.005) return "< 1 %";
  return `${Math.round(share * 100)} %`;
}

/** Cases an hour: "120 /h", "7.5 /h", "0.25 /h". */
export function formatRate(perHour: number): string {
  if (perHour >= 100) return `${Math.round(perHour)} /h`;
  return `${trimmed(perHour, perHour >= 1 ? 1 : 2)} /h`;
}

/** What an actor's utilisation means: a share of its time, or for a team without a size, the people busy on average. */
export function utilisationWords(load: Pick<ActorLoad, "people" | "utilisation">): string {
  if (load.people === null) return `${trimmed(load.utilisation, 1)} busy on average`;
  return formatShare(load.utilisation);
}

/** The task the simulator named as bottleneck, by its label; null when it named none. */
export function bottleneckName(prediction: Prediction): string | null {
  if (prediction.bottleneck === null) return null;
  const task = prediction.tasks.find((load) => load.task === prediction.bottleneck);
  return task?.label.trim() ? task.label : prediction.bottleneck;
}

/** One line of the side-by-side comparison: what, the draft's value, the version's, and the difference. */
export interface ComparisonRow {
  key: string;
  /** The rows of one group go under one heading: the cycle, each lane's utilisation, the bottleneck. */
  group: "cycle" | "utilisation" | "bottleneck";
  label: string;
  draft: string;
  version: string;
  difference: string;
  /** Whether the draft does better (true), worse (false), the same or no telling (null). */
  better: boolean | null;
}

/**
 * The rows that set the draft beside a published version: cycle time p50 and p90, throughput,
 * each actor's utilisation (every actor of either, in the draft's order then the version's new
 * ones), and the bottleneck. A value one side lacks shows as "–" with no difference.
 */
export function comparisonRows(draft: Prediction, version: Prediction): ComparisonRow[] {
  const rows: ComparisonRow[] = [];
  const times: [string, string, (p: Prediction) => number | null][] = [
    ["p50", "Cycle p50", (p) => p.cycle_time?.p50 ?? null],
    ["p90", "Cycle p90", (p) => p.cycle_time?.p90 ?? null],
  ];
  for (const [key, label, read] of times) rows.push(numberRow("cycle", key, label, read(draft), read(version), formatSeconds, false));
  rows.push(numberRow("cycle", "throughput", "Throughput", draft.throughput_per_hour, version.throughput_per_hour, formatRate, true, signedRate));
  const actors = [...new Set([...draft.actors, ...version.actors].map((load) => load.actor))];
  for (const actor of actors) {
    const ours = draft.actors.find((load) => load.actor === actor);
    const theirs = version.actors.find((load) => load.actor === actor);
    // A team without a size counts people busy, not a share: its difference is in people.
    const counted = ours?.people === null || theirs?.people === null;
    const signed = counted ? (difference: number) => `${difference > 0 ? "+" : "−"}${trimmed(Math.abs(difference), 1)} busy` : signedPoints;
    const row = numberRow("utilisation", `actor:${actor}`, actor, ours?.utilisation ?? null, theirs?.utilisation ?? null, formatShare, null, signed);
    if (ours) row.draft = utilisationWords(ours);
    if (theirs) row.version = utilisationWords(theirs);
    rows.push(row);
  }
  const mine = bottleneckName(draft);
  const yours = bottleneckName(version);
  rows.push({
    key: "bottleneck",
    group: "bottleneck",
    label: "Bottleneck",
    draft: mine ?? "none",
    version: yours ?? "none",
    difference: mine === yours ? "same" : "moved",
    better: null,
  });
  return rows;
}

/**
 * A numeric row; `higherIsBetter` says which way is better (null: neither). The difference is
 * the draft's value less the version's.
 */
function numberRow(
  group: ComparisonRow["group"],
  key: string,
  label: string,
  draft: number | null,
  version: number | null,
  format: (value: number) => string,
  higherIsBetter: boolean | null,
  signed: (difference: number) => string = (difference) => signedWith(difference, format),
): ComparisonRow {
  const row: ComparisonRow = { key, group, label, draft: draft === null ? "–" : format(draft), version: version === null ? "–" : format(version), difference: "", better: null };
  if (draft === null || version === null) return row;
  const difference = draft - version;
  const scale = Math.max(Math.abs(draft), Math.abs(version));
  // A difference under a thousandth of the values is noise of the sampling, not a change.
  if (Math.abs(difference) <= scale * 1e-3) {
    row.difference = "same";
    return row;
  }
  row.difference = signed(difference);
  if (higherIsBetter !== null) row.better = higherIsBetter === difference > 0;
  return row;
}

function signedWith(difference: number, format: (value: number) => string): string {
  return `${difference > 0 ? "+" : "−"}${format(Math.abs(difference))}`;
}

function signedRate(difference: number): string {
  return signedWith(difference, formatRate);
}

/** A difference of shares in percentage points; one decimal under a whole point. */
function signedPoints(difference: number): string {
  const points = Math.abs(difference * 100);
  return `${difference > 0 ? "+" : "−"}${points < 1 ? trimmed(points, 1) : Math.round(points)} pt`;
}

function trimmed(value: number, digits: number): string {
  return String(Number(value.toFixed(digits)));
}

function pad(value: number): string {
  return String(value).padStart(2, "0");
}
