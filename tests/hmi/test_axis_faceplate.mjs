// The axis faceplates (Motion page) against a real `syncplc run` of the
// four-axis demo driven by PLCopen blocks (projects/four_axis_table/plcopen.yaml),
// in Debian's chromium: a faceplate per MC_AXIS with its PLCopen state,
// values with units and the group move as the active command; an operator
// disables an axis after a confirmation and it goes Disabled (the reset
// button is not even shown to him); an engineer resets an axis in ErrorStop
// (made by forcing its feedback_ok FALSE) and it leaves ErrorStop.
//   node tests/hmi/test_axis_faceplate.mjs build/syncplc      (ctest hmi.axis_faceplate)
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { requireBrowser, launch, DESKTOP, ROOT, until } from './browser.mjs';

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
    project: join(ROOT, 'projects', 'four_axis_table', 'plcopen.yaml'),
    users: { olga: 'operator', erik: 'engineer' },
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

async function open() {
  const page = await browser.context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.setViewportSize(DESKTOP);
  await page.goto(`${plc.url}/#/motion`);
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

async function token(user) {
  const r = await plc.api('/login', { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ user, password: plc.users[user].password }) });
  return r.token;
}

const plate = (page, axis) => page.locator(`.axis-faceplate[data-axis=${axis}]`);
const stateOf = (page, axis) => plate(page, axis).getAttribute('data-state');

test('a faceplate per axis of the demo: state, values with units, the group move and its block', async () => {
  const page = await open();
  for (const axis of ['x1', 'x2', 'x3', 'x4']) await plate(page, axis).waitFor({ timeout: HANG_GUARD_MS });
  // The demo homes the axes and then moves them together, for ever.
  await until(async () => (await stateOf(page, 'x1')) === 'DiscreteMotion', HANG_GUARD_MS, 'x1 in the group move');
  await until(async () => (await plate(page, 'x1').locator('.axis-source').count()) > 0, HANG_GUARD_MS, 'its source block');
  assert.equal(await plate(page, 'x1').locator('.axis-command').innerText(), 'GroupMove');
  assert.equal(await plate(page, 'x1').locator('.axis-source').innerText(), 'group');
  assert.match(await plate(page, 'x1').innerText(), /Following error[\s\S]*rad/);
  assert.equal(await plate(page, 'x1').getAttribute('data-stale'), 'false');
  assert.equal(await plate(page, 'x1').locator('.axis-quality').getAttribute('data-quality'), 'good');
  assert.match(await plate(page, 'x1').locator('.axis-quality').innerText(), /^live, \d+(\.\d)? m?s old$/);
  assert.equal(await page.locator('.axis-actions button', { hasText: 'Reset' }).count(), 0, 'no reset without an engineer');
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('an operator disables x2 after a confirmation; it goes Disabled; reset is not shown to him', async () => {
  const page = await open();
  await login(page, 'olga');
  await plate(page, 'x2').waitFor({ timeout: HANG_GUARD_MS });
  assert.equal(await plate(page, 'x2').locator('button', { hasText: 'Reset' }).count(), 0);
  const disable = plate(page, 'x2').locator('button', { hasText: 'Disable' });
  await until(async () => disable.isEnabled(), HANG_GUARD_MS, 'Disable enabled');
  await disable.click();
  const dialog = page.locator('dialog[open]');
  assert.match(await dialog.innerText(), /x2 goes to Disabled at the next scan/);
  await dialog.locator('button[type=submit]').click();
  await until(async () => (await stateOf(page, 'x2')) === 'Disabled', HANG_GUARD_MS, 'x2 Disabled');
  await until(async () => (await plate(page, 'x2').innerText()).includes('HMI disabled'), HANG_GUARD_MS, 'the HMI-disabled mark');
  // Enabled again, the program's MC_Power powers it.
  const enable = plate(page, 'x2').locator('button', { hasText: 'Enable' });
  await until(async () => enable.isEnabled(), HANG_GUARD_MS, 'Enable enabled');
  await enable.click();
  await page.locator('dialog[open] button[type=submit]').click();
  await until(async () => (await stateOf(page, 'x2')) !== 'Disabled', HANG_GUARD_MS, 'x2 powered again');
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});

test('an engineer resets x3 from ErrorStop', async () => {
  const erik = await token('erik');
  const auth = { Authorization: `Bearer ${erik}`, 'Content-Type': 'application/json' };
  // Stale feedback: ErrorStop 0x0304 (docs/motion/plcopen.md, "Fail safe").
  await plc.api('/forces', { method: 'POST', headers: auth, body: JSON.stringify({ ref: 'x3.feedback_ok', value: false }) });
  const page = await open();
  await login(page, 'erik');
  await until(async () => (await stateOf(page, 'x3')) === 'ErrorStop', HANG_GUARD_MS, 'x3 in ErrorStop');
  assert.match(await plate(page, 'x3').locator('.axis-error').innerText(), /0x0304/);
  await plc.api(`/forces/${encodeURIComponent('x3.feedback_ok')}`, { method: 'DELETE', headers: auth });
  const reset = plate(page, 'x3').locator('button', { hasText: 'Reset' });
  await until(async () => reset.isEnabled(), HANG_GUARD_MS, 'Reset enabled in ErrorStop');
  await reset.click();
  assert.match(await page.locator('dialog[open]').innerText(), /acknowledged at the next scan, as MC_Reset does/);
  await page.locator('dialog[open] button[type=submit]').click();
  await until(async () => (await stateOf(page, 'x3')) !== 'ErrorStop', HANG_GUARD_MS, 'x3 leaves ErrorStop');
  await until(async () => (await plate(page, 'x3').locator('.axis-error').count()) === 0, HANG_GUARD_MS, 'the error gone');
  assert.deepEqual(page.jsErrors, []);
  await page.close();
});
