// The cobot's change page in the site admin (templates/admin/cobots/cobot/change_form.html):
// the live state, read every two seconds from the URL in the box's data-url.

import { getJson } from "../shared/http";

const REFRESH_MS = 2000;

function show(box: HTMLElement, state: Record<string, unknown>): void {
  box.replaceChildren();
  for (const [key, value] of Object.entries(state)) {
    const term = document.createElement("dt");
    term.textContent = key;
    const detail = document.createElement("dd");
    detail.textContent = String(value);
    box.append(term, detail);
  }
}

async function refresh(box: HTMLElement): Promise<void> {
  try {
    show(box, await getJson<Record<string, unknown>>(box.dataset.url ?? ""));
  } catch {
    show(box, { reachable: false, error: "the server did not answer" });
  }
  setTimeout(() => void refresh(box), REFRESH_MS);
}

const box = document.getElementById("cobot-live-state");
if (box) void refresh(box);
