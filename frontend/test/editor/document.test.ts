import { describe, expect, test } from "vitest";

import { DocumentError, emptyDocument, parseDocument, readDocument, writeDocument } from "../../src/editor/model/document";
import { example } from "./helpers";

function problems(value: unknown): string[] {
  try {
    readDocument(value);
  } catch (error) {
    expect(error).toBeInstanceOf(DocumentError);
    return (error as DocumentError).issues.map((issue) => issue.message);
  }
  throw new Error("the document was read without complaint");
}

describe("reading hrc-pattern/1", () => {
  test("a thesis example reads back unchanged, keys the editor does not know included", () => {
    const document = example("synch_1o1c_assembly");
    document.processes[0].transitions[2].task = { step: { program: "P", number: 2 }, extra: [1, 2] };
    expect(writeDocument(readDocument(document))).toEqual(document);
    expect(readDocument(document).source).toBe("thesis, section 4.3.1, CP_synch_1O1C");
  });

  test("absent lists are read as empty", () => {
    const document = readDocument({ format: "hrc-pattern/1", processes: [{ id: "N" }] });
    expect(document.actors).toEqual([]);
    expect(document.processes[0]).toMatchObject({ places: [], transitions: [], arcs: [], actors: [] });
  });

  test("the wrong format is refused by name", () => {
    expect(problems({ format: "bpmn" })).toEqual(['The document must say "format": "hrc-pattern/1", got "bpmn".']);
    expect(problems([1])[0]).toBe("The document must be a JSON object, got a list of 1.");
  });

  test("each shape problem names the element and where it is", () => {
    const document = example("synch_1o1c_assembly") as unknown as Record<string, any>;
    document.processes[0].places[1].tokens = -1;
    document.processes[0].arcs[3] = ["p3"];
    document.actors[1].type = "robot";
    document.constraints[0].type = 7;
    const messages = problems(document);
    expect(messages).toContain("processes[0] (N).places[1] (p2).tokens must be a whole number ≥ 0, got the number -1.");
    expect(messages).toContain("processes[0] (N).arcs[3] must be a pair of node ids [from, to], got a list of 1.");
    expect(messages).toContain('actors[1] (o).type must be "cobot" or "operator", got "robot".');
    expect(messages).toContain("constraints[0] (to1 → tc2).type must be a non-empty string, got the number 7.");
  });

  test("a document without a net is refused", () => {
    expect(problems({ format: "hrc-pattern/1", processes: [] })).toContain("The document has no process: a pattern needs at least one Petri net.");
  });

  test("JSON syntax errors say the line and column", () => {
    expect(() => parseDocument('{\n  "format": "hrc-pattern/1",\n  "actors": [,]\n}')).toThrowError('The file is not JSON: unexpected "," at line 3, column 14.');
    expect(() => parseDocument('{"format": "hrc-pattern/1"')).toThrowError("The file is not JSON: it ends too early, at line 1, column 27.");
  });

  test("an empty model has one net and nothing in it", () => {
    expect(readDocument(emptyDocument("X"))).toEqual(emptyDocument("X"));
  });
});
