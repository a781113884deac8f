import { expect, test } from "vitest";

import { refusalMessage } from "../../src/shared/http";
import { DocumentError } from "../../src/editor/model/document";
import { inspectFile, openElementNear } from "../../src/editor/model/files";
import { example } from "./helpers";

function refusal(name: string, text: string): string {
  try {
    inspectFile(name, text);
  } catch (error) {
    expect(error).toBeInstanceOf(DocumentError);
    return (error as DocumentError).message;
  }
  throw new Error("the file was accepted");
}

test("an hrc-pattern/1 file is read before it is sent", () => {
  const inspected = inspectFile("assembly.json", JSON.stringify(example("synch_1o1c_assembly")));
  expect(inspected.format).toBe("json");
  expect(JSON.parse(inspected.body).name).toBe("Assembly (1 operator, 1 cobot)");
});

test("a JSON file that is not a pattern names the element", () => {
  const document = example("synch_1o1c_assembly") as unknown as Record<string, any>;
  document.processes[0].transitions[3].performer = 5;
  expect(refusal("broken.json", JSON.stringify(document))).toBe("processes[0] (N).transitions[3] (tc2).performer must be a string, got the number 5.");
  expect(refusal("broken.json", '{"format": "hrc-pattern/1",')).toBe("The file is not JSON: it ends too early, at line 1, column 28.");
});

test("malformed XML is refused with the line and the element it was in", () => {
  const pnml = '<?xml version="1.0"?>\n<pnml>\n  <net id="N">\n    <place id="p1">\n  </net>\n</pnml>';
  const message = refusal("model.pnml", pnml);
  expect(message).toMatch(/^model\.pnml is not well-formed XML: .* at line 5, column \d+, inside <place>\.$/);
});

test("XML of another kind is refused by its root element", () => {
  expect(refusal("drawing.xml", "<svg xmlns='http://www.w3.org/2000/svg'/>")).toBe(
    "drawing.xml starts with the element <svg>: a PNML file starts with <pnml>, a BPMN 2.0 file with <definitions> in the namespace http://www.omg.org/spec/BPMN/20100524/MODEL.",
  );
  expect(refusal("notes.txt", "hello")).toBe("notes.txt is neither JSON nor XML: import an hrc-pattern/1 (.json), PNML (.pnml) or BPMN 2.0 (.bpmn) file.");
});

test("PNML and BPMN files are recognised and sent as they are", () => {
  const bpmn = '<definitions xmlns="http://www.omg.org/spec/BPMN/20100524/MODEL"><process id="P"/></definitions>';
  expect(inspectFile("a.bpmn", bpmn)).toEqual({ format: "bpmn", body: bpmn, contentType: "application/xml" });
  expect(inspectFile("a.pnml", "<pnml><net/></pnml>").format).toBe("pnml");
});

test("the element still open at an error is the one named", () => {
  expect(openElementNear("<a>\n<b x='1'>\n<c/>\n", 4, 1)).toBe("b");
  expect(openElementNear("<a><b></b>", 1, 11)).toBe("a");
});

test("the API's refusals read as one message", () => {
  expect(refusalMessage(400, { detail: "The draft does not pass the check; see the report.", report: { valid: false } })).toBe(
    "The draft does not pass the check; see the report.",
  );
  expect(refusalMessage(400, { detail: "Not readable:", errors: [{ code: "format", message: "bpmn:boundaryEvent b1 is not mapped.", elements: ["b1"] }] })).toBe(
    "Not readable: bpmn:boundaryEvent b1 is not mapped.",
  );
  expect(refusalMessage(400, { name: ["This field may not be blank."] })).toBe("name: This field may not be blank.");
  expect(refusalMessage(502, "<html>")).toBe("The server answered 502.");
});
