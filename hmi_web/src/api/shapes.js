// The server's JSON turned into what the pages use, in one place: names in
// the pages' words (camelCase), missing parts filled with null, a list
// whether it came bare or wrapped ({"tags": [...]}). Pure functions (tested
// in test/shapes.test.mjs).

const num = (v) => (typeof v === 'number' && Number.isFinite(v) ? v : (v === null || v === undefined || v === '' ? null : (Number.isFinite(Number(v)) ? Number(v) : null)));
const list = (data, key) => (Array.isArray(data) ? data : (data && Array.isArray(data[key]) ? data[key] : []));
// The first value given that is neither undefined nor null; null when none is.
const first = (...vs) => { const v = vs.find((x) => x !== undefined && x !== null); return v === undefined ? null : v; };

// {last, min, max, mean, p99} from either plain or _ns-suffixed keys.
function stats(s) {
  s = s || {};
  const k = (name) => num(first(s[name], s[`${name}_ns`]));
  return { last: k('last'), min: k('min'), max: k('max'), mean: k('mean'), p99: k('p99') };
}

export function normalizeHistogram(h) {
  if (!h) return null;
  const bounds = (h.bounds_ns || h.bounds || []).map(Number);
  const counts = (h.counts || []).map(Number);
  if (!counts.length) return null;
  return { boundsNs: bounds, counts };
}

export function normalizeTask(t) {
  const jitter = first(t.start_jitter_ns, t.jitter_ns, t.start_jitter, t.jitter, {}) || {};
  return {
    name: t.name,
    periodNs: num(first(t.period_ns, t.period)),
    priority: num(t.priority),
    cpu: first(t.cpu, null),
    state: t.state || 'running',
    stopReason: first(t.stop_reason, t.reason, null),
    scans: num(t.scans),
    overruns: num(t.overruns),
    watchdogTrips: num(first(t.watchdog_trips, t.watchdog)),
    exec: { ...stats(first(t.exec_ns, t.exec_time_ns, t.exec)), histogram: normalizeHistogram((first(t.exec_ns, t.exec_time_ns, t.exec) || {}).histogram) },
    jitter: { ...stats(jitter), histogram: normalizeHistogram(first(jitter.histogram, t.jitter_histogram)) },
  };
}

export function normalizeStatus(d) {
  d = d || {};
  const r = d.runtime || {};
  let store = first(r.store, d.store, null);
  if (typeof store === 'string') store = { state: store, detail: null };
  else if (store) store = { state: store.state || 'unknown', detail: first(store.detail, store.message, store.path, null) };
  return {
    runtime: {
      version: first(r.version, null),
      projectFile: first(r.project_file, r.project, null),
      projectName: first(r.project_name, r.program ? [r.program, r.program_version].filter(Boolean).join(' ') : null, null),
      projectVersion: first(r.project_version, null),
      uptimeS: num(first(r.uptime_s, r.uptime)),
      store,
      modbus: first(r.modbus, r.modbus_endpoint, null),
    },
    tasks: list(d, 'tasks').map(normalizeTask),
    forces: num(first(d.forces, d.active_forces, 0)),
  };
}

export function normalizeTag(t) {
  const length = num(first(t.length, 1));
  const lower = num(first(t.lower, t.lower_bound, t.array_lower, 1));
  // The element type with is_array, or the whole declaration as written.
  const type = t.is_array && !/^ARRAY/i.test(t.type) ? `ARRAY[${lower}..${lower + length - 1}] OF ${t.type}` : t.type;
  const access = first(t.hmi, t.access, 'read');
  return {
    name: t.name,
    type,
    length,
    lower,
    access,
    // hmi: readwrite, and not a tag the program writes every scan (that one can only be forced).
    writable: access === 'readwrite' && !t.written_every_scan,
    writtenEveryScan: !!t.written_every_scan,
    unit: t.unit || '',
    task: t.task || '',
    writer: first(t.writer, null),
    retain: !!t.retain,
    forced: first(t.forced, false),
    description: t.description || '',
  };
}

export const normalizeTags = (d) => list(d, 'tags').map(normalizeTag);

export function normalizeBlocks(d) {
  return list(d, 'blocks').map((b) => ({
    name: first(b.name, b.instance),
    type: b.type,
    task: b.task || '',
    position: num(first(b.position, b.order)),
    pins: (b.pins || []).map((p) => ({
      name: p.name,
      direction: first(p.direction, p.dir, 'in'),
      type: p.type,
      unit: p.unit || '',
      length: num(first(p.length, 1)),
      lower: num(first(p.lower, 1)),
      value: first(p.value, null),
      forced: first(p.forced, false),
    })),
    // An ST instance's variables (instance.path); none for other blocks.
    variables: (b.variables || []).map((v) => ({
      name: v.name,
      type: v.type,
      value: first(v.value, null),
      forced: first(v.forced, false),
    })),
  }));
}

export function normalizeEvent(e) {
  return {
    id: num(e.id),
    timeNs: num(first(e.time_ns, e.t_ns)),
    kind: e.kind || '',
    task: e.task || '',
    source: e.source || '',
    message: e.message || '',
    client: e.client || '',
    scan: num(e.scan),
  };
}

export const normalizeEvents = (d) => list(d, 'events').map(normalizeEvent);

export function normalizeTrend(d) {
  d = d || {};
  const point = (p) => (Array.isArray(p)
    ? { t: num(p[0]), min: num(p[1]), max: num(p[2]), mean: num(p[3]), count: num(p[4]) }
    : { t: num(first(p.t_ns, p.t)), min: num(p.min), max: num(p.max), mean: num(p.mean), count: num(p.count) });
  const series = Array.isArray(d.series)
    ? d.series.map((s) => ({ label: s.label || s.tag, unit: s.unit || d.unit || '', points: (s.points || []).map(point) }))
    : [{ label: d.label || d.tag, unit: d.unit || '', points: (d.points || []).map(point) }];
  return { tag: d.tag, series };
}

// "file.yaml:12:7" → {file, line, col}; a message that starts with it too.
export function parseWhere(text) {
  if (!text || typeof text !== 'string') return null;
  const m = /^(.*?):(\d+)(?::(\d+))?(?::|$)/.exec(text);
  if (!m || !m[1]) return null;
  return { file: m[1], line: Number(m[2]), col: m[3] ? Number(m[3]) : null };
}

export function normalizeError(e) {
  if (typeof e === 'string') {
    const where = parseWhere(e);
    const message = where ? e.replace(/^.*?:\d+(?::\d+)?:\s*/, '') : e;
    return { message, where, text: e };
  }
  const where = typeof e.where === 'string' ? parseWhere(e.where) : (e.where || null);
  const message = first(e.message, e.error, '');
  return { message, where, text: e.where ? `${e.where}: ${message}` : message };
}

const names = (v) => (Array.isArray(v) ? v.map((x) => (typeof x === 'string' ? x : x.name)) : []);

export function normalizeProjectReport(d) {
  d = d || {};
  const errors = (d.errors || (d.error ? [{ message: d.error, where: d.where }] : [])).map(normalizeError);
  const c = d.report || d.changes || d.change || null;
  const report = c ? {
    kept: names(c.kept), retuned: names(c.retuned), rewired: names(c.rewired), new: names(c.new || c.added), removed: names(c.removed),
    summary: c.summary || d.summary || '',
  } : null;
  return { ok: d.ok !== undefined ? !!d.ok : errors.length === 0, errors, report, version: first(d.version, null) };
}

export function normalizeVersions(d) {
  return list(d, 'versions').map((v) => ({
    version: num(first(v.version, v.id)),
    timeNs: num(first(v.time_ns, v.t_ns)),
    origin: v.origin || '',
    outcome: v.outcome || '',
    project: first(v.project, v.name, ''),
    hash: v.hash || '',
    files: num(v.files),
    errors: (v.errors || []).map(normalizeError),
    running: !!v.running,
  }));
}
