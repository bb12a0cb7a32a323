// Builds the HMI into dist/: one JavaScript bundle, one stylesheet and
// index.html, everything the browser needs (the PLC may have no internet, so
// nothing is loaded from elsewhere at run time).
//   node build.mjs            production build (minified, source maps)
//   node build.mjs --watch    rebuild on every change (development)
import * as esbuild from 'esbuild';
import { copyFile, mkdir, rm } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, 'dist');
const watch = process.argv.includes('--watch');

await rm(dist, { recursive: true, force: true });
await mkdir(dist, { recursive: true });
for (const f of ['index.html', 'favicon.svg']) await copyFile(join(here, 'src', f), join(dist, f));

const options = {
  entryPoints: { app: join(here, 'src', 'main.jsx') },
  outdir: dist,
  bundle: true,
  format: 'esm',
  target: ['es2020', 'chrome100', 'firefox100', 'safari15'],
  jsx: 'automatic',
  jsxImportSource: 'preact',
  minify: !watch,
  sourcemap: true,
  legalComments: 'linked',
  logLevel: 'info',
};

if (watch) {
  const ctx = await esbuild.context(options);
  await ctx.watch();
} else {
  await esbuild.build(options);
}
