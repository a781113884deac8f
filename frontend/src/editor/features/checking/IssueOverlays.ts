/**
 * The check's errors and warnings on the elements they name (see targets.ts):
 * a marker on the element and a badge whose tooltip is the message.
 */

import type Canvas from "diagram-js/lib/core/Canvas";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Overlays from "diagram-js/lib/features/overlays/Overlays";

import type { CheckIssue, CheckReport } from "../../api";
import { issueTargets } from "./targets";

const TYPE = "hrc-issue";

export default class IssueOverlays {
  static $inject = ["eventBus", "overlays", "elementRegistry", "canvas"];

  private marked: [string, string][] = [];

  constructor(
    eventBus: EventBus,
    private readonly overlays: Overlays,
    private readonly elementRegistry: ElementRegistry,
    private readonly canvas: Canvas,
  ) {
    eventBus.on("check.report", (event: { report: CheckReport }) => this.show(event.report));
    eventBus.on("diagram.clear", () => (this.marked = []));
  }

  show(report: CheckReport): void {
    this.clear();
    const byElement = new Map<string, { severity: "error" | "warning"; issues: CheckIssue[] }>();
    const root = this.canvas.getRootElement();
    const collect = (issues: CheckIssue[], severity: "error" | "warning") => {
      for (const issue of issues) {
        for (const { id } of issueTargets(issue, this.elementRegistry, root)) {
          const entry = byElement.get(id) ?? { severity, issues: [] };
          entry.issues.push(issue);
          byElement.set(id, entry);
        }
      }
    };
    collect(report.errors, "error");
    collect(report.warnings, "warning");
    for (const [id, { severity, issues }] of byElement) {
      const marker = `hrc-has-${severity}`;
      this.canvas.addMarker(id, marker);
      this.marked.push([id, marker]);
      const badge = document.createElement("div");
      badge.className = `hrc-issue-badge hrc-${severity}`;
      badge.dataset.element = id;
      badge.dataset.codes = issues.map((issue) => issue.code).join(" ");
      badge.title = issues.map((issue) => issue.message).join("\n\n");
      badge.textContent = severity === "error" ? "!" : "?";
      this.overlays.add(id, TYPE, { position: { top: -12, right: 10 }, html: badge });
    }
  }

  clear(): void {
    this.overlays.remove({ type: TYPE });
    for (const [id, marker] of this.marked) if (this.elementRegistry.get(id)) this.canvas.removeMarker(id, marker);
    this.marked = [];
  }
}
