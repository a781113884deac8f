/**
 * The server, as the editor uses it: drafts, checks, layout, the execution
 * net, predictions, publishing, import and export (hrc/patterns/api), through
 * the pages' one HTTP client (shared/http.ts).
 */

import { request, type Method } from "../shared/http";
import type { PatternDocument } from "./model/document";
import type { PredictionAnswer, PredictOptions } from "./model/prediction";

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

/** A published version as the versions' list gives it (hrc/patterns/api/serializers.py). */
export interface VersionSummary {
  id: number;
  pattern: number;
  number: number;
  published_at: string;
  retired_at: string | null;
}

export interface PredictRequest {
  document: PatternDocument;
  pattern?: number;
  compare_version?: number;
  options?: PredictOptions;
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

  /** Simulates many cases of the draft; with `compare_version`, that version too, with the same options. */
  predict(body: PredictRequest): Promise<PredictionAnswer> {
    return this.request("POST", "/patterns/predict/", body);
  }

  /** The pattern's published versions, the newest first. */
  async versions(pattern: number): Promise<VersionSummary[]> {
    const page = await this.request<{ results: VersionSummary[] }>("GET", `/pattern-versions/?pattern=${pattern}&limit=1000`);
    return page.results;
  }

  /** Creates a pattern from a file's text; the server converts PNML and BPMN. */
  importFile(format: string, body: string, contentType: string, organisation?: number): Promise<PatternRecord> {
    const into = organisation === undefined ? "" : `&organisation=${organisation}`;
    return this.request("POST", `/patterns/import/?format=${encodeURIComponent(format)}${into}`, body, contentType);
  }

  exportUrl(id: number, format: string): string {
    return `${this.base}/patterns/${id}/export/?format=${encodeURIComponent(format)}`;
  }

  private request<T>(method: Method, path: string, body?: unknown, contentType?: string): Promise<T> {
    return request<T>(method, `${this.base}${path}`, body, contentType);
  }
}
