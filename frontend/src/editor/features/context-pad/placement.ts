/** Where an appended node goes: right of its source, inside the source's lane. */

export interface Box {
  x: number;
  y: number;
  width: number;
  height: number;
}

const GAP = 20; // between two nodes, and between a node and its lane's border

/**
 * The centre for a node of `size` near `wanted`: there if free, else the nearest free
 * spot below or above it (a split's second branch) whose box stays inside `lane`,
 * else further right. `taken` are the boxes of the nodes already there. Without a lane,
 * the wanted spot is kept.
 */
export function placeInLane(wanted: { x: number; y: number }, size: { width: number; height: number }, lane: Box | null, taken: Box[]): { x: number; y: number } {
  if (!lane) return wanted;
  const top = lane.y + GAP + size.height / 2;
  const bottom = lane.y + lane.height - GAP - size.height / 2;
  const clamp = (y: number) => Math.min(Math.max(y, top), Math.max(top, bottom));
  const step = size.height + GAP;
  for (let column = 0; column < 20; column += 1) {
    const x = wanted.x + column * (size.width + 2 * GAP);
    const first = clamp(wanted.y);
    const candidates = [first];
    for (let n = 1; first + n * step <= bottom || first - n * step >= top; n += 1) {
      if (first + n * step <= bottom) candidates.push(first + n * step);
      if (first - n * step >= top) candidates.push(first - n * step);
    }
    const free = candidates.find((y) => !taken.some((box) => overlaps(box, { x: x - size.width / 2, y: y - size.height / 2, ...size })));
    if (free !== undefined) return { x, y: free };
  }
  return { x: wanted.x, y: clamp(wanted.y) };
}

function overlaps(a: Box, b: Box): boolean {
  return a.x < b.x + b.width + GAP / 2 && b.x < a.x + a.width + GAP / 2 && a.y < b.y + b.height + GAP / 2 && b.y < a.y + a.height + GAP / 2;
}
