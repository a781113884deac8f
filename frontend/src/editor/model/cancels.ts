/**
 * A silent transition's `cancels` key: the places and tasks of its own process
 * it empties when it fires (BPMN's terminate end events and interrupting
 * boundary events). The engine's check has the final word; the panel refuses
 * early what it would refuse: unknown ids, silent transitions (they never
 * run), and elements of another process.
 */

/** What the panel knows of a node it may be asked to cancel. */
export interface CancelTarget {
  kind: "place" | "task" | "silent";
  process: string;
}

/**
 * The ids of a comma- or space-separated list, each once and in the order written.
 * `process` is the cancelling transition's; `lookup` finds any node of the document.
 * Throws an Error naming every id that cannot be cancelled.
 */
export function parseCancels(text: string, process: string, lookup: (id: string) => CancelTarget | undefined): string[] {
  const ids = [...new Set(text.split(/[\s,;]+/).filter(Boolean))];
  const problems = ids.flatMap((id) => {
    const target = lookup(id);
    if (!target) return [`${id} is no place or task of this pattern`];
    if (target.kind === "silent") return [`${id} is a silent transition, which never runs`];
    if (target.process !== process) return [`${id} is in net ${target.process}, not in this transition's net ${process}`];
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
