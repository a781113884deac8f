// The few REST calls the tablet makes, with the session's CSRF token; a refusal's `detail` is the error.

export class ApiError extends Error {
  constructor(
    message: string,
    readonly status: number,
    /** The messages by field of a refused form (`fields` of a 400), when the server gave them. */
    readonly fields: Record<string, string[] | string> = {},
  ) {
    super(message);
  }
}

function csrfToken(): string {
  const match = document.cookie.match(/(?:^|;\s*)csrftoken=([^;]+)/);
  return match ? decodeURIComponent(match[1]) : "";
}

export async function request<T>(method: string, url: string, body?: unknown): Promise<T> {
  const response = await fetch(url, {
    method,
    credentials: "same-origin",
    headers: {
      Accept: "application/json",
      ...(body === undefined ? {} : { "Content-Type": "application/json" }),
      ...(method === "GET" ? {} : { "X-CSRFToken": csrfToken() }),
    },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  const data = (await response.json().catch(() => ({}))) as { detail?: string; fields?: Record<string, string[] | string> };
  if (!response.ok) {
    throw new ApiError(data.detail ?? `The server answered ${response.status}.`, response.status, data.fields ?? {});
  }
  return data as T;
}
