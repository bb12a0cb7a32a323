// The Tags page's filter: every word typed must appear in the tag's name,
// type, unit, task, access, description or shown value. Pure (test/lists.test.mjs).

// hmi: none is hidden from every reader but an engineer (docs/http-api.md,
// "Who sees what"): a page that shows such a tag is an engineer's.
export const ACCESS_WORDS = { readwrite: 'read & write', read: 'read only', none: 'engineers only (hmi: none)' };

export function tagMatches(t, q, value) {
  if (!q) return true;
  const hay = [t.name, t.type, t.unit, t.task, t.access, ACCESS_WORDS[t.access] || '', t.description, value].join(' ').toLowerCase();
  return q.toLowerCase().split(/\s+/).filter(Boolean).every((w) => hay.includes(w));
}
