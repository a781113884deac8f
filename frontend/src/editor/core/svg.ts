/** Small SVG helpers for the renderer and overlays, on the plain DOM. */

const SVG = "http://www.w3.org/2000/svg";

export function svg<K extends keyof SVGElementTagNameMap>(
  tag: K,
  attrs: Record<string, string | number> = {},
  parent?: Element,
): SVGElementTagNameMap[K] {
  const element = document.createElementNS(SVG, tag);
  for (const [name, value] of Object.entries(attrs)) element.setAttribute(name, String(value));
  parent?.appendChild(element);
  return element;
}

/** Text centred on (x, y), broken into lines of about `width` pixels at 12 px (no layout measuring). */
export function textBlock(
  parent: Element,
  text: string,
  x: number,
  y: number,
  options: { width?: number; size?: number; className?: string; maxLines?: number } = {},
): SVGTextElement {
  const size = options.size ?? 12;
  const perLine = Math.max(4, Math.floor((options.width ?? 120) / (size * 0.56)));
  const lines = wrap(text, perLine).slice(0, options.maxLines ?? 3);
  const element = svg("text", { x, y: y - ((lines.length - 1) * size * 1.15) / 2, "text-anchor": "middle", "dominant-baseline": "middle", "font-size": size, class: options.className ?? "hrc-text" }, parent);
  lines.forEach((line, index) => {
    const span = svg("tspan", { x, dy: index === 0 ? 0 : size * 1.15 }, element);
    span.textContent = line;
  });
  return element;
}

export function wrap(text: string, perLine: number): string[] {
  const lines: string[] = [];
  let current = "";
  for (const word of text.split(/\s+/).filter(Boolean)) {
    if (current && current.length + 1 + word.length > perLine) {
      lines.push(current);
      current = word;
    } else current = current ? `${current} ${word}` : word;
  }
  if (current) lines.push(current);
  return lines.map((line) => (line.length > perLine + 6 ? `${line.slice(0, perLine + 5)}…` : line));
}
