// The HMI's pages in Debian's chromium against a REAL `syncplc run` of
// tests/hmi/projects/hmi_cell (its own database with three users, its own
// ports, stopped at the end): what an operator and an engineer do, checked
// on the PLC itself (the API, and Modbus read with Debian's python3-pymodbus).
//   node tests/hmi/test_real_pages.mjs build/syncplc      (ctest -L hmi: hmi.real_pages)
import { existsSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { requireBrowser, launch, DESKTOP, ROOT, until } from './browser.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const PYTHON = '/usr/bin/python3'; // Debian's: the one that has python3-pymodbus

const binary = process.argv[2];
if (!binary || !existsSync(binary)) {
  console.error(`usage: node ${process.argv[1]} PATH/TO/syncplc${binary ? ` (${binary} does not exist)` : ''}`);
  process.exit(1);
}
requireBrowser();

const { test, before, after, afterEach } = await import('node:test');
const assert = (await import('node:assert/strict')).default;
const { execFile } = await import('node:child_process');
const { startPlc } = await import('./real_plc.mjs');

const PROJECT_DIR = join(here, 'projects', 'hmi_cell');
const MAIN = 'cell.yaml';
const IO = 'cell_io.yaml';
// Modbus places (cell_io.yaml): holding registers, high word first.
const MB = { speed_set: '4096', speed_out: '4100', ref_pos: '4104', limits: '1056', scan_count: '2088' };

let plc; let browser; let sources;

before(async () => {
  sources = { [MAIN]: await readFile(join(PROJECT_DIR, MAIN), 'utf8'), [IO]: await readFile(join(PROJECT_DIR, IO), 'utf8') };
  plc = await startPlc({
    binary,
    project: join(PROJECT_DIR, MAIN),
    users: { olga: 'operator', erik: 'engineer', vera: 'viewer' },
    extra: ['--hmi-dir', join(ROOT, 'hmi_web', 'dist')],
  });
  browser = await launch();
});
const pages = new Set();
afterEach(async () => {
  for (const p of pages) if (!p.isClosed()) await p.close();
  pages.clear();
});
after(async () => {
  if (browser) await browser.close();
  if (plc) {
    const end = await plc.stop();
    // It ran the whole test and stopped cleanly on SIGTERM (not by its --duration, not by a crash).
    assert.equal(end.code, 0, `syncplc run exited with ${JSON.stringify(end)}\nstderr:\n${end.stderr}`);
    assert.match(end.stdout, /Stopped by SIGTERM/);
  }
});

// A page of the HMI served by the PLC; JavaScript errors and console errors
// (a blocked resource, a content security policy violation) are collected,
// except the browser's own line for a refused request (tests 6 and a failed
// login ask for those).
async function open(path) {
  const page = await browser.context.newPage();
  pages.add(page);
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error' && !/status of (400|401|403|404|409)/.test(m.text())) errors.push(m.text()); });
  await page.setViewportSize(DESKTOP);
  await page.goto(`${plc.url}/#/${path}`);
  page.jsErrors = errors;
  return page;
}

async function login(page, user) {
  await page.getByRole('button', { name: 'Log in' }).first().click();
  await page.getByLabel('User name').fill(user);
  await page.getByLabel('Password').fill(plc.users[user].password);
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.who .user-name', { hasText: user }).waitFor({ timeout: HANG_GUARD_MS });
}

// Every wait is for a condition (a value, a count of scans, an element); its
// time limit only ends a hang, so a loaded machine makes the test slower,
// not wrong.
const HANG_GUARD_MS = 120000;

const pause = (ms) => new Promise((r) => setTimeout(r, ms));

// [[values at ADDRESS1], ...] read with pymodbus 3.0 from the PLC's Modbus server.
function modbusRead(...addressTypes) {
  return new Promise((resolve, reject) => {
    execFile(PYTHON, [join(here, 'modbus_read.py'), String(plc.modbusPort), ...addressTypes], { timeout: 30000 },
      (err, stdout, stderr) => (err ? reject(new Error(`modbus_read.py: ${err.message}\n${stderr}`)) : resolve(JSON.parse(stdout))));
  });
}

const values = async (...refs) => plc.api(`/values?refs=${refs.map(encodeURIComponent).join(',')}`);
const task = async (name = 'main') => (await plc.api('/status')).tasks.find((t) => t.name === name);
const rowValue = (page, tag) => page.locator(`tr[data-tag=${tag}] .value .num`).innerText();
const noValue = (t) => t === '' || t === '–';

test('1. overview: the task with its period and growing scan count; tags: live values move', async () => {
  const page = await open('overview');
  const card = page.locator('[data-task=main]');
  await card.waitFor({ timeout: HANG_GUARD_MS });
  assert.match(await card.innerText(), /every 10 ms/);
  assert.match(await card.locator('.pill').innerText(), /running/);
  await page.locator('.runtime', { hasText: 'hmi_cell 1.0.0' }).waitFor();
  assert.doesNotMatch(await page.locator('body').innerText(), /undefined|NaN/);
  assert.ok(await card.locator('canvas').count() > 0, 'the start-jitter histogram is drawn');
  const scans = card.locator('.stat', { hasText: 'Scans' }).locator('dd');
  const s1 = await until(async () => { const t = await scans.innerText(); return !noValue(t) && t; }, HANG_GUARD_MS, 'a scan count');
  await until(async () => (await scans.innerText()) !== s1, HANG_GUARD_MS, `the scan count to grow from ${s1}`);

  await page.goto(`${plc.url}/#/tags`);
  for (const tag of ['ref_pos', 'scan_count']) {
    const first = await until(async () => { const t = await rowValue(page, tag); return !noValue(t) && t; }, HANG_GUARD_MS, `a live value of ${tag}`);
    await until(async () => (await rowValue(page, tag)) !== first, HANG_GUARD_MS, `${tag} to move from ${first}`);
  }
  assert.equal((await page.locator('tr[data-tag=ref_pos] .value .unit').innerText()).trim(), 'rad');
  assert.equal(await page.locator('.conn').innerText(), 'Live');
  // The array, whole, with the project's initial values.
  await until(async () => (await rowValue(page, 'limits')).replace(/\s/g, '') === '10,20,30', HANG_GUARD_MS, 'limits shown as 10, 20, 30');
  assert.deepEqual(page.jsErrors, []);
});

test('2. write: an operator writes a setpoint and an array element from the page; pymodbus reads them back, also as the program copied them', async () => {
  const page = await open('tags');
  await login(page, 'olga');
  const row = page.locator('tr[data-tag=speed_set]');
  const before = (await values('speed_set')).values.speed_set;
  const want = before === 2.25 ? 1.75 : 2.25;
  await row.locator('button', { hasText: 'Write' }).click();
  await page.locator('dialog[open] input[name=value]').fill(String(want));
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.ok-note', { hasText: 'Written to speed_set.' }).waitFor();
  // The tag itself and speed_out, which the program copies from it every scan.
  const [[set], [out]] = await until(async () => {
    const v = await modbusRead(MB.speed_set, 'LREAL', MB.speed_out, 'LREAL');
    return v[1][0] === want && v;
  }, HANG_GUARD_MS, `pymodbus to read speed_out = ${want}`);
  assert.equal(set, want);
  assert.equal(out, want);
  await until(async () => (await rowValue(page, 'speed_set')) === String(want), HANG_GUARD_MS, 'the written value on the page');

  await page.locator('tr[data-tag=limits] button', { hasText: 'Write' }).click();
  await page.locator('dialog[open] input[name=element]').fill('2');
  await page.locator('dialog[open] input[name=value]').fill('25');
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.ok-note', { hasText: 'Written to limits[2].' }).waitFor();
  const [limits] = await until(async () => {
    const v = await modbusRead(MB.limits, 'INT,INT,INT');
    return v[0][1] === 25 && v;
  }, HANG_GUARD_MS, 'pymodbus to read limits[2] = 25');
  assert.deepEqual(limits, [10, 25, 30]);

  // What an operator cannot do: write a value the program writes every scan, or one with hmi: read; force.
  const everyScan = page.locator('tr[data-tag=speed_out] button', { hasText: 'Write' });
  assert.equal(await everyScan.isDisabled(), true);
  assert.match(await everyScan.getAttribute('title'), /every scan/);
  assert.equal(await row.locator('button', { hasText: 'Force' }).isDisabled(), true);
  // The PLC's event log names the user.
  const events = (await plc.api('/events?kind=hmi-write')).events.map((e) => e.message);
  assert.ok(events.some((m) => m.includes(`speed_set := ${want}`) && m.includes('olga')), events.join('\n'));
  assert.deepEqual(page.jsErrors, []);
});

test('3. force: an engineer forces a value the program writes every scan; it holds, flagged F, until unforced', async () => {
  const page = await open('tags');
  await login(page, 'erik');
  const row = page.locator('tr[data-tag=ref_pos]');
  await row.locator('button', { hasText: 'Force' }).click();
  await page.locator('dialog[open] input[name=value]').fill('0.75');
  await page.locator('dialog[open] input[name=confirm]').check();
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.ok-note', { hasText: 'ref_pos is forced.' }).waitFor();
  await row.locator('.badge-forced').waitFor();
  assert.equal(await row.locator('.value').getAttribute('data-forced'), 'true');
  await until(async () => { const v = await values('ref_pos'); return v.values.ref_pos === 0.75 && v.forced.ref_pos === true; }, HANG_GUARD_MS, 'ref_pos forced to 0.75');
  // Held over reads at least a second apart while the program runs on (its scan counter grows).
  const reads = [];
  for (let i = 0; i < 6; i++) {
    reads.push(await values('ref_pos', 'scan_count'));
    await pause(250);
  }
  await until(async () => (await values('scan_count')).values.scan_count > reads[0].values.scan_count + 100, HANG_GUARD_MS, 'a hundred scans under the force');
  reads.push(await values('ref_pos', 'scan_count'));
  for (const r of reads) {
    assert.equal(r.values.ref_pos, 0.75);
    assert.equal(r.forced.ref_pos, true);
  }
  assert.ok(reads.at(-1).values.scan_count > reads[0].values.scan_count, 'the program ran meanwhile');
  assert.deepEqual((await modbusRead(MB.ref_pos, 'LREAL'))[0], [0.75], 'Modbus reads the forced value too');
  assert.equal((await plc.api('/forces')).forces.length, 1);
  await until(async () => (await rowValue(page, 'ref_pos')) === '0.75', HANG_GUARD_MS, 'the page to show 0.75');
  assert.ok((await page.locator('tr[data-tag=ref_pos].forced-row').count()) === 1);

  await row.locator('button', { hasText: 'Unforce' }).click();
  await page.locator('.ok-note', { hasText: 'ref_pos is no longer forced.' }).waitFor();
  await until(async () => (await row.locator('.badge-forced').count()) === 0, HANG_GUARD_MS, 'the F badge gone');
  await until(async () => (await values('ref_pos')).forced.ref_pos === false, HANG_GUARD_MS, 'ref_pos released');
  const a = (await values('ref_pos')).values.ref_pos;
  await until(async () => { const b = (await values('ref_pos')).values.ref_pos; return b !== a && b !== 0.75; }, HANG_GUARD_MS, 'ref_pos to move again');
  assert.deepEqual((await plc.api('/forces')).forces, []);
  assert.deepEqual(page.jsErrors, []);
});

// The test's own edit of the project: the line and column of `find` in the result.
function edit(text, from, to) {
  assert.ok(text.includes(from), `${MAIN} has no '${from}'`);
  const out = text.replace(from, to);
  const at = out.indexOf(to);
  const line = out.slice(0, at).split('\n').length;
  return { text: out, line, col: at - out.lastIndexOf('\n', at - 1) };
}

async function upload(page, mainText, extra = []) {
  await page.locator('input[name=files]').setInputFiles([
    { name: MAIN, mimeType: 'text/yaml', buffer: Buffer.from(mainText) },
    { name: IO, mimeType: 'text/yaml', buffer: Buffer.from(sources[IO]) },
    ...extra.map(([name, text]) => ({ name, mimeType: 'text/plain', buffer: Buffer.from(text) })),
  ]);
  assert.equal(await page.getByLabel('Main file').inputValue(), MAIN);
}

async function plcState() {
  const status = await plc.api('/status');
  const v = await values('speed_set', 'limits', 'scan_count');
  const running = (await plc.api('/projects')).versions.filter((x) => x.running).map((x) => x.version);
  return { status, task: status.tasks.find((t) => t.name === 'main'), values: v.values, running };
}

test('4. a bad upload: its error at its line in the source view; the running program is untouched', async () => {
  const page = await open('project');
  await login(page, 'erik');
  const bad = edit(sources[MAIN], 'period: 10ms', 'period: 10xs');
  const valueCol = bad.col + 'period: '.length;
  const was = await plcState();
  await upload(page, bad.text);
  for (const [action, said] of [['Check', '1 error: the project would not load'], ['Load onto the PLC', '1 error: not loaded; the running program is unchanged']]) {
    await page.getByRole('button', { name: action }).click();
    await page.locator('#check-result.bad', { hasText: said }).waitFor({ timeout: HANG_GUARD_MS });
    await page.locator('#check-result button.link', { hasText: `${MAIN}, line ${bad.line}, column ${valueCol}` }).waitFor();
    const line = page.locator('.src-line.has-error');
    assert.equal(await line.count(), 1, action);
    assert.equal(await line.getAttribute('data-line'), String(bad.line));
    assert.match(await line.innerText(), new RegExp(`period: 10xs[\\s\\S]*column ${valueCol}: .*10xs`));
  }
  assert.equal(await page.locator('#change-report').count(), 0);
  // Untouched: the same version runs, on and on, with the same values.
  // Counted, not timed: the program's own scan counter must pass a hundred more scans
  // (under ASan the published values can trail the task's scan count).
  await until(async () => (await task()).scans > was.task.scans + 100, HANG_GUARD_MS, 'a hundred more scans');
  await until(async () => (await values('scan_count')).values.scan_count > was.values.scan_count + 100,
    HANG_GUARD_MS, 'the program counts on');
  const now = await plcState();
  assert.equal(now.status.runtime.program_version, was.status.runtime.program_version);
  assert.deepEqual(now.running, was.running);
  assert.equal(now.values.speed_set, was.values.speed_set);
  assert.deepEqual(now.values.limits, was.values.limits);
  assert.ok(now.values.scan_count > was.values.scan_count + 100, 'the program counts on');
  assert.equal(now.task.state, 'running');
  assert.deepEqual(page.jsErrors, []);
});

test('4b. an upload with Structured Text: its type error at its line in the .st file\'s source view', async () => {
  const page = await open('project');
  await login(page, 'erik');
  const glue = 'PROGRAM Glue\nVAR x : INT; END_VAR\nx := 1.5;\nEND_PROGRAM\n';
  await upload(page, `${sources[MAIN]}\nsources: [glue.st]\nprograms: [{name: glue, type: Glue}]\n`, [['glue.st', glue]]);
  await page.getByRole('button', { name: 'Check' }).click();
  await page.locator('#check-result.bad', { hasText: '1 error: the project would not load' }).waitFor({ timeout: HANG_GUARD_MS });
  const link = page.locator('#check-result button.link', { hasText: 'glue.st, line 3, column 6' });
  await link.waitFor();
  await link.click();
  const line = page.locator('.src-line.has-error');
  await until(async () => (await line.count()) === 1, HANG_GUARD_MS, 'the line in error shown');
  assert.equal(await line.getAttribute('data-line'), '3');
  assert.match(await line.innerText(), /x := 1\.5;[\s\S]*column 6: .*expected INT, found a real literal/);
});

test('5. a good upload is loaded by online change: the change report, no skipped scan, no overrun', async () => {
  const page = await open('project');
  await login(page, 'erik');
  const was = await plcState();
  // This machine is shared: a scan may start late (and overrun) now and then
  // whatever the PLC does, so the counters are compared over the load alone
  // (read just before the click and just after the answer is shown), and a
  // load during which such a stall happened is repeated, at most three times.
  // A load that itself made a scan miss fails every attempt.
  const attempts = [];
  for (const [version, omega] of [['1.0.1', 2], ['1.0.2', 1], ['1.0.3', 2]]) {
    const text = edit(edit(sources[MAIN], 'version: 1.0.0', `version: ${version}`).text, 'omega: 1,', `omega: ${omega},`).text;
    await upload(page, text);
    const before = await task();
    const t0 = Date.now();
    await page.getByRole('button', { name: 'Load onto the PLC' }).click();
    await page.locator('#check-result.good', { hasText: 'Loaded' }).waitFor({ timeout: HANG_GUARD_MS });
    const after = await task();
    const report = await page.locator('#change-report').innerText();
    assert.match(report, /Retuned \(new tunable parameters, state kept\)\s*1\s*ref\b/);
    assert.match(report, /Kept \(state carried over\)\s*3\b/);
    assert.match(report, /New\s*0\b/);
    assert.match(report, /Removed\s*0\b/);
    await until(async () => (await plc.api('/status')).runtime.program_version === version, HANG_GUARD_MS, `version ${version} running`);
    attempts.push({ version, ms: Date.now() - t0, skipped: [before.skipped, after.skipped], overruns: [before.overruns, after.overruns] });
    if (after.skipped === before.skipped && after.overruns === before.overruns) break;
  }
  console.log(`# loads (skipped, overruns before and after each): ${JSON.stringify(attempts)}`);
  const clean = attempts.at(-1);
  assert.deepEqual([clean.skipped[1], clean.overruns[1]], [clean.skipped[0], clean.overruns[0]],
    `every load had a scan skipped or overrun: ${JSON.stringify(attempts)}`);
  assert.doesNotMatch(await page.locator('#check-result').innerText(), /undefined|null|NaN/);
  // The newest stored version runs, and the page's list says so.
  const newest = Math.max(...(await plc.api('/projects')).versions.map((v) => v.version));
  await page.locator(`#versions tr[data-version="${newest}"]`, { hasText: 'running' }).waitFor({ timeout: HANG_GUARD_MS });
  assert.match(await page.locator(`#versions tr[data-version="${newest}"]`).innerText(), new RegExp(`upload\\s+accepted\\s+hmi_cell ${attempts.at(-1).version}`));
  assert.equal(await page.locator('#versions .pill', { hasText: 'running' }).count(), 1);
  await until(async () => (await task()).scans > was.task.scans + 100, HANG_GUARD_MS, 'a hundred scans after the load');
  const now = await plcState();
  assert.equal(now.task.state, 'running');
  assert.notDeepEqual(now.running, was.running);
  // State carried over: the counter went on from where it was, the setpoint kept.
  assert.ok(now.values.scan_count > was.values.scan_count, `scan_count ${was.values.scan_count} → ${now.values.scan_count}`);
  assert.equal(now.values.speed_set, was.values.speed_set);
  assert.deepEqual(page.jsErrors, []);
});

test('5b. an ST program loaded by online change shows its variables under its instance: an engineer writes one, an operator may not', async () => {
  const page = await open('project');
  await login(page, 'erik');
  const counter = 'PROGRAM Counter\nVAR_EXTERNAL enable : BOOL; END_VAR\nVAR\n  runs : DINT;\n  step : DINT := 1;\n'
    + '  last : ARRAY[1..3] OF DINT;\nEND_VAR\nIF enable THEN\n  runs := runs + step;\nEND_IF;\n'
    + 'last[3] := last[2]; last[2] := last[1]; last[1] := runs;\nEND_PROGRAM\n';
  const text = edit(sources[MAIN], 'version: 1.0.0', 'version: 1.1.0').text;
  await upload(page, `${text}\nsources: [counter.st]\nprograms: [{name: counter, type: Counter}]\n`, [['counter.st', counter]]);
  await page.getByRole('button', { name: 'Load onto the PLC' }).click();
  await page.locator('#check-result.good', { hasText: 'Loaded' }).waitFor({ timeout: HANG_GUARD_MS });
  assert.match(await page.locator('#change-report').innerText(), /New\s*1\b/);

  await page.goto(`${plc.url}/#/tags`);
  await page.locator('#blocks-table button.disclosure', { hasText: 'counter' }).click();
  const runs = page.locator('tr[data-ref="counter.runs"] .value .num');
  const first = await until(async () => { const t = await runs.innerText(); return !noValue(t) && Number(t); }, HANG_GUARD_MS, 'counter.runs live');
  await until(async () => Number(await runs.innerText()) > first, HANG_GUARD_MS, `counter.runs to count on from ${first}`);
  for (const ref of ['counter.step', 'counter.last[1]', 'counter.last[3]']) await page.locator(`tr[data-ref="${ref}"]`).waitFor();
  assert.equal(await page.locator('tr[data-ref="counter.(variables)"]').count(), 0, 'the hidden pin is not listed');

  // The engineer writes step once: runs then grows by 1000 a scan.
  await page.locator('tr[data-ref="counter.step"] button', { hasText: 'Write' }).click();
  await page.locator('dialog[open] input[name=value]').fill('1000');
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.ok-note', { hasText: 'Written to counter.step.' }).waitFor();
  const [a, b] = await until(async () => {
    const v = (await values('counter.last[1]', 'counter.last[2]')).values;
    return v['counter.last[1]'] - v['counter.last[2]'] === 1000 && [v['counter.last[1]'], v['counter.last[2]']];
  }, HANG_GUARD_MS, 'runs to grow by 1000 a scan');
  assert.ok(a > b);
  const events = (await plc.api('/events?kind=hmi-write')).events.map((e) => e.message);
  assert.ok(events.some((m) => m.includes('counter.step := 1000') && m.includes('erik')), events.join('\n'));

  // An operator sees the variables but cannot write them.
  const op = await open('tags');
  await login(op, 'olga');
  await op.locator('#blocks-table button.disclosure', { hasText: 'counter' }).click();
  const write = op.locator('tr[data-ref="counter.step"] button', { hasText: 'Write' });
  await write.waitFor();
  assert.equal(await write.isDisabled(), true);
  assert.match(await write.getAttribute('title'), /engineer role/);
  assert.deepEqual(page.jsErrors, []);
  assert.deepEqual(op.jsErrors, []);
});

test('6. without login nothing changes the PLC: the API answers 401 to the page, and its controls are disabled', async () => {
  const page = await open('tags');
  await page.locator('tr[data-tag=speed_set]').waitFor();
  for (const tag of ['speed_set', 'limits', 'ref_pos']) {
    const write = page.locator(`tr[data-tag=${tag}] button`, { hasText: 'Write' });
    const force = page.locator(`tr[data-tag=${tag}] button`, { hasText: 'Force' });
    assert.equal(await write.isDisabled(), true, `${tag} Write`);
    assert.match(await write.getAttribute('title'), /operator/);
    assert.equal(await force.isDisabled(), true, `${tag} Force`);
    assert.match(await force.getAttribute('title'), /engineer/);
  }
  await page.goto(`${plc.url}/#/project`);
  await upload(page, sources[MAIN]);
  for (const name of ['Check', 'Load onto the PLC']) {
    const b = page.getByRole('button', { name });
    assert.equal(await b.isDisabled(), true, name);
    assert.match(await b.getAttribute('title'), /engineer/);
  }
  await page.locator('#versions tbody tr').first().waitFor();
  for (const b of await page.getByRole('button', { name: 'Roll back to this' }).all()) assert.equal(await b.isDisabled(), true);

  const was = await plcState();
  const project = { main: MAIN, files: sources };
  const calls = [
    ['PUT', '/api/v1/tags/speed_set', { value: 9 }],
    ['PUT', '/api/v1/tags/limits%5B2%5D', { value: 99 }],
    ['POST', '/api/v1/forces', { ref: 'ref_pos', value: 1 }],
    ['DELETE', '/api/v1/forces/ref_pos'],
    ['DELETE', '/api/v1/forces'],
    ['POST', '/api/v1/projects/check', project],
    ['POST', '/api/v1/projects/load', project],
    ['POST', '/api/v1/projects/rollback', { version: 1 }],
    ['POST', '/api/v1/projects/reload', {}],
  ];
  // From the page itself (its origin, no token), as a script on it would.
  const call = (token) => page.evaluate(async ({ calls, token }) => {
    const out = {};
    for (const [method, url, body] of calls) {
      const headers = { Accept: 'application/json' };
      if (body) headers['Content-Type'] = 'application/json';
      if (token) headers.Authorization = `Bearer ${token}`;
      const res = await fetch(url, { method, headers, body: body ? JSON.stringify(body) : undefined });
      out[`${method} ${url}`] = res.status;
    }
    return out;
  }, { calls, token });
  const anonymous = await call(null);
  assert.deepEqual(anonymous, Object.fromEntries(calls.map(([m, u]) => [`${m} ${u}`, 401])));
  // A viewer's token is refused too (403: the role is too low).
  await login(page, 'vera');
  const token = await page.evaluate(() => JSON.parse(sessionStorage.getItem('syncplc.session')).token);
  assert.deepEqual(await call(token), Object.fromEntries(calls.map(([m, u]) => [`${m} ${u}`, 403])));
  const now = await plcState();
  assert.equal(now.values.speed_set, was.values.speed_set);
  assert.deepEqual(now.values.limits, was.values.limits);
  assert.deepEqual(now.running, was.running);
  assert.equal(now.status.forces, 0);
  assert.deepEqual((await plc.api('/forces')).forces, []);
  assert.deepEqual(page.jsErrors, []);
});

test('7. every page under the server\'s Content-Security-Policy, with no console error', async () => {
  const page = await browser.context.newPage();
  pages.add(page);
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.addInitScript(() => {
    window.cspViolations = [];
    document.addEventListener('securitypolicyviolation', (e) => window.cspViolations.push(`${e.violatedDirective} ${e.blockedURI}`));
  });
  const res = await page.goto(`${plc.url}/#/overview`);
  const csp = res.headers()['content-security-policy'] || '';
  assert.match(csp, /(^|;)\s*default-src 'self'\s*(;|$)/, `Content-Security-Policy: ${csp}`);
  assert.doesNotMatch(csp, /unsafe-inline|unsafe-eval/);
  await login(page, 'erik');
  const scenes = {
    overview: () => page.locator('[data-task=main] canvas').first().waitFor(),
    tags: async () => {
      await until(async () => !noValue(await rowValue(page, 'ref_pos')), HANG_GUARD_MS, 'a live value');
      await page.locator('#blocks-table button.disclosure', { hasText: 'ref' }).click();
      await until(async () => !noValue(await page.locator('tr[data-ref="ref.x"] .value .num').innerText()), HANG_GUARD_MS, 'the pin ref.x live');
    },
    axes: () => page.locator('h1', { hasText: 'Axes' }).waitFor(),
    trends: async () => {
      await page.getByLabel('Tag').fill('ref_pos');
      await page.getByRole('button', { name: 'Show' }).click();
      await page.locator('.plot canvas').first().waitFor({ timeout: HANG_GUARD_MS });
    },
    events: () => page.locator('#events-table tbody tr').first().waitFor(),
    project: () => page.locator('#versions tbody tr').first().waitFor(),
  };
  for (const [name, scene] of Object.entries(scenes)) {
    await page.goto(`${plc.url}/#/${name}`);
    await scene();
    // Every shape the page reads from the server filled in: no "undefined" or "NaN" shown.
    assert.doesNotMatch(await page.locator('body').innerText(), /undefined|NaN/, `the ${name} page`);
  }
  assert.deepEqual(await page.evaluate(() => window.cspViolations), []);
  assert.deepEqual(errors, []);
});
