// The HMI's pages in Debian's chromium against the test fixture
// (fixture_server.mjs, canned JSON after the agreed API outline): what an
// operator and an engineer do on each page, at desktop and phone size.
// The tests against a real `syncplc run` follow when runtime/web is merged.
//   node --test tests/hmi/test_fixture_pages.mjs      (ctest -L hmi)
import { requireBrowser, launch, until, PHONE, DESKTOP } from './browser.mjs';

requireBrowser();

const { test, before, after, afterEach } = await import('node:test');
const assert = (await import('node:assert/strict')).default;
const { startFixture } = await import('./fixture_server.mjs');

const USERS = {
  olga: { password: 'op-secret-1', role: 'operator' },
  erik: { password: 'eng-secret-2', role: 'engineer' },
  vera: { password: 'view-secret-3', role: 'viewer' },
};
let fixture; let browser;

before(async () => {
  fixture = await startFixture({ users: USERS });
  browser = await launch();
});
// A test that failed half-way leaves no page (and no live stream) behind.
const pages = new Set();
afterEach(async () => {
  for (const p of pages) if (!p.isClosed()) await p.close();
  pages.clear();
});
after(async () => {
  if (browser) await browser.close();
  if (fixture) await fixture.close();
});

async function open(path, viewport = DESKTOP) {
  const page = await browser.context.newPage();
  pages.add(page);
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  // A blocked resource (the content security policy, a missing file) is an error too.
  page.on('console', (m) => { if (m.type() === 'error' && !/status of (401|403|404|409|400|503)/.test(m.text())) errors.push(m.text()); });
  await page.setViewportSize(viewport);
  await page.goto(`${fixture.url}/#/${path}`);
  page.jsErrors = errors;
  return page;
}

async function login(page, user) {
  await page.getByRole('button', { name: 'Log in' }).first().click();
  await page.getByLabel('User name').fill(user);
  await page.getByLabel('Password').fill(USERS[user].password);
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.who .user-name', { hasText: user }).waitFor();
}

test('overview: a card per task with statistics and a jitter histogram; a stopped task is shown as such', async () => {
  const page = await open('overview');
  for (const name of ['servo', 'planner', 'slow']) await page.locator(`[data-task=${name}]`).waitFor();
  assert.equal(await page.locator('[data-task=servo] canvas').count() > 0, true);
  assert.match(await page.locator('[data-task=servo]').innerText(), /every 1 ms/);
  assert.match(await page.locator('.runtime').innerText(), /bottle_line 1\.0\.1 \(version 3\)/);
  // The execution-time histogram a click away, where the PLC sends one.
  await page.locator('[data-task=servo] .segmented label', { hasText: 'execution' }).click();
  await page.locator('[data-task=servo] h4', { hasText: 'Execution time: scans per duration' }).waitFor();
  assert.equal(await page.locator('[data-task=planner] .segmented').count(), 0);
  fixture.stopTask(true);
  await page.locator('.banner-bad', { hasText: 'Task slow has stopped' }).waitFor();
  assert.match(await page.locator('[data-task=slow]').getAttribute('class'), /\bbad\b/);
  assert.match(await page.locator('[data-task=slow]').innerText(), /watchdog: scan took 412 ms/);
  fixture.stopTask(false);
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('tags: live values move, the filter narrows, and without login nothing can be changed', async () => {
  const page = await open('tags');
  const pos = page.locator('tr[data-tag=pos] .value .num');
  await pos.waitFor();
  const first = await until(async () => { const t = await pos.innerText(); return t !== '–' && t; }, 10000, 'a live value');
  await until(async () => (await pos.innerText()) !== first, 10000, 'the value to move');
  assert.equal(await page.locator('.conn').innerText(), 'Live');
  await page.getByLabel('Filter').fill('read & write');
  await until(async () => (await page.locator('#tags-table tbody tr').count()) === 4, 5000, 'four tags with hmi: readwrite');
  await page.getByLabel('Filter').fill('speed');
  await until(async () => (await page.locator('#tags-table tbody tr').count()) === 1, 5000, 'one row');
  const write = page.locator('tr[data-tag=speed] button', { hasText: 'Write' });
  assert.equal(await write.isDisabled(), true);
  assert.match(await write.getAttribute('title'), /operator/);
  assert.match(await page.locator('tr[data-tag=speed] button', { hasText: 'Force' }).getAttribute('title'), /engineer/);
  await page.close();
});

test('login: a wrong password is said in words; an operator writes a value; forcing stays refused', async () => {
  const page = await open('tags');
  await page.getByRole('button', { name: 'Log in' }).click();
  await page.getByLabel('User name').fill('olga');
  await page.getByLabel('Password').fill('wrong');
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('dialog[open] .error-note', { hasText: 'The user name or the password is wrong.' }).waitFor();
  await page.getByLabel('Password').fill(USERS.olga.password);
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.who .role', { hasText: 'operator' }).waitFor();
  // The token lives in this tab's sessionStorage and never in a cookie.
  const stored = await page.evaluate(() => ({ s: sessionStorage.getItem('syncplc.session'), c: document.cookie }));
  assert.match(JSON.parse(stored.s).token, /^[\w-]{20,}$/);
  assert.equal(stored.c, '');

  const row = page.locator('tr[data-tag=speed]');
  await row.locator('button', { hasText: 'Write' }).click();
  const value = page.locator('dialog[open] input[name=value]');
  await value.fill('fast');
  await page.locator('dialog[open] .error-note', { hasText: 'LREAL takes a number' }).waitFor();
  assert.equal(await page.locator('dialog[open] button[type=submit]').isDisabled(), true);
  await value.fill('2.25');
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.ok-note', { hasText: 'Written to speed.' }).waitFor();
  assert.equal(fixture.state.written.speed, 2.25);
  await until(async () => (await row.locator('.value .num').innerText()) === '2.25', 5000, 'the written value shown');
  // BOOL: two buttons, no typing.
  await page.locator('tr[data-tag=enable] button', { hasText: 'Write' }).click();
  await page.locator('dialog[open] .segmented label', { hasText: 'FALSE' }).click();
  await page.locator('dialog[open] button[type=submit]').click();
  await until(() => fixture.state.written.enable === false, 5000, 'enable written FALSE');
  const readOnly = page.locator('tr[data-tag=pos] button', { hasText: 'Write' });
  assert.equal(await readOnly.isDisabled(), true);
  assert.match(await readOnly.getAttribute('title'), /hmi: read/);
  const everyScan = page.locator('tr[data-tag=cmd] button', { hasText: 'Write' });
  assert.equal(await everyScan.isDisabled(), true);
  assert.match(await everyScan.getAttribute('title'), /writes this value every scan/);
  assert.equal(await row.locator('button', { hasText: 'Force' }).isDisabled(), true);
  // A reload keeps the session (this tab); a token the PLC forgot ends it.
  await page.reload();
  await page.locator('.who .user-name', { hasText: 'olga' }).waitFor();
  fixture.state.tokens.clear();
  await page.reload();
  await page.getByRole('button', { name: 'Log in' }).waitFor();
  await login(page, 'olga');
  await page.getByRole('button', { name: 'Log out' }).click();
  await page.getByRole('button', { name: 'Log in' }).waitFor();
  assert.equal(await page.evaluate(() => sessionStorage.getItem('syncplc.session')), null);
  await page.close();
});

test('force: an engineer forces after confirming; the value is flagged forced everywhere; unforce releases it', async () => {
  const page = await open('tags');
  await login(page, 'erik');
  const row = page.locator('tr[data-tag=batch]');
  await row.locator('button', { hasText: 'Force' }).click();
  await page.locator('dialog[open] input[name=value]').fill('99999999999');
  await page.locator('dialog[open] .error-note', { hasText: 'DINT holds -2147483648 to 2147483647' }).waitFor();
  await page.locator('dialog[open] input[name=value]').fill('7');
  const submit = page.locator('dialog[open] button[type=submit]');
  assert.equal(await submit.isDisabled(), true, 'a force needs the confirmation');
  await page.locator('dialog[open] input[name=confirm]').check();
  await submit.click();
  await page.locator('.ok-note', { hasText: 'batch is forced.' }).waitFor();
  assert.equal(fixture.state.forces.batch, 7);
  await row.locator('.badge-forced').waitFor();
  assert.equal(await row.locator('.value').getAttribute('data-forced'), 'true');
  // An array element, then a block pin.
  await page.locator('tr[data-tag=cmd] button', { hasText: 'Force' }).click();
  await page.locator('dialog[open] input[name=element]').fill('3');
  await page.locator('dialog[open] input[name=value]').fill('0.5');
  await page.locator('dialog[open] input[name=confirm]').check();
  await page.locator('dialog[open] button[type=submit]').click();
  await until(() => fixture.state.forces['cmd[3]'] === 0.5, 5000, 'cmd[3] forced');
  await page.locator('tr[data-tag=cmd] .badge-forced').waitFor();
  await page.locator('#blocks-table button.disclosure', { hasText: 'sync' }).click();
  await page.locator('tr[data-ref="sync.reset"] button', { hasText: 'Force' }).click();
  await page.locator('dialog[open] .segmented label', { hasText: 'TRUE' }).click();
  await page.locator('dialog[open] input[name=confirm]').check();
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('tr[data-ref="sync.reset"] .badge-forced').waitFor();
  // The overview counts the forces.
  await page.goto(`${fixture.url}/#/overview`);
  await page.locator('.stat', { hasText: 'Forced values' }).locator('text=3 active').waitFor();
  await page.goto(`${fixture.url}/#/tags`);
  await page.locator('tr[data-tag=batch] button', { hasText: 'Unforce' }).click();
  await page.locator('.ok-note', { hasText: 'batch is no longer forced.' }).waitFor();
  assert.equal('batch' in fixture.state.forces, false);
  await until(async () => (await page.locator('tr[data-tag=batch] .badge-forced').count()) === 0, 5000, 'the badge gone');
  await page.close();
});

test('connection: a lost stream is shown and the page reconnects by itself; a hidden page stops streaming', async () => {
  const page = await open('tags');
  await page.locator('.conn', { hasText: 'Live' }).waitFor();
  fixture.dropStreams(2500);
  await page.locator('.banner-lost', { hasText: 'Connection to the PLC lost' }).waitFor();
  assert.equal(await page.locator('.conn').getAttribute('data-state'), 'lost');
  await page.locator('.conn', { hasText: 'Live' }).waitFor({ timeout: 20000 });
  assert.equal(await page.locator('.banner-lost').count(), 0);
  const streams = () => fixture.state.streams.size;
  await until(() => streams() >= 1, 5000, 'a stream');
  const before = streams();
  await page.evaluate(() => { Object.defineProperty(document, 'hidden', { value: true, configurable: true }); document.dispatchEvent(new Event('visibilitychange')); });
  await until(() => streams() === before - 1, 5000, 'the stream to stop while hidden');
  await page.evaluate(() => { Object.defineProperty(document, 'hidden', { value: false, configurable: true }); document.dispatchEvent(new Event('visibilitychange')); });
  await until(() => streams() === before, 5000, 'the stream back when visible');
  await page.close();
});

test('live values: one subscription changed as views come and go; a value that is not live is greyed and says why', async () => {
  const earlier = new Set(fixture.state.subscriptions.keys()); // other tests' pages
  const page = await open('tags');
  await page.locator('.conn', { hasText: 'Live' }).waitFor();
  const mine = () => [...fixture.state.subscriptions].find(([id]) => !earlier.has(id))?.[1];
  await until(() => mine() && mine().refs.includes('speed') && mine().refs.includes('pos'), 5000, 'a subscription with the page\'s refs');
  const patches = fixture.state.patches.length;
  const streams = fixture.state.streams.size;
  // The filter hides rows: their refs are dropped from the subscription, the stream stays.
  await page.getByLabel('Filter').fill('speed');
  await until(() => fixture.state.patches.length > patches && !mine().refs.includes('pos'), 5000, 'a PATCH dropping the hidden rows');
  assert.ok(fixture.state.patches.slice(patches).some((p) => p.drop.includes('pos')));
  assert.equal(fixture.state.streams.size, streams, 'no stream reopened for a change of refs');
  const cell = page.locator('tr[data-tag=speed] .value');
  // The PLC says the driver behind it failed: greyed, with the reason.
  fixture.state.quality.speed = 'driver_not_ok';
  await page.locator('tr[data-tag=speed] .value.stale .badge-stale', { hasText: 'driver not ok' }).waitFor();
  assert.equal(await cell.getAttribute('data-quality'), 'driver_not_ok');
  fixture.state.quality.speed = 'task_stopped';
  await page.locator('tr[data-tag=speed] .badge-stale', { hasText: 'task stopped' }).waitFor();
  delete fixture.state.quality.speed;
  await until(async () => (await page.locator('tr[data-tag=speed] .value.stale').count()) === 0, 5000, 'live again');
  assert.equal(await cell.getAttribute('data-quality'), 'good');
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('axes: suggested from the program, plots live, the transient with its predicted end', async () => {
  const page = await open('axes');
  await page.locator('text=Suggested from the program').waitFor();
  await until(async () => (await page.locator('.plot canvas').count()) === 3, 10000, 'three plots');
  await until(async () => /arrive together in \d+\.\d\d s|All axes track/.test(await page.locator('.transient-summary').innerText()), 10000, 'the transient summary');
  // A forced axis value is flagged here too.
  fixture.state.forces['ax2.x'] = 1;
  await page.locator('.forced-note', { hasText: 'ax2.x' }).waitFor();
  delete fixture.state.forces['ax2.x'];
  await until(async () => (await page.locator('.forced-note').count()) === 0, 5000, 'the forced note gone');
  // The user's choice is remembered in this browser.
  await page.getByRole('button', { name: 'Choose axes…' }).click();
  await page.getByRole('button', { name: 'Remove ax4' }).click();
  await page.getByRole('button', { name: 'Show these axes' }).click();
  const saved = JSON.parse(await page.evaluate(() => localStorage.getItem('syncplc.axes')));
  assert.deepEqual(saved.axes.map((a) => a.position), ['ax1.x', 'ax2.x', 'ax3.x']);
  assert.equal(saved.transient, 'sync');
  await page.reload();
  await page.locator('text=3 axes, transient of sync').waitFor();
  assert.equal(await page.locator('text=Suggested from the program').count(), 0);
  // A name the PLC does not know is named, not silently left empty.
  await page.getByRole('button', { name: 'Choose axes…' }).click();
  await page.getByRole('button', { name: 'Add an axis' }).click();
  await page.locator('.axis-row').nth(3).getByLabel('Position').fill('nope.x');
  await page.getByRole('button', { name: 'Show these axes' }).click();
  await page.locator('.error-note', { hasText: 'No value from the PLC for nope.x' }).waitFor();
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('trends: a tag over a time range as a min/max band; an unknown tag is an error in words', async () => {
  const page = await open('trends');
  await page.getByLabel('Tag').fill('speed');
  await page.getByRole('button', { name: 'Show' }).click();
  await page.locator('.plot canvas').first().waitFor();
  assert.ok(fixture.state.requests.some((r) => r.startsWith('GET /trends')));
  await page.getByLabel('Tag').fill('nope');
  await page.getByRole('button', { name: 'Show' }).click();
  await page.locator('.error-note', { hasText: "no trend of 'nope'" }).waitFor();
  await page.close();
});

test('events: newest first, following new ones, filtered by kind', async () => {
  const page = await open('events');
  await page.locator('#events-table tbody tr').first().waitFor();
  const ids = await page.locator('#events-table tbody tr').evaluateAll((rows) => rows.map((r) => Number(r.dataset.id)));
  assert.deepEqual(ids, [...ids].sort((a, b) => b - a));
  const top = ids[0];
  fixture.state.events.push({ id: fixture.state.events.length + 1, time_ns: Date.now() * 1e6, kind: 'watchdog', task: 'slow', message: 'watchdog tripped (scan 412 ms)', scan: 5 });
  const id = fixture.state.events.length;
  await until(async () => Number(await page.locator('#events-table tbody tr').first().getAttribute('data-id')) > top, 5000, 'the new event on top');
  // Faults stand out (the fixture may have added an overrun after it).
  assert.match(await page.locator(`#events-table tr[data-id="${id}"]`).getAttribute('class'), /row-bad/);
  await page.getByLabel('Kind of event').selectOption('watchdog');
  assert.equal(await page.locator('#events-table tbody tr').count(), 1);
  // A kind not seen yet can be chosen; the PLC is asked for it.
  await page.getByLabel('Kind of event').selectOption('reload-failed');
  await page.locator('text=No events of kind reload-failed yet.').waitFor();
  await until(() => fixture.state.requests.some((r) => r.startsWith('GET /events?') && r.includes('kind=reload-failed')), 5000, 'the PLC asked for that kind');
  await page.close();
});

test('layout: a long project name and a long event message stay inside their boxes', async () => {
  fixture.state.program = 'bottle_line_with_a_name_far_longer_than_any_column_of_the_overview_has_room_for';
  try {
    const page = await open('overview');
    const project = page.locator('.runtime .stat', { hasText: 'Project' }).locator('dd');
    await project.filter({ hasText: 'far_longer' }).waitFor();
    const running = page.locator('.runtime .stat', { hasText: 'Running for' });
    const a = await project.boundingBox();
    const b = await running.boundingBox();
    const overlap = !(a.x + a.width <= b.x || b.x + b.width <= a.x || a.y + a.height <= b.y || b.y + b.height <= a.y);
    assert.ok(!overlap, `the project name ${JSON.stringify(a)} overlaps "Running for" ${JSON.stringify(b)}`);
    // The name is wrapped inside its box, not cut or spilled.
    assert.ok(await project.evaluate((e) => e.scrollWidth <= e.clientWidth + 1), 'the project name fits its box');
    await page.close();
  } finally {
    delete fixture.state.program;
  }
  const long = `reload refused: ${'project.yaml:12:7: unknown block type ADDD; '.repeat(12)}`;
  fixture.state.events.push({ id: fixture.state.events.length + 1, time_ns: Date.now() * 1e6, kind: 'reload-failed', task: null, message: long, scan: null });
  const id = fixture.state.events.length;
  const page = await open('events');
  const cell = page.locator(`#events-table tr[data-id="${id}"] td[data-label="What"]`);
  await cell.waitFor();
  const wrap = await page.locator('.table-wrap').boundingBox();
  const box = await cell.boundingBox();
  assert.ok(box.x + box.width <= wrap.x + wrap.width + 1, `the message ends at ${box.x + box.width}, past the table's right edge ${wrap.x + wrap.width}`);
  assert.ok(await page.locator('.table-wrap').evaluate((e) => e.scrollWidth <= e.clientWidth + 1), 'no sideways scrolling to read it');
  assert.match(await cell.innerText(), /unknown block type ADDD; $/m);
  await page.close();
});

test('project: a bad upload shows its error at its line; a good one loads with the change report; rollback', async () => {
  const page = await open('project');
  assert.equal(await page.getByRole('button', { name: 'Roll back to this' }).first().isDisabled(), true);
  await login(page, 'erik');
  const bad = 'project: {name: bottle_line, version: 1.0.2}\ninclude: [tasks.yaml]\n';
  const tasks = 'tasks:\n  - name: main\n    period: 10xs\n';
  await page.locator('input[name=files]').setInputFiles([
    { name: 'bottle_line.yaml', mimeType: 'text/yaml', buffer: Buffer.from(bad) },
    { name: 'tasks.yaml', mimeType: 'text/yaml', buffer: Buffer.from(tasks) },
  ]);
  assert.equal(await page.getByLabel('Main file').inputValue(), 'bottle_line.yaml');
  await page.getByRole('button', { name: 'Check' }).click();
  await page.locator('#check-result', { hasText: '1 error' }).waitFor();
  await page.locator('#check-result button.link', { hasText: 'tasks.yaml, line 3, column 13' }).waitFor();
  const line = page.locator('.src-line.has-error');
  assert.equal(await line.count(), 1);
  assert.equal(await line.getAttribute('data-line'), '3');
  assert.match(await line.innerText(), /period: 10xs[\s\S]*column 13: period: '10xs' is not a duration/);
  await page.locator('input[name=files]').setInputFiles([
    { name: 'bottle_line.yaml', mimeType: 'text/yaml', buffer: Buffer.from(bad) },
    { name: 'tasks.yaml', mimeType: 'text/yaml', buffer: Buffer.from(tasks.replace('10xs', '10ms')) },
  ]);
  await page.getByRole('button', { name: 'Load onto the PLC' }).click();
  await page.locator('#check-result', { hasText: 'Loaded as version 4.' }).waitFor();
  assert.match(await page.locator('#change-report').innerText(), /Kept \(state carried over\)\s*3/);
  await page.locator('tr[data-version="4"]', { hasText: 'running' }).waitFor();
  await page.locator('tr[data-version="1"] button', { hasText: 'Roll back' }).click();
  await page.locator('dialog[open] button', { hasText: 'Roll back' }).click();
  await page.locator('#check-result', { hasText: 'Rolled back.' }).waitFor();
  await page.locator('tr[data-version="5"]', { hasText: 'rollback' }).waitFor();
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('phone: the navigation folds into a menu, tables become cards, no page is wider than the screen', async () => {
  const page = await open('overview', PHONE);
  const nav = page.locator('nav.nav');
  // isVisible does not wait: first the page as styled (the menu button shows only then).
  await page.getByRole('button', { name: 'Menu' }).waitFor();
  assert.equal(await nav.isVisible(), false);
  await page.getByRole('button', { name: 'Menu' }).click();
  assert.equal(await nav.isVisible(), true);
  await page.locator('nav.nav a', { hasText: 'Tags & pins' }).click();
  assert.equal(await nav.isVisible(), false);
  await page.locator('#tags-table tbody tr').first().waitFor();
  assert.equal(await page.locator('#tags-table thead').isVisible(), false);
  for (const p of ['overview', 'tags', 'axes', 'trends', 'events', 'project']) {
    await page.goto(`${fixture.url}/#/${p}`);
    await page.waitForTimeout(800);
    const w = await page.evaluate(() => document.scrollingElement.scrollWidth);
    assert.ok(w <= PHONE.width, `${p} is ${w} px wide on a ${PHONE.width} px screen`);
  }
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});
