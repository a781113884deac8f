// The one HTTP client of every page: the session's cookie and CSRF token, JSON in and out, and
// the API's refusals (hrc/api/exceptions.py: {"detail": str, "fields"?: {...}}) as one ApiError.

export type FieldErrors = Record<string, string[] | string>;

export type Method = "GET" | "POST" | "PUT" | "PATCH" | "DELETE";

const JSON_TYPE = "application/json";

/** A request the server refused (its status), or one that never reached it (status 0). */
export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    /** The messages by field of a refused form (`fields` of a 400), when the server gave them. */
    readonly fields: FieldErrors = {},
    /** The refusal's JSON body as the server sent it; null when it sent none, or not JSON. */
    readonly body: unknown = null,
  ) {
    super(message);
    this.name = "ApiError";
  }
}

/**
 * The token Django's CsrfViewMiddleware wants back in X-CSRFToken: the csrftoken cookie (always
 * the current one), else the page's <meta name="csrf-token">; "" when the page has neither.
 */
export function csrfToken(): string {
  const match = /(?:^|;\s*)csrftoken=([^;]+)/.exec(document.cookie);
  if (match) return decodeURIComponent(match[1]);
  return document.querySelector<HTMLMetaElement>('meta[name="csrf-token"]')?.content ?? "";
}

/**
 * One readable text from a refusal's body: its detail, then the messages of its `errors` and
 * its field errors that the detail does not already say (DRF's bare field errors too).
 */
export function refusalMessage(status: number, body: unknown): string {
  const fallback = status === 0 ? "The server cannot be reached." : `The server answered ${status}.`;
  if (!isRecord(body)) return fallback;
  const parts: string[] = [];
  const say = (text: string): void => {
    if (text && !parts.some((part) => part.includes(text))) parts.push(text);
  };
  if (typeof body.detail === "string") say(body.detail);
  for (const issue of Array.isArray(body.errors) ? body.errors : []) {
    if (isRecord(issue) && typeof issue.message === "string") say(issue.message);
  }
  for (const [field, messages] of Object.entries(fieldsOf(body))) {
    say(`${field}: ${Array.isArray(messages) ? messages.join(" ") : messages}`);
  }
  return parts.join(" ") || fallback;
}

/** What to show for a failed request: the server's refusal, or the error itself. */
export function problemOf(error: unknown): string {
  return error instanceof ApiError ? error.message : String(error);
}

/**
 * Sends a request and answers its JSON body (null for an empty one). A string body goes as
 * the text it is, typed `contentType` (a file to import); any other body as JSON.
 * Throws ApiError when the server refuses or cannot be reached.
 */
export async function request<T>(method: Method, url: string, body?: unknown, contentType = JSON_TYPE): Promise<T> {
  const headers: Record<string, string> = { Accept: JSON_TYPE };
  if (method !== "GET") headers["X-CSRFToken"] = csrfToken();
  if (body !== undefined) headers["Content-Type"] = contentType;
  const payload = body === undefined ? undefined : typeof body === "string" ? body : JSON.stringify(body);
  let response: Response;
  try {
    response = await fetch(url, { method, headers, credentials: "same-origin", body: payload });
  } catch {
    throw new ApiError(0, refusalMessage(0, null));
  }
  const data = parsed(await response.text());
  if (!response.ok) {
    const refusal = isRecord(data) ? data : null;
    throw new ApiError(response.status, refusalMessage(response.status, refusal), refusal ? fieldsOf(refusal) : {}, refusal);
  }
  // A 200 page of HTML (the sign-in page after the session ended) is no answer to trust.
  if (data === NOT_JSON) throw new ApiError(response.status, `The server answered ${response.status} without JSON.`);
  return data as T;
}

export function getJson<T>(url: string): Promise<T> {
  return request<T>("GET", url);
}

export function postJson<T>(url: string, body: unknown): Promise<T> {
  return request<T>("POST", url, body);
}

const NOT_JSON = Symbol("not JSON");

/** The body's JSON: null for an empty body, NOT_JSON for one that is not JSON (a proxy's error page). */
function parsed(text: string): unknown {
  if (!text) return null;
  try {
    return JSON.parse(text) as unknown;
  } catch {
    return NOT_JSON;
  }
}

/** The field errors of a refusal: under `fields`, or DRF's bare `{"name": [...]}` without a detail. */
function fieldsOf(body: Record<string, unknown>): FieldErrors {
  const source = isRecord(body.fields) ? body.fields : "detail" in body ? {} : body;
  const fields: FieldErrors = {};
  for (const [field, messages] of Object.entries(source)) {
    if (typeof messages === "string" || (Array.isArray(messages) && messages.every((m) => typeof m === "string"))) {
      fields[field] = messages;
    }
  }
  return fields;
}

function isRecord(value: unknown): value is Record<string, unknown> {
  return typeof value === "object" && value !== null && !Array.isArray(value);
}
