// The bars of a task's start-jitter histogram. Pure (test/lists.test.mjs).
import { formatNs } from './format.js';

// Buckets with counts, trimmed of empty ones at both ends.
export function histogramBars({ boundsNs, counts }) {
  let lo = counts.findIndex((c) => c > 0);
  let hi = counts.length - 1 - [...counts].reverse().findIndex((c) => c > 0);
  if (lo < 0) { lo = 0; hi = Math.min(counts.length - 1, 0); }
  const idx = []; const cnt = []; const labels = [];
  for (let i = lo; i <= hi; i++) {
    idx.push(idx.length);
    cnt.push(counts[i]);
    labels.push(i < boundsNs.length ? `≤${formatNs(boundsNs[i])}` : `>${formatNs(boundsNs[boundsNs.length - 1])}`);
  }
  return { idx, cnt, labels };
}
