// The pure part of the axis faceplates (components/axis_faceplate.jsx):
// GET /api/v1/axes's answer in the HMI's words, the colour of a PLCopen
// state, whether an axis's values are live, and which of the three commands
// the logged-in role may give now. No DOM (test/axis_faceplate.test.mjs).
import { rank } from '../auth/session.js';

// The faceplates poll GET /axes this often (ms).
export const AXES_POLL_MS = 250;

// PLCopen Part 1 §2.1's states, in MC_AXIS's `state` order, with the
// faceplate's colour: grey powerless, green standing ready, blue moving,
// amber stopping, red in error.
export const AXIS_STATES = [
  { name: 'Disabled', tone: 'off' },
  { name: 'Standstill', tone: 'ready' },
  { name: 'Homing', tone: 'moving' },
  { name: 'DiscreteMotion', tone: 'moving' },
  { name: 'ContinuousMotion', tone: 'moving' },
  { name: 'SynchronizedMotion', tone: 'moving' },
  { name: 'Stopping', tone: 'stopping' },
  { name: 'ErrorStop', tone: 'error' },
];

export function stateTone(name) {
  const s = AXIS_STATES.find((x) => x.name === name);
  return s ? s.tone : 'off';
}

// "0x0301": an ErrorID as the PLCopen tables write it.
export const errorIdText = (id) => `0x${(Number(id) || 0).toString(16).padStart(4, '0')}`;

// One axis of the answer, with defaults for what an older PLC does not send.
export function normalizeAxis(a, receivedAtMs) {
  const q = a.quality || {};
  return {
    name: String(a.name),
    task: a.task || '',
    periodNs: Number(a.period_ns) || 0,
    unit: a.unit || 'u',
    state: a.state || 'Disabled',
    position: a.position ?? null,
    velocity: a.velocity ?? null,
    setPosition: a.set_position ?? null,
    followingError: a.following_error ?? null,
    command: a.command || null,
    commandBlock: a.command_block || null,
    remainingScans: a.remaining_scans ?? -1,
    errorId: Number(a.error_id) || 0,
    error: a.error || '',
    powered: !!a.powered,
    homed: !!a.homed,
    hmiEnable: a.hmi_enable !== false,
    hmiEnableWired: !!a.hmi_enable_wired,
    quality: { q: q.q || 'stale', ageNs: Number(q.age_ns) || 0, at: receivedAtMs },
  };
}

export function normalizeAxes(answer, receivedAtMs = 0) {
  return ((answer && answer.axes) || []).map((a) => normalizeAxis(a, receivedAtMs));
}

const QUALITY_WORDS = { stale: 'stale', task_stopped: 'task stopped', driver_not_ok: 'driver not ok' };

// Whether the axis's values may be read as the machine's state now: not when
// the PLC says they are not live, nor when they are older than three periods
// of the axis's task and two polls (nothing newer came), as the live values'
// rule says (live/hub.js qualityOf). {stale, text, ageMs}.
export function axisQuality(axis, nowMs, pollMs = AXES_POLL_MS) {
  const q = axis.quality;
  const ageMs = q.ageNs / 1e6 + Math.max(0, nowMs - q.at);
  if (QUALITY_WORDS[q.q]) return { stale: true, text: QUALITY_WORDS[q.q], ageMs };
  const limitMs = (3 * axis.periodNs) / 1e6 + 2 * pollMs + 100;
  if (ageMs > limitMs) return { stale: true, text: 'stale', ageMs };
  return { stale: false, text: q.q === 'forced' ? 'forced' : '', ageMs };
}

// "3 ms old", "1.2 s old": a value's age as the faceplate shows it.
export function ageText(ageMs) {
  if (!(ageMs >= 0)) return '';
  return ageMs < 1000 ? `${Math.round(ageMs)} ms old` : `${(ageMs / 1000).toFixed(1)} s old`;
}

const atLeast = (session, role) => !!(session && rank(session.role) >= rank(role));

// The faceplate's buttons: whether each is shown and may be pressed, and
// why not. Reset is shown to engineers only and acts in ErrorStop only;
// enable/disable to operators and engineers, unless the project wires the
// permissive (then the program decides it).
export function axisControls(axis, session) {
  const operator = atLeast(session, 'operator');
  const engineer = atLeast(session, 'engineer');
  const wired = axis.hmiEnableWired;
  const opHint = !operator ? 'Enabling and disabling an axis needs an operator or engineer login.'
    : wired ? `${axis.name}.hmi_enable is wired in the project: the program decides it.` : '';
  return {
    reset: {
      shown: engineer,
      enabled: engineer && axis.state === 'ErrorStop',
      hint: axis.state === 'ErrorStop' ? 'Acknowledge the axis error (as MC_Reset)' : `Nothing to reset: ${axis.name} is in ${axis.state}, not ErrorStop.`,
    },
    disable: { shown: true, enabled: operator && !wired && axis.hmiEnable, hint: opHint || (axis.hmiEnable ? 'Take the axis to Disabled' : 'Already disabled from the HMI') },
    enable: { shown: true, enabled: operator && !wired && !axis.hmiEnable, hint: opHint || (axis.hmiEnable ? 'The HMI already permits this axis' : "Permit the program's MC_Power again") },
  };
}

// What the confirmation says, in words, before a command goes out.
export function confirmText(command, axis) {
  if (command === 'disable') {
    return `${axis.name} goes to Disabled at the next scan, as if its MC_Power.Enable were FALSE: a move in progress is aborted and the power stage switched off. It stays disabled until enabled here again.`;
  }
  if (command === 'enable') {
    return `${axis.name} is permitted again: the program's MC_Power powers it if it asks for power. Enabling here never powers an axis the program does not.`;
  }
  return `The error of ${axis.name} (${errorIdText(axis.errorId)}${axis.error ? `: ${axis.error}` : ''}) is acknowledged at the next scan, as MC_Reset does: the axis leaves ErrorStop once it stands and its drive's fault is gone.`;
}
