// The session: the token from POST /api/v1/login, kept in sessionStorage
// (this tab only, gone when it closes; never a cookie), the user's name and
// role, and what each role may do (viewer < operator < engineer).
import { configureHttp } from '../api/http.js';

const KEY = 'syncplc.session';
const listeners = new Set();
let session = load();

function load() {
  try {
    const s = JSON.parse(sessionStorage.getItem(KEY) || 'null');
    if (s && s.token && (!s.expiresAt || s.expiresAt > Date.now())) return s;
  } catch { /* no storage or bad JSON: no session */ }
  return null;
}

function save(s) {
  session = s;
  try {
    if (s) sessionStorage.setItem(KEY, JSON.stringify(s)); else sessionStorage.removeItem(KEY);
  } catch { /* storage refused: the session lives in memory */ }
  for (const l of listeners) l(s);
}

export const ROLES = ['viewer', 'operator', 'engineer'];
export const rank = (role) => ROLES.indexOf(role);

// What each action needs, with the words shown on a disabled control.
export const NEEDS = {
  write: { role: 'operator', hint: 'Writing values needs an operator or engineer login.' },
  acknowledge: { role: 'operator', hint: 'Acknowledging needs an operator or engineer login.' },
  force: { role: 'engineer', hint: 'Forcing needs an engineer login.' },
  project: { role: 'engineer', hint: 'Loading projects needs an engineer login.' },
};

export function can(action, s = session) {
  const need = NEEDS[action];
  return !!(s && need && rank(s.role) >= rank(need.role));
}

export const hint = (action) => (NEEDS[action] ? NEEDS[action].hint : '');
export const current = () => session;

export function onSession(l) {
  listeners.add(l);
  return () => listeners.delete(l);
}

// From the login answer {"token","user","role","expires_in_s"}.
export function begin(answer) {
  save({
    token: answer.token,
    user: answer.user,
    role: answer.role,
    expiresAt: answer.expires_in_s ? Date.now() + answer.expires_in_s * 1000 : null,
  });
}

export const end = () => save(null);

configureHttp({
  token: () => (session ? session.token : null),
  // The server no longer knows the token (expired, revoked, restarted).
  unauthorized: () => { if (session) save(null); },
});
