/**
 * A silent transition's `cancels` key: the places and tasks of its own process
 * it empties when it fires (BPMN's terminate end events and interrupting
 * boundary events). The engine's check has the final word; the panel refuses
 * early what it would refuse: ids of no node, and nodes of another process.
 * A silent transition may be listed (an importer may list a whole region): it
 * holds nothing, so that cancels nothing.
 */

/**
 * The ids of a comma- or space-separated list, each once and in the order written.
 * `process` is the cancelling transition's; `processOf` gives the process of any
 * node of the document, undefined for an id that is no node.
 * Throws an Error naming every id that cannot be cancelled.
 */
export function parseCancels(text: string, process: string, processOf: (id: string) => string | undefined): string[] {
  const ids = [...new Set(text.split(/[\s,;]+/).filter(Boolean))];
  const problems = ids.flatMap((id) => {
    const found = processOf(id);
    if (found === undefined) return [`${id} is no place or task of this pattern`];
    if (found !== process) return [`${id} is in net ${found}, not in this transition's net ${process}`];
    return [];
  });
  if (problems.length) throw new Error(`Cannot cancel: ${problems.join("; ")}.`);
  return ids;
}

/** The ids a transition's `cancels` key lists; none when it has none or is malformed. */
export function cancelsOf(data: Record<string, unknown>): string[] {
  return Array.isArray(data.cancels) ? data.cancels.filter((id): id is string => typeof id === "string") : [];
}

/** The `cancels` list with one id renamed, or null when it does not list `from`. */
export function renamedCancels(data: Record<string, unknown>, from: string, to: string): string[] | null {
  const ids = cancelsOf(data);
  return ids.includes(from) ? ids.map((id) => (id === from ? to : id)) : null;
}
