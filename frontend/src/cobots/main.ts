// The cobot page (templates/cobots/cobot_detail.html): each button asks for a confirmation
// in a dialog, then posts the command with confirm: true to the REST API (hrc/cobots/api/)
// and shows the result or the refusal; the state is refreshed every few seconds, the record
// and the registers after each command.

import { element, pageConfig } from "../shared/dom";
import { getJson, postJson, problemOf } from "../shared/http";
import type { PageJson } from "../supervisor/api";
import {
  commandBody,
  commandRow,
  doneText,
  question,
  registerText,
  stateFields,
  type CommandJson,
  type RegistersJson,
  type StateJson,
} from "./model";

interface PageConfig {
  cobot: number;
  name: string;
  refreshSeconds: number;
  api: { base: string; state: string; registers: string; commands: string };
}

const config = pageConfig<PageConfig>("cobot-page")!;
const dialog = document.getElementById("confirm") as HTMLDialogElement;
const outcome = document.getElementById("outcome") as HTMLElement;
const problem = document.getElementById("problem") as HTMLElement;
const programSelect = document.getElementById("program") as HTMLSelectElement;

function tell(done: string, refused: string): void {
  outcome.textContent = done;
  problem.textContent = refused;
}

/** Asks in the dialog; resolves true when the person confirmed. */
function confirmed(text: string): Promise<boolean> {
  (document.getElementById("confirm-question") as HTMLElement).textContent = text;
  return new Promise((resolve) => {
    dialog.addEventListener("close", () => resolve(dialog.returnValue === "confirm"), { once: true });
    dialog.returnValue = "";
    dialog.showModal();
  });
}

async function run(button: HTMLButtonElement): Promise<void> {
  const command = button.dataset.command ?? "";
  const program = programSelect?.value ?? "";
  if (!(await confirmed(question(command, config.name, program)))) return;
  tell("", "");
  button.disabled = true;
  try {
    const url = `${config.api.base}${button.dataset.path}/`;
    const record = await postJson<CommandJson>(url, commandBody(command, program));
    tell(doneText(record, config.name), "");
  } catch (error) {
    tell("", problemOf(error));
  } finally {
    button.disabled = false;
    await Promise.allSettled([refreshState(), refreshCommands(), refreshRegisters()]);
  }
}

async function refreshState(): Promise<void> {
  let state: StateJson;
  try {
    state = await getJson<StateJson>(config.api.state);
  } catch (error) {
    state = { reachable: false, error: problemOf(error) };
  }
  const fields = stateFields(state);
  for (const cell of document.querySelectorAll<HTMLElement>("#state [data-field]")) {
    cell.textContent = fields[cell.dataset.field ?? ""] ?? "–";
  }
  const badge = document.querySelector<HTMLElement>("#state-badge [data-state]");
  if (badge) {
    badge.textContent = state.reachable ? (state.RobotMode ?? "–") : "unreachable";
    badge.className = `status ${badgeClass(state)}`;
  }
}

function badgeClass(state: StateJson): string {
  if (!state.reachable || state.RobotMode === "Power Off") return "failed";
  return state.RobotMode === "Running" ? "running" : "suspended";
}

async function refreshCommands(): Promise<void> {
  const page = await getJson<PageJson<CommandJson>>(`${config.api.commands}?limit=20`);
  const body = document.querySelector("#commands tbody");
  if (!body || new URLSearchParams(location.search).has("page")) return; // an older page stays
  body.replaceChildren(
    ...page.results.map((record) => {
      const classes = ["", "", "", `outcome-${record.outcome}`, "detail"];
      const cells = commandRow(record).map((text, index) => element("td", classes[index] ?? "", text));
      return element("tr", { "data-command-id": String(record.id) }, ...cells);
    }),
  );
}

async function refreshRegisters(): Promise<void> {
  const registers = await getJson<RegistersJson>(config.api.registers);
  for (const row of document.querySelectorAll<HTMLElement>("#registers tr[data-register]")) {
    const name = row.dataset.register ?? "";
    for (const cell of row.querySelectorAll<HTMLElement>("[data-direction]")) {
      const values = cell.dataset.direction === "inputs" ? registers.inputs : registers.outputs;
      cell.textContent = registerText(values[name]);
    }
  }
}

for (const button of document.querySelectorAll<HTMLButtonElement>("button[data-command]")) {
  button.addEventListener("click", () => void run(button));
}
document.getElementById("refresh-registers")?.addEventListener("click", () => {
  refreshRegisters().catch((error: unknown) => tell("", problemOf(error)));
});
setInterval(() => void refreshState(), config.refreshSeconds * 1000);
