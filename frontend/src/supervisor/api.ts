// The REST API as the supervisor pages read it (hrc/cases/api/serializers.py), and the
// requests they make: session cookie and CSRF token, as any form of the site.

export type Marking = Record<string, number>;

export interface JobJson {
  cobot_name: string;
  state: string;
  queue_position: number | null;
  waiting_for: string;
  attempt: number;
  last_error: string;
}

export interface WorkItemJson {
  id: number;
  task: string;
  label: string;
  actor: string;
  kind: string;
  state: string;
  claimed_by: string | null;
  job: JobJson | null;
}

export interface IncidentJson {
  id: number;
  case: number;
  work_item: number | null;
  task: string | null;
  kind: string;
  message: string;
  cobot_state: unknown;
  opened_at: string;
  resolved_at: string | null;
  resolution: string;
  resolved_by: string | null;
}

export interface CaseJson {
  id: number;
  status: string;
  marking: Marking;
  data: Record<string, unknown>;
  last_seq: number;
  ended_at: string | null;
  work_items: WorkItemJson[];
  incidents: IncidentJson[];
}

export interface EventJson {
  seq: number;
  at: string;
  type: string;
  task: string;
  actor: string;
  user: string | null;
  marking_before: Marking;
  marking_after: Marking;
  detail: Record<string, unknown>;
}

export interface PageJson<T> {
  count: number;
  next: string | null;
  results: T[];
}

/** A request the server refused (4xx) or could not answer; the message is the page's to show. */
export class Refusal extends Error {
  constructor(
    readonly status: number,
    message: string,
  ) {
    super(message);
  }
}

/** What to show for a failed request: the server's refusal, or the error itself. */
export function problemOf(error: unknown): string {
  return error instanceof Refusal ? error.message : String(error);
}

/** What the API says went wrong: its `detail` (every refusal has one), else the status. */
export function refusalMessage(status: number, body: unknown): string {
  if (body && typeof body === "object" && "detail" in body) {
    const detail = (body as { detail: unknown }).detail;
    if (typeof detail === "string" && detail) return detail;
  }
  if (status === 0) return "The server cannot be reached.";
  return `The server answered ${status}.`;
}

async function answer<T>(response: Response): Promise<T> {
  let body: unknown = null;
  try {
    body = await response.json();
  } catch {
    body = null; // an HTML error page: the status says enough
  }
  if (!response.ok) throw new Refusal(response.status, refusalMessage(response.status, body));
  return body as T;
}

async function send(url: string, init: RequestInit): Promise<Response> {
  try {
    return await fetch(url, { credentials: "same-origin", ...init });
  } catch {
    throw new Refusal(0, refusalMessage(0, null));
  }
}

export async function getJson<T>(url: string): Promise<T> {
  return answer<T>(await send(url, { headers: { Accept: "application/json" } }));
}

export async function postJson<T>(url: string, body: unknown, csrfToken: string): Promise<T> {
  const response = await send(url, {
    method: "POST",
    headers: {
      Accept: "application/json",
      "Content-Type": "application/json",
      "X-CSRFToken": csrfToken,
    },
    body: JSON.stringify(body),
  });
  return answer<T>(response);
}
