// Events: the PLC's event log, newest first, following new events live
// (GET /events?since=<newest id> every second), filtered by kind.
import { useEffect, useRef, useState } from 'preact/hooks';
import { getEvents } from '../api/endpoints.js';
import { formatWallNs } from '../lib/format.js';
import { mergeEvents } from '../lib/events.js';
import { ErrorNote } from '../components/common.jsx';

const KEEP = 2000; // events kept on the page
// The kinds the PLC records (docs/store.md), offered before any is seen.
const KNOWN_KINDS = ['start', 'stop', 'start-failed', 'reload', 'reload-failed', 'watchdog', 'task-stopped', 'safe-state',
  'overrun', 'block-fault', 'scan-hung', 'driver-fault', 'queue-overflow', 'hmi-write', 'modbus-refused', 'store-fault',
  'store-ok', 'store-moved-aside'];
const BAD = new Set(['watchdog', 'task-stopped', 'safe-state', 'scan-hung', 'driver-fault', 'block-fault', 'store-fault', 'reload-failed', 'start-failed', 'queue-overflow', 'login-failed']);
const WARN = new Set(['overrun', 'force', 'unforce', 'modbus-refused', 'store-moved-aside']);


export function EventsPage() {
  const [events, setEvents] = useState([]);
  const [kind, setKind] = useState('');
  const [follow, setFollow] = useState(true);
  const [error, setError] = useState(null);
  const newest = useRef(0);

  useEffect(() => {
    let stopped = false; let timer = null;
    async function poll() {
      if (stopped) return;
      if (!document.hidden) {
        try {
          const fresh = await getEvents({ since: newest.current, limit: 500 });
          if (stopped) return;
          if (fresh.length) {
            newest.current = Math.max(newest.current, ...fresh.map((e) => e.id));
            setEvents((list) => mergeEvents(list, fresh, KEEP));
          }
          setError(null);
        } catch (e) { if (!stopped) setError(e); }
      }
      if (follow && !stopped) timer = setTimeout(poll, 1000);
    }
    poll();
    return () => { stopped = true; clearTimeout(timer); };
  }, [follow]);

  const kinds = [...new Set([...KNOWN_KINDS, ...events.map((e) => e.kind)])].sort();

  // A kind chosen: its older events too, asked of the PLC by kind.
  useEffect(() => {
    if (!kind) return;
    getEvents({ kind, limit: 500 }).then((fresh) => setEvents((list) => mergeEvents(list, fresh, KEEP))).catch(setError);
  }, [kind]);
  const shown = kind ? events.filter((e) => e.kind === kind) : events;
  return (
    <>
      <h1>Events</h1>
      <div class="toolbar">
        <label>Kind
          <select value={kind} onChange={(e) => setKind(e.currentTarget.value)} aria-label="Kind of event">
            <option value="">every kind</option>
            {kinds.map((k) => <option value={k}>{k}</option>)}
          </select>
        </label>
        <label class="check"><input type="checkbox" checked={follow} onChange={(e) => setFollow(e.currentTarget.checked)} /> follow new events</label>
        <span class="sub">{shown.length} shown, newest first</span>
      </div>
      <ErrorNote error={error} />
      <div class="table-wrap">
        <table class="data cards" id="events-table">
          <thead><tr><th>Time</th><th>Kind</th><th>Task</th><th>Scan</th><th>What happened</th></tr></thead>
          <tbody>
            {shown.map((e) => (
              <tr data-id={e.id} class={BAD.has(e.kind) ? 'row-bad' : WARN.has(e.kind) ? 'row-warn' : ''}>
                <td data-label="Time" class="nowrap">{formatWallNs(e.timeNs)}</td>
                <td data-label="Kind"><span class="pill">{e.kind}</span></td>
                <td data-label="Task">{e.task || e.source || '–'}</td>
                <td data-label="Scan">{e.scan ?? '–'}</td>
                <td data-label="What">{e.message}{e.client ? <span class="sub"> (client {e.client})</span> : null}</td>
              </tr>
            ))}
          </tbody>
        </table>
        {!shown.length && !error ? <p class="hint">No events{kind ? ` of kind ${kind}` : ''} yet.</p> : null}
      </div>
    </>
  );
}
