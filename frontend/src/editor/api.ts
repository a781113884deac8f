/**
 * The server, as the editor uses it: drafts, checks, layout, the execution
 * net, publishing, import and export (hrc/patterns/api). Session auth: the
 * csrftoken cookie goes back as X-CSRFToken on every write.
 */

import { isObject, type PatternDocument } from "./model/document";

export interface PatternRecord {
  id: number;
  name: string;
  draft: PatternDocument;
  latest_version: number | null;
}

export interface CheckIssue {
  code: string;
  message: string;
  elements: string[];
  witness?: string[];
}

export interface CheckReport {
  valid: boolean;
  patterns: string[];
  sound: boolean | null;
  errors: CheckIssue[];
  warnings: CheckIssue[];
}

export class ApiError extends Error {
  constructor(
    readonly status: number,
    readonly body: unknown,
  ) {
    super(errorMessage(status, body));
    this.name = "ApiError";
  }
}

/** One readable sentence (or several) from the API's error format: detail, errors[], fields. */
export function errorMessage(status: number, body: unknown): string {
  if (!isObject(body)) return `The server answered ${status}.`;
  const parts: string[] = [];
  if (typeof body.detail === "string") parts.push(body.detail);
  for (const issue of Array.isArray(body.errors) ? body.errors : []) {
    if (isObject(issue) && typeof issue.message === "string" && !parts.some((part) => part.includes(issue.message as string))) parts.push(issue.message);
  }
  const fields = isObject(body.fields) ? body.fields : body;
  for (const [field, messages] of Object.entries(fields)) {
    if (["detail", "errors", "report", "fields"].includes(field)) continue;
    if (Array.isArray(messages)) parts.push(`${field}: ${messages.join(" ")}`);
  }
  return parts.join(" ") || `The server answered ${status}.`;
}

export class Api {
  constructor(private readonly base = "/api") {}

  getPattern(id: number): Promise<PatternRecord> {
    return this.request("GET", `/patterns/${id}/`);
  }

  createPattern(name: string, draft: PatternDocument, organisation?: number): Promise<PatternRecord> {
    return this.request("POST", "/patterns/", organisation === undefined ? { name, draft } : { name, draft, organisation });
  }

  savePattern(id: number, name: string, draft: PatternDocument): Promise<PatternRecord> {
    return this.request("PATCH", `/patterns/${id}/`, { name, draft });
  }

  publish(id: number): Promise<{ id: number; number: number }> {
    return this.request("POST", `/patterns/${id}/publish/`);
  }

  checkDocument(document: PatternDocument): Promise<CheckReport> {
    return this.request("POST", "/patterns/check-document/", document);
  }

  layout(document: PatternDocument): Promise<PatternDocument> {
    return this.request("POST", "/patterns/layout/", document);
  }

  executionNet(document: PatternDocument): Promise<unknown> {
    return this.request("POST", "/patterns/execution-net/", document);
  }

  /** Creates a pattern from a file's text; the server converts PNML and BPMN. */
  importFile(format: string, body: string, contentType: string, organisation?: number): Promise<PatternRecord> {
    const into = organisation === undefined ? "" : `&organisation=${organisation}`;
    return this.request("POST", `/patterns/import/?format=${encodeURIComponent(format)}${into}`, body, contentType);
  }

  exportUrl(id: number, format: string): string {
    return `${this.base}/patterns/${id}/export/?format=${encodeURIComponent(format)}`;
  }

  private async request<T>(method: string, path: string, body?: unknown, contentType = "application/json"): Promise<T> {
    const headers: Record<string, string> = { Accept: "application/json" };
    if (method !== "GET") {
      headers["X-CSRFToken"] = csrfToken();
      headers["Content-Type"] = contentType;
    }
    const response = await fetch(`${this.base}${path}`, {
      method,
      headers,
      credentials: "same-origin",
      body: body === undefined ? undefined : typeof body === "string" ? body : JSON.stringify(body),
    });
    const text = await response.text();
    let data: unknown = text;
    try {
      data = text ? JSON.parse(text) : null;
    } catch {
      // Not JSON (a proxy's error page): keep the text for the message.
    }
    if (!response.ok) throw new ApiError(response.status, isObject(data) ? data : { detail: `The server answered ${response.status}.` });
    return data as T;
  }
}

export function csrfToken(): string {
  const match = /(?:^|;\s*)csrftoken=([^;]+)/.exec(document.cookie);
  return match ? decodeURIComponent(match[1]) : "";
}
