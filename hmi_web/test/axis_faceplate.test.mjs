import { test } from 'node:test';
import assert from 'node:assert/strict';
import { ageText, axisControls, axisQuality, confirmText, errorIdText, normalizeAxes, stateTone } from '../src/lib/axis_faceplate.js';

const answer = {
  now_ns: 5e9,
  axes: [{
    name: 'x1', task: 'servo', period_ns: 1e6, unit: 'rad', state: 'ErrorStop', state_code: 7, position: 1.5,
    velocity: 0, set_position: 1.5, following_error: 0.01, command: null, command_block: null, error_id: 0x301,
    error: 'the drive faulted', powered: false, homed: true, hmi_enable: true, hmi_enable_wired: false,
    quality: { q: 'good', scan_ns: 4.99e9, age_ns: 2e6 },
  }, {
    name: 'x2', task: 'servo', period_ns: 1e6, unit: 'mm', state: 'DiscreteMotion', command: 'GroupMove',
    command_block: 'group', error_id: 0, hmi_enable: false, hmi_enable_wired: true, quality: { q: 'task_stopped', age_ns: 0 },
  }],
};

test('the answer of GET /axes in the HMI words, with its time of arrival', () => {
  const [x1, x2] = normalizeAxes(answer, 1000);
  assert.equal(x1.name, 'x1');
  assert.equal(x1.unit, 'rad');
  assert.equal(x1.errorId, 0x301);
  assert.equal(x1.quality.at, 1000);
  assert.equal(x1.hmiEnable, true);
  assert.equal(x2.command, 'GroupMove');
  assert.equal(x2.commandBlock, 'group');
  assert.equal(x2.hmiEnable, false);
  assert.equal(x2.hmiEnableWired, true);
  assert.deepEqual(normalizeAxes(null), []);
});

test('PLCopen states have a colour each; error red, motion blue, disabled grey', () => {
  assert.equal(stateTone('ErrorStop'), 'error');
  assert.equal(stateTone('DiscreteMotion'), 'moving');
  assert.equal(stateTone('SynchronizedMotion'), 'moving');
  assert.equal(stateTone('Standstill'), 'ready');
  assert.equal(stateTone('Stopping'), 'stopping');
  assert.equal(stateTone('Disabled'), 'off');
  assert.equal(stateTone('nonsense'), 'off');
  assert.equal(errorIdText(0x301), '0x0301');
  assert.equal(errorIdText(0), '0x0000');
});

test('values are stale when the PLC says so or when no newer answer came in time', () => {
  const [x1, x2] = normalizeAxes(answer, 1000);
  assert.deepEqual(axisQuality(x1, 1000), { stale: false, text: '', ageMs: 2 });
  // 3 periods (3 ms) + two polls (500 ms) + 100 ms: 603 ms.
  assert.equal(axisQuality(x1, 1000 + 600).stale, false);
  const late = axisQuality(x1, 1000 + 602);
  assert.equal(late.stale, true);
  assert.equal(late.text, 'stale');
  assert.equal(axisQuality(x2, 1000).text, 'task stopped');
  assert.equal(axisQuality(x2, 1000).stale, true);
});

test('reset for engineers only and only in ErrorStop; enable/disable for operators unless wired', () => {
  const [x1, x2] = normalizeAxes(answer, 0);
  const viewer = { role: 'viewer' }; const operator = { role: 'operator' }; const engineer = { role: 'engineer' };
  assert.equal(axisControls(x1, null).reset.shown, false);
  assert.equal(axisControls(x1, operator).reset.shown, false);
  assert.equal(axisControls(x1, engineer).reset.shown, true);
  assert.equal(axisControls(x1, engineer).reset.enabled, true);
  const standing = { ...x1, state: 'Standstill' };
  assert.equal(axisControls(standing, engineer).reset.enabled, false);
  assert.match(axisControls(standing, engineer).reset.hint, /not ErrorStop/);
  assert.equal(axisControls(x1, viewer).disable.enabled, false);
  assert.match(axisControls(x1, viewer).disable.hint, /operator/);
  assert.equal(axisControls(x1, operator).disable.enabled, true);
  assert.equal(axisControls(x1, operator).enable.enabled, false, 'already permitted');
  assert.equal(axisControls(x2, engineer).enable.enabled, false, 'the project wires the permissive');
  assert.match(axisControls(x2, engineer).enable.hint, /wired/);
  const off = { ...x1, hmiEnable: false };
  assert.equal(axisControls(off, operator).enable.enabled, true);
  assert.equal(axisControls(off, operator).disable.enabled, false);
});

test('the confirmation says what the command does', () => {
  const [x1] = normalizeAxes(answer, 0);
  assert.match(confirmText('disable', x1), /Disabled at the next scan/);
  assert.match(confirmText('enable', x1), /never powers an axis the program does not/);
  assert.match(confirmText('reset', x1), /0x0301: the drive faulted/);
});

test('the age as the faceplate writes it', () => {
  assert.equal(ageText(2.4), '2 ms old');
  assert.equal(ageText(1234), '1.2 s old');
  assert.equal(ageText(NaN), '');
});
