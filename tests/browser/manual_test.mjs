// Browser test of the manual (docs/check.sh runs it after building the site, so it is part of the ctest
// docs.Manual): opens the home page, a tutorial, the command reference, the C++ API and the Python API pages of
// the built site in Debian's headless chromium driven by playwright-core, and checks that each renders: no
// console error, no page error, no request beyond the site's own files, a title, and the text each page must
// hold (the API pages their documented names).
//
//   node tests/browser/manual_test.mjs --site BUILD/check-html --node-modules BUILD/web/node_modules
//
// Exit 0: passed; 1: failed; 77: skipped (no chromium, or no playwright-core), with a message saying so.
// PEGASUS_CHROMIUM overrides /usr/bin/chromium.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const site = path.resolve(option('--site', 'build-docs/check-html'));
const nodeModules = path.resolve(option('--node-modules', 'build/web/node_modules'));
const chromiumPath = process.env.PEGASUS_CHROMIUM || '/usr/bin/chromium';

function skip(why) {
  console.log(`SKIPPED the manual's browser test: ${why}`);
  process.exit(77);
}
if (!fs.existsSync(chromiumPath)) skip(`no chromium at ${chromiumPath} (scripts/install-deps.sh installs Debian's)`);
let chromium;
try {
  ({ chromium } = createRequire(path.join(nodeModules, 'noop.js'))('playwright-core'));
} catch (e) {
  skip(`playwright-core not installed in ${nodeModules} (the build runs npm ci there): ${e.message}`);
}

// Each page: its file in the site, and text its article must contain.
const pages = [
  ['index.html', ['Pegasus']],
  ['tutorials/own-simulator-cpp.html', ['find_package(pegasus']],
  ['reference/cli.html', ['pegasus heli fly', '--compare-pilot']],
  ['reference/cpp-api.html', ['pegasus::']],
  ['reference/python-api.html', ['pegasus.']],
];

const failures = [];
const fail = (what) => { failures.push(what); console.log(`FAIL ${what}`); };
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'pegasus-manual-chromium-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: chromiumPath,
  headless: true,
  viewport: { width: 1280, height: 900 },
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  for (const [file, texts] of pages) {
    const full = path.join(site, file);
    if (!fs.existsSync(full)) { fail(`${file}: not in the site ${site}`); continue; }
    const page = await context.newPage();
    const errors = [];
    page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
    page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
    page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}`));
    page.on('request', (r) => {
      const url = r.url();
      if (!url.startsWith('file:') && !url.startsWith('data:')) errors.push(`network request: ${url}`);
    });
    await page.goto(`file://${full}`, { waitUntil: 'load' });
    const { title, text } = await page.evaluate(() => ({
      title: (document.querySelector('article h1') || document.querySelector('h1') || {}).textContent || '',
      text: (document.querySelector('article') || document.body).innerText,
    }));
    if (!title.trim()) errors.push('no heading');
    for (const t of texts) if (!text.includes(t)) errors.push(`its text lacks "${t}"`);
    if (errors.length) fail(`${file}: ${errors.join('; ')}`);
    else console.log(`ok   ${file}: "${title.replace(/\s+/g, ' ').replace(/#$/, '').trim()}", ${text.length} characters`);
    await page.close();
  }
} finally {
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
if (failures.length) {
  console.log(`the manual's browser test: ${failures.length} failure(s)`);
  process.exit(1);
}
console.log(`the manual's browser test: ${pages.length} pages render with no console error`);
