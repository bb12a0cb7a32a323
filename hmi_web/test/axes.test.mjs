import { test } from 'node:test';
import assert from 'node:assert/strict';
import { configRefs, loadConfig, predictedEndS, saveConfig, suggestAxes, syncErrors, validConfig } from '../src/lib/axes_config.js';

test('synchronization errors: eps_k = e_k - mean(e_1..e_(k-1)), paper 000 eq. (6)', () => {
  assert.deepEqual(syncErrors([1, 3, 5, 2]), [0, 2, 3, 2 - 3]);
  assert.deepEqual(syncErrors([0.5]), [0]);
  assert.deepEqual(syncErrors([1, null, 4]), [0, null, null]);
});

test('the predicted end: arrival scans times the task period', () => {
  assert.equal(predictedEndS(42, 10e6), 0.42);
  assert.equal(predictedEndS(0, 10e6), null);
  assert.equal(predictedEndS(-1, 10e6), null);
  assert.equal(predictedEndS(5, null), null);
});

test('suggestions from the blocks: controllers in axis order, the TRANSIENT_SYNC', () => {
  const pin = (name, unit = 'rad', length = 1) => ({ name, unit, length });
  const blocks = [
    { name: 'ax10', type: 'SYNC_CONTROLLER', pins: [pin('x'), pin('e')] },
    { name: 'ax2', type: 'SYNC_CONTROLLER', pins: [pin('x'), pin('e')] },
    { name: 'sync', type: 'TRANSIENT_SYNC', pins: [pin('x', 'm', 3)] },
  ];
  const s = suggestAxes(blocks);
  assert.deepEqual(s.axes.map((a) => a.position), ['ax2.x', 'ax10.x']);
  assert.equal(s.axes[0].error, 'ax2.e');
  assert.equal(s.transient, 'sync');
  const only = suggestAxes([blocks[2]]);
  assert.deepEqual(only.axes.map((a) => a.position), ['sync.x[1]', 'sync.x[2]', 'sync.x[3]']);
  assert.deepEqual(configRefs(s).slice(0, 4), ['ax2.x', 'ax2.e', 'ax10.x', 'ax10.e']);
  assert.ok(configRefs(s).includes('sync.arrival'));
});

test('the choice is kept in storage; anything malformed gives an empty choice', () => {
  const mem = new Map();
  const storage = { getItem: (k) => mem.get(k) ?? null, setItem: (k, v) => mem.set(k, v) };
  assert.deepEqual(loadConfig(storage), { axes: [], transient: '', windowS: 10 });
  saveConfig({ axes: [{ label: 'a', position: 'pos[1]', error: 'err[1]', unit: 'rad' }], transient: 'sync', windowS: 30 }, storage);
  assert.deepEqual(loadConfig(storage).axes[0], { label: 'a', position: 'pos[1]', error: 'err[1]', unit: 'rad' });
  assert.equal(loadConfig(storage).windowS, 30);
  mem.set('syncplc.axes', '{not json');
  assert.deepEqual(loadConfig(storage).axes, []);
  assert.equal(validConfig({ axes: [], windowS: 1e9 }).windowS, 10);
});
