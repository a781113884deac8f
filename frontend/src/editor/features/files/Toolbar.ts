/** The toolbar above the canvas: name, undo/redo, save, publish, import, export, layout, token game, predict. */

import type CommandStack from "diagram-js/lib/command/CommandStack";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Canvas from "diagram-js/lib/core/Canvas";

import type AutoLayout from "../layout/AutoLayout";
import type PredictPanel from "../prediction/PredictPanel";
import type TokenGameMode from "../token-game/TokenGameMode";
import type PatternFiles from "./PatternFiles";
import type { ExportFormat, FilesMessage } from "./PatternFiles";

export default class Toolbar {
  static $inject = ["eventBus", "config.shell", "patternFiles", "commandStack", "autoLayout", "tokenGame", "config.pattern", "canvas", "predictPanel"];

  constructor(
    eventBus: EventBus,
    shell: { toolbar: HTMLElement },
    files: PatternFiles,
    commandStack: CommandStack,
    autoLayout: AutoLayout,
    tokenGame: TokenGameMode,
    pattern: { canWrite: boolean },
    canvas: Canvas,
    predictPanel: PredictPanel,
  ) {
    const bar = shell.toolbar;
    const name = document.createElement("input");
    name.className = "hrc-name";
    name.setAttribute("aria-label", "Pattern name");
    name.addEventListener("change", () => {
      try {
        files.rename(name.value);
      } catch (error) {
        show({ text: (error as Error).message, kind: "error" });
      }
    });
    name.addEventListener("input", () => fitToText(name));
    // Enter keeps the name and goes back to drawing.
    name.addEventListener("keydown", (event) => {
      if (event.key === "Enter") canvas.focus();
    });
    bar.appendChild(name);
    const button = (text: string, title: string, run: () => unknown) => {
      const node = document.createElement("button");
      node.type = "button";
      node.textContent = text;
      node.title = title;
      node.addEventListener("click", () => {
        void run();
        // Back to the drawing, so its keys (Ctrl+Z, Delete, A…) work right after.
        canvas.focus();
      });
      bar.appendChild(node);
      return node;
    };
    const undo = button("Undo", "Undo (Ctrl+Z)", () => commandStack.undo());
    const redo = button("Redo", "Redo (Ctrl+Y)", () => commandStack.redo());
    const save = button("Save", "Save the draft", () => files.save());
    const publish = button("Publish", "Publish the draft as a new version", () => files.publish());
    publish.classList.add("primary");
    button("Show all", "Fit the whole drawing into view", () => eventBus.fire("editor.fit", {}));
    button("Layout", "Lay the model out in its actor lanes", () => autoLayout.layout().catch((error: Error) => show({ text: `Layout failed: ${error.message}`, kind: "error" })));
    button("Token game", "Play the model: fire tasks by click", () => tokenGame.start().catch((error: Error) => show({ text: `The token game could not start: ${error.message}`, kind: "error" })));
    // Opens a panel and moves the focus into it, so not back to the drawing as the others do.
    const predict = document.createElement("button");
    predict.type = "button";
    predict.textContent = "Predict";
    predict.title = "Predict cycle time, utilisation and the bottleneck by simulating many cases";
    predict.setAttribute("aria-controls", predictPanel.section.id);
    predict.setAttribute("aria-expanded", "false");
    predict.addEventListener("click", () => predictPanel.toggle());
    eventBus.on("prediction.toggled", (event: { open: boolean }) => predict.setAttribute("aria-expanded", String(event.open)));
    bar.appendChild(predict);

    const importLabel = document.createElement("label");
    importLabel.className = "button hrc-import";
    importLabel.textContent = "Import…";
    const picker = document.createElement("input");
    picker.type = "file";
    picker.accept = ".json,.pnml,.xml,.bpmn";
    picker.setAttribute("aria-label", "Import a file");
    picker.addEventListener("change", () => {
      const file = picker.files?.[0];
      picker.value = "";
      if (file) void files.importFile(file);
    });
    importLabel.appendChild(picker);
    bar.appendChild(importLabel);

    const exporter = document.createElement("select");
    exporter.setAttribute("aria-label", "Export");
    for (const [value, text] of [["", "Export…"], ["json", "hrc-pattern/1 (.json)"], ["pnml", "PNML (.pnml)"], ["bpmn", "BPMN 2.0 (.bpmn)"]]) {
      const option = document.createElement("option");
      option.value = value;
      option.textContent = text;
      exporter.appendChild(option);
    }
    exporter.addEventListener("change", () => {
      const format = exporter.value as ExportFormat;
      exporter.value = "";
      if (format) void files.exportAs(format);
    });
    bar.appendChild(exporter);

    const status = document.createElement("output");
    status.className = "hrc-status";
    status.setAttribute("role", "status");
    bar.appendChild(status);
    const show = (message: FilesMessage) => {
      if (message.href) {
        const link = document.createElement("a");
        link.href = message.href;
        link.textContent = message.text;
        status.replaceChildren(link);
      } else status.textContent = message.text;
      status.dataset.kind = message.kind;
      status.setAttribute("role", message.kind === "error" ? "alert" : "status");
    };
    eventBus.on("files.message", show);
    eventBus.on(["files.changed", "commandStack.changed", "import.done"], () => {
      name.value = files.name;
      fitToText(name);
      undo.disabled = !commandStack.canUndo();
      redo.disabled = !commandStack.canRedo();
      save.disabled = !pattern.canWrite || files.busy;
      publish.disabled = !pattern.canWrite || files.busy;
      bar.dataset.dirty = String(files.dirty);
    });
    window.addEventListener("beforeunload", (event) => {
      if (files.dirty) event.preventDefault();
    });
  }
}

const measure = document.createElement("canvas").getContext("2d");

/** Widens the name field to its whole text (the toolbar's width at most, by CSS), so no name is cut off. */
function fitToText(input: HTMLInputElement): void {
  if (!measure) return;
  const style = getComputedStyle(input);
  measure.font = style.font;
  const text = measure.measureText(input.value || input.placeholder).width;
  const frame = ["paddingLeft", "paddingRight", "borderLeftWidth", "borderRightWidth"].reduce((sum, key) => sum + (parseFloat(style[key as "paddingLeft"]) || 0), 0);
  input.style.width = `${Math.max(208, Math.ceil(text + frame + 8))}px`;
}
