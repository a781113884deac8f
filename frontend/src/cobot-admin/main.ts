// The cobot's change page in the site admin (templates/admin/cobots/cobot/change_form.html):
// the live state, read every two seconds from the URL in the box's data-url.

import { element } from "../shared/dom";
import { getJson } from "../shared/http";

const REFRESH_MS = 2000;

function show(box: HTMLElement, state: Record<string, unknown>): void {
  box.replaceChildren(...Object.entries(state).flatMap(([key, value]) => [element("dt", "", key), element("dd", "", String(value))]));
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
