import { test } from 'node:test';
import assert from 'node:assert/strict';
import { normalizeBlocks, normalizeEvents, normalizeProjectReport, normalizeStatus, normalizeTags, normalizeTrend, normalizeVersions, parseWhere } from '../src/api/shapes.js';

test('status after the outline: runtime, tasks with statistics and histogram, forces', () => {
  const s = normalizeStatus({
    runtime: { version: '0.1.0', project_file: 'p.yaml', project_version: 3, uptime_s: 12.5, store: 'ok', modbus: '127.0.0.1:502' },
    tasks: [{ name: 'servo', period_ns: 1000000, priority: 80, cpu: 1, state: 'stopped', stop_reason: 'watchdog', scans: 10, overruns: 1, watchdog_trips: 2,
      exec_ns: { last: 5, min: 1, max: 9, mean: 4, p99: 8 }, start_jitter_ns: { min: 1, max: 3, p99: 2, histogram: { bounds_ns: [1000], counts: [4, 1] } } }],
    forces: 2,
  });
  assert.deepEqual(s.runtime.store, { state: 'ok', detail: null });
  assert.equal(s.runtime.projectVersion, 3);
  const t = s.tasks[0];
  assert.equal(t.periodNs, 1e6);
  assert.equal(t.state, 'stopped');
  assert.equal(t.watchdogTrips, 2);
  assert.deepEqual(t.exec, { last: 5, min: 1, max: 9, mean: 4, p99: 8, histogram: null });
  assert.deepEqual(t.jitter.histogram, { boundsNs: [1000], counts: [4, 1] });
  assert.equal(s.forces, 2);
  assert.deepEqual(normalizeStatus({}).tasks, []);
});

test('lists bare or wrapped; tags keep their access, forced flags and bounds', () => {
  const bare = normalizeTags([{ name: 'a', type: 'INT', hmi: 'readwrite' }]);
  const wrapped = normalizeTags({ tags: [{ name: 'a', type: 'INT', hmi: 'readwrite' }] });
  assert.deepEqual(bare, wrapped);
  assert.equal(bare[0].access, 'readwrite');
  const arr = normalizeTags({ tags: [{ name: 'v', type: 'ARRAY[0..1] OF BOOL', length: 2, lower: 0, forced: [false, true] }] })[0];
  assert.deepEqual([arr.length, arr.lower, arr.forced], [2, 0, [false, true]]);
  assert.equal(normalizeEvents({ events: [{ id: 3, time_ns: 5, kind: 'start', message: 'm' }] })[0].timeNs, 5);
});

test('file:line:col in errors, strings or objects', () => {
  assert.deepEqual(parseWhere('tasks.yaml:3:13'), { file: 'tasks.yaml', line: 3, col: 13 });
  assert.deepEqual(parseWhere('dir/a.yaml:12'), { file: 'dir/a.yaml', line: 12, col: null });
  assert.equal(parseWhere('no location'), null);
  const r = normalizeProjectReport({ ok: false, errors: ["a.yaml:16:13: period: '10xs' is not a duration", { where: 'b.yaml:2:1', message: 'unknown key' }, { message: 'no where' }] });
  assert.equal(r.ok, false);
  assert.deepEqual(r.errors.map((e) => [e.where && e.where.file, e.where && e.where.line, e.message]),
    [['a.yaml', 16, "period: '10xs' is not a duration"], ['b.yaml', 2, 'unknown key'], [null, null, 'no where']]);
  const single = normalizeProjectReport({ error: 'bad', where: 'a.yaml:1:2' });
  assert.equal(single.ok, false);
  assert.equal(single.errors[0].where.col, 2);
});

test('a change report and the versions', () => {
  const r = normalizeProjectReport({ ok: true, version: 4, report: { kept: ['a', { name: 'b' }], retuned: [], rewired: ['d'], new: ['c'], removed: [], summary: 's' } });
  assert.deepEqual(r.report, { kept: ['a', 'b'], retuned: [], rewired: ['d'], new: ['c'], removed: [], summary: 's' });
  assert.equal(r.version, 4);
  const v = normalizeVersions({ versions: [{ version: 2, outcome: 'rejected', errors: ['x.yaml:1:1: bad'] }] })[0];
  assert.equal(v.errors[0].where.file, 'x.yaml');
});

test('trends: one series or several, points as objects or rows', () => {
  const one = normalizeTrend({ tag: 'pos', unit: 'rad', points: [{ t_ns: 1, min: 0, max: 2, mean: 1, count: 10 }] });
  assert.deepEqual(one.series[0], { label: 'pos', unit: 'rad', points: [{ t: 1, min: 0, max: 2, mean: 1, count: 10 }] });
  const many = normalizeTrend({ tag: 'axes', series: [{ label: 'axes[1]', points: [[1, 0, 2, 1, 5]] }] });
  assert.equal(many.series[0].points[0].max, 2);
});

test('the server as runtime/web writes it: _ns keys, jitter, element type with is_array, written every scan', () => {
  const s = normalizeStatus({ runtime: { program: 'demo', program_version: '1.0.0', store: 'ok' },
    tasks: [{ name: 't', exec: { count: 3, min_ns: 1, max_ns: 9, mean_ns: 4, p99_ns: 8, last_ns: 5, histogram: { bounds_ns: [2000, 4000], counts: [1, 2] } }, jitter: { min_ns: 2, max_ns: 7, p99_ns: 6, histogram: { bounds_ns: [1000], counts: [3] } } }] });
  assert.equal(s.runtime.projectName, 'demo 1.0.0');
  // What it leaves out is null, never undefined (the overview showed "(version undefined)").
  assert.equal(s.runtime.projectVersion, null);
  assert.equal(s.tasks[0].cpu, null);
  assert.equal(s.tasks[0].stopReason, null);
  // A load's answer without "version" (runtime/web/api_projects.cpp sends none): null, shown as "Loaded."
  const load = normalizeProjectReport({ ok: true, summary: 's', errors: [], lines: [], report: { kept: ['a'], retuned: ['b'], new: [], removed: [] } });
  assert.equal(load.version, null);
  assert.deepEqual(load.report, { kept: ['a'], retuned: ['b'], rewired: [], new: [], removed: [], summary: 's' });
  assert.deepEqual(s.tasks[0].exec, { last: 5, min: 1, max: 9, mean: 4, p99: 8, histogram: { boundsNs: [2000, 4000], counts: [1, 2] } });
  assert.equal(s.tasks[0].jitter.p99, 6);
  assert.deepEqual(s.tasks[0].jitter.histogram.counts, [3]);
  const [arr, every] = normalizeTags({ tags: [
    { name: 'pos', type: 'LREAL', is_array: true, length: 4, array_lower: 0, hmi: 'readwrite' },
    { name: 'cmd', type: 'INT', is_array: false, length: 1, hmi: 'readwrite', written_every_scan: true },
  ] });
  assert.equal(arr.type, 'ARRAY[0..3] OF LREAL');
  assert.equal(arr.writable, true);
  assert.equal(every.type, 'INT');
  assert.equal(every.writable, false);
});

test('blocks keep their pins, and an ST instance its variables', () => {
  const [b, c] = normalizeBlocks({ blocks: [
    { name: 'cell', type: 'Cell', task: 'main', position: 0, pins: [{ name: 'run_in', direction: 'in', type: 'BOOL', value: true }],
      variables: [{ name: 'scans', type: 'DINT', value: 7, forced: false }, { name: 't.ET', type: 'TIME', value: null, forced: true }] },
    { name: 'k', type: 'MOVE<LREAL>', pins: [] },
  ] });
  assert.deepEqual(b.variables, [{ name: 'scans', type: 'DINT', value: 7, forced: false }, { name: 't.ET', type: 'TIME', value: null, forced: true }]);
  assert.equal(b.pins[0].name, 'run_in');
  assert.deepEqual(c.variables, []);
});
