// Every value on the page carries its quality: Debian's chromium against a
// real `syncplc run` of tests/hmi/projects/quality, whose task `bad` is
// stopped by its watchdog and whose modbus_client device does not answer.
// On the Tags page a value of the stopped task says "task stopped", the
// driver's value "driver not ok", both greyed; the running task's value is
// live and not greyed.
//   node tests/hmi/test_value_quality.mjs build/syncplc      (ctest hmi.value_quality)
import { existsSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { requireBrowser, launch, DESKTOP, ROOT, until } from './browser.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const binary = process.argv[2];
if (!binary || !existsSync(binary)) {
  console.error(`usage: node ${process.argv[1]} PATH/TO/syncplc`);
  process.exit(1);
}
requireBrowser();

const { test, before, after } = await import('node:test');
const assert = (await import('node:assert/strict')).default;
const { startPlc } = await import('./real_plc.mjs');

const HANG_GUARD_MS = 120000; // only ends a hang: a loaded machine makes the test slower, not wrong

let plc; let browser;
before(async () => {
  plc = await startPlc({
    binary,
    project: join(here, 'projects', 'quality', 'quality.yaml'),
    extra: ['--hmi-dir', join(ROOT, 'hmi_web', 'dist')],
  });
  browser = await launch();
});
after(async () => {
  if (browser) await browser.close();
  if (plc) {
    const end = await plc.stop();
    assert.equal(end.code, 0, `syncplc run exited with ${JSON.stringify(end)}\nstderr:\n${end.stderr}`);
  }
});

const opacity = (page, selector) => page.locator(selector).first().evaluate((e) => Number(getComputedStyle(e).opacity));

test('tags page: a stopped task\'s value and a failed driver\'s value are greyed with the reason; a live one is not', async () => {
  const page = await browser.context.newPage();
  await page.setViewportSize(DESKTOP);
  await page.goto(`${plc.url}/#/tags`);
  const quality = (tag) => page.locator(`tr[data-tag=${tag}] .value`).getAttribute('data-quality');
  await until(async () => (await quality('bad_w')) === 'task_stopped', HANG_GUARD_MS, 'bad_w: task stopped');
  assert.equal(await page.locator('tr[data-tag=bad_w] .badge-stale').innerText(), 'task stopped');
  assert.ok((await opacity(page, 'tr[data-tag=bad_w] .value .num')) < 1, 'greyed');
  await until(async () => (await quality('remote')) === 'driver_not_ok', HANG_GUARD_MS, 'remote: driver not ok');
  assert.equal(await page.locator('tr[data-tag=remote] .badge-stale').innerText(), 'driver not ok');
  assert.ok((await opacity(page, 'tr[data-tag=remote] .value .num')) < 1, 'greyed');
  // The running task's value moves, good and not greyed.
  const num = page.locator('tr[data-tag=counter] .value .num');
  const first = await until(async () => { const t = await num.innerText(); return t && t !== '–' && t; }, HANG_GUARD_MS, 'a counter value');
  await until(async () => (await num.innerText()) !== first, HANG_GUARD_MS, 'counter to move');
  assert.equal(await quality('counter'), 'good');
  assert.equal(await page.locator('tr[data-tag=counter] .badge-stale').count(), 0);
  assert.equal(await opacity(page, 'tr[data-tag=counter] .value .num'), 1);
  await page.close();
});
