/** Inline icons for the palette and the context pad (no icon font to load). */

const wrap = (body: string) =>
  `<svg viewBox="0 0 24 24" width="22" height="22" fill="none" stroke="currentColor" stroke-width="1.8" stroke-linecap="round" stroke-linejoin="round" aria-hidden="true">${body}</svg>`;

export const ICONS: Record<string, string> = {
  hand: wrap('<path d="M8 12V6a1.5 1.5 0 0 1 3 0v5M11 11V4.5a1.5 1.5 0 0 1 3 0V11M14 11V6a1.5 1.5 0 0 1 3 0v7c0 4-2.5 7-6 7-2.5 0-4-1.5-5.5-4L4 13a1.4 1.4 0 0 1 2.3-1.6L8 13.5"/>'),
  lasso: wrap('<rect x="4" y="4" width="16" height="16" stroke-dasharray="3 2"/>'),
  arc: wrap('<path d="M4 18 L18 6"/><path d="M12 6h6v6"/>'),
  place: wrap('<circle cx="12" cy="12" r="8"/><circle cx="12" cy="12" r="2" fill="currentColor"/>'),
  task: wrap('<rect x="3" y="6" width="18" height="12" rx="3"/>'),
  silent: '<svg viewBox="0 0 24 24" width="22" height="22" aria-hidden="true"><rect x="10" y="3" width="4" height="18" fill="currentColor"/></svg>',
  cobot: wrap('<path d="M4 20h9M8 20v-6l6-6 3 3"/><circle cx="8" cy="14" r="1.6" fill="currentColor"/>'),
  operator: wrap('<circle cx="12" cy="7" r="3.5"/><path d="M5 21c0-5 14-5 14 0"/>'),
  time: '<svg viewBox="0 0 24 24" width="22" height="22" aria-hidden="true"><path d="M3 12h14" stroke="#1f5fbf" stroke-width="2.2" stroke-dasharray="4 2"/><path d="M15 7l6 5-6 5z" fill="#1f5fbf"/></svg>',
  space: '<svg viewBox="0 0 24 24" width="22" height="22" aria-hidden="true"><path d="M6 12h12" stroke="#c2410c" stroke-width="2.2" stroke-dasharray="2 2"/><path d="M1 12l3-3 3 3-3 3zM17 12l3-3 3 3-3 3z" fill="#fff" stroke="#c2410c" stroke-width="1.5"/></svg>',
  func: '<svg viewBox="0 0 24 24" width="22" height="22" aria-hidden="true"><path d="M5 12h14" stroke="#7e22ce" stroke-width="2.2" stroke-dasharray="5 2 1 2"/><circle cx="4" cy="12" r="3" fill="#7e22ce"/><circle cx="20" cy="12" r="3" fill="#7e22ce"/></svg>',
  "token-add": wrap('<circle cx="10" cy="12" r="6"/><circle cx="10" cy="12" r="1.6" fill="currentColor"/><path d="M19 6v6M16 9h6"/>'),
  "token-remove": wrap('<circle cx="10" cy="12" r="6"/><path d="M16 9h6"/>'),
  label: wrap('<path d="M4 20h4L19 9l-4-4L4 16z"/>'),
  delete: wrap('<path d="M5 7h14M10 7V4h4v3M7 7l1 13h8l1-13"/>'),
};

export function entryHtml(icon: string, text = ""): string {
  return `<div class="entry hrc-entry" draggable="true">${ICONS[icon] ?? ""}${text ? `<span>${text}</span>` : ""}</div>`;
}
