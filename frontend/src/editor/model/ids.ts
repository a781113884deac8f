/**
 * New ids in the thesis' style: places p1, p2…; silent transitions t1, t2…;
 * tasks t<actor><n> (tc1 for cobot c, to11 for operator o1); actors c, o,
 * then c2, o2… Ids are unique across the whole document.
 */

export type IdKind = "place" | "silent" | "task" | "actor" | "process";

/** `actor`: the task's actor id for a task, the ActorType for an actor. */
export function nextId(kind: IdKind, taken: (id: string) => boolean, actor?: string): string {
  const prefix = {
    place: "p",
    silent: "t",
    task: `t${actor ?? ""}`,
    actor: actor === "cobot" ? "c" : "o",
    process: "N",
  }[kind];
  if ((kind === "actor" || kind === "process") && !taken(prefix)) return prefix;
  for (let n = kind === "actor" || kind === "process" ? 2 : 1; ; n += 1) {
    const id = `${prefix}${n}`;
    if (!taken(id)) return id;
  }
}

/** Ids are non-empty and plain: letters, digits, `_`, `-`, `.`; what an engineer types in a form. */
export function idProblem(id: string, taken: (id: string) => boolean): string | null {
  if (!id) return "An id cannot be empty.";
  if (!/^[A-Za-z_][A-Za-z0-9_.-]*$/.test(id)) {
    return `"${id}" is not a plain id: start with a letter, then letters, digits, _, - or .`;
  }
  if (taken(id)) return `The id ${id} is already used in this pattern.`;
  return null;
}
