// A task's histogram (start jitter or execution time) as a small bar chart: one bar per
// bucket of the runtime's log-linear histogram, labelled by its upper bound.
import { useMemo } from 'preact/hooks';
import uPlot from 'uplot';
import { histogramBars } from '../lib/histogram.js';
import { Plot } from './plot.jsx';


// Grid lines at 1, 10, 100 … only (a log scale's default has nine per decade).
const decades = (min, max) => {
  const out = [];
  for (let d = 1; d <= max; d *= 10) if (d >= min) out.push(d);
  return out;
};

export function ScanHistogram({ histogram, label }) {
  const bars = histogramBars(histogram);
  const key = bars.labels.join('|');
  const options = useMemo(() => ({
    legend: { show: false },
    cursor: { show: true, points: { show: false } },
    scales: { x: { time: false, range: (u, min, max) => [min - 0.5, max + 0.5] }, y: { distr: 3, log: 10, range: (u, min, max) => [0.5, Math.max(10, max * 2)] } },
    axes: [
      { values: (u, splits) => splits.map((s) => bars.labels[s] ?? ''), grid: { show: false }, space: 60, size: 30, font: '11px system-ui' },
      { size: 46, font: '11px system-ui', grid: { stroke: '#eaeef2', width: 1 }, ticks: { show: false }, splits: (u, i, min, max) => decades(min, max), values: (u, splits) => splits.map((s) => (s >= 1000 ? `${s / 1000}k` : s)) },
    ],
    series: [{}, { label: 'scans', fill: '#1f6feb99', stroke: '#1f6feb', paths: uPlot.paths.bars({ size: [0.8, 40] }), points: { show: false } }],
  }), [key]);
  const data = [bars.idx, bars.cnt.map((c) => (c > 0 ? c : null))];
  return <Plot options={options} data={data} height={140} label={label || "histogram"} />;
}
