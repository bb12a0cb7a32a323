// One live subscription for the whole page (docs/http-api.md, "Live
// values"): every view subscribes the refs it shows, the hub keeps the union
// on the PLC's side with POST /subscriptions and PATCH (add, drop) as views
// open and close, and reads all of them from one stream. Views read the
// newest value of a ref from here, with its quality: a value is shown as
// stale when the PLC says so (stale, task stopped, driver not ok) or when
// it is older than three periods of its task and two of the stream's
// updates (the PLC sent nothing newer for it).
import { request } from '../api/http.js';
import { openStream } from '../api/stream.js';

const subscribers = new Map(); // id → {refs:Set, notify}
const latest = new Map(); // ref → value
const forcedNow = new Map(); // ref → bool
const qualities = new Map(); // ref → {q, scanNs, ageNs, at (performance.now() when received)}
const refErrors = new Map(); // ref → why the PLC does not stream it
const periods = new Map(); // ref → its task's period in ns (from the subscription's answers)
let stream = null;
let subscription = null; // {id, refs:Set}: what the PLC holds for this page
let syncing = false;
let syncAgain = false;
let syncTimer = null;
let connection = { state: 'idle' };
const connectionListeners = new Set();
let nextId = 1;
const rate = 10; // values per second: enough to read and to plot

function wantedRefs() {
  const all = new Set();
  for (const s of subscribers.values()) for (const r of s.refs) all.add(r);
  return all;
}

function setConnection(c) {
  // 'live' comes with every event: tell the views only about changes.
  if (c.state === connection.state && c.error === connection.error && c.retryInMs === connection.retryInMs) return;
  connection = c;
  for (const l of connectionListeners) l(c);
}

function remember(answers) {
  for (const [r, a] of Object.entries(answers || {})) {
    if (a && a.error) { refErrors.set(r, a.error); periods.delete(r); } else if (a) { refErrors.delete(r); periods.set(r, a.period_ns); }
  }
}

function forget(ref) {
  latest.delete(ref); forcedNow.delete(ref); qualities.delete(ref); refErrors.delete(ref); periods.delete(ref);
}

function onValues({ tNs, values, forced, quality, errors }) {
  const at = typeof performance !== 'undefined' ? performance.now() : Date.now();
  for (const [r, v] of Object.entries(values)) latest.set(r, v);
  for (const [r, f] of Object.entries(forced)) forcedNow.set(r, !!f);
  for (const [r, q] of Object.entries(quality)) qualities.set(r, { q: q.q, scanNs: q.scan_ns, ageNs: q.age_ns, at });
  for (const [r, e] of Object.entries(errors)) { refErrors.set(r, e); latest.delete(r); qualities.delete(r); }
  for (const r of refErrors.keys()) if (r in values) refErrors.delete(r); // known again (an online change)
  for (const s of subscribers.values()) {
    for (const r of s.refs) if (r in values || r in errors) { s.notify(tNs, values); break; }
  }
}

function openFor(id) {
  if (stream) stream.close();
  stream = openStream({
    path: `/subscriptions/${id}/stream`, rate, onState: setConnection, onValues,
    // The PLC restarted, or the subscription expired: make a new one.
    onGone: () => { stream = null; subscription = null; scheduleSync(0); },
  });
}

// Brings the PLC's subscription to the views' union: one request at a time.
async function sync() {
  if (syncing) { syncAgain = true; return; }
  syncing = true;
  try {
    const want = wantedRefs();
    if (!subscription) {
      if (!want.size) { setConnection({ state: 'idle' }); return; }
      const refs = [...want].sort();
      const j = await request('POST', '/subscriptions', { body: { refs, rate } });
      subscription = { id: j.id, refs: new Set(refs) };
      remember(j.refs);
      openFor(j.id);
    } else {
      const add = [...want].filter((r) => !subscription.refs.has(r)).sort();
      const drop = [...subscription.refs].filter((r) => !want.has(r)).sort();
      if (add.length || drop.length) {
        const j = await request('PATCH', `/subscriptions/${subscription.id}`, { body: { add, drop } });
        for (const r of add) subscription.refs.add(r);
        // Values no longer streamed would be stale when a view shows them again.
        for (const r of drop) { subscription.refs.delete(r); forget(r); }
        remember(j.refs);
      }
      if (!stream) openFor(subscription.id);
    }
  } catch (e) {
    if (e && e.status === 404) subscription = null; // gone on the PLC's side: make a new one
    // Unreachable or refused: the link badge says so; try again shortly.
    setConnection({ state: 'lost', error: e && e.message ? e.message : String(e), retryInMs: 1000 });
    scheduleSync(1000);
  } finally {
    syncing = false;
    if (syncAgain) { syncAgain = false; scheduleSync(0); }
  }
}

function scheduleSync(ms = 50) {
  clearTimeout(syncTimer);
  syncTimer = setTimeout(sync, ms);
}

// Subscribes refs; notify(tNs, values) is called after every update that
// carries one of them. Returns an unsubscribe function.
export function subscribe(refs, notify) {
  const id = nextId++;
  subscribers.set(id, { refs: new Set(refs), notify });
  scheduleSync();
  return () => { subscribers.delete(id); scheduleSync(); };
}

// Start again (after a login or logout: the subscription belongs to a session).
export function restart() {
  if (stream) stream.close();
  stream = null;
  const old = subscription;
  subscription = null;
  if (old) request('DELETE', `/subscriptions/${old.id}`).catch(() => {});
  scheduleSync(0);
}

export const valueOf = (ref) => latest.get(ref);
export const isForced = (ref) => forcedNow.get(ref) === true;
export const hasValue = (ref) => latest.has(ref);
// Why the PLC does not stream ref (unknown, hmi: none), or undefined.
export const refError = (ref) => refErrors.get(ref);

const QUALITY_WORDS = { stale: 'stale', task_stopped: 'task stopped', driver_not_ok: 'driver not ok' };

// {q, stale, text, ageMs} of ref's newest value, or null before the first.
// stale: not to be read as the machine's state now.
export function qualityOf(ref) {
  const q = qualities.get(ref);
  if (!q) return null;
  const now = typeof performance !== 'undefined' ? performance.now() : Date.now();
  const ageMs = q.ageNs / 1e6 + (now - q.at);
  const period = periods.get(ref);
  const limitMs = (period ? (3 * period) / 1e6 : 0) + 2 * (1000 / rate) + 100;
  if (QUALITY_WORDS[q.q]) return { q: q.q, stale: true, text: QUALITY_WORDS[q.q], ageMs };
  if (ageMs > limitMs) return { q: 'stale', stale: true, text: 'stale', ageMs };
  return { q: q.q, stale: false, text: q.q === 'forced' ? 'forced' : '', ageMs };
}

export const connectionState = () => connection;
export function onConnection(listener) {
  connectionListeners.add(listener);
  return () => connectionListeners.delete(listener);
}
