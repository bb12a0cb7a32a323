// Every call the HMI makes, in one module, after the agreed outline of
// issue 14 (prefix /api/v1). Pages call these and never build URLs
// themselves, so a resource that changes shape changes here only.
import { ApiError, request } from './http.js';
import { normalizeStatus, normalizeTags, normalizeBlocks, normalizeEvents, normalizeTrend,
  normalizeProjectReport, normalizeVersions } from './shapes.js';

const enc = encodeURIComponent;

// --- session
export const login = (user, password) => request('POST', '/login', { body: { user, password } });
export const logout = () => request('POST', '/logout');
export const me = () => request('GET', '/me');

// --- reading the PLC
export const getStatus = async (opts) => normalizeStatus(await request('GET', '/status', opts));
export const getTags = async (filter) => normalizeTags(await request('GET', '/tags', { query: { filter } }));
export const getTag = (name) => request('GET', `/tags/${enc(name)}`);
export const getValues = (refs) => request('GET', '/values', { query: { refs } });
export const getBlocks = async () => normalizeBlocks(await request('GET', '/blocks'));
export const getBlock = (instance) => request('GET', `/blocks/${enc(instance)}`);
// since: the id of the newest event already shown (0: from the start).
export const getEvents = async ({ since, kind, limit } = {}) =>
  normalizeEvents(await request('GET', '/events', { query: { since, kind, limit } }));
// since/until: wall time in ns since 1970 (as the store keeps it).
export const getTrend = async ({ tag, since, until, points }) =>
  normalizeTrend(await request('GET', '/trends', { query: { tag, since, until, points } }));

// --- changing the PLC (operator: write; engineer: force)
export const writeTag = (name, value) => request('PUT', `/tags/${enc(name)}`, { body: { value } });
export const force = (ref, value) => request('POST', '/forces', { body: { ref, value } });
export const unforce = (ref) => request('DELETE', `/forces/${enc(ref)}`);
export const getForces = () => request('GET', '/forces');

// --- PLCopen axes (docs/http-api.md, "Axes"): every MC_AXIS with its live
// state; enable/disable (operator) and reset (engineer) act at the next scan.
export const getAxes = () => request('GET', '/axes');
export const axisCommand = (name, command) => request('POST', `/axes/${enc(name)}/${command}`, { body: {} });

// --- projects (engineer). A project is its main YAML file and its includes,
// sent as text: {"main": "sync.yaml", "files": {"sync.yaml": "...", "table.yaml": "..."}}.
// check: loads it beside the running program without changing anything and
// answers {"ok", "errors": [{"message", "where": "file:line:col"}]};
// load: the same, then the online change, answering the change report too.
// A project the loader refused comes back as 400 with its errors: that is a
// report to show, not a failure of the call.
async function projectCall(path, body) {
  try {
    return normalizeProjectReport(await request('POST', path, { body }));
  } catch (e) {
    if (e instanceof ApiError && (e.status === 400 || e.status === 409) && e.body) return normalizeProjectReport(e.body);
    throw e;
  }
}
export const checkProject = (project) => projectCall('/projects/check', project);
export const loadProject = (project) => projectCall('/projects/load', project);
export const getProjects = async () => normalizeVersions(await request('GET', '/projects'));
export const rollback = (version) => projectCall('/projects/rollback', { version });
