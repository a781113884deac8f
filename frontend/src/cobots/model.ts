// What the cobot page shows, as pure functions of the API's answers (hrc/cobots/api/).

import { COMMAND_OUTCOMES, CONTROL_COMMANDS } from "../shared/choices";

/** A control command as the record shows it (hrc.cobots.api.serializers.CobotCommandSerializer). */
export interface CommandJson {
  id: number;
  cobot: number;
  command: string;
  arguments: Record<string, unknown>;
  requested_by: string | null;
  requested_at: string;
  finished_at: string | null;
  outcome: string;
  message: string;
}

/** The cobot's state now (hrc.cobots.selectors.live_state). */
export interface StateJson {
  reachable: boolean;
  error?: string;
  RobotMode?: string;
  SafetyMode?: string;
  ProgramState?: string;
  CurrentProgram?: string;
  LastError?: string;
}

export interface RegistersJson {
  inputs: Record<string, unknown>;
  outputs: Record<string, unknown>;
}

/** The request body of a command: always confirmed (the dialog asked), a load names its program. */
export function commandBody(command: string, program: string): Record<string, unknown> {
  return command === "load-program" ? { program, confirm: true } : { confirm: true };
}

// How the dialog asks, before the cobot's name.
const QUESTIONS: Record<string, string> = {
  "power-on": "Power on",
  "brake-release": "Release the brakes of",
  "power-off": "Power off",
  "start-program": "Start the program of",
  "pause-program": "Pause the program of",
  "stop-program": "Stop the program of",
};

/** The dialog's question: "Power on cobot1?", "Load Pick on cobot1?". */
export function question(command: string, cobot: string, program: string): string {
  if (command === "load-program") return `Load ${program || "(no program)"} on ${cobot}?`;
  return `${QUESTIONS[command] ?? CONTROL_COMMANDS[command] ?? command} ${cobot}?`;
}

/** What the page says once the cobot has done a command. */
export function doneText(record: CommandJson, cobot: string): string {
  return `${CONTROL_COMMANDS[record.command] ?? record.command}: ${cobot} done.`;
}

/** The cells of a row of the record: when, who, what, outcome, message. */
export function commandRow(record: CommandJson): string[] {
  const program = typeof record.arguments.program === "string" ? ` ${record.arguments.program}` : "";
  return [
    formatTime(record.requested_at),
    record.requested_by ?? "–",
    `${CONTROL_COMMANDS[record.command] ?? record.command}${program}`,
    COMMAND_OUTCOMES[record.outcome] ?? record.outcome,
    record.message,
  ];
}

/** "2025-03-01 10:00:00" in local time, as the server renders it. */
export function formatTime(iso: string): string {
  const at = new Date(iso);
  if (Number.isNaN(at.getTime())) return iso;
  const two = (n: number) => String(n).padStart(2, "0");
  return (
    `${at.getFullYear()}-${two(at.getMonth() + 1)}-${two(at.getDate())} ` +
    `${two(at.getHours())}:${two(at.getMinutes())}:${two(at.getSeconds())}`
  );
}

/** The state's fields as the page lists them; an unreachable cobot says why in `error`. */
export function stateFields(state: StateJson): Record<string, string> {
  const shown = (value: string | undefined) => value || "–";
  return {
    RobotMode: shown(state.RobotMode),
    SafetyMode: shown(state.SafetyMode),
    CurrentProgram: shown(state.CurrentProgram),
    ProgramState: shown(state.ProgramState),
    LastError: shown(state.LastError),
    error: state.reachable ? "reachable" : shown(state.error),
  };
}

/** A register value as the server renders it (JSON: true, 3, 0.25). */
export function registerText(value: unknown): string {
  return JSON.stringify(value) ?? "";
}
