// A Server-Sent Events parser (the WHATWG "event stream" format) for a stream
// read with fetch(): EventSource cannot send an Authorization header, fetch
// can. Feed it text as it arrives; it hands back complete events.

export class SseParser {
  constructor() {
    this.buffer = '';
    this.reset();
    this.lastEventId = '';
    this.retryMs = null;
  }

  reset() {
    this.eventType = '';
    this.data = [];
  }

  // Returns the events completed by this chunk: [{event, data, id}].
  push(chunk) {
    this.buffer += chunk;
    const out = [];
    for (;;) {
      const m = /\r\n|\r|\n/.exec(this.buffer);
      if (!m) break;
      // A lone \r at the end of the buffer may be the first half of \r\n.
      if (m[0] === '\r' && m.index === this.buffer.length - 1) break;
      const line = this.buffer.slice(0, m.index);
      this.buffer = this.buffer.slice(m.index + m[0].length);
      this.line(line, out);
    }
    return out;
  }

  line(line, out) {
    if (line === '') {
      // An empty data buffer dispatches nothing (WHATWG: "data:" alone too).
      const data = this.data.join('\n');
      if (data !== '') out.push({ event: this.eventType || 'message', data, id: this.lastEventId });
      this.reset();
      return;
    }
    if (line.startsWith(':')) return; // a comment (keep-alive)
    const colon = line.indexOf(':');
    const field = colon < 0 ? line : line.slice(0, colon);
    let value = colon < 0 ? '' : line.slice(colon + 1);
    if (value.startsWith(' ')) value = value.slice(1);
    if (field === 'event') this.eventType = value;
    else if (field === 'data') this.data.push(value);
    else if (field === 'id' && !value.includes('\0')) this.lastEventId = value;
    else if (field === 'retry' && /^\d+$/.test(value)) this.retryMs = Number(value);
  }
}

// Reconnection back-off: 0.5 s, 1 s, 2 s … up to 10 s, with ±20 % spread
// so that many browsers do not come back in the same instant.
export function backoffMs(attempt, random = Math.random) {
  const base = Math.min(10000, 500 * 2 ** Math.max(0, attempt));
  return Math.round(base * (0.8 + 0.4 * random()));
}
