import { test } from 'node:test';
import assert from 'node:assert/strict';
import { SseParser, backoffMs } from '../src/api/sse.js';

test('events split over chunks, CRLF and CR line ends, comments and multi-line data', () => {
  const p = new SseParser();
  assert.deepEqual(p.push(': keep-alive\n\nevent: val'), []);
  assert.deepEqual(p.push('ues\ndata: {"a":'), []);
  assert.deepEqual(p.push('1}\n\n'), [{ event: 'values', data: '{"a":1}', id: '' }]);
  assert.deepEqual(p.push('data: one\r\ndata: two\r\n\r\n'), [{ event: 'message', data: 'one\ntwo', id: '' }]);
  // A CR at the end of a chunk may be half of CRLF: no empty line is seen.
  assert.deepEqual(p.push('id: 7\rdata:x\r'), []);
  assert.deepEqual(p.push('\n\r\n'), [{ event: 'message', data: 'x', id: '7' }]);
});

test('the event type does not leak into the next event; an event without data is dropped', () => {
  const p = new SseParser();
  assert.deepEqual(p.push('event: values\n\ndata: 2\n\n'), [{ event: 'message', data: '2', id: '' }]);
  p.push('retry: 1500\n\n');
  assert.equal(p.retryMs, 1500);
  assert.deepEqual(p.push('data\n\ndata:\n\n'), []);
});

test('back-off doubles from 0.5 s to at most 10 s with a ±20 % spread', () => {
  assert.equal(backoffMs(0, () => 0.5), 500);
  assert.equal(backoffMs(1, () => 0.5), 1000);
  assert.equal(backoffMs(3, () => 0.5), 4000);
  assert.equal(backoffMs(10, () => 0.5), 10000);
  assert.equal(backoffMs(0, () => 0), 400);
  assert.equal(backoffMs(0, () => 1), 600);
});

test('a stream is taken as lost after 2 s without an event, or three periods at a low rate', async () => {
  const { silenceLimitMs } = await import('../src/api/stream.js');
  assert.equal(silenceLimitMs(10), 2000);
  assert.equal(silenceLimitMs(50), 2000);
  assert.equal(silenceLimitMs(1), 3000);
});
