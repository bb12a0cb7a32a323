// TEST FIXTURE ONLY — never part of the product. A stand-in for `syncplc run`'s
// HTTP API (the shape agreed for issue 14, prefix /api/v1) with canned,
// moving values, so the HMI's pages can be tried and screenshotted before
// the real server (runtime/web) is merged. The browser tests against the real
// server replace it; nothing in hmi_web/ or runtime/ uses this file.
//
//   node tests/hmi/fixture_server.mjs [PORT]   serves hmi_web/dist on 127.0.0.1
import { createServer } from 'node:http';
import { randomBytes } from 'node:crypto';
import { readFile } from 'node:fs/promises';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
export const DIST = resolve(here, '../../hmi_web/dist');
const TYPES = { '.svg': 'image/svg+xml', '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.map': 'application/json', '.txt': 'text/plain' };
const RANK = { viewer: 0, operator: 1, engineer: 2 };

const TAGS = [
  { name: 'pos', type: 'ARRAY[1..4] OF LREAL', length: 4, lower: 1, unit: 'rad', task: 'servo', hmi: 'read', writer: 'table', retain: false, description: 'measured axis positions' },
  { name: 'err', type: 'ARRAY[1..4] OF LREAL', length: 4, lower: 1, unit: 'rad', task: 'servo', hmi: 'read', writer: 'ax1..ax4', retain: false, description: 'e_i(k) each node writes into the frame' },
  { name: 'cmd', type: 'ARRAY[1..4] OF LREAL', length: 4, lower: 1, unit: 'PWM', task: 'servo', hmi: 'readwrite', writer: 'ax1..ax4', written_every_scan: true, retain: false, description: 'drive commands' },
  { name: 'speed', type: 'LREAL', length: 1, lower: 1, unit: 'm/s', task: 'servo', hmi: 'readwrite', writer: null, retain: true, description: 'conveyor speed set-point' },
  { name: 'enable', type: 'BOOL', length: 1, lower: 1, unit: '', task: 'servo', hmi: 'readwrite', writer: null, retain: false, description: 'run the conveyor' },
  { name: 'batch', type: 'DINT', length: 1, lower: 1, unit: '', task: 'planner', hmi: 'readwrite', writer: null, retain: true, description: 'bottles per batch' },
  { name: 'frames_lost', type: 'ULINT', length: 1, lower: 1, unit: '', task: 'servo', hmi: 'read', writer: 'ring', retain: false, description: 'ring frames lost' },
  { name: 'r', type: 'ARRAY[1..3] OF LREAL', length: 3, lower: 1, unit: 'm', task: 'planner', hmi: 'read', writer: 'ref1..ref3', retain: false, description: 'rough references' },
];

const pin = (name, direction, type, unit = '', length = 1) => ({ name, direction, type, unit, length, lower: 1 });
const BLOCKS = [
  ...[1, 2, 3, 4].map((k) => ({ name: `ax${k}`, type: 'SYNC_CONTROLLER', task: 'servo', position: 12 + k, pins: [
    pin('x_d', 'in', 'LREAL', 'rad'), pin('x', 'in', 'LREAL', 'rad'), pin('tau', 'out', 'LREAL', 'PWM'), pin('e', 'out', 'LREAL', 'rad'), pin('ENO', 'out', 'BOOL')] })),
  { name: 'sync', type: 'TRANSIENT_SYNC', task: 'planner', position: 3, pins: [
    pin('r', 'in', 'ARRAY[1..3] OF LREAL', 'm', 3), pin('x', 'out', 'ARRAY[1..3] OF LREAL', 'm', 3), pin('arrival', 'out', 'LINT'),
    pin('synchronized', 'out', 'BOOL'), pin('spread', 'out', 'LINT'), pin('windows', 'out', 'LINT'), pin('reset', 'in', 'BOOL')] },
];

const MAIN_YAML = 'project: {name: bottle_line, version: 1.0.1}\ninclude: [tasks.yaml]\ntags:\n  - {name: speed, type: LREAL, unit: m/s, hmi: readwrite}\n';

// The values of the canned "program" at time t (s since the fixture started).
function programValues(t, st) {
  const xd = 4 * Math.PI * (1 - Math.cos(t));
  const err = [1, 2, 3, 4].map((i) => 1e-3 * Math.sin(2 * t + i) * (1 + 0.2 * i));
  // A transient of the synchronizer every 4 s, lasting 1.5 s (planner: 10 ms).
  const phase = t % 4;
  const arrival = phase < 1.5 ? Math.round((1.5 - phase) / 0.01) : 0;
  const target = [[1, -2, 0.5], [2.5, 0, -1]][Math.floor(t / 4) % 2];
  const start = [[2.5, 0, -1], [1, -2, 0.5]][Math.floor(t / 4) % 2];
  const s = phase < 1.5 ? 0.5 - 0.5 * Math.cos(Math.PI * phase / 1.5) : 1;
  const x = target.map((g, i) => start[i] + (g - start[i]) * s);
  const v = {
    pos: [1, 2, 3, 4].map((i, j) => xd - err[j]), err, cmd: err.map((e) => Math.max(-1, Math.min(1, e * 200))),
    speed: st.written.speed ?? 1.5, enable: st.written.enable ?? true, batch: st.written.batch ?? 24,
    frames_lost: Math.floor(t * 3), r: target,
    'sync.r': target, 'sync.x': x, 'sync.arrival': arrival, 'sync.synchronized': arrival === 0,
    'sync.spread': 0, 'sync.windows': Math.floor(t / 4), 'sync.reset': false,
  };
  [1, 2, 3, 4].forEach((k, j) => Object.assign(v, { [`ax${k}.x_d`]: xd, [`ax${k}.x`]: v.pos[j], [`ax${k}.e`]: err[j], [`ax${k}.tau`]: v.cmd[j], [`ax${k}.ENO`]: true }));
  return v;
}

// tag, tag[i], instance.pin, instance.pin[i] → {value, forced} or null.
function readRef(ref, vals, forces) {
  const m = /^([A-Za-z_][\w.]*?)(?:\[(-?\d+)\])?$/.exec(ref);
  if (!m || !(m[1] in vals)) return null;
  const base = vals[m[1]];
  const forcedOf = (r) => Object.prototype.hasOwnProperty.call(forces, r);
  if (m[2] !== undefined) {
    if (!Array.isArray(base)) return null;
    const i = Number(m[2]) - 1;
    if (i < 0 || i >= base.length) return null;
    return { value: forcedOf(ref) ? forces[ref] : base[i], forced: forcedOf(ref) };
  }
  if (Array.isArray(base)) {
    const value = base.map((x, i) => (forcedOf(`${ref}[${i + 1}]`) ? forces[`${ref}[${i + 1}]`] : x));
    return { value, forced: base.some((_, i) => forcedOf(`${ref}[${i + 1}]`)) };
  }
  return { value: forcedOf(ref) ? forces[ref] : base, forced: forcedOf(ref) };
}

function checkProject(body) {
  if (!body || typeof body.main !== 'string' || !body.files || typeof body.files !== 'object' || !(body.main in body.files)) {
    return { status: 400, json: { error: 'the upload must name its main file and send it' } };
  }
  const errors = [];
  for (const [name, text] of Object.entries(body.files)) {
    text.split('\n').forEach((line, i) => {
      const m = /(\d+)xs\b/.exec(line);
      if (m) errors.push({ where: `${name}:${i + 1}:${m.index + 1}`, message: `period: '${m[0]}' is not a duration (unknown unit 'xs'; write e.g. 1ms, 250us, 0.5s, T#1m30s)` });
    });
  }
  return errors.length ? { status: 400, json: { ok: false, errors } } : null;
}

export async function startFixture({ port = 0, users = {}, distDir = DIST } = {}) {
  const t0 = Date.now();
  const st = {
    written: {}, forces: {}, tokens: new Map(), streams: new Set(), refuseStreamsUntil: 0,
    subscriptions: new Map(), patches: [], quality: {}, // quality: ref → a quality the test sets ('stale', 'driver_not_ok' …)
    events: [], versions: [
      { version: 1, time_ns: (t0 - 3600e3) * 1e6, origin: 'run', outcome: 'accepted', project: 'bottle_line 1.0.0', hash: '298e4d1f0a', files: 2, errors: [] },
      { version: 2, time_ns: (t0 - 1800e3) * 1e6, origin: 'reload', outcome: 'rejected', project: '', hash: 'ccb459ba11', files: 2, errors: ["bottle_line.yaml:16:13: period: '10xs' is not a duration"] },
      { version: 3, time_ns: (t0 - 600e3) * 1e6, origin: 'reload', outcome: 'accepted', project: 'bottle_line 1.0.1', hash: '828db81c22', files: 2, errors: [], running: true },
    ],
    requests: [],
  };
  const event = (kind, message, extra = {}) => st.events.push({ id: st.events.length + 1, time_ns: Date.now() * 1e6, kind, task: '', source: 'run', message, client: '', scan: null, ...extra });
  event('start', 'syncplc run projects/bottle_line/bottle_line.yaml (database /tmp/plc.db)');
  event('overrun', 'scan overran its period (scan took 1.21ms)', { task: 'servo', scan: 1834 });
  event('hmi-write', 'speed := 1.5', { task: 'servo', client: '127.0.0.1:40512', source: 'modbus' });
  const ticker = setInterval(() => event('overrun', `scan overran its period (scan took ${(1 + Math.random()).toFixed(2)}ms)`, { task: 'servo', scan: Math.floor((Date.now() - t0)) }), 7000);

  const sessionOf = (req) => {
    const m = /^Bearer (\S+)$/.exec(req.headers.authorization || '');
    return m ? st.tokens.get(m[1]) || null : null;
  };
  const send = (res, status, json) => { res.writeHead(status, { 'Content-Type': 'application/json', 'Cache-Control': 'no-store' }); res.end(JSON.stringify(json)); };
  const need = (req, res, role) => {
    const s = sessionOf(req);
    if (!s) { send(res, 401, { error: 'log in first: this changes the PLC' }); return null; }
    if (RANK[s.role] < RANK[role]) { send(res, 403, { error: `this needs the ${role} role; you are ${s.role}` }); return null; }
    return s;
  };
  const body = (req) => new Promise((ok) => { let d = ''; req.on('data', (c) => { d += c; }); req.on('end', () => { try { ok(JSON.parse(d || 'null')); } catch { ok(undefined); } }); });
  const now = () => (Date.now() - t0) / 1000;
  const TASK_PERIODS = { servo: 1e6, planner: 1e7, slow: 1e8 };
  const taskOf = (ref) => {
    const base = ref.replace(/\[.*$/, '');
    const tag = TAGS.find((t) => t.name === base);
    if (tag) return tag.task;
    const b = BLOCKS.find((x) => base.startsWith(`${x.name}.`));
    return b ? b.task : null;
  };
  const describeAll = (refs) => {
    const out = {};
    const v = programValues(now(), st);
    for (const r of refs) {
      const task = taskOf(r);
      out[r] = readRef(r, v, st.forces) && task ? { task, period_ns: TASK_PERIODS[task], type: 'LREAL', length: 1 } : { error: `no tag or pin '${r}'` };
    }
    return out;
  };
  // A live stream of refs() (read at every tick: a subscription changes), each value with its quality.
  const openSse = (req, res, refs, rate) => {
    res.writeHead(200, { 'Content-Type': 'text/event-stream', 'Cache-Control': 'no-store', Connection: 'keep-alive' });
    const tick = () => {
      const v = programValues(now(), st);
      const nowNs = Math.round((Date.now() - t0) * 1e6);
      const out = { t_ns: Date.now() * 1e6, now_ns: nowNs, values: {}, forced: {}, quality: {} };
      for (const r of refs()) {
        const x = readRef(r, v, st.forces);
        if (!x) { out.errors = { ...(out.errors || {}), [r]: `no tag or pin '${r}'` }; continue; }
        out.values[r] = x.value; out.forced[r] = x.forced;
        const q = st.quality[r] || (x.forced ? 'forced' : 'good');
        out.quality[r] = { q, scan_ns: nowNs - 500000, age_ns: q === 'stale' ? 5e9 : 500000 };
      }
      res.write(`event: values\ndata: ${JSON.stringify(out)}\n\n`);
    };
    tick();
    const timer = setInterval(tick, 1000 / rate);
    const s = { res, timer };
    st.streams.add(s);
    req.on('close', () => { clearInterval(timer); st.streams.delete(s); });
  };

  function status() {
    const t = now();
    const hist = (scale) => ({ bounds_ns: [1e3, 2e3, 5e3, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5], counts: [0, Math.round(t * 800 * scale), Math.round(t * 160 * scale), Math.round(t * 30 * scale), Math.round(t * 8 * scale), Math.round(t * scale), Math.round(t * 0.1 * scale), 1, 0, 0] });
    return {
      runtime: { version: '0.1.0', project_file: '/srv/plc/projects/bottle_line/bottle_line.yaml', program: st.program || 'bottle_line', program_version: '1.0.1', project_version: 3, uptime_s: t + 7260, store: { state: 'ok' }, modbus: '127.0.0.1:5020' },
      tasks: [
        { name: 'servo', period_ns: 1e6, priority: 80, cpu: 1, state: 'running', scans: Math.floor(t * 1000) + 7260000, overruns: 2, watchdog_trips: 0,
          exec: { last_ns: 41200, min_ns: 28100, max_ns: 212000, mean_ns: 39800, p99_ns: 88000, histogram: { bounds_ns: [2e4, 5e4, 1e5, 2e5, 5e5], counts: [Math.round(t * 20), Math.round(t * 950), Math.round(t * 25), Math.round(t * 2), 1] } }, jitter: { min_ns: 1200, max_ns: 187000, p99_ns: 14200, histogram: hist(1) } },
        { name: 'planner', period_ns: 1e7, priority: 60, cpu: 1, state: 'running', scans: Math.floor(t * 100) + 726000, overruns: 0, watchdog_trips: 0,
          exec: { last_ns: 12100, min_ns: 9800, max_ns: 61000, mean_ns: 11900, p99_ns: 20400 }, jitter: { min_ns: 1500, max_ns: 95000, p99_ns: 11800, histogram: hist(0.1) } },
        { name: 'slow', period_ns: 1e8, priority: 10, cpu: null, state: st.slowStopped ? 'stopped' : 'running', stop_reason: st.slowStopped ? 'watchdog: scan took 412 ms (watchdog 200 ms), action stop' : null,
          scans: 71812, overruns: 3, watchdog_trips: st.slowStopped ? 1 : 0, exec_ns: { last: 812000, min: 790000, max: 412000000, mean: 830000, p99: 1.2e6 }, start_jitter_ns: { min: 2000, max: 40000, p99: 21000, histogram: hist(0.01) } },
      ],
      forces: Object.keys(st.forces).length,
    };
  }

  async function api(req, res, url) {
    const path = url.pathname.slice('/api/v1'.length);
    st.requests.push(`${req.method} ${path}${url.search}`);
    const vals = programValues(now(), st);
    if (req.method === 'POST' && path === '/login') {
      const b = await body(req);
      const u = b && users[b.user];
      if (!u || u.password !== b.password) { event('login-failed', `login failed for ${b && b.user}`); send(res, 401, { error: 'wrong user name or password' }); return; }
      const token = randomBytes(32).toString('base64url');
      st.tokens.set(token, { user: b.user, role: u.role });
      event('login', `${b.user} logged in (${u.role})`);
      send(res, 200, { token, user: b.user, role: u.role, expires_in_s: 3600 });
      return;
    }
    if (req.method === 'POST' && path === '/logout') { const m = /^Bearer (\S+)$/.exec(req.headers.authorization || ''); if (m) st.tokens.delete(m[1]); send(res, 200, {}); return; }
    if (req.method === 'GET' && path === '/me') { const s = sessionOf(req); if (!s) send(res, 401, { error: 'not logged in' }); else send(res, 200, s); return; }
    if (req.method === 'GET' && path === '/status') { send(res, 200, status()); return; }
    if (req.method === 'GET' && path === '/tags') {
      const f = url.searchParams.get('filter') || '';
      // As runtime/web writes a tag: the element type, is_array and array_lower.
      const info = (t) => {
        const m = /^ARRAY\[(-?\d+)\.\.-?\d+\] OF (\w+)$/.exec(t.type);
        const { lower, ...rest } = t;
        return m ? { ...rest, type: m[2], is_array: true, array_lower: Number(m[1]) } : { ...rest, is_array: false };
      };
      send(res, 200, { tags: TAGS.filter((t) => t.name.includes(f)).map((t) => ({ ...info(t), forced: t.length > 1 ? Array.from({ length: t.length }, (_, i) => `${t.name}[${i + 1}]` in st.forces) : t.name in st.forces })) });
      return;
    }
    if (req.method === 'GET' && path.startsWith('/tags/')) {
      const name = decodeURIComponent(path.slice('/tags/'.length));
      const t = TAGS.find((x) => x.name === name);
      if (!t) { send(res, 404, { error: `no tag '${name}'` }); return; }
      const { lower, ...rest } = t;
      send(res, 200, { ...rest, value: vals[name], forced: name in st.forces });
      return;
    }
    if (req.method === 'GET' && path.startsWith('/blocks/')) {
      const name = decodeURIComponent(path.slice('/blocks/'.length));
      const b = BLOCKS.find((x) => x.name === name);
      if (!b) { send(res, 404, { error: `no block instance '${name}'` }); return; }
      send(res, 200, { ...b, pins: b.pins.map((p) => ({ ...p, ...readRef(`${b.name}.${p.name}`, vals, st.forces) })) });
      return;
    }
    if (req.method === 'GET' && path === '/blocks') {
      send(res, 200, { blocks: BLOCKS.map((b) => ({ ...b, pins: b.pins.map((p) => ({ ...p, ...readRef(`${b.name}.${p.name}`, vals, st.forces) })) })) });
      return;
    }
    if (req.method === 'GET' && path === '/values') {
      const refs = (url.searchParams.get('refs') || '').split(',').filter(Boolean);
      const out = { t_ns: Date.now() * 1e6, values: {}, forced: {} };
      for (const r of refs) { const v = readRef(r, vals, st.forces); if (!v) { send(res, 404, { error: `no tag or pin '${r}'` }); return; } out.values[r] = v.value; out.forced[r] = v.forced; }
      send(res, 200, out);
      return;
    }
    // --- subscriptions (docs/http-api.md, "Live values"), as the PLC keeps them
    if (req.method === 'POST' && path === '/subscriptions') {
      const b = await body(req);
      if (!b || (b.refs !== undefined && !Array.isArray(b.refs))) { send(res, 400, { error: "'refs' must be an array of references" }); return; }
      const id = randomBytes(16).toString('hex');
      const refs = [...new Set(b.refs || [])];
      st.subscriptions.set(id, { refs, rate: b.rate || 10 });
      send(res, 201, { id, rate: b.rate || 10, stream: `/api/v1/subscriptions/${id}/stream`, refs: describeAll(refs) });
      return;
    }
    const sm = /^\/subscriptions\/([0-9a-f]+)(\/stream)?$/.exec(path);
    if (sm) {
      const sub = st.subscriptions.get(sm[1]);
      if (!sub) { send(res, 404, { error: `no subscription ${sm[1]} of this session` }); return; }
      if (req.method === 'PATCH' && !sm[2]) {
        const b = await body(req);
        const add = (b && b.add) || []; const drop = new Set((b && b.drop) || []);
        const dropped = sub.refs.filter((r) => drop.has(r));
        const added = add.filter((r) => !sub.refs.includes(r) && !drop.has(r));
        sub.refs = [...sub.refs.filter((r) => !drop.has(r)), ...added];
        st.patches.push({ add: added, drop: dropped });
        send(res, 200, { id: sm[1], refs: describeAll(added), dropped });
        return;
      }
      if (req.method === 'DELETE' && !sm[2]) { st.subscriptions.delete(sm[1]); res.writeHead(204); res.end(); return; }
      if (req.method === 'GET' && sm[2]) {
        if (Date.now() < st.refuseStreamsUntil) { send(res, 503, { error: 'the PLC is restarting' }); return; }
        openSse(req, res, () => sub.refs, sub.rate);
        return;
      }
    }
    if (req.method === 'GET' && path === '/stream') {
      if (Date.now() < st.refuseStreamsUntil) { send(res, 503, { error: 'the PLC is restarting' }); return; }
      const refs = (url.searchParams.get('refs') || '').split(',').filter(Boolean);
      const rate = Math.min(50, Math.max(1, Number(url.searchParams.get('rate') || 10)));
      openSse(req, res, () => refs, rate);
      return;
    }
    if (req.method === 'GET' && path === '/events') {
      const since = Number(url.searchParams.get('since') || 0);
      const kind = url.searchParams.get('kind');
      const limit = Number(url.searchParams.get('limit') || 1000);
      send(res, 200, { events: st.events.filter((e) => e.id > since && (!kind || e.kind === kind)).slice(-limit) });
      return;
    }
    if (req.method === 'GET' && path === '/trends') {
      const tag = url.searchParams.get('tag');
      const since = Number(url.searchParams.get('since')); const until = Number(url.searchParams.get('until'));
      const n = Math.min(500, Number(url.searchParams.get('points') || 200));
      if (!['speed', 'pos[1]', 'frames_lost'].includes(tag)) { send(res, 404, { error: `no trend of '${tag}' (trended: speed, pos[1], frames_lost)` }); return; }
      const span = (until - since) / n;
      const points = Array.from({ length: n }, (_, i) => {
        const tt = (since + i * span) / 1e9;
        const mean = 1.5 + 0.4 * Math.sin(tt / 60) + 0.1 * Math.sin(tt / 7);
        return { t_ns: since + i * span, min: mean - 0.05 - 0.03 * Math.abs(Math.sin(tt / 11)), max: mean + 0.05 + 0.04 * Math.abs(Math.cos(tt / 13)), mean, count: 100 };
      });
      send(res, 200, { tag, unit: tag === 'speed' ? 'm/s' : tag === 'pos[1]' ? 'rad' : '', points });
      return;
    }
    if (req.method === 'PUT' && path.startsWith('/tags/')) {
      if (!need(req, res, 'operator')) return;
      const name = decodeURIComponent(path.slice('/tags/'.length));
      const tag = TAGS.find((t) => t.name === name);
      if (!tag) { send(res, 404, { error: `no tag '${name}'` }); return; }
      if (tag.hmi !== 'readwrite') { send(res, 403, { error: `${name} is not writable from outside (hmi: ${tag.hmi})` }); return; }
      const b = await body(req);
      if (!b || !('value' in b)) { send(res, 400, { error: 'expected {"value": ...}' }); return; }
      st.written[name] = b.value;
      event('hmi-write', `${name} := ${JSON.stringify(b.value)}`, { task: tag.task, source: 'web', client: req.socket.remoteAddress });
      send(res, 200, { ok: true });
      return;
    }
    if (req.method === 'POST' && path === '/forces') {
      const s = need(req, res, 'engineer'); if (!s) return;
      const b = await body(req);
      if (!b || typeof b.ref !== 'string' || !('value' in b)) { send(res, 400, { error: 'expected {"ref": ..., "value": ...}' }); return; }
      if (!readRef(b.ref, vals, {})) { send(res, 404, { error: `no tag or pin '${b.ref}'` }); return; }
      st.forces[b.ref] = b.value;
      event('force', `${b.ref} forced to ${JSON.stringify(b.value)} by ${s.user}`);
      send(res, 200, { ok: true });
      return;
    }
    if (req.method === 'DELETE' && path.startsWith('/forces/')) {
      const s = need(req, res, 'engineer'); if (!s) return;
      const ref = decodeURIComponent(path.slice('/forces/'.length));
      if (!(ref in st.forces)) { send(res, 404, { error: `${ref} is not forced` }); return; }
      delete st.forces[ref];
      event('unforce', `${ref} unforced by ${s.user}`);
      send(res, 200, { ok: true });
      return;
    }
    if (req.method === 'DELETE' && path === '/forces') {
      const s = need(req, res, 'engineer'); if (!s) return;
      const released = Object.keys(st.forces);
      st.forces = {};
      released.forEach((ref) => event('unforce', `${ref} unforced by ${s.user}`));
      send(res, 200, { ok: true, released });
      return;
    }
    if (req.method === 'POST' && path === '/projects/reload') {
      if (!need(req, res, 'engineer')) return;
      send(res, 200, { ok: true, version: st.versions.length, summary: 'instances: 5 kept, 0 retuned, 0 rewired, 0 new, 0 removed', report: { kept: [], retuned: [], new: [], removed: [] } });
      return;
    }
    if (req.method === 'GET' && path === '/projects') { send(res, 200, { versions: st.versions }); return; }
    if (req.method === 'POST' && (path === '/projects/check' || path === '/projects/load')) {
      if (!need(req, res, 'engineer')) return;
      const b = await body(req);
      const bad = checkProject(b);
      if (bad) { send(res, bad.status, bad.json); return; }
      if (path === '/projects/check') { send(res, 200, { ok: true, errors: [] }); return; }
      const version = st.versions.length + 1;
      st.versions.forEach((v) => { v.running = false; });
      st.versions.push({ version, time_ns: Date.now() * 1e6, origin: 'upload', outcome: 'accepted', project: 'bottle_line 1.0.2', hash: randomBytes(5).toString('hex'), files: Object.keys(b.files).length, errors: [], running: true });
      event('reload', `loaded version ${version}`);
      send(res, 200, { ok: true, version, errors: [], report: { kept: ['filler', 'capper', 'counter'], retuned: ['speed_pid'], new: ['labeler'], removed: [], summary: 'instances: 3 kept, 1 retuned, 0 rewired, 1 new, 0 removed; tasks: 2 kept; 12 tag values carried over' } });
      return;
    }
    if (req.method === 'POST' && path === '/projects/rollback') {
      if (!need(req, res, 'engineer')) return;
      const b = await body(req);
      const v = st.versions.find((x) => x.version === (b && b.version));
      if (!v || v.outcome !== 'accepted') { send(res, 409, { error: `rollback refused: version ${b && b.version} was not accepted` }); return; }
      const version = st.versions.length + 1;
      st.versions.forEach((x) => { x.running = false; });
      st.versions.push({ ...v, version, origin: 'rollback', time_ns: Date.now() * 1e6, running: true });
      send(res, 200, { ok: true, version, errors: [], report: { kept: ['filler', 'capper'], retuned: [], new: [], removed: ['labeler'], summary: 'instances: 2 kept, 0 retuned, 0 rewired, 0 new, 1 removed' } });
      return;
    }
    send(res, 404, { error: `no resource ${req.method} ${path}` });
  }

  async function serveStatic(req, res, url) {
    let p = decodeURIComponent(url.pathname);
    if (p === '/') p = '/index.html';
    const file = resolve(distDir, normalize(`.${p}`));
    if (!file.startsWith(distDir + sep)) { res.writeHead(404); res.end(); return; }
    try {
      const data = await readFile(file);
      // The strictest policy the HMI is meant to work under: everything from
      // the PLC itself, no inline script or style, no other origin.
      res.writeHead(200, { 'Content-Type': TYPES[extname(file)] || 'application/octet-stream',
        'Content-Security-Policy': "default-src 'self'; frame-ancestors 'none'; form-action 'none'; base-uri 'none'" });
      res.end(data);
    } catch { res.writeHead(404, { 'Content-Type': 'text/plain' }); res.end('not found'); }
  }

  const server = createServer((req, res) => {
    const url = new URL(req.url, 'http://fixture');
    if (url.pathname.startsWith('/api/v1/')) api(req, res, url).catch((e) => send(res, 500, { error: String(e) }));
    else serveStatic(req, res, url);
  });
  await new Promise((ok) => server.listen(port, '127.0.0.1', ok));
  return {
    url: `http://127.0.0.1:${server.address().port}`,
    state: st,
    // Cut every live stream and refuse new ones for ms (a PLC gone away).
    dropStreams(ms) {
      st.refuseStreamsUntil = Date.now() + ms;
      for (const s of st.streams) { clearInterval(s.timer); s.res.destroy(); }
      st.streams.clear();
    },
    stopTask(stopped = true) { st.slowStopped = stopped; },
    close() {
      clearInterval(ticker);
      for (const s of st.streams) { clearInterval(s.timer); s.res.destroy(); }
      server.closeAllConnections && server.closeAllConnections();
      return new Promise((ok) => server.close(ok));
    },
    MAIN_YAML,
  };
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const f = await startFixture({ port: Number(process.argv[2] || 8088), users: { viewer: { password: 'viewer-pw', role: 'viewer' }, operator: { password: 'operator-pw', role: 'operator' }, engineer: { password: 'engineer-pw', role: 'engineer' } } });
  console.log(`fixture (test only) at ${f.url}; users viewer/operator/engineer, password <name>-pw`);
}
