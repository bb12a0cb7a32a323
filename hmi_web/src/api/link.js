// Whether the PLC answers. Every request (http.js) reports here; the badge,
// the banner and the pages' stale marking read it. A request with no answer
// for NO_ANSWER_MS, while no other request was answered in that time, makes
// the link 'lost' (a PLC stopped by SIGSTOP, a cable pulled: the TCP
// connection stays open and the request simply waits). Any answer, even a
// refusal, makes it 'online' again. Pure apart from its timers
// (test/link.test.mjs).

export const NO_ANSWER_MS = 2000;

export function createLink({ setTimer = setTimeout, clearTimer = clearTimeout } = {}) {
  let state = { state: 'unknown' }; // 'unknown' | 'online' | 'lost'
  let answers = 0; // answers counted so far: one after a request started tells the PLC answers
  const listeners = new Set();

  function set(next) {
    if (next.state === state.state && next.error === state.error) return;
    state = next;
    for (const l of listeners) l(state);
  }

  return {
    state: () => state,
    onChange(listener) { listeners.add(listener); return () => listeners.delete(listener); },
    // A request goes out; call the returned function when it ends (answered
    // or not: answered()/failed() say which).
    started() {
      const answersBefore = answers;
      const timer = setTimer(() => {
        if (answers === answersBefore) set({ state: 'lost', error: `no answer from the PLC for ${NO_ANSWER_MS / 1000} s` });
      }, NO_ANSWER_MS);
      return () => clearTimer(timer);
    },
    answered() {
      answers += 1;
      set({ state: 'online' });
    },
    failed(error) {
      set({ state: 'lost', error: error || 'the PLC cannot be reached' });
    },
  };
}

export const link = createLink();
