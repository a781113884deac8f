// The REST API as the supervisor pages read it (hrc/cases/api/serializers.py); the requests
// go through the pages' one HTTP client (shared/http.ts).

export type Marking = Record<string, number>;

export interface JobJson {
  cobot_name: string | null;
  device_name: string | null;
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
