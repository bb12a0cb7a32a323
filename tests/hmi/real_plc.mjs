// A real `syncplc run` for the browser tests and the screenshots: users made
// with `syncplc user add` in a database of its own, the HTTP server and the
// Modbus server each on a free port of 127.0.0.1 (port 0: the server picks
// one and prints it), XDG_STATE_HOME and the pid file in a temporary
// directory, a --duration safety limit, stopped with SIGTERM by stop() and
// killed when the test process exits whatever happened.
import { spawn, spawnSync } from 'node:child_process';
import { randomBytes } from 'node:crypto';
import { mkdtemp, rm } from 'node:fs/promises';
import { constants, tmpdir } from 'node:os';
import { join } from 'node:path';

const live = new Set();
process.on('exit', () => { for (const p of live) try { p.kill('SIGKILL'); } catch { /* gone */ } });
for (const sig of ['SIGINT', 'SIGTERM', 'SIGHUP']) {
  process.on(sig, () => { for (const p of live) try { p.kill('SIGKILL'); } catch { /* gone */ } process.exit(128 + constants.signals[sig]); });
}

// users: {name: role}; each gets a random password, returned in plc.users[name].
export async function startPlc({ binary, project, users = {}, duration = '300s', extra = [] }) {
  const dir = await mkdtemp(join(tmpdir(), 'syncplc-hmi-real-'));
  const db = join(dir, 'plc.db');
  const env = { ...process.env, XDG_STATE_HOME: join(dir, 'state'), XDG_RUNTIME_DIR: dir };
  const passwords = {};
  for (const [name, role] of Object.entries(users)) {
    const password = `${name}-${randomBytes(9).toString('base64url')}`;
    const r = spawnSync(binary, ['user', 'add', name, '--role', role, '--password-stdin', '--db', db],
      { input: `${password}\n`, env, encoding: 'utf8', timeout: 60000 });
    if (r.status !== 0) throw new Error(`syncplc user add ${name} --role ${role} failed (status ${r.status}):\n${r.stdout}${r.stderr}`);
    passwords[name] = { password, role };
  }
  const args = ['run', project, '--no-status', '--db', db, '--http', '127.0.0.1:0', '--modbus-port', '0',
    '--duration', duration, '--pid-file', join(dir, 'plc.pid'), ...extra];
  const proc = spawn(binary, args, { env, stdio: ['ignore', 'pipe', 'pipe'] });
  live.add(proc);
  let stdout = '';
  let stderr = '';
  proc.stdout.setEncoding('utf8').on('data', (d) => { stdout += d; });
  proc.stderr.setEncoding('utf8').on('data', (d) => { stderr += d; });
  const exited = new Promise((resolve) => proc.on('exit', (code, signal) => { live.delete(proc); resolve({ code, signal }); }));
  let gone = null;
  exited.then((e) => { gone = e; });

  // Both ports from stderr: "HMI and HTTP API on http://127.0.0.1:N/", "modbus: listening on 127.0.0.1:M".
  const end = Date.now() + 60000;
  let url = null; let modbusPort = null;
  while (!(url && modbusPort)) {
    url = url || (/HMI and HTTP API on (http:\/\/127\.0\.0\.1:\d+)\//.exec(stderr) || [])[1];
    modbusPort = modbusPort || Number((/modbus: listening on 127\.0\.0\.1:(\d+)/.exec(stderr) || [])[1]) || null;
    if (url && modbusPort) break;
    if (gone || Date.now() > end) {
      proc.kill('SIGKILL');
      await exited;
      await rm(dir, { recursive: true, force: true });
      throw new Error(`syncplc ${args.join(' ')} did not report its HTTP and Modbus ports${gone ? ` (it exited: ${JSON.stringify(gone)})` : ''}\nstderr:\n${stderr}\nstdout:\n${stdout}`);
    }
    await new Promise((r) => setTimeout(r, 50));
  }

  return {
    url,
    modbusPort,
    db,
    dir,
    users: passwords,
    proc,
    get stderr() { return stderr; },
    get stdout() { return stdout; },
    running: () => !gone,
    // JSON from the API (no login: reads are anonymous on loopback).
    async api(path, init = {}) {
      const res = await fetch(`${url}/api/v1${path}`, { ...init, headers: { Accept: 'application/json', ...(init.headers || {}) } });
      const body = await res.json().catch(() => null);
      if (!res.ok && !init.allowError) throw new Error(`${init.method || 'GET'} ${path}: HTTP ${res.status} ${JSON.stringify(body)}`);
      return init.allowError ? { status: res.status, body } : body;
    },
    // SIGTERM, then SIGKILL after 30 s; the exit and what it printed.
    async stop() {
      if (!gone) {
        proc.kill('SIGTERM');
        const t = setTimeout(() => proc.kill('SIGKILL'), 30000);
        await exited;
        clearTimeout(t);
      }
      await rm(dir, { recursive: true, force: true });
      return { ...gone, stdout, stderr };
    },
  };
}
