/**
 * The editor page's entry point (static hrc/editor.js): reads the page's
 * configuration, builds the editor into #hrc-editor and opens the draft.
 */

import "diagram-js/assets/diagram-js.css";
import "./editor.css";

import { addElement, pageConfig } from "../shared/dom";
import { Api } from "./api";
import { PatternEditor } from "./editor";
import { emptyDocument, readDocument, DocumentError } from "./model/document";

export interface PageConfig {
  pattern: { id: number | null; name: string; canWrite: boolean; organisation?: number };
  api?: string;
  draft?: unknown;
  liveChecking?: boolean;
  /** The engine's device calls and their arguments (hrc/engine/taskconfig.py). */
  deviceCalls?: Record<string, string[]>;
}

export async function mount(root: HTMLElement, config: PageConfig): Promise<PatternEditor> {
  root.classList.add("hrc-editor");
  const toolbar = addElement(root, "div", "hrc-toolbar");
  toolbar.setAttribute("role", "toolbar");
  toolbar.setAttribute("aria-label", "Pattern");
  const body = addElement(root, "div", "hrc-body");
  const canvas = addElement(body, "div", "hrc-canvas");
  const side = addElement(body, "aside", "hrc-side");
  const editor = new PatternEditor({ canvas, toolbar, side, api: new Api(config.api ?? "/api"), pattern: config.pattern, liveChecking: config.liveChecking, deviceCalls: config.deviceCalls });
  const notice = addElement(root, "p", "hrc-notice");
  notice.setAttribute("role", "alert");
  try {
    const document = config.draft === undefined || config.draft === null ? emptyDocument(config.pattern.name) : readDocument(config.draft);
    const dropped = await editor.open(document);
    if (dropped.length) notice.textContent = `Left out because an end does not exist: ${dropped.join("; ")}.`;
  } catch (error) {
    const message = error instanceof DocumentError ? error.issues.map((issue) => issue.message).join(" ") : (error as Error).message;
    notice.textContent = `The draft could not be opened: ${message}`;
  }
  root.dataset.ready = "true";
  return editor;
}

const root = document.getElementById("hrc-editor");
const config = pageConfig<PageConfig>("hrc-editor-config");
if (root && config) {
  void mount(root, config).then((editor) => {
    // The browser tests and the bench reach the editor through the page.
    (window as unknown as { hrcEditor: PatternEditor }).hrcEditor = editor;
  });
}
