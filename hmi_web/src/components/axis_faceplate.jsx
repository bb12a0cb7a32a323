// One PLCopen axis (an MC_AXIS instance) as a faceplate: its state in
// PLCopen's words and colour, position, velocity and following error with
// the axis's unit, the active command with the block that gave it, the axis
// error, whether the values are live (greyed, with a badge, when not), and
// the HMI's commands: enable/disable for operators, reset for engineers,
// each after a confirmation in words.
import { useState } from 'preact/hooks';
import { axisCommand } from '../api/endpoints.js';
import { ageText, axisControls, axisQuality, confirmText, errorIdText, stateTone } from '../lib/axis_faceplate.js';
import { formatScalar } from '../lib/format.js';
import { ErrorNote, Modal, Stat } from './common.jsx';

const LABELS = { enable: 'Enable', disable: 'Disable', reset: 'Reset' };

function Num({ v, unit, stale }) {
  return (
    <span class={stale ? 'value stale' : 'value'}>
      <span class="num">{v === null ? '–' : formatScalar(v, 'LREAL')}</span>
      {unit ? <span class="unit"> {unit}</span> : null}
    </span>
  );
}

function ConfirmCommand({ command, axis, onClose, onDone }) {
  const [error, setError] = useState(null);
  const [busy, setBusy] = useState(false);
  async function go(e) {
    e.preventDefault();
    setBusy(true);
    setError(null);
    try {
      await axisCommand(axis.name, command);
      onDone(`${LABELS[command]} ${axis.name}: sent, acts at the next scan of task ${axis.task}.`);
    } catch (err) {
      setError(err);
    } finally {
      setBusy(false);
    }
  }
  return (
    <Modal open title={`${LABELS[command]} ${axis.name}`} onClose={onClose}>
      <form class="form" onSubmit={go}>
        <p class="confirm-text">{confirmText(command, axis)}</p>
        <ErrorNote error={error} />
        <div class="actions">
          <button type="button" class="btn" onClick={onClose}>Cancel</button>
          <button type="submit" class={command === 'enable' ? 'btn primary' : 'btn danger'} disabled={busy}>{LABELS[command]}</button>
        </div>
      </form>
    </Modal>
  );
}

export function AxisFaceplate({ axis, session, nowMs, onNotice }) {
  const [asking, setAsking] = useState(null);
  const q = axisQuality(axis, nowMs);
  const controls = axisControls(axis, session);
  const tone = stateTone(axis.state);
  const u = axis.unit;
  return (
    <section class={`card axis-faceplate tone-${tone}${q.stale ? ' stale' : ''}`} data-axis={axis.name}
      data-state={axis.state} data-stale={q.stale ? 'true' : 'false'}>
      <header class="card-head">
        <h3>{axis.name} <span class="sub">task {axis.task}</span></h3>
        <span class={`pill axis-state state-${tone}`} title={`PLCopen state ${axis.state}`}>{axis.state}</span>
      </header>
      {q.stale ? (
        <p class="stale-note axis-quality" data-quality={axis.quality.q}><span class="badge badge-stale">{q.text}</span> values {ageText(q.ageMs)}: not the axis's state now</p>
      ) : (
        <p class="sub axis-quality" data-quality={axis.quality.q}>live{q.text ? ` (${q.text})` : ''}, {ageText(q.ageMs)}</p>
      )}
      <dl class="stats">
        <Stat label="Position"><Num v={axis.position} unit={u} stale={q.stale} /></Stat>
        <Stat label="Velocity"><Num v={axis.velocity} unit={`${u}/s`} stale={q.stale} /></Stat>
        <Stat label="Following error"><Num v={axis.followingError} unit={u} stale={q.stale} /></Stat>
      </dl>
      <dl class="stats">
        <Stat label="Command">
          <span class="axis-command">{axis.command ? axis.command : 'none'}</span>
          {axis.commandBlock ? <span class="sub"> by <span class="axis-source">{axis.commandBlock}</span></span> : null}
        </Stat>
        <Stat label="Power">{axis.powered ? 'on' : 'off'}{axis.hmiEnable ? '' : <span class="pill pill-bad">HMI disabled</span>}</Stat>
        <Stat label="Homed">{axis.homed ? 'yes' : 'no'}</Stat>
      </dl>
      {axis.errorId ? (
        <p class="error-note axis-error" role="alert">Error {errorIdText(axis.errorId)}: {axis.error}</p>
      ) : null}
      <div class="actions axis-actions">
        {['enable', 'disable', 'reset'].filter((c) => controls[c].shown).map((c) => (
          <button type="button" class={c === 'enable' ? 'btn small' : 'btn small danger'} disabled={!controls[c].enabled}
            title={controls[c].hint} onClick={() => setAsking(c)}>{LABELS[c]}</button>
        ))}
      </div>
      {asking ? (
        <ConfirmCommand command={asking} axis={axis} onClose={() => setAsking(null)}
          onDone={(text) => { setAsking(null); onNotice(text); }} />
      ) : null}
    </section>
  );
}
