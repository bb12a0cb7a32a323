import { test } from 'node:test';
import assert from 'node:assert/strict';
import { parseInput } from '../src/lib/iec.js';

test('BOOL takes TRUE/FALSE, 1/0, on/off', () => {
  for (const t of ['TRUE', 'true', '1', 'on']) assert.deepEqual(parseInput(t, 'BOOL'), { ok: true, value: true });
  for (const t of ['FALSE', '0', 'Off']) assert.deepEqual(parseInput(t, 'BOOL'), { ok: true, value: false });
  assert.equal(parseInput('yes', 'BOOL').ok, false);
});

test('integers: IEC bases, ranges per type, large values exact as text', () => {
  assert.deepEqual(parseInput('-128', 'SINT'), { ok: true, value: -128 });
  assert.match(parseInput('128', 'SINT').error, /SINT holds -128 to 127/);
  assert.deepEqual(parseInput('16#FF', 'BYTE'), { ok: true, value: 255 });
  assert.deepEqual(parseInput('2#1010_1010', 'USINT'), { ok: true, value: 170 });
  assert.deepEqual(parseInput('1_000', 'INT'), { ok: true, value: 1000 });
  assert.equal(parseInput('-1', 'UINT').ok, false);
  assert.equal(parseInput('1.5', 'DINT').ok, false);
  assert.deepEqual(parseInput('18446744073709551615', 'ULINT'), { ok: true, value: '18446744073709551615' });
  assert.equal(parseInput('18446744073709551616', 'ULINT').ok, false);
  assert.deepEqual(parseInput('9007199254740992', 'LINT'), { ok: true, value: 9007199254740992 });
});

test('reals: a point, not a comma; exponents; REAL range', () => {
  assert.deepEqual(parseInput('1.5', 'LREAL'), { ok: true, value: 1.5 });
  assert.deepEqual(parseInput('-2e-3', 'REAL'), { ok: true, value: -0.002 });
  assert.deepEqual(parseInput('.5', 'LREAL'), { ok: true, value: 0.5 });
  assert.match(parseInput('1,5', 'LREAL').error, /a point, not a comma/);
  assert.equal(parseInput('1e39', 'REAL').ok, false);
  assert.equal(parseInput('1e39', 'LREAL').ok, true);
  assert.equal(parseInput('', 'LREAL').ok, false);
});

test('durations and strings', () => {
  assert.deepEqual(parseInput('T#1m30s', 'TIME'), { ok: true, value: 'T#1m30s' });
  assert.deepEqual(parseInput('250ms', 'TIME'), { ok: true, value: '250ms' });
  assert.deepEqual(parseInput('1.5s', 'TIME'), { ok: true, value: '1.5s' });
  assert.equal(parseInput('soon', 'TIME').ok, false);
  assert.deepEqual(parseInput('hello', 'STRING'), { ok: true, value: 'hello' });
});
