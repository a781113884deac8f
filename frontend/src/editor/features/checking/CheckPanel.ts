/**
 * What the check says, in words: the pattern class as a badge in the toolbar,
 * and the list of errors and warnings beside the canvas. Clicking an issue
 * selects its elements; an issue with a firing sequence can be played back.
 */

import type EventBus from "diagram-js/lib/core/EventBus";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type Selection from "diagram-js/lib/features/selection/Selection";
import type Canvas from "diagram-js/lib/core/Canvas";

import { addElement, element } from "../../../shared/dom";
import type { CheckIssue, CheckReport } from "../../api";
import type TokenGameMode from "../token-game/TokenGameMode";
import { listOfNames } from "../../model/words";
import { issueTargets } from "./targets";

const PATTERN_WORDS: Record<string, string> = {
  synchronized: "Synchronized",
  cooperation: "Cooperation",
  collaboration: "Collaboration",
  coexistence: "Coexistence",
};

export default class CheckPanel {
  static $inject = ["eventBus", "config.shell", "elementRegistry", "selection", "canvas", "tokenGame"];

  readonly badge: HTMLElement;
  readonly list: HTMLElement;

  constructor(
    eventBus: EventBus,
    shell: { toolbar: HTMLElement; side: HTMLElement },
    private readonly elementRegistry: ElementRegistry,
    private readonly selection: Selection,
    private readonly canvas: Canvas,
    private readonly tokenGame: TokenGameMode,
  ) {
    this.badge = addElement(shell.toolbar, "output", "hrc-pattern-badge");
    this.badge.setAttribute("aria-label", "Pattern class");
    this.badge.setAttribute("aria-live", "polite");
    const section = addElement(shell.side, "section", "hrc-check");
    section.setAttribute("aria-label", "Check");
    addElement(section, "h2", "", "Check");
    this.list = addElement(section, "div", "hrc-issues");
    this.badge.textContent = "Not checked yet";
    eventBus.on("check.pending", () => this.badge.classList.add("hrc-pending"));
    eventBus.on("check.report", (event: { report: CheckReport }) => this.show(event.report));
    eventBus.on("check.failed", (event: { message: string }) => {
      this.badge.classList.remove("hrc-pending");
      this.badge.textContent = "Check failed";
      this.list.replaceChildren(element("p", "hrc-error", `The server could not check the model: ${event.message}`));
    });
  }

  show(report: CheckReport): void {
    this.badge.classList.remove("hrc-pending");
    const words = report.patterns.map((name) => PATTERN_WORDS[name] ?? name);
    this.badge.textContent = words.length ? words.join(" · ") : "No pattern";
    this.badge.dataset.valid = String(report.valid);
    this.badge.dataset.sound = String(report.sound);
    this.badge.title = report.valid ? "Valid and sound: ready to publish." : `${report.errors.length} error(s): see the check beside the drawing.`;
    const items = [
      ...report.errors.map((issue) => this.item(issue, "error")),
      ...report.warnings.map((issue) => this.item(issue, "warning")),
    ];
    const summary = report.valid ? "No errors: the model is valid and sound." : `${report.errors.length} error${report.errors.length === 1 ? "" : "s"}.`;
    this.list.replaceChildren(element("p", report.valid ? "hrc-ok" : "hrc-error", summary), ...items);
  }

  private nameOf(id: string): string {
    return this.tokenGame.nameOf(id);
  }

  private item(issue: CheckIssue, severity: "error" | "warning"): HTMLElement {
    const item = element("article", { class: `hrc-issue hrc-${severity}`, "data-code": issue.code }, element("p", "", issue.message));
    const known = issue.elements.filter((id) => this.elementRegistry.get(id));
    const elements = issueTargets(issue, this.elementRegistry, this.canvas.getRootElement());
    if (elements.length) {
      // A process is not drawn: its issue selects its lanes.
      const show = button(known.length ? `Show ${listOfNames(known, (id) => this.nameOf(id))}` : "Show its lanes", item);
      show.title = known.length ? `Select ${listOfNames(known, (id) => this.nameOf(id), known.length)} in the drawing` : "Select the lanes of the process in the drawing";
      show.addEventListener("click", () => {
        this.selection.select(elements);
        this.canvas.scrollToElement(elements[0] as never);
      });
    }
    if (issue.witness) {
      const play = button("Play the witness", item);
      play.classList.add("hrc-play-witness");
      const steps = addElement(item, "ol", "hrc-witness-steps");
      for (const label of issue.witness) {
        addElement(steps, "li", { "data-firing": label }, this.tokenGame.stepWords(label));
      }
      play.addEventListener("click", () => void this.tokenGame.replay(issue.witness as string[], issue.elements));
    }
    return item;
  }
}

function button(text: string, parent: HTMLElement): HTMLButtonElement {
  return addElement(parent, "button", { type: "button" }, text);
}
