/**
 * Live checking: a moment after the model stops changing, the server's engine
 * checks it (POST /api/patterns/check-document/); the answer is published on
 * the event bus as `check.report`. An answer to an older model is dropped.
 */

import type EventBus from "diagram-js/lib/core/EventBus";

import type { Api, CheckReport } from "../../api";
import type PatternImporter from "../../core/PatternImporter";

export const CHECK_DELAY_MS = 600;

export default class LiveChecker {
  static $inject = ["eventBus", "config.api", "patternImporter", "config.liveChecking"];

  report: CheckReport | null = null;
  private timer: ReturnType<typeof setTimeout> | undefined;
  private generation = 0;

  constructor(
    private readonly eventBus: EventBus,
    private readonly api: Api,
    private readonly importer: PatternImporter,
    enabled: boolean,
  ) {
    if (enabled === false) return;
    eventBus.on(["commandStack.changed", "import.done"], () => this.schedule());
  }

  schedule(): void {
    clearTimeout(this.timer);
    this.generation += 1;
    this.eventBus.fire("check.pending", {});
    this.timer = setTimeout(() => void this.check(), CHECK_DELAY_MS);
  }

  async check(): Promise<void> {
    const generation = this.generation;
    try {
      const report = await this.api.checkDocument(this.importer.document());
      if (generation !== this.generation) return;
      this.report = report;
      this.eventBus.fire("check.report", { report });
    } catch (error) {
      if (generation !== this.generation) return;
      this.eventBus.fire("check.failed", { message: (error as Error).message });
    }
  }
}
