// A live value stream: a subscription's GET /api/v1/subscriptions/ID/stream
// read with fetch (so the session's Authorization header goes along),
// parsed as Server-Sent Events, reconnected with back-off, stopped while the
// page is hidden (a phone in a pocket costs the PLC nothing).
import { apiUrl, authHeaders, statusWords } from './http.js';
import { NO_ANSWER_MS } from './link.js';
import { SseParser, backoffMs } from './sse.js';

// onValues({tNs, nowNs, values, forced, quality, errors}); onState({state:
// 'connecting'|'live'|'lost'|'paused'|'idle', error, retryInMs}); onGone():
// the PLC no longer knows the subscription (404: it restarted, or the
// subscription expired): the stream stops, the caller makes a new one.
// The server sends an event every 1/rate s whatever the values do: a stream
// silent for longer than this is taken as lost (a PLC stopped by SIGSTOP or a
// cable pulled leaves the TCP connection open and just quiet), closed and
// tried again.
export function silenceLimitMs(rate) {
  return Math.max(NO_ANSWER_MS, Math.ceil(3000 / rate));
}

export function openStream({ path, rate = 10, onValues, onState, onGone }) {
  let stopped = false;
  let controller = null;
  let attempt = 0;
  let timer = null;
  let silence = null;
  let silent = false;

  const state = (s, extra = {}) => onState && onState({ state: s, ...extra });

  async function connect() {
    clearTimeout(timer);
    if (stopped) return;
    if (typeof document !== 'undefined' && document.hidden) { state('paused'); return; }
    if (controller) controller.abort(); // never two streams at once
    controller = new AbortController();
    const mine = controller;
    silent = false;
    // (Re)armed by every chunk read: connecting counts too.
    const heard = () => {
      clearTimeout(silence);
      silence = setTimeout(() => { silent = true; mine.abort(); }, silenceLimitMs(rate));
    };
    heard();
    if (!attempt) state('connecting'); // while retrying, the state stays 'lost'
    let error = null;
    let streamError = null;
    try {
      const res = await fetch(apiUrl(path), {
        headers: { Accept: 'text/event-stream', ...authHeaders() },
        credentials: 'omit', cache: 'no-store', signal: controller.signal,
      });
      if (res.status === 404 && onGone) {
        stopped = true;
        clearTimeout(silence);
        onGone();
        return;
      }
      if (!res.ok || !res.body) {
        let msg = statusWords(res.status);
        try { const j = await res.json(); if (j && j.error) msg = j.error; } catch { /* not JSON */ }
        throw new Error(msg);
      }
      const parser = new SseParser();
      const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        heard();
        for (const ev of parser.push(value)) {
          if (ev.event === 'error') {
            // The server says why it ends the stream (e.g. a ref it does not know).
            try { streamError = JSON.parse(ev.data).error; } catch { streamError = ev.data; }
            continue;
          }
          if (ev.event !== 'values') continue;
          let d;
          try { d = JSON.parse(ev.data); } catch { continue; }
          attempt = 0;
          state('live');
          onValues({ tNs: d.t_ns, nowNs: d.now_ns, values: d.values || {}, forced: d.forced || {},
            quality: d.quality || {}, errors: d.errors || {} });
        }
      }
      error = streamError || 'The PLC closed the live stream.';
    } catch (e) {
      if (stopped || (e && e.name === 'AbortError' && !silent)) return;
      error = silent ? `no update from the PLC for ${silenceLimitMs(rate) / 1000} s` : (e && e.message ? e.message : String(e));
    } finally {
      clearTimeout(silence);
    }
    if (stopped) return;
    if (typeof document !== 'undefined' && document.hidden) { state('paused'); return; }
    const wait = backoffMs(attempt++);
    state('lost', { error, retryInMs: wait });
    timer = setTimeout(connect, wait);
  }

  function onVisibility() {
    if (document.hidden) {
      if (controller) controller.abort();
      clearTimeout(timer);
      state('paused');
    } else {
      attempt = 0;
      connect();
    }
  }

  if (typeof document !== 'undefined') document.addEventListener('visibilitychange', onVisibility);
  connect();

  return {
    close() {
      stopped = true;
      clearTimeout(timer);
      clearTimeout(silence);
      if (controller) controller.abort();
      if (typeof document !== 'undefined') document.removeEventListener('visibilitychange', onVisibility);
    },
  };
}
