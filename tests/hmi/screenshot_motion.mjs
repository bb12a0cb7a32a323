// The Motion page's screenshot for docs/hmi/: Debian's chromium against
// `syncplc run projects/four_axis_table/plcopen.yaml`, logged in as an
// engineer, with x2 disabled from the HMI and x4 in ErrorStop (its
// feedback_ok forced FALSE: stale feedback, 0x0304); x1 and x3 stand, as the
// demo's sequence waits until every axis is powered again.
//   node tests/hmi/screenshot_motion.mjs build/syncplc   (writes docs/hmi/real-motion-desktop.png)
import { join } from 'node:path';
import { requireBrowser, launch, DESKTOP, ROOT, until } from './browser.mjs';
import { startPlc } from './real_plc.mjs';

const binary = process.argv[2];
requireBrowser();
const plc = await startPlc({
  binary,
  project: join(ROOT, 'projects', 'four_axis_table', 'plcopen.yaml'),
  users: { erik: 'engineer' },
  extra: ['--hmi-dir', join(ROOT, 'hmi_web', 'dist')],
});
const browser = await launch();
try {
  const { token } = await plc.api('/login', { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ user: 'erik', password: plc.users.erik.password }) });
  const auth = { Authorization: `Bearer ${token}`, 'Content-Type': 'application/json' };
  const page = await browser.context.newPage();
  await page.setViewportSize(DESKTOP);
  await page.goto(`${plc.url}/#/motion`);
  await page.getByRole('button', { name: 'Log in' }).first().click();
  await page.getByLabel('User name').fill('erik');
  await page.getByLabel('Password').fill(plc.users.erik.password);
  await page.locator('dialog[open] button[type=submit]').click();
  const state = (axis) => page.locator(`.axis-faceplate[data-axis=${axis}]`).getAttribute('data-state');
  await until(async () => (await state('x1')) === 'DiscreteMotion', 60000, 'the group move');
  await plc.api('/axes/x2/disable', { method: 'POST', headers: auth, body: '{}' });
  await plc.api('/forces', { method: 'POST', headers: auth, body: JSON.stringify({ ref: 'x4.feedback_ok', value: false }) });
  await until(async () => (await state('x4')) === 'ErrorStop' && (await state('x2')) === 'Disabled', 60000, 'x2 and x4');
  await plc.api('/forces/x4.feedback_ok', { method: 'DELETE', headers: auth });
  await page.waitForTimeout(1500);
  const file = join(ROOT, 'docs', 'hmi', 'real-motion-desktop.png');
  await page.screenshot({ path: file, fullPage: true });
  console.log(file);
} finally {
  await browser.close();
  await plc.stop();
}
