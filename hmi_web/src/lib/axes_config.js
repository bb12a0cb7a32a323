// What the Axes page shows: a list of axes (a position and a tracking error
// e_i each, as refs to tags or pins) and optionally one TRANSIENT_SYNC
// instance whose transient and predicted end are drawn. Chosen by the user,
// kept in localStorage; suggestAxes() proposes a set from the program's
// blocks (a future GET /api/v1/axes would hand back the same shape).
// Pure except load/save (test/axes.test.mjs).

const KEY = 'syncplc.axes';

export const emptyConfig = () => ({ axes: [], transient: '', windowS: 10 });

export function validConfig(c) {
  if (!c || typeof c !== 'object' || !Array.isArray(c.axes)) return emptyConfig();
  return {
    axes: c.axes.filter((a) => a && typeof a === 'object').map((a, i) => ({
      label: String(a.label || `axis ${i + 1}`), position: String(a.position || ''), error: String(a.error || ''), unit: String(a.unit || ''),
    })),
    transient: typeof c.transient === 'string' ? c.transient : '',
    windowS: Number.isFinite(c.windowS) && c.windowS >= 2 && c.windowS <= 120 ? c.windowS : 10,
  };
}

export function loadConfig(storage = globalThis.localStorage) {
  try { return validConfig(JSON.parse(storage.getItem(KEY) || 'null')); } catch { return emptyConfig(); }
}

export function saveConfig(c, storage = globalThis.localStorage) {
  try { storage.setItem(KEY, JSON.stringify(validConfig(c))); } catch { /* storage refused: kept for this visit */ }
}

// Paper 000 eq. (6) with T's row k: eps_k = e_k - mean(e_1 .. e_(k-1)), eps_1 = 0
// (the synchronization error of the metrics in docs/project-format.md).
export function syncErrors(e) {
  const out = [];
  let sum = 0;
  for (let k = 0; k < e.length; k++) {
    const v = e[k];
    out.push(k === 0 || !Number.isFinite(v) || !Number.isFinite(sum) ? (k === 0 ? 0 : null) : v - sum / k);
    sum += Number.isFinite(v) ? v : NaN;
  }
  return out;
}

// Axes proposed from the program: one per SYNC_CONTROLLER instance (its x pin
// as position, its e pin as error, ordered by its axis number, else by name),
// and the first TRANSIENT_SYNC instance as the transient to draw.
export function suggestAxes(blocks) {
  const controllers = blocks.filter((b) => b.type === 'SYNC_CONTROLLER' || b.type === 'PD_CONTROLLER');
  const axes = controllers
    .sort((a, b) => a.name.localeCompare(b.name, 'en', { numeric: true }))
    .map((b) => {
      const x = b.pins.find((p) => p.name === 'x');
      return { label: b.name, position: `${b.name}.x`, error: b.pins.some((p) => p.name === 'e') ? `${b.name}.e` : '', unit: x ? x.unit : '' };
    });
  const ts = blocks.find((b) => b.type === 'TRANSIENT_SYNC');
  if (ts && !axes.length) {
    const x = ts.pins.find((p) => p.name === 'x');
    const n = x && x.length ? x.length : 0;
    for (let i = 1; i <= n; i++) axes.push({ label: `${ts.name} ${i}`, position: `${ts.name}.x[${i}]`, error: '', unit: x.unit });
  }
  return { axes, transient: ts ? ts.name : '', windowS: 10 };
}

// The refs a config streams.
export function configRefs(c) {
  const refs = new Set();
  for (const a of c.axes) { if (a.position) refs.add(a.position); if (a.error) refs.add(a.error); }
  if (c.transient) for (const p of ['x', 'r', 'arrival', 'synchronized', 'spread', 'windows']) refs.add(`${c.transient}.${p}`);
  return [...refs];
}

// Predicted end of the transient: now plus `arrival` scans of the block's task.
export function predictedEndS(arrivalScans, periodNs) {
  if (!Number.isFinite(arrivalScans) || arrivalScans <= 0 || !Number.isFinite(periodNs)) return null;
  return (arrivalScans * periodNs) / 1e9;
}
