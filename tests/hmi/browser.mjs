// The browser tests' harness: Debian's chromium driven by playwright-core
// (from hmi_web/node_modules), headless, in a new empty profile, talking only
// to 127.0.0.1. A missing chromium is a skip (exit 77, which ctest reports as
// skipped), never a pass; scripts/test.sh installs it.
import { existsSync } from 'node:fs';
import { mkdtemp, rm } from 'node:fs/promises';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
export const ROOT = resolve(here, '../..');
export const CHROMIUM = process.env.SYNCPLC_CHROMIUM || '/usr/bin/chromium';
export const SKIP = 77;

export const DESKTOP = { width: 1280, height: 860 };
export const PHONE = { width: 390, height: 844 };

// Exits with 77 (skipped) and says why when the browser tests cannot run here.
export function requireBrowser() {
  if (!existsSync(CHROMIUM)) {
    console.log(`SKIPPED: ${CHROMIUM} not found; install Debian's chromium (scripts/build_hmi.sh --browser does) to run the HMI browser tests`);
    process.exit(SKIP);
  }
  const missing = ['hmi_web/node_modules/playwright-core', 'hmi_web/dist/index.html'].filter((p) => !existsSync(join(ROOT, p)));
  if (missing.length) {
    console.error(`missing ${missing.join(', ')}: run scripts/build_hmi.sh first`);
    process.exit(1);
  }
}

export function playwright() {
  const require = createRequire(join(ROOT, 'hmi_web', 'package.json'));
  return require('playwright-core');
}

export async function launch() {
  const profile = await mkdtemp(join(tmpdir(), 'syncplc-hmi-chromium-'));
  const context = await playwright().chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    viewport: DESKTOP,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    timeout: 60000,
  });
  context.setDefaultTimeout(15000);
  return {
    context,
    async close() {
      await context.close();
      await rm(profile, { recursive: true, force: true });
    },
  };
}

// Polls fn (every 50 ms) until it returns something truthy, which it returns;
// throws after ms naming `what`. Timing is the page's, not the test's: a
// loaded machine makes a test slower, never wrong (ms only ends a hang).
export async function until(fn, ms = 10000, what = 'condition') {
  const end = Date.now() + ms;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() > end) throw new Error(`timed out after ${ms} ms waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 50));
  }
}
