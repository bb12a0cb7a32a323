// One live stream for the whole page: every view subscribes the refs it shows,
// the hub keeps the union and reopens the stream (once, shortly after) when
// it changes. Views read the newest value of a ref from here.
import { openStream } from '../api/stream.js';

const subscribers = new Map(); // id → {refs:Set, notify}
const latest = new Map(); // ref → value
const forcedNow = new Map(); // ref → bool
let stream = null;
let streamKey = '';
let reopenTimer = null;
let connection = { state: 'idle' };
const connectionListeners = new Set();
let nextId = 1;
const rate = 10; // values per second: enough to read and to plot

function wantedRefs() {
  const all = new Set();
  for (const s of subscribers.values()) for (const r of s.refs) all.add(r);
  return [...all].sort();
}

function setConnection(c) {
  // 'live' comes with every event: tell the views only about changes.
  if (c.state === connection.state && c.error === connection.error && c.retryInMs === connection.retryInMs) return;
  connection = c;
  for (const l of connectionListeners) l(c);
}

function reopen() {
  clearTimeout(reopenTimer);
  reopenTimer = setTimeout(() => {
    const refs = wantedRefs();
    const key = `${rate}|${refs.join(',')}`;
    if (key === streamKey && stream) return;
    if (stream) stream.close();
    stream = null;
    streamKey = key;
    // Values no longer streamed would be stale when a view shows them again.
    const keep = new Set(refs);
    for (const r of [...latest.keys()]) if (!keep.has(r)) { latest.delete(r); forcedNow.delete(r); }
    if (!refs.length) { setConnection({ state: 'idle' }); return; }
    stream = openStream({
      refs, rate,
      onState: setConnection,
      onValues: ({ tNs, values, forced }) => {
        for (const [r, v] of Object.entries(values)) latest.set(r, v);
        for (const [r, f] of Object.entries(forced)) forcedNow.set(r, !!f);
        // Only those whose refs this event carries (the stream being replaced
        // may still deliver one event of the refs it had).
        for (const s of subscribers.values()) {
          for (const r of s.refs) if (r in values) { s.notify(tNs, values); break; }
        }
      },
    });
  }, 50);
}

// Subscribes refs; notify(tNs, values) is called after every update that
// carries one of them. Returns an
// unsubscribe function.
export function subscribe(refs, notify) {
  const id = nextId++;
  subscribers.set(id, { refs: new Set(refs), notify });
  reopen();
  return () => { subscribers.delete(id); reopen(); };
}

// Reconnect now (after a login: the stream may now be allowed).
export function restart() {
  if (stream) stream.close();
  stream = null;
  streamKey = '';
  reopen();
}

export const valueOf = (ref) => latest.get(ref);
export const isForced = (ref) => forcedNow.get(ref) === true;
export const hasValue = (ref) => latest.has(ref);
export const connectionState = () => connection;
export function onConnection(listener) {
  connectionListeners.add(listener);
  return () => connectionListeners.delete(listener);
}
