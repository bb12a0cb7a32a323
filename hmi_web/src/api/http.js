// The one place that talks HTTP to the PLC (prefix /api/v1, docs/http-api.md).
// The session token goes in `Authorization: Bearer`, never in a cookie
// (credentials: 'omit'), so another site's page cannot act with it.

import { link } from './link.js';

export const API_PREFIX = '/api/v1';

// An error the pages can show as is: `message` in words, `where` the
// file:line:col the server named (project errors), `status` the HTTP status.
export class ApiError extends Error {
  constructor(status, message, where, body) {
    super(message);
    this.name = 'ApiError';
    this.status = status;
    this.where = where || null;
    this.body = body || null;
  }
}

const STATUS_WORDS = {
  0: 'The PLC cannot be reached (no answer from the server).',
  400: 'The PLC refused the request as malformed.',
  401: 'You are not logged in, or your session has expired. Log in and try again.',
  403: 'Your role does not allow this.',
  404: 'Not found on the PLC.',
  405: 'The PLC does not allow this here.',
  409: 'The PLC refused this in its current state.',
  413: 'The upload is larger than the PLC accepts.',
  429: 'Too many attempts. Wait a little and try again.',
  500: 'The PLC had an internal error.',
  501: 'This PLC does not offer this yet.',
  503: 'The PLC is busy; try again shortly.',
};

export function statusWords(status) {
  return STATUS_WORDS[status] || `The PLC answered with HTTP status ${status}.`;
}

let currentToken = () => null;
let unauthorizedHandler = () => {};

// session.js tells where the token is and what to do when it is refused.
export function configureHttp({ token, unauthorized }) {
  if (token) currentToken = token;
  if (unauthorized) unauthorizedHandler = unauthorized;
}

export function authHeaders() {
  const t = currentToken();
  return t ? { Authorization: `Bearer ${t}` } : {};
}

export function apiUrl(path, query) {
  let url = API_PREFIX + path;
  if (query) {
    const q = new URLSearchParams();
    for (const [k, v] of Object.entries(query)) {
      if (v === undefined || v === null || v === '') continue;
      q.set(k, Array.isArray(v) ? v.join(',') : String(v));
    }
    const s = q.toString();
    if (s) url += `?${s}`;
  }
  return url;
}

// One request: JSON in, JSON out; a refusal becomes an ApiError in words.
export async function request(method, path, { query, body, signal } = {}) {
  const headers = { Accept: 'application/json', ...authHeaders() };
  const init = { method, headers, signal, credentials: 'omit', cache: 'no-store' };
  if (body !== undefined) {
    headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  let res;
  const ended = link.started();
  try {
    res = await fetch(apiUrl(path, query), init);
    link.answered();
  } catch (e) {
    if (e && e.name === 'AbortError') throw e;
    link.failed(statusWords(0));
    throw new ApiError(0, statusWords(0));
  } finally {
    ended();
  }
  let data = null;
  const type = res.headers.get('Content-Type') || '';
  if (type.includes('json')) {
    try { data = await res.json(); } catch { data = null; }
  } else {
    const text = await res.text();
    data = text ? { text } : null;
  }
  if (!res.ok) {
    // A refused login says nothing about the session this tab may hold.
    if (res.status === 401 && path !== '/login') unauthorizedHandler();
    const message = (data && data.error) || statusWords(res.status);
    throw new ApiError(res.status, message, data && data.where, data);
  }
  return data;
}
