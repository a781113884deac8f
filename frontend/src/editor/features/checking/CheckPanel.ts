/**
 * What the check says, in words: the pattern class as a badge in the toolbar,
 * and the list of errors and warnings beside the canvas. Clicking an issue
 * selects its elements; an issue with a firing sequence can be played back.
 */

import type EventBus from "diagram-js/lib/core/EventBus";
import type ElementRegistry from "diagram-js/lib/core/ElementRegistry";
import type Selection from "diagram-js/lib/features/selection/Selection";
import type Canvas from "diagram-js/lib/core/Canvas";

import type { CheckIssue, CheckReport } from "../../api";
import type TokenGameMode from "../token-game/TokenGameMode";
import { listOfNames } from "../../model/words";

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
    this.badge = element("output", "hrc-pattern-badge", shell.toolbar);
    this.badge.setAttribute("aria-label", "Pattern class");
    this.badge.setAttribute("aria-live", "polite");
    const section = element("section", "hrc-check", shell.side);
    section.setAttribute("aria-label", "Check");
    element("h2", "", section).textContent = "Check";
    this.list = element("div", "hrc-issues", section);
    this.badge.textContent = "Not checked yet";
    eventBus.on("check.pending", () => this.badge.classList.add("hrc-pending"));
    eventBus.on("check.report", (event: { report: CheckReport }) => this.show(event.report));
    eventBus.on("check.failed", (event: { message: string }) => {
      this.badge.classList.remove("hrc-pending");
      this.badge.textContent = "Check failed";
      this.list.replaceChildren(paragraph(`The server could not check the model: ${event.message}`, "hrc-error"));
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
    this.list.replaceChildren(paragraph(summary, report.valid ? "hrc-ok" : "hrc-error"), ...items);
  }

  private nameOf(id: string): string {
    return this.tokenGame.nameOf(id);
  }

  private item(issue: CheckIssue, severity: "error" | "warning"): HTMLElement {
    const item = document.createElement("article");
    item.className = `hrc-issue hrc-${severity}`;
    item.dataset.code = issue.code;
    const text = element("p", "", item);
    text.textContent = issue.message;
    const known = issue.elements.filter((id) => this.elementRegistry.get(id));
    if (known.length) {
      const show = button(`Show ${listOfNames(known, (id) => this.nameOf(id))}`, item);
      show.title = `Select ${listOfNames(known, (id) => this.nameOf(id), known.length)} in the drawing`;
      show.addEventListener("click", () => {
        const elements = known.map((id) => this.elementRegistry.get(id)).filter((e) => e !== undefined);
        this.selection.select(elements);
        this.canvas.scrollToElement(elements[0] as never);
      });
    }
    if (issue.witness) {
      const play = button("Play the witness", item);
      play.classList.add("hrc-play-witness");
      const steps = element("ol", "hrc-witness-steps", item);
      for (const label of issue.witness) {
        const step = element("li", "", steps);
        step.textContent = this.tokenGame.stepWords(label);
        step.dataset.firing = label;
      }
      play.addEventListener("click", () => void this.tokenGame.replay(issue.witness as string[], issue.elements));
    }
    return item;
  }
}

function element(tag: string, className: string, parent: HTMLElement): HTMLElement {
  const node = document.createElement(tag);
  if (className) node.className = className;
  parent.appendChild(node);
  return node;
}

function button(text: string, parent: HTMLElement): HTMLButtonElement {
  const node = document.createElement("button");
  node.type = "button";
  node.textContent = text;
  parent.appendChild(node);
  return node;
}

function paragraph(text: string, className: string): HTMLElement {
  const node = document.createElement("p");
  node.className = className;
  node.textContent = text;
  return node;
}
