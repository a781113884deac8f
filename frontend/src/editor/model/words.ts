/** Elements named for people: labels rather than ids, each once, and not too many. */

/**
 * "“Pick insert”, “Place insert” and 2 more" for a list of element ids:
 * duplicates dropped (an issue may name an element twice), each by `name`,
 * at most `limit` shown.
 */
export function listOfNames(ids: string[], name: (id: string) => string, limit = 3): string {
  const names = [...new Set(ids)].map(name);
  const unique = [...new Set(names)];
  if (unique.length <= limit) {
    return unique.length <= 1 ? (unique[0] ?? "") : `${unique.slice(0, -1).join(", ")} and ${unique[unique.length - 1]}`;
  }
  return `${unique.slice(0, limit).join(", ")} and ${unique.length - limit} more`;
}

/** A label in quotes, or the id where there is no label. */
export function quotedName(id: string, label: string | undefined): string {
  return label?.trim() ? `“${label.trim()}”` : id;
}
