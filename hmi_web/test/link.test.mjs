// api/link.js: when the HMI says the PLC does not answer, and when it answers again.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { createLink, NO_ANSWER_MS } from '../src/api/link.js';

// A clock and timers the test moves by hand.
function fakeTime() {
  let t = 0;
  const timers = new Map();
  let next = 1;
  return {
    now: () => t,
    setTimer: (fn, ms) => { const id = next++; timers.set(id, { at: t + ms, fn }); return id; },
    clearTimer: (id) => timers.delete(id),
    advance(ms) {
      t += ms;
      for (const [id, x] of [...timers]) if (x.at <= t) { timers.delete(id); x.fn(); }
    },
  };
}

test('a request unanswered for NO_ANSWER_MS makes the link lost; an answer makes it online', () => {
  const c = fakeTime();
  const link = createLink(c);
  const seen = [];
  link.onChange((s) => seen.push(s.state));
  const end1 = link.started();
  link.answered();
  end1();
  assert.equal(link.state().state, 'online');
  link.started(); // never answered: the PLC was stopped
  c.advance(NO_ANSWER_MS - 1);
  assert.equal(link.state().state, 'online');
  c.advance(1);
  assert.equal(link.state().state, 'lost');
  assert.match(link.state().error, /no answer from the PLC for 2 s/);
  link.answered();
  assert.deepEqual(seen, ['online', 'lost', 'online']);
});

test('a slow request is not a lost link while other requests are answered', () => {
  const c = fakeTime();
  const link = createLink(c);
  link.started(); // a reload that takes its time
  c.advance(NO_ANSWER_MS / 2);
  const end = link.started();
  link.answered(); // a poll answered meanwhile
  end();
  c.advance(NO_ANSWER_MS);
  assert.equal(link.state().state, 'online');
});

test('a request that ends in time clears its timer', () => {
  const c = fakeTime();
  const link = createLink(c);
  const end = link.started();
  link.answered();
  end();
  c.advance(10 * NO_ANSWER_MS);
  assert.equal(link.state().state, 'online');
});

test('a network error is a lost link at once', () => {
  const link = createLink(fakeTime());
  link.failed('The PLC cannot be reached (no answer from the server).');
  assert.equal(link.state().state, 'lost');
});
