// Axes: live positions, tracking errors e_i and synchronization errors eps_i
// (paper 000), and a TRANSIENT_SYNC transient with its predicted end drawn
// ahead of now (paper 004). Which refs are axes is the user's choice (or the
// program's suggestion), remembered in this browser.
import { useCallback, useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { getBlocks, getStatus, getTags } from '../api/endpoints.js';
import { hasValue, isForced, qualityOf, refError, valueOf } from '../live/hub.js';
import { useLive, useLiveCallback } from '../live/hooks.js';
import { configRefs, loadConfig, predictedEndS, saveConfig, suggestAxes, syncErrors, validConfig } from '../lib/axes_config.js';
import { elementType } from '../lib/format.js';
import { ErrorNote } from '../components/common.jsx';
import { PALETTE, Plot } from '../components/plot.jsx';

const scalarOf = (v) => (typeof v === 'number' ? v : typeof v === 'boolean' ? (v ? 1 : 0) : null);

// Samples of several series over a sliding window of wall time (the stream's t_ns).
class Window {
  constructor(n) { this.t = []; this.ys = Array.from({ length: n }, () => []); }
  push(tS, values, keepS) {
    this.t.push(tS);
    values.forEach((v, i) => this.ys[i].push(v));
    while (this.t.length && this.t[0] < tS - keepS) { this.t.shift(); for (const y of this.ys) y.shift(); }
  }
  relative(nowS) { return [this.t.map((t) => t - nowS), ...this.ys]; }
}

function plotOptions(labels, unit, { dashedFrom = Infinity, marker = null, ahead = 0, colorMod = Infinity } = {}) {
  return {
    legend: { show: true, live: false },
    cursor: { drag: { x: false, y: false } },
    scales: { x: { time: false, range: (u, min, max) => [Math.min(min, -1), Math.max(ahead.current || 0.5, 0.5)] } },
    axes: [
      { label: 's from now', size: 40, font: '11px system-ui', labelFont: '11px system-ui' },
      { label: unit || '', size: 56, font: '11px system-ui', labelFont: '11px system-ui' },
    ],
    series: [{ label: 't' }, ...labels.map((l, i) => ({
      label: l, stroke: PALETTE[(i % colorMod) % PALETTE.length], width: 1.5, dash: i >= dashedFrom ? [4, 4] : undefined, points: { show: false },
    }))],
    hooks: marker ? { draw: [(u) => marker(u)] } : {},
  };
}

// A vertical line at "now" and, when a transient runs, a dashed one at its
// predicted end with the time left written beside it.
function drawMarkers(u, endRef) {
  const { ctx } = u;
  const top = u.bbox.top; const h = u.bbox.height;
  const line = (x, color, dash) => {
    ctx.save(); ctx.strokeStyle = color; ctx.setLineDash(dash); ctx.lineWidth = 1.5 * devicePixelRatio;
    ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + h); ctx.stroke(); ctx.restore();
  };
  line(u.valToPos(0, 'x', true), '#57606a', []);
  const end = endRef.current;
  if (end !== null) {
    const x = u.valToPos(end, 'x', true);
    line(x, '#d1242f', [6, 4]);
    ctx.save(); ctx.fillStyle = '#d1242f'; ctx.font = `${12 * devicePixelRatio}px system-ui`;
    const text = `end in ${end.toFixed(2)} s`;
    const w = ctx.measureText(text).width;
    ctx.fillText(text, Math.min(x + 4 * devicePixelRatio, u.bbox.left + u.bbox.width - w), top + 14 * devicePixelRatio);
    ctx.restore();
  }
}

function AxisEditor({ config, onSave, refOptions, blocks }) {
  const [draft, setDraft] = useState(config);
  const set = (i, key, v) => setDraft({ ...draft, axes: draft.axes.map((a, j) => (j === i ? { ...a, [key]: v } : a)) });
  const transients = (blocks || []).filter((b) => b.type === 'TRANSIENT_SYNC');
  return (
    <form class="card form axis-editor" onSubmit={(e) => { e.preventDefault(); onSave(validConfig(draft)); }}>
      <h2>Axes shown</h2>
      <p class="hint">Pick a position and a tracking error (e<sub>i</sub> = x<sub>d,i</sub> − x<sub>i</sub>) per axis, as a tag, an element (pos[2]) or a pin (ax1.x). The synchronization error ε<sub>i</sub> = e<sub>i</sub> − mean(e<sub>1</sub> … e<sub>i−1</sub>) is computed from the errors in this order. Saved in this browser.</p>
      <datalist id="ref-options">{refOptions.map((r) => <option value={r} />)}</datalist>
      {draft.axes.map((a, i) => (
        <div class="axis-row">
          <label>Name<input value={a.label} onInput={(e) => set(i, 'label', e.currentTarget.value)} /></label>
          <label>Position<input list="ref-options" value={a.position} placeholder="e.g. pos[1]" onInput={(e) => set(i, 'position', e.currentTarget.value)} /></label>
          <label>Tracking error<input list="ref-options" value={a.error} placeholder="e.g. err[1]" onInput={(e) => set(i, 'error', e.currentTarget.value)} /></label>
          <label class="narrow">Unit<input value={a.unit} placeholder="rad" onInput={(e) => set(i, 'unit', e.currentTarget.value)} /></label>
          <button type="button" class="btn small" aria-label={`Remove ${a.label}`} onClick={() => setDraft({ ...draft, axes: draft.axes.filter((_, j) => j !== i) })}>Remove</button>
        </div>
      ))}
      <div class="actions left">
        <button type="button" class="btn small" onClick={() => setDraft({ ...draft, axes: [...draft.axes, { label: `axis ${draft.axes.length + 1}`, position: '', error: '', unit: '' }] })}>Add an axis</button>
        {blocks && blocks.length ? <button type="button" class="btn small" onClick={() => setDraft(suggestAxes(blocks))}>Suggest from the program</button> : null}
      </div>
      <label>Transient synchronizer (TRANSIENT_SYNC instance)
        <select value={draft.transient} onChange={(e) => setDraft({ ...draft, transient: e.currentTarget.value })}>
          <option value="">none</option>
          {transients.map((b) => <option value={b.name}>{b.name}</option>)}
          {draft.transient && !transients.some((b) => b.name === draft.transient) ? <option value={draft.transient}>{draft.transient}</option> : null}
        </select>
      </label>
      <label>Time shown (s)
        <input type="number" min="2" max="120" value={draft.windowS} onInput={(e) => setDraft({ ...draft, windowS: Number(e.currentTarget.value) })} />
      </label>
      <div class="actions"><button type="submit" class="btn primary">Show these axes</button></div>
    </form>
  );
}

function LivePlots({ config, periodNs }) {
  const axes = config.axes;
  const refs = useMemo(() => configRefs(config), [config]);
  const withErr = axes.filter((a) => a.error);
  const nTs = useRef(0);
  const posPlot = useRef(null); const errPlot = useRef(null); const tsPlot = useRef(null);
  const endRef = useRef(null);
  const aheadRef = useRef(0.5);
  const [summary, setSummary] = useState(null);
  const seen = useRef(0);
  useLive(refs, 1000); // a slow re-render for the words (the plots draw on their own)
  const win = useRef(null);
  const tsWin = useRef(null);

  const posOpts = useMemo(() => plotOptions(axes.map((a) => a.label), axes[0] && axes[0].unit, { marker: (u) => drawMarkers(u, { current: null }) }), [config]);
  const errOpts = useMemo(() => plotOptions([...withErr.map((a) => `e ${a.label}`), ...withErr.slice(1).map((a) => `ε ${a.label}`)],
    withErr[0] && withErr[0].unit, { dashedFrom: withErr.length, marker: (u) => drawMarkers(u, { current: null }) }), [config]);
  const [tsOpts, setTsOpts] = useState(null);

  useEffect(() => {
    win.current = new Window(axes.length + withErr.length + Math.max(0, withErr.length - 1));
    tsWin.current = null;
    setTsOpts(null);
    nTs.current = 0;
  }, [config]);

  let lastDraw = 0;
  const onUpdate = useCallback((tNs, values) => {
    // Refs the PLC does not know stay empty (named below the plots).
    if (!refs.some((r) => r in values)) return;
    seen.current += 1;
    const tS = (tNs ?? Date.now() * 1e6) / 1e9;
    const pos = axes.map((a) => scalarOf(valueOf(a.position)));
    const e = withErr.map((a) => scalarOf(valueOf(a.error)));
    const eps = syncErrors(e).slice(1);
    win.current.push(tS, [...pos, ...e, ...eps], config.windowS);
    if (config.transient) {
      const x = valueOf(`${config.transient}.x`);
      const r = valueOf(`${config.transient}.r`);
      const xs = Array.isArray(x) ? x : [];
      const rs = Array.isArray(r) ? r : [];
      if (xs.length && nTs.current !== xs.length) {
        nTs.current = xs.length;
        tsWin.current = new Window(xs.length * 2);
        const labels = [...xs.map((_, i) => `x${i + 1}`), ...xs.map((_, i) => `r${i + 1}`)];
        setTsOpts({ ...plotOptions(labels, '', { dashedFrom: xs.length, colorMod: xs.length, marker: (u) => drawMarkers(u, endRef), ahead: aheadRef }), key: labels.join() });
      }
      if (tsWin.current) tsWin.current.push(tS, [...xs, ...xs.map((_, i) => (rs[i] ?? null))], config.windowS);
      const arrival = scalarOf(valueOf(`${config.transient}.arrival`));
      const end = predictedEndS(arrival, periodNs);
      endRef.current = end;
      aheadRef.current = end !== null ? Math.max(0.5, end * 1.1) : 0.5;
      setSummary({ arrival, end, synchronized: valueOf(`${config.transient}.synchronized`), spread: scalarOf(valueOf(`${config.transient}.spread`)), windows: scalarOf(valueOf(`${config.transient}.windows`)), atNs: tNs });
    }
    const now = performance.now();
    if (now - lastDraw < 50) return;
    lastDraw = now;
    const rel = win.current.relative(tS);
    const t = rel[0];
    if (posPlot.current) posPlot.current.setData([t, ...rel.slice(1, 1 + axes.length)]);
    if (errPlot.current) errPlot.current.setData([t, ...rel.slice(1 + axes.length)]);
    if (tsPlot.current && tsWin.current) tsPlot.current.setData(tsWin.current.relative(tS));
  }, [config, periodNs, refs]);
  useLiveCallback(refs, onUpdate);

  const missing = seen.current > 20 ? refs.filter((r) => !hasValue(r)) : [];
  const forced = refs.filter(isForced);
  // Values that are not the machine's state now: the plots go on drawing
  // them, greyed, and this says which and why.
  const notLive = refs.map((r) => [r, qualityOf(r)]).filter(([, q]) => q && q.stale);
  return (
    <>
      {notLive.length ? (
        <p class="stale-note" role="status" data-stale={notLive.length}><span class="badge badge-stale">not live</span>{' '}
          {notLive.map(([r, q]) => `${r} (${q.text})`).join(', ')}</p>
      ) : null}
      {forced.length ? (
        <p class="forced-note" role="status"><span class="badge badge-forced">F</span> Forced, so not what the program computes: {forced.join(', ')}</p>
      ) : null}
      {missing.length ? <p class="error-note">No value from the PLC for {missing.map((r) => (refError(r) ? `${r} (${refError(r)})` : r)).join(', ')}: check these names under “Choose axes…”.</p> : null}
      {axes.length ? (
        <section class={notLive.length ? 'card stale' : 'card'}>
          <h2>Positions</h2>
          <Plot options={posOpts} plotRef={posPlot} height={220} label="axis positions" />
        </section>
      ) : null}
      {withErr.length ? (
        <section class={notLive.length ? 'card stale' : 'card'}>
          <h2>Tracking errors e<sub>i</sub> (solid) and synchronization errors ε<sub>i</sub> (dashed)</h2>
          <Plot options={errOpts} plotRef={errPlot} height={220} label="tracking and synchronization errors" />
        </section>
      ) : null}
      {config.transient ? (
        <section class="card" id="transient">
          <h2>Filter transient: {config.transient}</h2>
          <p class="transient-summary" role="status">{transientWords(summary, periodNs)}</p>
          {tsOpts ? <Plot key={tsOpts.key} options={tsOpts} plotRef={tsPlot} height={240} label="filtered positions and references with predicted end" /> : <p class="hint">Waiting for {config.transient}.x…</p>}
        </section>
      ) : null}
    </>
  );
}

function transientWords(s, periodNs) {
  if (!s) return 'Waiting for values…';
  if (s.synchronized === true || s.arrival === 0) {
    return `All axes track their references.${s.windows !== null ? ` ${s.windows} transients so far` : ''}${s.spread !== null ? `; the last one's arrival spread: ${s.spread} scans (0 = all arrived together).` : '.'}`;
  }
  if (s.end === null) return periodNs ? 'A transient is running; its end is not known yet.' : 'A transient is running (the task period is not known, so its end cannot be predicted).';
  return `Transient running: all axes arrive together in ${s.end.toFixed(2)} s (${s.arrival} scans), predicted at ${new Date(((s.atNs ?? Date.now() * 1e6) / 1e6) + s.end * 1000).toLocaleTimeString()}.`;
}

export function AxesPage() {
  const [config, setConfig] = useState(loadConfig());
  const stored = config.axes.length > 0 || !!config.transient;
  const [suggested, setSuggested] = useState(false);
  const [editing, setEditing] = useState(false);
  const [blocks, setBlocks] = useState(null);
  const [tags, setTags] = useState([]);
  const [periods, setPeriods] = useState({});
  const [error, setError] = useState(null);

  useEffect(() => {
    getBlocks().then((b) => {
      setBlocks(b);
      // Nothing chosen in this browser yet: show what the program suggests.
      if (!stored) {
        const s = suggestAxes(b);
        if (s.axes.length || s.transient) { setConfig(s); setSuggested(true); } else setEditing(true);
      }
    }).catch((e) => { setBlocks([]); setError(e); setEditing(true); });
    getTags().then(setTags).catch(() => {});
    getStatus().then((s) => setPeriods(Object.fromEntries(s.tasks.map((t) => [t.name, t.periodNs])))).catch(() => {});
  }, []);

  const refOptions = useMemo(() => {
    const out = [];
    for (const t of tags) {
      const m = /^ARRAY\s*\[\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*\]/i.exec(t.type);
      if (m) for (let i = Number(m[1]); i <= Math.min(Number(m[2]), Number(m[1]) + 63); i++) out.push(`${t.name}[${i}]`);
      else if (elementType(t.type) !== 'STRING') out.push(t.name);
    }
    for (const b of blocks || []) for (const p of b.pins) if (p.length <= 1) out.push(`${b.name}.${p.name}`);
    return out;
  }, [tags, blocks]);

  const tsBlock = (blocks || []).find((b) => b.name === config.transient);
  const periodNs = tsBlock ? periods[tsBlock.task] : null;

  const save = (c) => { saveConfig(c); setConfig(c); setEditing(false); setSuggested(false); };
  return (
    <>
      <h1>Axes</h1>
      <div class="toolbar">
        <button type="button" class="btn" onClick={() => setEditing(!editing)} aria-expanded={editing}>{editing ? 'Close the axis choice' : 'Choose axes…'}</button>
        <span class="sub">{config.axes.length} axes{config.transient ? `, transient of ${config.transient}` : ''}, last {config.windowS} s</span>
      </div>
      <ErrorNote error={error} />
      {suggested && !editing ? <p class="hint">Suggested from the program's blocks ({config.axes.map((a) => a.label).join(', ')}{config.transient ? `; transient of ${config.transient}` : ''}). Use “Choose axes…” to change and keep your own choice.</p> : null}
      {editing ? <AxisEditor config={config} onSave={save} refOptions={refOptions} blocks={blocks} /> : null}
      {!editing && !config.axes.length && !config.transient ? <p class="hint">No axes chosen yet.</p> : null}
      <LivePlots config={config} periodNs={periodNs} />
    </>
  );
}
