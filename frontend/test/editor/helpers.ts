/** Shared test data: the thesis' examples, read from the example library. */

import { readFileSync } from "node:fs";

import type { PatternDocument } from "../../src/editor/model/document";

// Through a variable: Vite would take `new URL(…, import.meta.url)` for an asset to bundle.
const here = import.meta.url;

export function example(name: string): PatternDocument {
  const url = new URL(`../../../hrc/patterns/examples/${name}.json`, here);
  return JSON.parse(readFileSync(url, "utf-8")) as PatternDocument;
}
