import { test } from 'node:test';
import assert from 'node:assert/strict';
import { arrayBounds, elementType, formatNs, formatPeriod, formatUptime, formatValue } from '../src/lib/format.js';

test('durations in the unit that fits, three significant digits', () => {
  assert.equal(formatNs(850), '850 ns');
  assert.equal(formatNs(1234), '1.23 µs');
  assert.equal(formatNs(41200), '41.2 µs');
  assert.equal(formatNs(212000), '212 µs');
  assert.equal(formatNs(1.2e6), '1.20 ms');
  assert.equal(formatNs(4.12e8), '412 ms');
  assert.equal(formatNs(2.5e9), '2.50 s');
  assert.equal(formatNs(null), '–');
  assert.equal(formatPeriod(1e6), '1 ms');
  assert.equal(formatPeriod(250e3), '250 µs');
  assert.equal(formatPeriod(1.5e6), '1500 µs');
  assert.equal(formatUptime(7260), '2 h 1 min');
  assert.equal(formatUptime(93784), '1 d 2 h 3 min');
});

test('values as the PLC shows them', () => {
  assert.equal(formatValue(true, 'BOOL'), 'TRUE');
  assert.equal(formatValue(0, 'BOOL'), 'FALSE');
  assert.equal(formatValue(1.23456789, 'LREAL'), '1.23457');
  assert.equal(formatValue(2, 'LREAL'), '2');
  assert.equal(formatValue(1e-7, 'LREAL'), '1.0000e-7');
  assert.equal(formatValue(42, 'DINT'), '42');
  assert.equal(formatValue([1, 2.5], 'ARRAY[1..2] OF LREAL'), '1, 2.5');
  assert.equal(formatValue([true, false], 'ARRAY[0..1] OF BOOL'), 'TRUE, FALSE');
  assert.equal(formatValue(undefined, 'INT'), '–');
  assert.equal(elementType('ARRAY[1..4] OF LREAL'), 'LREAL');
  assert.deepEqual(arrayBounds('ARRAY[-2..3] OF INT'), { lower: -2, upper: 3 });
  assert.equal(arrayBounds('INT'), null);
});
