// Numbers, times and values as people read them. Pure (test/format.test.mjs).

// 1234567 ns → "1.23 ms"; three significant digits, the unit that fits.
export function formatNs(ns) {
  if (ns === null || ns === undefined || !Number.isFinite(ns)) return '–';
  const a = Math.abs(ns);
  const sig = (v) => (Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 10 ? v.toFixed(1) : v.toFixed(2));
  if (a < 1e3) return `${Math.round(ns)} ns`;
  if (a < 1e6) return `${sig(ns / 1e3)} µs`;
  if (a < 1e9) return `${sig(ns / 1e6)} ms`;
  return `${sig(ns / 1e9)} s`;
}

// A task period: 1000000 → "1 ms" (exact when it is round).
export function formatPeriod(ns) {
  if (!Number.isFinite(ns)) return '–';
  if (ns % 1e9 === 0) return `${ns / 1e9} s`;
  if (ns % 1e6 === 0) return `${ns / 1e6} ms`;
  if (ns % 1e3 === 0) return `${ns / 1e3} µs`;
  return `${ns} ns`;
}

export function formatUptime(s) {
  if (!Number.isFinite(s)) return '–';
  s = Math.floor(s);
  const d = Math.floor(s / 86400); const h = Math.floor((s % 86400) / 3600);
  const m = Math.floor((s % 3600) / 60); const sec = s % 60;
  if (d) return `${d} d ${h} h ${m} min`;
  if (h) return `${h} h ${m} min`;
  if (m) return `${m} min ${sec} s`;
  return `${sec} s`;
}

export function formatCount(n) {
  if (n === null || n === undefined || !Number.isFinite(n)) return '–';
  return n.toLocaleString('en-US');
}

// One value as the PLC shows it: BOOL TRUE/FALSE, reals with up to 6
// significant digits, TIME as the server sends it (an IEC literal).
export function formatScalar(v, type) {
  if (v === null || v === undefined) return '–';
  if (typeof v === 'boolean' || type === 'BOOL') return v === true || v === 1 || v === 'TRUE' ? 'TRUE' : 'FALSE';
  if (typeof v === 'number') {
    if (type === 'REAL' || type === 'LREAL' || !Number.isInteger(v)) {
      if (v === 0) return '0';
      const a = Math.abs(v);
      if (a >= 1e6 || a < 1e-4) return v.toExponential(4);
      return String(Number(v.toPrecision(6)));
    }
    return String(v);
  }
  return String(v);
}

export function formatValue(v, type) {
  const el = elementType(type);
  if (Array.isArray(v)) return v.map((x) => formatScalar(x, el)).join(', ');
  return formatScalar(v, el);
}

// "ARRAY[1..4] OF LREAL" → "LREAL"; other types as they are.
export function elementType(type) {
  const m = /^ARRAY\s*\[.*?\]\s*OF\s+(.+)$/i.exec(type || '');
  return m ? m[1].trim() : type;
}

export function arrayBounds(type) {
  const m = /^ARRAY\s*\[\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*\]/i.exec(type || '');
  return m ? { lower: Number(m[1]), upper: Number(m[2]) } : null;
}

// Wall time in ns → local "2026-11-25 10:21:03.125".
export function formatWallNs(ns, withMs = true) {
  if (!Number.isFinite(ns)) return '–';
  const d = new Date(ns / 1e6);
  const p = (x, n = 2) => String(x).padStart(n, '0');
  const base = `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}:${p(d.getSeconds())}`;
  return withMs ? `${base}.${p(d.getMilliseconds(), 3)}` : base;
}
