// The few DOM helpers every page's script uses: building elements, and reading the
// configuration a template hands its script.

/** An element's attributes by name; a string alone is its class. */
export type Attributes = Record<string, string> | string;

/** A new element with its attributes (or just a class, "" for none) and children. */
export function element<K extends keyof HTMLElementTagNameMap>(
  tag: K,
  attributes: Attributes = {},
  ...children: (Node | string)[]
): HTMLElementTagNameMap[K] {
  const node = document.createElement(tag);
  if (typeof attributes === "string") {
    if (attributes) node.className = attributes;
  } else {
    for (const [name, value] of Object.entries(attributes)) node.setAttribute(name, value);
  }
  node.append(...children);
  return node;
}

/** A new element, as element() builds it, appended to `parent`. */
export function addElement<K extends keyof HTMLElementTagNameMap>(
  parent: Node,
  tag: K,
  attributes: Attributes = {},
  ...children: (Node | string)[]
): HTMLElementTagNameMap[K] {
  return parent.appendChild(element(tag, attributes, ...children));
}

/**
 * Makes `parent`'s children equal to `wanted`, keeping every child that already equals the one
 * wanted in its place: a live page renders on every update, and a button replaced between an
 * operator's press and release loses the tap.
 */
export function patchChildren(parent: Element, wanted: Node[]): void {
  wanted.forEach((node, index) => {
    const current = parent.childNodes[index];
    if (!current) parent.append(node);
    else if (!current.isEqualNode(node)) current.replaceWith(node);
  });
  while (parent.childNodes.length > wanted.length) parent.lastChild!.remove();
}

/** The JSON of the page's `<script type="application/json" id=…>` (Django's json_script); null without one. */
export function pageConfig<T>(id: string): T | null {
  const source = document.getElementById(id)?.textContent;
  return source ? (JSON.parse(source) as T) : null;
}
