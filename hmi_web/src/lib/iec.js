// What a person types, checked against the tag's IEC type before it is sent
// (the server checks again). Pure (test/iec.test.mjs).
// Returns {ok: true, value} or {ok: false, error: "in words"}.

const INT_RANGES = {
  SINT: [-128n, 127n], INT: [-32768n, 32767n], DINT: [-2147483648n, 2147483647n],
  LINT: [-9223372036854775808n, 9223372036854775807n],
  USINT: [0n, 255n], UINT: [0n, 65535n], UDINT: [0n, 4294967295n], ULINT: [0n, 18446744073709551615n],
  BYTE: [0n, 255n], WORD: [0n, 65535n], DWORD: [0n, 4294967295n], LWORD: [0n, 18446744073709551615n],
};

export const isIntegerType = (t) => Object.prototype.hasOwnProperty.call(INT_RANGES, t);
export const isRealType = (t) => t === 'REAL' || t === 'LREAL';

export function intRange(type) {
  const r = INT_RANGES[type];
  return r ? { min: r[0].toString(), max: r[1].toString() } : null;
}

export function parseInput(text, type) {
  const s = String(text ?? '').trim();
  if (type === 'BOOL') {
    const u = s.toUpperCase();
    if (u === 'TRUE' || u === '1' || u === 'ON') return { ok: true, value: true };
    if (u === 'FALSE' || u === '0' || u === 'OFF') return { ok: true, value: false };
    return { ok: false, error: 'Enter TRUE or FALSE.' };
  }
  if (s === '') return { ok: false, error: 'Enter a value.' };
  if (isIntegerType(type)) {
    let n;
    const m = /^([+-]?)(?:16#([0-9a-f_]+)|2#([01_]+)|8#([0-7_]+)|([0-9_]+))$/i.exec(s);
    if (!m) return { ok: false, error: `${type} takes a whole number, e.g. 42${type === 'BYTE' || type === 'WORD' ? ' or 16#2A' : ''}.` };
    const digits = (m[2] || m[3] || m[4] || m[5]).replace(/_/g, '');
    const prefix = m[2] ? '0x' : m[3] ? '0b' : m[4] ? '0o' : '';
    n = BigInt(prefix + digits);
    if (m[1] === '-') n = -n;
    const [lo, hi] = INT_RANGES[type];
    if (n < lo || n > hi) return { ok: false, error: `${type} holds ${lo} to ${hi}; ${s} is outside.` };
    // Exact as a JSON number up to 2^53; beyond, sent as a string.
    const value = n >= -(2n ** 53n) && n <= 2n ** 53n ? Number(n) : n.toString();
    return { ok: true, value };
  }
  if (isRealType(type)) {
    if (!/^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i.test(s.replace(/_/g, ''))) {
      return { ok: false, error: `${type} takes a number, e.g. 1.5 or -2e-3 (a point, not a comma).` };
    }
    const v = Number(s.replace(/_/g, ''));
    if (!Number.isFinite(v)) return { ok: false, error: 'The number is too large.' };
    if (type === 'REAL' && Math.abs(v) > 3.4028234663852886e38) return { ok: false, error: 'REAL holds up to about 3.4e38.' };
    return { ok: true, value: v };
  }
  if (type === 'TIME' || type === 'LTIME') {
    // IEC literal (T#1s500ms) or a plain duration (250ms, 1.5s): sent as text.
    if (!/^((L?TIME|L?T)#)?-?(\d+(\.\d+)?(d|h|m|s|ms|us|ns)_?)+$/i.test(s)) {
      return { ok: false, error: 'Enter a duration, e.g. 250ms, 1.5s or T#1m30s.' };
    }
    return { ok: true, value: s };
  }
  return { ok: true, value: s };
}
