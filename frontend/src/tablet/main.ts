// The operator tablet: live task cards, the cobot panel, display messages, STOP and resume.

import "./tablet.css";
import type { CobotData, LiveEvent, WorkItemData } from "../live/events";
import { type ConnectionStatus, LiveSocket } from "../live/socket";
import { type LiveState, LiveStore } from "../live/store";
import { element, pageConfig, patchChildren } from "../shared/dom";
import { ApiError, problemOf, request } from "../shared/http";
import { buildForm, type FormSchema } from "./form";
import {
  activity,
  atThisCell,
  cellsOf,
  cellWords,
  cobotWork,
  type DisplayMessage,
  degrees,
  elsewhere,
  humanSafety,
  mayGiveBack,
  myTasks,
  nextAction,
  teamTasks,
  timersOf,
  waitingLine,
  waitingTimers,
  withDisplayMessages,
} from "./view";

interface Config {
  organisation: number;
  cell: string;
  user: number;
  socket: string;
}

const STATUS_TEXT: Record<ConnectionStatus, string> = {
  connecting: "Connecting…",
  live: "Live",
  reconnecting: "Connection lost: reconnecting…",
  refused: "Refused",
};
const MAX_MESSAGES = 20;

const root = document.getElementById("tablet") as HTMLElement;
const config = pageConfig<Config>("tablet-config")!;
const $ = <T extends HTMLElement>(selector: string): T => root.querySelector(selector) as T;

const store = new LiveStore();
const scheme = location.protocol === "https:" ? "wss:" : "ws:";
const socket = new LiveSocket({
  url: `${scheme}//${location.host}${config.socket}`,
  store,
  onStatus: showStatus,
});
let messages: DisplayMessage[] = [];
let frame = 0;

store.subscribe((event: LiveEvent) => {
  if (event.type === "cobot-state" || event.type === "snapshot") collectMessages();
  if (!frame) frame = requestAnimationFrame(render);
});

function showStatus(status: ConnectionStatus, detail: string): void {
  root.dataset.status = status;
  $(".connection").textContent = STATUS_TEXT[status] + (detail ? ` (${detail})` : "");
}

// Rendering -------------------------------------------------------------------------------

function render(): void {
  frame = 0;
  const state = store.state;
  if (!state) return;
  renderCards($(".cards.mine"), myTasks(state), state, "Nothing for you right now.");
  renderCards($(".cards.team"), teamTasks(state), state, "No open team tasks.");
  renderElsewhere(state);
  renderWaiting(state);
  renderCobots(state);
  renderStop(state);
  renderMessages();
}

function renderElsewhere(state: LiveState): void {
  const note = root.querySelector<HTMLElement>(".elsewhere");
  if (!note) return; // the whole floor's tablet shows every task
  const items = elsewhere(state);
  const count = items.length;
  note.hidden = count === 0;
  note.textContent = `${count} more ${count === 1 ? "task waits" : "tasks wait"} for you at ${cellWords(cellsOf(state, items), true)}.`;
}

function renderWaiting(state: LiveState): void {
  const timers = waitingTimers(state);
  const section = $(".waiting");
  section.hidden = timers.length === 0;
  section.querySelector("ul")!.replaceChildren(
    ...timers.map((timer) => {
      const caseName = state.cases.get(timer.case)?.name ?? "";
      const line = element("li", "timer", `${caseName ? `${caseName} · ` : ""}case ${timer.case}: ${waitingLine(timer)}`);
      line.dataset.case = String(timer.case);
      return line;
    }),
  );
}

function renderCards(container: HTMLElement, items: WorkItemData[], state: LiveState, empty: string): void {
  const cards = items.length ? items.map((item) => card(item, state)) : [element("p", "empty", empty)];
  patchChildren(container, cards); // a card unchanged keeps its buttons under the operator's finger
}

function card(item: WorkItemData, state: LiveState): HTMLElement {
  const article = element("article", `card ${item.state}`);
  article.dataset.item = String(item.id);
  article.dataset.state = item.state;
  const caseName = state.cases.get(item.case)?.name ?? "";
  article.append(
    element("h3", "", item.label || item.task),
    element("p", "meta", `${caseName ? `${caseName} · ` : ""}case ${item.case} · ${item.state}`),
  );
  // Only a task the operator holds shows up here from another cell: say so, or they wait in vain.
  if (!atThisCell(state, item)) {
    const where = cellWords(cellsOf(state, [item]));
    article.append(element("p", "away", `At ${where}: go there to do it.`));
  }
  if (item.in_area) {
    // The process, not the operator, ended it: the cobot it held waits for them to be out.
    article.append(element("p", "in-area", "Cancelled. A cobot stays paused until you have left the shared area."));
  }
  for (const timer of timersOf(state, item.case)) article.append(element("p", "timer", waitingLine(timer)));
  if (item.instructions) article.append(element("p", "instructions", item.instructions));
  const work = cobotWork(state, item);
  if (work.length) {
    const list = element("ul", "with-cobots");
    list.append(...work.map((line) => element("li", "", line)));
    article.append(list);
  }
  const actions = element("div", "card-actions");
  const action = nextAction(state, item);
  if (action) actions.append(actionButton(item, action, `action ${action === "complete" || action === "left-area" ? "primary" : ""}`));
  if (mayGiveBack(state, item)) actions.append(actionButton(item, "unclaim", "give-back"));
  if (actions.childElementCount) article.append(actions);
  return article;
}

function actionButton(item: WorkItemData, action: string, className: string): HTMLButtonElement {
  const button = element("button", className, label(action));
  button.type = "button";
  button.dataset.action = action;
  button.dataset.item = String(item.id);
  return button;
}

function label(action: string): string {
  const labels: Record<string, string> = {
    claim: "Claim",
    start: "Start",
    complete: "Complete…",
    unclaim: "Give back",
    "left-area": "I have left the area",
  };
  return labels[action] ?? action;
}

function renderCobots(state: LiveState): void {
  const cobots = [...state.cobots.values()].sort((a, b) => a.name.localeCompare(b.name));
  const container = $(".cobots");
  if (!cobots.length) {
    container.replaceChildren(element("p", "empty", "No cobots in this cell."));
    return;
  }
  container.replaceChildren(...cobots.map(cobotPanel));
}

function cobotPanel(cobot: CobotData): HTMLElement {
  const panel = element("section", "cobot");
  panel.dataset.cobot = String(cobot.id);
  const state = cobot.state;
  panel.classList.toggle("stopped", cobot.stopped);
  panel.classList.toggle("unsafe", !!state && !["SAFETY_MODE_NORMAL", "SAFETY_MODE_REDUCED"].includes(state.safety_mode));
  panel.append(element("h3", "", cobot.name), element("p", "doing", activity(cobot)));
  const facts = element("dl", "facts");
  const rows: Array<[string, string]> = [
    ["Mode", state ? state.robot_mode : "unknown"],
    ["Safety", state ? humanSafety(state.safety_mode) : "unknown"],
    ["Program", state ? `${programName(state.program) || "none"} · ${state.program_state}` : "unknown"],
    ["Step", cobot.queue.current ? `${cobot.queue.current.step ?? "device call"} · case ${cobot.queue.current.case}` : "none"],
    ["Queue", String(cobot.queue.queue_length)],
  ];
  for (const [term, value] of rows) {
    facts.append(element("dt", "", term), element("dd", term.toLowerCase(), value));
  }
  panel.append(facts);
  if (state) {
    const joints = element("div", "joints");
    degrees(state.joints).forEach((value, index) => {
      const joint = element("div", "joint");
      const bar = element("span", "bar");
      bar.style.width = `${Math.min(100, (Math.abs(value) / 360) * 100)}%`;
      joint.append(element("span", "name", `J${index + 1}`), bar, element("span", "value", `${value}°`));
      joints.append(joint);
    });
    panel.append(joints);
  }
  return panel;
}

/** "pick" for "/programs/pick.urp": the name people gave it. */
function programName(path: string): string {
  return path.replace(/\\/g, "/").split("/").pop()!.replace(/\.urp$/i, "");
}

function renderStop(state: LiveState): void {
  const banner = $(".stop-banner");
  const resume = $<HTMLButtonElement>(".resume");
  const stop = state.stop;
  root.classList.toggle("stopped", stop !== null);
  banner.hidden = resume.hidden = stop === null;
  const stopButton = root.querySelector<HTMLButtonElement>(".stop");
  if (stopButton) stopButton.disabled = stop !== null; // the whole floor's tablet has none
  if (stop) {
    const problems = Object.values(stop.problems);
    banner.textContent =
      `STOPPED by ${stop.stopped_by} at ${new Date(stop.stopped_at).toLocaleTimeString()}` +
      (problems.length ? ` — ${problems.join("; ")}` : "");
  }
}

function collectMessages(): void {
  const state = store.state;
  if (state) messages = withDisplayMessages(messages, state.cobots.values(), MAX_MESSAGES);
}

function renderMessages(): void {
  const list = $(".messages");
  if (!messages.length) {
    list.replaceChildren(element("li", "empty", "No messages from the cobots' displays."));
    return;
  }
  list.replaceChildren(
    ...messages.map((message) => {
      const item = element("li", "message");
      item.append(
        element("time", "", new Date(message.at * 1000).toLocaleTimeString()),
        element("strong", "", message.name),
        element("span", "text", message.text),
      );
      return item;
    }),
  );
}

// Actions -----------------------------------------------------------------------------------

root.addEventListener("click", (event) => {
  const button = (event.target as HTMLElement).closest<HTMLButtonElement>("button[data-action]");
  if (!button) return;
  const id = Number(button.dataset.item);
  const action = button.dataset.action!;
  if (action === "complete") void openForm(id);
  else void act(button, `/api/work-items/${id}/${action}/`);
});

async function act(button: HTMLButtonElement, url: string, body?: unknown): Promise<boolean> {
  button.disabled = true;
  try {
    await request("POST", url, body ?? {});
    return true;
  } catch (error) {
    flash(problemOf(error));
    return false;
  } finally {
    button.disabled = false;
  }
}

async function openForm(id: number): Promise<void> {
  const dialog = $<HTMLDialogElement>(".form-dialog");
  let detail: { label: string; instructions: string; form: FormSchema | null };
  try {
    detail = await request("GET", `/api/work-items/${id}/`);
  } catch (error) {
    flash(problemOf(error));
    return;
  }
  const form = element("form", "task-form");
  form.method = "dialog";
  form.noValidate = true; // the server checks the form and names each field it refuses
  const fields = element("div", "fields");
  const answers = buildForm(fields, detail.form);
  const error = element("p", "errors");
  error.setAttribute("role", "alert");
  const cancel = element("button", "", "Cancel");
  cancel.type = "button";
  cancel.addEventListener("click", () => dialog.close());
  const submit = element("button", "primary", "Complete");
  submit.type = "submit";
  const actions = element("div", "actions");
  actions.append(cancel, submit);
  form.append(element("h2", "", detail.label), element("p", "instructions", detail.instructions), fields, error, actions);
  const complete = async (): Promise<void> => {
    error.textContent = "";
    // Required answers are asked for here, at their fields; the server refuses them too.
    if (!answers.check()) {
      error.textContent = "Answer the questions marked above.";
      return;
    }
    submit.disabled = true;
    try {
      await request("POST", `/api/work-items/${id}/complete/`, { data: answers.values() });
      dialog.close();
    } catch (failure) {
      if (failure instanceof ApiError && Object.keys(failure.fields).length) {
        const rest = answers.showErrors(failure.fields);
        error.textContent = rest.length ? rest.join(" ") : "Correct the answers marked above.";
      } else {
        error.textContent = problemOf(failure);
      }
    } finally {
      submit.disabled = false;
    }
  };
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    void complete();
  });
  dialog.replaceChildren(form);
  dialog.showModal();
}

root.querySelector(".stop")?.addEventListener("click", () => {
  void act($(".stop"), "/api/cells/stop/", { organisation: config.organisation, cell: config.cell });
});

$(".resume").addEventListener("click", () => $<HTMLDialogElement>(".confirm-dialog").showModal());
$<HTMLDialogElement>(".confirm-dialog").addEventListener("close", () => {
  const dialog = $<HTMLDialogElement>(".confirm-dialog");
  if (dialog.returnValue === "resume") {
    void act($(".resume"), "/api/cells/resume/", {
      organisation: config.organisation,
      cell: config.cell,
      confirm: true,
    });
  }
  dialog.returnValue = "";
});

function flash(text: string): void {
  const connection = $(".connection");
  const note = element("span", "flash", text);
  note.setAttribute("role", "alert");
  connection.after(note);
  setTimeout(() => note.remove(), 6000);
}

// For the browser tests and a curious engineer's console.
(window as unknown as { hrcTablet: unknown }).hrcTablet = { store, socket };
socket.start();
