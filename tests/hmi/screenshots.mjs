// Screenshots of every HMI page into docs/hmi/ (PNG), taken in Debian's
// chromium:
//   node tests/hmi/screenshots.mjs [OUT_DIR]
//     against the test fixture (canned values after the API outline), desktop
//     and phone size: <page>-desktop.png, <page>-phone.png, and three dialogs;
//   node tests/hmi/screenshots.mjs --real build/syncplc [OUT_DIR]
//     against a real `syncplc run` of tests/hmi/projects/hmi_cell at desktop
//     size (real-<page>-desktop.png), the Axes page against the demo
//     projects/four_axis_table/sync.yaml.
import { mkdir } from 'node:fs/promises';
import { join } from 'node:path';
import { requireBrowser, launch, DESKTOP, PHONE, ROOT } from './browser.mjs';
import { startFixture } from './fixture_server.mjs';

requireBrowser();
const args = process.argv.slice(2);
const realAt = args.indexOf('--real');
if (realAt >= 0) {
  const [, binary] = args.splice(realAt, 2);
  if (!binary) { console.error('usage: node tests/hmi/screenshots.mjs --real PATH/TO/syncplc [OUT_DIR]'); process.exit(1); }
  const { realScreenshots } = await import('./screenshots_real.mjs');
  const taken = await realScreenshots(binary, args[0] || join(ROOT, 'docs', 'hmi'));
  console.log(taken.join('\n'));
  process.exit(0);
}
const out = args[0] || join(ROOT, 'docs', 'hmi');
await mkdir(out, { recursive: true });
const users = { erik: { password: 'eng-secret-2', role: 'engineer' } };
const fixture = await startFixture({ users });
const browser = await launch();
const taken = [];
try {
  const page = await browser.context.newPage();
  await page.goto(`${fixture.url}/#/overview`);
  await page.getByRole('button', { name: 'Log in' }).click();
  await page.getByLabel('User name').fill('erik');
  await page.getByLabel('Password').fill(users.erik.password);
  await page.locator('dialog[open] button[type=submit]').click();
  await page.locator('.who .user-name').waitFor();
  // Something forced, so the flag shows; a stopped task on the overview.
  fixture.state.forces.enable = false;
  fixture.state.forces['cmd[3]'] = 0.5;
  fixture.stopTask(true);

  const scenes = {
    overview: async () => { await page.locator('[data-task=slow].bad').waitFor(); await page.waitForTimeout(500); },
    tags: async () => {
      await page.locator('tr[data-tag=enable] .badge-forced').waitFor();
      await page.locator('#blocks-table button.disclosure', { hasText: 'ax1' }).click();
      await page.locator('tr[data-ref="ax1.e"] .value .num').waitFor();
      await page.waitForTimeout(800);
    },
    axes: async () => { await page.waitForTimeout(4500); },
    trends: async () => {
      await page.getByLabel('Tag').fill('speed');
      await page.getByRole('button', { name: 'Show' }).click();
      await page.locator('.plot canvas').first().waitFor();
      await page.waitForTimeout(300);
    },
    events: async () => { await page.locator('#events-table tbody tr').first().waitFor(); await page.waitForTimeout(300); },
    project: async () => {
      await page.locator('input[name=files]').setInputFiles([
        { name: 'bottle_line.yaml', mimeType: 'text/yaml', buffer: Buffer.from('project: {name: bottle_line, version: 1.0.2}\ninclude: [tasks.yaml]\ntags:\n  - {name: speed, type: LREAL, unit: m/s, hmi: readwrite}\n') },
        { name: 'tasks.yaml', mimeType: 'text/yaml', buffer: Buffer.from('# the line\'s tasks\ntasks:\n  - name: main\n    period: 10xs\n    priority: 50\n  - name: slow\n    period: 100ms\n') },
      ]);
      await page.getByRole('button', { name: 'Check' }).click();
      await page.locator('.src-line.has-error').waitFor();
      await page.waitForTimeout(300);
    },
  };
  for (const [size, viewport] of [['desktop', DESKTOP], ['phone', PHONE]]) {
    await page.setViewportSize(viewport);
    for (const [name, scene] of Object.entries(scenes)) {
      await page.goto(`${fixture.url}/#/${name}`);
      await scene();
      const file = join(out, `${name}-${size}.png`);
      await page.evaluate(() => window.scrollTo(0, 0));
      await page.screenshot({ path: file, fullPage: true });
      taken.push(file);
    }
  }
  // The force dialog with its confirmation, and the login dialog, on a phone.
  await page.goto(`${fixture.url}/#/tags`);
  await page.locator('tr[data-tag=speed] button', { hasText: 'Force' }).click();
  await page.locator('dialog[open] input[name=value]').fill('0.8');
  await page.locator('dialog[open] input[name=confirm]').check();
  await page.screenshot({ path: join(out, 'force-phone.png') });
  taken.push(join(out, 'force-phone.png'));
  await page.keyboard.press('Escape');
  await page.getByRole('button', { name: 'Log out' }).click();
  await page.getByRole('button', { name: 'Log in' }).click();
  await page.getByLabel('User name').fill('erik');
  await page.screenshot({ path: join(out, 'login-phone.png') });
  taken.push(join(out, 'login-phone.png'));
  await page.keyboard.press('Escape');
  // The menu of the phone layout, opened.
  await page.goto(`${fixture.url}/#/overview`);
  await page.getByRole('button', { name: 'Menu' }).click();
  await page.screenshot({ path: join(out, 'menu-phone.png') });
  taken.push(join(out, 'menu-phone.png'));
} finally {
  await browser.close();
  await fixture.close();
}
console.log(taken.join('\n'));
