// Project: upload a project (its main YAML file, includes and ST sources), check it
// without loading (errors shown at their line), load it by online change
// (the kept/retuned/new/removed report), the stored versions and rollback.
import { useEffect, useState } from 'preact/hooks';
import { checkProject, getProjects, loadProject, rollback } from '../api/endpoints.js';
import { can, hint } from '../auth/session.js';
import { errorsByLine, guessMain, projectBody, relativeNames, sameFile } from '../lib/project_files.js';
import { formatWallNs } from '../lib/format.js';
import { usePoll } from '../lib/poll.js';
import { ErrorNote, Modal } from '../components/common.jsx';

function SourceView({ file, errors, focusLine }) {
  const lines = file.text.split('\n');
  const byLine = errorsByLine(errors, file.name);
  useEffect(() => {
    if (!focusLine) return;
    // Scroll the source box only, not the page.
    const el = document.getElementById(`src-line-${focusLine}`);
    const box = el && el.parentElement;
    if (el && box) box.scrollTop = Math.max(0, el.offsetTop - box.offsetTop - box.clientHeight / 2);
  }, [file.name, focusLine]);
  return (
    <div class="source" aria-label={`source of ${file.name}`}>
      {lines.map((text, i) => {
        const n = i + 1;
        const errs = byLine.get(n);
        return (
          <div id={`src-line-${n}`} class={errs ? 'src-line has-error' : 'src-line'} data-line={n}>
            <span class="ln">{n}</span>
            <code class="txt">{text || ' '}</code>
            {errs ? (
              <span class="src-msg" role="note">
                {errs.map((e) => <span>{e.where.col ? `column ${e.where.col}: ` : ''}{e.message}</span>)}
              </span>
            ) : null}
          </div>
        );
      })}
    </div>
  );
}

function ChangeReport({ report }) {
  if (!report) return null;
  const groups = [['kept', 'Kept (state carried over)'], ['retuned', 'Retuned (new tunable parameters, state kept)'], ['rewired', 'Rewired (new wiring, state kept)'], ['new', 'New'], ['removed', 'Removed']];
  return (
    <section class="card report" id="change-report">
      <h2>What the change did</h2>
      {report.summary ? <p>{report.summary}</p> : null}
      <dl class="stats wide">
        {groups.map(([k, label]) => (
          <div class="stat"><dt>{label}</dt><dd><strong>{report[k].length}</strong>{report[k].length ? <span class="sub"> {report[k].join(', ')}</span> : null}</dd></div>
        ))}
      </dl>
    </section>
  );
}

function Versions({ session, reloadKey, onRolledBack }) {
  // Read again every few seconds: the PLC marks the new version running a
  // moment after it answers a load, and a change may come from elsewhere
  // (`syncplc reload`, another browser).
  const { data: versions, error: readError } = usePoll(getProjects, 3000, [reloadKey]);
  const [actionError, setError] = useState(null);
  const error = actionError || (versions ? null : readError);
  const [confirm, setConfirm] = useState(null);
  const [busy, setBusy] = useState(false);

  async function doRollback() {
    setBusy(true);
    setError(null);
    try {
      const r = await rollback(confirm.version);
      setConfirm(null);
      onRolledBack(r, confirm.version);
    } catch (e) { setError(e); setConfirm(null); } finally { setBusy(false); }
  }

  return (
    <section class="card" id="versions">
      <h2>Stored versions</h2>
      <ErrorNote error={error} />
      {versions ? (
        <div class="table-wrap">
          <table class="data cards">
            <thead><tr><th>#</th><th>Time</th><th>How</th><th>Outcome</th><th>Project</th><th>Files</th><th /></tr></thead>
            <tbody>
              {[...versions].sort((a, b) => b.version - a.version).map((v) => (
                <tr data-version={v.version} class={v.outcome === 'rejected' ? 'row-bad' : ''}>
                  <td data-label="Version">{v.version}{v.running ? <span class="pill pill-ok">running</span> : null}</td>
                  <td data-label="Time" class="nowrap">{formatWallNs(v.timeNs, false)}</td>
                  <td data-label="How">{v.origin}</td>
                  <td data-label="Outcome">{v.outcome}{v.errors.length ? <div class="sub">{v.errors[0].text}</div> : null}</td>
                  <td data-label="Project">{v.project || '–'} <span class="sub">{v.hash.slice(0, 8)}</span></td>
                  <td data-label="Files">{v.files ?? '–'}</td>
                  <td data-label="">
                    <button type="button" class="btn small" disabled={!can('project', session) || v.outcome !== 'accepted' || v.running}
                      title={!can('project', session) ? hint('project') : v.outcome !== 'accepted' ? 'Only an accepted version can be loaded again.' : v.running ? 'This version is running.' : ''}
                      onClick={() => setConfirm(v)}>Roll back to this</button>
                  </td>
                </tr>
              ))}
            </tbody>
          </table>
        </div>
      ) : !error ? <p class="hint">Reading the versions…</p> : null}
      <Modal open={!!confirm} title={confirm ? `Roll back to version ${confirm.version}` : ''} onClose={() => setConfirm(null)}>
        {confirm ? (
          <div class="form">
            <p>The PLC loads version {confirm.version} ({confirm.project || 'no name'}) by online change: block instances that match keep their state, the others start afresh. The running program is not stopped.</p>
            <div class="actions">
              <button type="button" class="btn" onClick={() => setConfirm(null)}>Cancel</button>
              <button type="button" class="btn danger" disabled={busy} onClick={doRollback}>Roll back</button>
            </div>
          </div>
        ) : null}
      </Modal>
    </section>
  );
}

export function ProjectPage({ session }) {
  const [files, setFiles] = useState([]);
  const [main, setMain] = useState('');
  const [result, setResult] = useState(null); // {kind: 'check'|'load'|'rollback', report}
  const [viewFile, setViewFile] = useState('');
  const [focusLine, setFocusLine] = useState(null);
  const [error, setError] = useState(null);
  const [busy, setBusy] = useState('');
  const [versionsKey, setVersionsKey] = useState(0);
  const [skipped, setSkipped] = useState(0);
  const allowed = can('project', session);

  async function pick(e) {
    const all = [...e.currentTarget.files];
    // From a folder: the project's text files only (YAML and CSV tables).
    const list = all.filter((f) => /\.(ya?ml|csv|st)$/i.test(f.name));
    setSkipped(all.length - list.length);
    const read = await Promise.all(list.map(async (f) => ({ path: f.webkitRelativePath || f.name, text: await f.text() })));
    const named = relativeNames(read);
    setFiles(named);
    const m = guessMain(named);
    setMain(m);
    setViewFile(m);
    setResult(null);
    setError(null);
  }

  async function run(kind) {
    setBusy(kind);
    setError(null);
    try {
      const call = kind === 'check' ? checkProject : loadProject;
      const report = await call(projectBody(files, main));
      setResult({ kind, report });
      const firstErr = report.errors.find((x) => x.where);
      if (firstErr) {
        const f = files.find((x) => sameFile(firstErr.where.file, x.name));
        if (f) setViewFile(f.name);
        setFocusLine(firstErr.where.line);
      }
      if (kind === 'load') setVersionsKey((k) => k + 1);
    } catch (e) { setError(e); } finally { setBusy(''); }
  }

  const shownFile = files.find((f) => f.name === viewFile);
  const r = result && result.report;
  return (
    <>
      <h1>Project</h1>
      {!allowed ? <p class="hint">{hint('project')} You can still look at the stored versions.</p> : null}
      <section class="card form">
        <h2>Upload a project</h2>
        <p class="hint">Choose the project's files: the main YAML file, every file it includes and its Structured Text sources (select several at once, or a whole folder).</p>
        <div class="toolbar">
          <label class="btn file-btn">Choose files…<input type="file" multiple accept=".yaml,.yml,.csv,.st" onChange={pick} name="files" /></label>
          <label class="btn file-btn">Choose a folder…<input type="file" webkitdirectory multiple onChange={pick} name="folder" /></label>
        </div>
        {files.length ? (
          <>
            <label>Main file
              <select value={main} onChange={(e) => setMain(e.currentTarget.value)}>{files.map((f) => <option value={f.name}>{f.name}</option>)}</select>
            </label>
            <p class="sub">{files.length} file{files.length > 1 ? 's' : ''}: {files.map((f) => f.name).join(', ')}{skipped ? ` (${skipped} other file${skipped > 1 ? 's' : ''} left out: only .yaml, .yml, .csv and .st are sent)` : ''}</p>
            <div class="actions left">
              <button type="button" class="btn" disabled={!allowed || !!busy} title={allowed ? 'Check without changing the running program' : hint('project')} onClick={() => run('check')}>{busy === 'check' ? 'Checking…' : 'Check'}</button>
              <button type="button" class="btn primary" disabled={!allowed || !!busy} title={allowed ? 'Load by online change; the running program is replaced between two scans' : hint('project')} onClick={() => run('load')}>{busy === 'load' ? 'Loading…' : 'Load onto the PLC'}</button>
            </div>
          </>
        ) : null}
        <ErrorNote error={error} />
      </section>
      {r ? (
        <section class={`card ${r.ok ? 'good' : 'bad'}`} id="check-result">
          <h2>{r.ok ? (result.kind === 'check' ? 'The project is fine: it would load.' : result.kind === 'rollback' ? 'Rolled back.' : `Loaded${r.version !== null ? ` as version ${r.version}` : ''}.`)
            : `${r.errors.length} error${r.errors.length === 1 ? '' : 's'}: ${result.kind === 'check' ? 'the project would not load' : 'not loaded; the running program is unchanged'}.`}</h2>
          {r.errors.length ? (
            <ul class="errors">
              {r.errors.map((e) => (
                <li>
                  {e.where ? (
                    <button type="button" class="link" onClick={() => { const f = files.find((x) => sameFile(e.where.file, x.name)); if (f) setViewFile(f.name); setFocusLine(e.where.line); }}>
                      {e.where.file}, line {e.where.line}{e.where.col ? `, column ${e.where.col}` : ''}
                    </button>
                  ) : null}
                  {e.where ? ': ' : ''}{e.message}
                </li>
              ))}
            </ul>
          ) : null}
        </section>
      ) : null}
      {r && r.report ? <ChangeReport report={r.report} /> : null}
      {shownFile ? (
        <section class="card">
          <div class="toolbar">
            <h2>Source</h2>
            {files.length > 1 ? (
              <select value={viewFile} aria-label="File shown" onChange={(e) => setViewFile(e.currentTarget.value)}>{files.map((f) => <option value={f.name}>{f.name}</option>)}</select>
            ) : <span class="sub">{shownFile.name}</span>}
          </div>
          <SourceView file={shownFile} errors={r ? r.errors : []} focusLine={focusLine} />
        </section>
      ) : null}
      <Versions session={session} reloadKey={versionsKey}
        onRolledBack={(report, v) => { setResult({ kind: 'rollback', report: { ...report, version: report.version ?? v } }); setVersionsKey((k) => k + 1); }} />
    </>
  );
}
