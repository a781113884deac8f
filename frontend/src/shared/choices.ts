// The server's vocabularies (hrc/cases/choices.py, hrc/cobots/choices.py) as the pages name
// them: each value with its label. tests/test_typescript_mirror.py fails when they part.

/** CaseStatus. */
export const CASE_STATUSES: Record<string, string> = {
  running: "Running",
  suspended: "Suspended",
  completed: "Completed",
  cancelled: "Cancelled",
  failed: "Failed",
};

/** OPEN_CASE_STATUSES: a case in these has not ended. */
export const OPEN_CASE_STATUSES: ReadonlySet<string> = new Set(["running", "suspended"]);

/** OPEN_WORK_ITEM_STATES: a work item in these still waits for someone (or a cobot). */
export const OPEN_WORK_ITEM_STATES: ReadonlySet<string> = new Set(["offered", "claimed", "running"]);

/** EventType: what a case event's `type` says happened. */
export const EVENT_TYPES: Record<string, string> = {
  "case-started": "Case started",
  "case-suspended": "Case suspended",
  "case-resumed": "Case resumed",
  "case-cancelled": "Case cancelled",
  "case-completed": "Case completed",
  "case-failed": "Case failed",
  "task-offered": "Task offered",
  "task-claimed": "Task claimed",
  "task-unclaimed": "Task unclaimed",
  "task-reassigned": "Task reassigned",
  "task-started": "Task started",
  "task-completed": "Task completed",
  "task-withdrawn": "Task withdrawn",
  "task-cancelled": "Task cancelled",
  "cancelled-step-ended": "Cancelled task's step ended",
  "task-interrupted": "Task interrupted",
  "task-resumed": "Task resumed",
  "area-left": "Operator left the area",
  "task-kept-out": "Task kept out of a shared area",
  "transition-fired": "Transition fired",
  "message-sent": "Message sent",
  "message-received": "Message received",
  "timer-armed": "Timer armed",
  "timer-fired": "Timer fired",
  "timer-disarmed": "Timer disarmed",
  "step-retry": "Step will be retried",
  "step-failed": "Step failed",
  "incident-opened": "Incident opened",
  "incident-resolved": "Incident resolved",
};

/** IncidentKind. */
export const INCIDENT_KINDS: Record<string, string> = {
  "step-failed": "Cobot step failed",
  "device-failed": "Device call failed",
  "lease-expired": "Worker lost the job repeatedly",
  "case-fault": "Case fault",
};

/** Resolution: how a person resolves an incident. */
export const RESOLUTIONS = ["retry", "skip", "cancel"] as const;
export type Resolution = (typeof RESOLUTIONS)[number];

/** ControlCommand: what a person may ask of a cobot from its page. */
export const CONTROL_COMMANDS: Record<string, string> = {
  "power-on": "Power on",
  "brake-release": "Release the brakes",
  "power-off": "Power off",
  "load-program": "Load a program",
  "start-program": "Start the program",
  "pause-program": "Pause the program",
  "stop-program": "Stop the program",
};

/** CommandOutcome: what came of a control command. */
export const COMMAND_OUTCOMES: Record<string, string> = {
  running: "Running",
  ok: "Done",
  refused: "Refused",
  failed: "Failed",
};
