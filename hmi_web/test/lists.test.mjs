import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mergeEvents } from '../src/lib/events.js';
import { histogramBars } from '../src/lib/histogram.js';
import { tagMatches } from '../src/lib/tag_filter.js';
import { trendData } from '../src/lib/trend_data.js';
import { errorsByLine, guessMain, projectBody, relativeNames } from '../src/lib/project_files.js';

test('events: merged newest first, without duplicates, at most `keep`', () => {
  const list = mergeEvents([{ id: 2 }, { id: 1 }], [{ id: 3 }, { id: 2 }, { id: 4 }]);
  assert.deepEqual(list.map((e) => e.id), [4, 3, 2, 1]);
  assert.deepEqual(mergeEvents(list, [{ id: 5 }], 3).map((e) => e.id), [5, 4, 3]);
  assert.equal(mergeEvents(list, [{ id: 4 }]), list);
});

test('histogram bars: empty buckets at both ends trimmed, the overflow bucket labelled', () => {
  const b = histogramBars({ boundsNs: [1000, 2000, 5000], counts: [0, 4, 0, 1] });
  assert.deepEqual(b.cnt, [4, 0, 1]);
  assert.deepEqual(b.labels, ['≤2.00 µs', '≤5.00 µs', '>5.00 µs']);
});

test('tag filter: every word must match somewhere, case-insensitive, values too', () => {
  const t = { name: 'speed', type: 'LREAL', unit: 'm/s', task: 'servo', access: 'readwrite', description: 'conveyor set-point' };
  assert.ok(tagMatches(t, 'SPEED', ''));
  assert.ok(tagMatches(t, 'read & write servo', ''));
  assert.ok(tagMatches(t, 'm/s 2.25', '2.25'));
  assert.ok(!tagMatches(t, 'speed planner', ''));
  assert.ok(!tagMatches(t, 'read only', ''));
});

test('trend columns: times in s, min/max/mean per series, gaps as null', () => {
  const cols = trendData({ series: [
    { label: 'a', points: [{ t: 1e9, min: 0, max: 2, mean: 1 }, { t: 2e9, min: 1, max: 3, mean: 2 }] },
    { label: 'b', points: [{ t: 2e9, min: 5, max: 6, mean: 5.5 }] },
  ] });
  assert.deepEqual(cols, [[1, 2], [0, 1], [2, 3], [1, 2], [null, 5], [null, 6], [null, 5.5]]);
});

test('project files: named from their common folder; the main file is the one not included', () => {
  const named = relativeNames([{ path: 'proj/sync.yaml', text: 'project: {name: s}\ninclude: table.yaml\n' }, { path: 'proj/table.yaml', text: 'tasks: []\n' }]);
  assert.deepEqual(named.map((f) => f.name), ['sync.yaml', 'table.yaml']);
  assert.equal(guessMain([named[1], named[0]]), 'sync.yaml');
  assert.equal(guessMain([{ name: 'a.yaml', text: 'include:\n  - parts/b.yaml\n' }, { name: 'parts/b.yaml', text: 'x: 1' }]), 'a.yaml');
  assert.equal(guessMain([{ name: 'x.yaml', text: 'include: [y.yaml, z.yaml]' }, { name: 'y.yaml', text: '' }, { name: 'z.yaml', text: '' }]), 'x.yaml');
  assert.deepEqual(projectBody(named, 'sync.yaml'), { main: 'sync.yaml', files: { 'sync.yaml': named[0].text, 'table.yaml': 'tasks: []\n' } });
  const byLine = errorsByLine([{ where: { file: '/tmp/x/table.yaml', line: 3, col: 1 }, message: 'm' }, { where: null, message: 'n' }], 'table.yaml');
  assert.deepEqual([...byLine.keys()], [3]);
});

test('a tag with hmi: none is named for who sees it: engineers only', async () => {
  const { ACCESS_WORDS, tagMatches } = await import('../src/lib/tag_filter.js');
  assert.equal(ACCESS_WORDS.none, 'engineers only (hmi: none)');
  assert.ok(tagMatches({ name: 'sw', type: 'BOOL', access: 'none' }, 'engineers', 'TRUE'));
});
