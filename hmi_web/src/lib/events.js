// The event list the Events page keeps. Pure (test/lists.test.mjs).

// Merges new events (any order) into a newest-first list without duplicates.
export function mergeEvents(list, fresh, keep = 2000) {
  const seen = new Set(list.map((e) => e.id));
  const add = fresh.filter((e) => !seen.has(e.id));
  if (!add.length) return list;
  return [...add, ...list].sort((a, b) => b.id - a.id).slice(0, keep);
}
