/**
 * A file picked for import, looked at before it is sent: JSON must be an
 * hrc-pattern/1 document in shape, XML must be well formed with a PNML or BPMN
 * root. Each refusal names where the problem is; nothing is changed by a
 * refused file. The server converts PNML and BPMN and has the final word.
 */

import { DocumentError, parseDocument } from "./document";

export type FileFormat = "json" | "pnml" | "bpmn";

export interface InspectedFile {
  format: FileFormat;
  /** The text to send: the JSON as read, or the XML unchanged. */
  body: string;
  contentType: string;
}

const BPMN_NAMESPACE = "http://www.omg.org/spec/BPMN/20100524/MODEL";

export function inspectFile(name: string, text: string): InspectedFile {
  const trimmed = text.trimStart();
  if (trimmed.startsWith("{") || /\.json$/i.test(name)) {
    const document = parseDocument(text);
    return { format: "json", body: JSON.stringify(document), contentType: "application/json" };
  }
  if (!trimmed.startsWith("<")) {
    throw refusal(`${name} is neither JSON nor XML: import an hrc-pattern/1 (.json), PNML (.pnml) or BPMN 2.0 (.bpmn) file.`);
  }
  const xml = new DOMParser().parseFromString(text, "application/xml");
  const broken = xml.getElementsByTagName("parsererror")[0];
  if (broken) throw refusal(`${name} is not well-formed XML: ${describeParserError(broken.textContent ?? "", text)}`);
  const root = xml.documentElement;
  if (root.localName === "pnml") return { format: "pnml", body: text, contentType: "application/xml" };
  if (root.localName === "definitions" && root.namespaceURI === BPMN_NAMESPACE) {
    return { format: "bpmn", body: text, contentType: "application/xml" };
  }
  throw refusal(
    `${name} starts with the element <${root.tagName}>: a PNML file starts with <pnml>, a BPMN 2.0 file with <definitions> in the namespace ${BPMN_NAMESPACE}.`,
  );
}

function refusal(message: string): DocumentError {
  return new DocumentError([{ message, elements: [] }]);
}

/** The parser's complaint in one line (Chromium, Firefox and jsdom word it differently), with the element it was in. */
export function describeParserError(report: string, text: string): string {
  const forms = [
    /error on line (\d+) at column (\d+):\s*([^\n]*)/i,
    /^(\d+):(\d+):\s*([^\n]*)/,
    /Line Number (\d+), Column (\d+):\s*([^\n]*)/i,
  ];
  for (const form of forms) {
    const match = form.exec(report.trim());
    if (!match) continue;
    const [line, column] = [Number(match[1]), Number(match[2])];
    const element = openElementNear(text, line, column);
    const detail = match[3].trim().replace(/\.$/, "");
    return `${detail} at line ${line}, column ${column}${element ? `, inside <${element}>` : ""}.`;
  }
  return report.trim().split("\n")[0] || "the parser gave no reason.";
}

/** The innermost element still open at a position: where a person looks for the mistake. */
export function openElementNear(text: string, line: number, column: number): string | null {
  const lines = text.split("\n");
  const upTo = lines.slice(0, line - 1).join("\n").length + (line > 1 ? 1 : 0) + Math.max(0, column - 1);
  const open: string[] = [];
  for (const match of text.slice(0, upTo).matchAll(/<(\/?)([A-Za-z_][\w.:-]*)[^>]*?(\/?)>/g)) {
    if (match[1]) {
      const index = open.lastIndexOf(match[2]);
      if (index >= 0) open.length = index;
    } else if (!match[3]) open.push(match[2]);
  }
  return open.length ? open[open.length - 1] : null;
}
