// Trends: a trended tag's history from the historian, each point a bucket's
// min, max and mean (every scan counted, docs/store.md), drawn as a band
// from min to max with the mean as a line.
import { useEffect, useMemo, useState } from 'preact/hooks';
import { getTags, getTrend } from '../api/endpoints.js';
import { ErrorNote } from '../components/common.jsx';
import { trendData } from '../lib/trend_data.js';
import { PALETTE, Plot } from '../components/plot.jsx';

const RANGES = [
  { id: '5m', label: 'last 5 minutes', s: 300 },
  { id: '1h', label: 'last hour', s: 3600 },
  { id: '24h', label: 'last 24 hours', s: 86400 },
  { id: '7d', label: 'last 7 days', s: 7 * 86400 },
  { id: 'custom', label: 'from … to …', s: null },
];

const toLocalInput = (ms) => {
  const d = new Date(ms - new Date(ms).getTimezoneOffset() * 60000);
  return d.toISOString().slice(0, 16);
};


export function TrendsPage() {
  const [tags, setTags] = useState([]);
  const [tag, setTag] = useState(() => localStorage.getItem('syncplc.trend.tag') || '');
  const [range, setRange] = useState('1h');
  const [from, setFrom] = useState(toLocalInput(Date.now() - 3600e3));
  const [to, setTo] = useState(toLocalInput(Date.now()));
  const [trend, setTrend] = useState(null);
  const [error, setError] = useState(null);
  const [busy, setBusy] = useState(false);

  useEffect(() => { getTags().then(setTags).catch(() => {}); }, []);

  async function show(e) {
    if (e) e.preventDefault();
    if (!tag) return;
    localStorage.setItem('syncplc.trend.tag', tag);
    const r = RANGES.find((x) => x.id === range);
    const untilMs = r.s ? Date.now() : new Date(to).getTime();
    const sinceMs = r.s ? untilMs - r.s * 1000 : new Date(from).getTime();
    if (!(sinceMs < untilMs)) { setError('The start must be before the end.'); return; }
    setBusy(true);
    setError(null);
    try {
      const points = Math.max(100, Math.min(2000, Math.round(window.innerWidth)));
      setTrend(await getTrend({ tag, since: Math.round(sinceMs * 1e6), until: Math.round(untilMs * 1e6), points }));
    } catch (err) { setError(err); setTrend(null); } finally { setBusy(false); }
  }
  useEffect(() => { if (tag) show(); }, []);

  const options = useMemo(() => {
    if (!trend) return null;
    const series = [{}]; const bands = [];
    trend.series.forEach((s, i) => {
      const c = PALETTE[i % PALETTE.length];
      const base = 1 + i * 3;
      series.push({ label: `${s.label} min`, stroke: `${c}55`, width: 1, points: { show: false } });
      series.push({ label: `${s.label} max`, stroke: `${c}55`, width: 1, points: { show: false } });
      series.push({ label: `${s.label} mean`, stroke: c, width: 1.5, points: { show: false } });
      bands.push({ series: [base + 1, base], fill: `${c}22` });
    });
    const unit = trend.series[0] ? trend.series[0].unit : '';
    return {
      series, bands, legend: { show: true, live: false },
      axes: [{ font: '11px system-ui' }, { label: unit, size: 60, font: '11px system-ui', labelFont: '11px system-ui' }],
      scales: { x: { time: true } },
      key: trend.series.map((s) => s.label).join(),
    };
  }, [trend]);

  const numeric = tags.filter((t) => !/STRING/.test(t.type));
  const empty = trend && trend.series.every((s) => !s.points.length);
  return (
    <>
      <h1>Trends</h1>
      <form class="toolbar trend-form" onSubmit={show}>
        <label>Tag
          <input list="trend-tags" value={tag} placeholder="a trended tag, e.g. pos" onInput={(e) => setTag(e.currentTarget.value)} required />
          <datalist id="trend-tags">{numeric.map((t) => <option value={t.name}>{t.type}{t.unit ? `, ${t.unit}` : ''}</option>)}</datalist>
        </label>
        <label>Time
          <select value={range} onChange={(e) => setRange(e.currentTarget.value)}>{RANGES.map((r) => <option value={r.id}>{r.label}</option>)}</select>
        </label>
        {range === 'custom' ? (
          <>
            <label>From<input type="datetime-local" value={from} onInput={(e) => setFrom(e.currentTarget.value)} /></label>
            <label>To<input type="datetime-local" value={to} onInput={(e) => setTo(e.currentTarget.value)} /></label>
          </>
        ) : null}
        <button type="submit" class="btn primary" disabled={busy || !tag}>{busy ? 'Reading…' : 'Show'}</button>
      </form>
      <p class="hint">Tags marked <code>trend:</code> in the project are recorded by the historian. Each point holds the minimum, maximum and mean over every scan of its time slice: the shaded band is min to max, the line the mean.</p>
      <ErrorNote error={error} />
      {empty ? <p class="hint">No points of {tag} in this time range.</p> : null}
      {trend && options && !empty ? (
        <section class="card"><Plot key={options.key} options={options} data={trendData(trend)} height={320} label={`trend of ${tag}`} /></section>
      ) : null}
    </>
  );
}
