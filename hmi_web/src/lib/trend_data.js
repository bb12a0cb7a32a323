// A trend's series as uPlot columns. Pure (test/lists.test.mjs).

// uPlot data with, per series, three columns: min, max (the band), mean.
export function trendData(trend) {
  const times = [...new Set(trend.series.flatMap((s) => s.points.map((p) => p.t)))].sort((a, b) => a - b);
  const index = new Map(times.map((t, i) => [t, i]));
  const cols = [times.map((t) => t / 1e9)];
  for (const s of trend.series) {
    const mn = new Array(times.length).fill(null); const mx = [...mn]; const mean = [...mn];
    for (const p of s.points) { const i = index.get(p.t); mn[i] = p.min; mx[i] = p.max; mean[i] = p.mean; }
    cols.push(mn, mx, mean);
  }
  return cols;
}
