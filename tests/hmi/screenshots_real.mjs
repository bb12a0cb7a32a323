// screenshots.mjs --real BINARY: every HMI page at desktop size against a
// real `syncplc run` (real_plc.mjs), logged in as an engineer:
// tests/hmi/projects/hmi_cell with a written setpoint and a forced array
// element, a bad upload checked and a good one loaded; the Axes page against
// the demo projects/four_axis_table/sync.yaml (four SYNC_CONTROLLER axes).
import { mkdir, readFile } from 'node:fs/promises';
import { join } from 'node:path';
import { launch, until, DESKTOP, ROOT } from './browser.mjs';
import { startPlc } from './real_plc.mjs';

const CELL = join(ROOT, 'tests', 'hmi', 'projects', 'hmi_cell');

async function login(page, plc, user) {
  await page.getByRole('button', { name: 'Log in' }).first().click();
  await page.getByLabel('User name').fill(user);
  await page.getByLabel('Password').fill(plc.users[user].password);
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.who .user-name', { hasText: user }).waitFor({ timeout: 30000 });
}

// A change through the API with the page's session (as the page's own controls send it).
async function apiAs(page, method, path, body) {
  const status = await page.evaluate(async ({ method, path, body }) => {
    const { token } = JSON.parse(sessionStorage.getItem('syncplc.session'));
    const res = await fetch(`/api/v1${path}`, { method, headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${token}` }, body: JSON.stringify(body) });
    return res.status;
  }, { method, path, body });
  if (status !== 200) throw new Error(`${method} ${path}: HTTP ${status}`);
}

async function shoot(page, out, name, taken) {
  const file = join(out, `real-${name}-desktop.png`);
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: file, fullPage: true });
  taken.push(file);
}

export async function realScreenshots(binary, out) {
  await mkdir(out, { recursive: true });
  const hmi = ['--hmi-dir', join(ROOT, 'hmi_web', 'dist')];
  const taken = [];
  const browser = await launch();
  let plc = null;
  try {
    plc = await startPlc({ binary, project: join(CELL, 'cell.yaml'), users: { erik: 'engineer' }, extra: hmi });
    const page = await browser.context.newPage();
    await page.setViewportSize(DESKTOP);
    await page.goto(`${plc.url}/#/overview`);
    await login(page, plc, 'erik');
    await apiAs(page, 'PUT', '/tags/speed_set', { value: 1.2 });
    await apiAs(page, 'POST', '/forces', { ref: 'limits[3]', value: 35 });

    await page.locator('[data-task=main] canvas').first().waitFor();
    // Some history for the histograms and the trend.
    await until(async () => (await plc.api('/status')).runtime.uptime_s >= 12, 60000, '12 s of running');
    await page.waitForTimeout(1200);
    await shoot(page, out, 'overview', taken);

    await page.goto(`${plc.url}/#/tags`);
    await page.locator('tr[data-tag=limits] .badge-forced').waitFor();
    await page.locator('#blocks-table button.disclosure', { hasText: 'ref' }).click();
    await until(async () => !/^–?$/.test(await page.locator('tr[data-ref="ref.x"] .value .num').innerText()), 20000, 'ref.x live');
    await page.waitForTimeout(500);
    await shoot(page, out, 'tags', taken);

    await page.goto(`${plc.url}/#/trends`);
    await page.getByLabel('Tag').fill('ref_pos');
    await page.getByRole('button', { name: 'Show' }).click();
    await page.locator('.plot canvas').first().waitFor({ timeout: 30000 });
    await page.waitForTimeout(500);
    await shoot(page, out, 'trends', taken);

    await page.goto(`${plc.url}/#/events`);
    await page.locator('#events-table tbody tr').first().waitFor();
    await page.waitForTimeout(500);
    await shoot(page, out, 'events', taken);

    // A bad upload checked (its error at its line), then a good one loaded (the change report).
    const main = await readFile(join(CELL, 'cell.yaml'), 'utf8');
    const io = await readFile(join(CELL, 'cell_io.yaml'), 'utf8');
    const files = (text) => [
      { name: 'cell.yaml', mimeType: 'text/yaml', buffer: Buffer.from(text) },
      { name: 'cell_io.yaml', mimeType: 'text/yaml', buffer: Buffer.from(io) },
    ];
    await page.goto(`${plc.url}/#/project`);
    await page.locator('input[name=files]').setInputFiles(files(main.replace('period: 10ms', 'period: 10xs')));
    await page.getByRole('button', { name: 'Check' }).click();
    await page.locator('.src-line.has-error').waitFor({ timeout: 60000 });
    await page.waitForTimeout(300);
    await shoot(page, out, 'project', taken);
    await page.locator('input[name=files]').setInputFiles(files(main.replace('version: 1.0.0', 'version: 1.0.1').replace('omega: 1,', 'omega: 2,')));
    await page.getByRole('button', { name: 'Load onto the PLC' }).click();
    await page.locator('#change-report').waitFor({ timeout: 60000 });
    await page.locator('#versions tr[data-version="2"]', { hasText: 'running' }).waitFor({ timeout: 20000 });
    await page.waitForTimeout(300);
    await shoot(page, out, 'project-loaded', taken);
    await page.close();
    await plc.stop();
    plc = null;

    // The Axes page against the demo: four axes, their errors and synchronization errors.
    plc = await startPlc({ binary, project: join(ROOT, 'projects', 'four_axis_table', 'sync.yaml'), users: {}, extra: hmi });
    const axes = await browser.context.newPage();
    await axes.setViewportSize(DESKTOP);
    await axes.goto(`${plc.url}/#/axes`);
    await axes.locator('text=Suggested from the program').waitFor({ timeout: 30000 });
    await until(async () => (await axes.locator('.plot canvas').count()) >= 2, 20000, 'the plots');
    await axes.waitForTimeout(6000);
    await shoot(axes, out, 'axes', taken);
    await axes.close();
  } finally {
    if (plc) await plc.stop();
    await browser.close();
  }
  return taken;
}
