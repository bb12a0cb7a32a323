// Overview: the runtime, one card per task (scans, overruns, watchdog,
// execution time, start jitter and its histogram), the store; what is wrong
// first and in colour.
import { useState } from 'preact/hooks';
import { getStatus } from '../api/endpoints.js';
import { formatCount, formatNs, formatPeriod, formatUptime } from '../lib/format.js';
import { usePoll } from '../lib/poll.js';
import { ErrorNote, Stat } from '../components/common.jsx';
import { ScanHistogram } from '../components/histogram.jsx';

// The start-jitter histogram, or the execution-time one when the PLC sends it.
function TaskHistograms({ t }) {
  const [which, setWhich] = useState('jitter');
  const shown = which === 'exec' && t.exec.histogram ? 'exec' : 'jitter';
  const h = shown === 'exec' ? t.exec.histogram : t.jitter.histogram;
  return (
    <>
      <div class="hist-head">
        <h4>{shown === 'exec' ? 'Execution time: scans per duration' : 'Start jitter: scans per delay'}</h4>
        {t.exec.histogram ? (
          <div class="segmented small" role="radiogroup" aria-label={`histogram of ${t.name}`}>
            {[['jitter', 'jitter'], ['exec', 'execution']].map(([id, label]) => (
              <label class={shown === id ? 'on' : ''}><input type="radio" name={`hist-${t.name}`} checked={shown === id} onChange={() => setWhich(id)} /> {label}</label>
            ))}
          </div>
        ) : null}
      </div>
      {h ? <ScanHistogram histogram={h} label={`${shown === 'exec' ? 'execution time' : 'start jitter'} histogram of ${t.name}`} /> : <p class="hint">No histogram yet.</p>}
    </>
  );
}

function TaskCard({ t }) {
  const stopped = t.state !== 'running';
  const trouble = stopped || t.watchdogTrips > 0 || t.overruns > 0;
  return (
    <section class={`card task ${stopped ? 'bad' : trouble ? 'warn' : ''}`} data-task={t.name}>
      <header class="card-head">
        <h3>{t.name}</h3>
        <span class={`pill ${stopped ? 'pill-bad' : 'pill-ok'}`}>{stopped ? 'stopped' : 'running'}</span>
      </header>
      {stopped && t.stopReason ? <p class="error-note">Stopped: {t.stopReason}</p> : null}
      <p class="sub">every {formatPeriod(t.periodNs)}{t.priority !== null ? `, priority ${t.priority}` : ''}{t.cpu !== null && t.cpu !== undefined ? `, CPU ${t.cpu}` : ''}</p>
      <dl class="stats">
        <Stat label="Scans">{formatCount(t.scans)}</Stat>
        <Stat label="Overruns" warn={t.overruns > 0}>{formatCount(t.overruns)}</Stat>
        <Stat label="Watchdog trips" warn={t.watchdogTrips > 0}>{formatCount(t.watchdogTrips)}</Stat>
      </dl>
      <table class="mini">
        <thead><tr><th /><th>last</th><th>min</th><th>mean</th><th>p99</th><th>max</th></tr></thead>
        <tbody>
          <tr><th scope="row">Execution time</th><td>{formatNs(t.exec.last)}</td><td>{formatNs(t.exec.min)}</td><td>{formatNs(t.exec.mean)}</td><td>{formatNs(t.exec.p99)}</td><td>{formatNs(t.exec.max)}</td></tr>
          <tr><th scope="row">Start jitter</th><td>–</td><td>{formatNs(t.jitter.min)}</td><td>–</td><td>{formatNs(t.jitter.p99)}</td><td>{formatNs(t.jitter.max)}</td></tr>
        </tbody>
      </table>
      <TaskHistograms t={t} />
    </section>
  );
}

export function OverviewPage() {
  const { data, error, loading } = usePoll(getStatus, 1000);
  if (loading && !data) return <p class="hint">Reading the PLC's status…</p>;
  if (!data) return <ErrorNote error={error} />;
  const r = data.runtime;
  const stopped = data.tasks.filter((t) => t.state !== 'running');
  const storeBad = r.store && r.store.state !== 'ok';
  return (
    <>
      <h1>Overview</h1>
      <ErrorNote error={error} />
      {stopped.length ? (
        <div class="banner banner-bad" role="alert">
          {stopped.length === 1 ? `Task ${stopped[0].name} has stopped.` : `${stopped.length} tasks have stopped: ${stopped.map((t) => t.name).join(', ')}.`}
        </div>
      ) : null}
      <section class="card runtime">
        <dl class="stats wide">
          <Stat label="Project">{r.projectName || r.projectFile || '–'}{r.projectVersion !== null ? ` (version ${r.projectVersion})` : ''}</Stat>
          <Stat label="Running for">{formatUptime(r.uptimeS)}</Stat>
          <Stat label="Store" warn={storeBad}>{r.store ? r.store.state : 'none'}{r.store && r.store.detail ? `: ${r.store.detail}` : ''}</Stat>
          <Stat label="Forced values" warn={data.forces > 0}>{data.forces > 0 ? <a href="#/tags?forced">{data.forces} active</a> : 'none'}</Stat>
          <Stat label="Modbus server">{r.modbus || 'off'}</Stat>
          <Stat label="syncplc">{r.version || '–'}</Stat>
        </dl>
        {r.projectFile ? <p class="sub path">{r.projectFile}</p> : null}
      </section>
      <div class="grid">
        {data.tasks.map((t) => <TaskCard key={t.name} t={t} />)}
      </div>
    </>
  );
}
