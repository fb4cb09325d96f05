// `make figures`: the README's images of the headline figures, regenerated from scratch. Runs the shipped
// experiment configs (small ones where the full size takes long), writes their reports, opens each in
// headless chromium (playwright-core) and screenshots the key charts to PNG in docs/images/.
//
//   node web/figures.mjs --cli build/pegasus --node-modules build/web/node_modules --out docs/images
//                        [--runs runs/figures] [--only NAME] [--no-run]
// --no-run keeps the run directories of an earlier call and only rewrites their reports (after a change to the
// page code) before photographing them.
import { createRequire } from 'node:module';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const cli = path.resolve(option('--cli', path.join(source, 'build', 'pegasus')));
const nodeModules = path.resolve(option('--node-modules', path.join(source, 'build', 'web', 'node_modules')));
const out = path.resolve(option('--out', path.join(source, 'docs', 'images')));
const runsDir = path.resolve(option('--runs', path.join(source, 'runs', 'figures')));
const only = option('--only', '');
const noRun = args.includes('--no-run');
const chromiumPath = process.env.PEGASUS_CHROMIUM || '/usr/bin/chromium';
const { chromium } = createRequire(path.join(nodeModules, 'noop.js'))('playwright-core');

function pegasus(argv) {
  const t0 = Date.now();
  execFileSync(cli, argv, { cwd: source, stdio: ['ignore', 'ignore', 'inherit'] });
  console.log(`  pegasus ${argv.join(' ')}  (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
}
const dir = (name) => path.join(runsDir, name);

// Each figure: the runs it needs, and what to photograph in which report (a chart by its title, or a
// section by its id).
const figures = [
  {
    name: 'pomdp',
    make: () => pegasus(['pomdp-gridworld', '--config', 'experiments/pomdp-gridworld-demo.toml', '--out', dir('pomdp'), '--force', '--quiet']),
    shots: [{ run: 'pomdp', chart: 'value of the chosen policy', file: 'fig-4-5b-value-vs-m.png' }],
  },
  {
    name: 'shaping',
    make: () => {
      pegasus(['shaping', 'gridworld', '--config', 'experiments/shaping-gridworld-10.toml', '--out', dir('shaping-gridworld-10'), '--force', '--quiet']);
      pegasus(['shaping', 'flags', '--config', 'experiments/flags-5.toml', '--out', dir('flags-5'), '--force', '--quiet']);
    },
    shots: [
      { run: 'shaping-gridworld-10', chart: 'log-log', file: 'fig-3-2a-shaping-gridworld.png' },
      { run: 'flags-5', chart: 'log-log', file: 'fig-3-3a-shaping-flags.png' },
    ],
  },
  {
    name: 'bicycle',
    make: () => pegasus(['bicycle', 'experiment', '--config', 'experiments/bicycle-demo.toml', '--out', dir('bicycle'), '--force', '--quiet']),
    shots: [
      { run: 'bicycle', section: 'rides', file: 'bicycle-rides.png' },
      { run: 'bicycle', chart: 'U-hat against optimizer iterations', file: 'bicycle-learning-curves.png' },
    ],
  },
  {
    name: 'heli',
    make: () => {
      pegasus(['heli', 'pilot', '--config', 'experiments/heli-pilot-train.toml', '--out', dir('heli-train'), '--force', '--quiet']);
      pegasus(['heli', 'pilot', '--config', 'experiments/heli-pilot-test.toml', '--out', dir('heli-test'), '--force', '--quiet']);
      pegasus(['heli', 'identify', '--config', 'experiments/heli-identify.toml', '--train', path.join(dir('heli-train'), 'log.csv'),
        '--test', path.join(dir('heli-test'), 'log.csv'), '--out', dir('heli-id'), '--force', '--quiet']);
    },
    shots: [
      { run: 'heli-id', chart: 'xdot_b', file: 'fig-5-2-identification-xdot.png' },
      { run: 'heli-id', chart: 'ydot_b on hold-out data', file: 'fig-5-3-noise-check.png' },
      { run: 'heli-test', replay: true, file: 'heli-replay.png' },
    ],
  },
  {
    name: 'hover',
    // The helicopter main job (make demo): its `fly` stage flies the learned hover policy and the pilot.
    // Then a manoeuvre (III.2, the nose-in circle) on the model the pipeline identified.
    make: () => {
      pegasus(['heli', 'pipeline', '--config', 'experiments/heli-demo.toml', '--out', dir('heli-demo'), '--force', '--quiet']);
      pegasus(['heli', 'maneuver', '--config', 'experiments/heli-maneuver-demo.toml', '--model',
        path.join(dir('heli-demo'), 'identify', 'model.json'), '--out', dir('heli-maneuver'), '--force', '--quiet']);
    },
    shots: [
      { run: 'heli-demo/fly', section: 'hover', file: 'fig-5-6-5-7-hover-vs-pilot.png' },
      { run: 'heli-demo/fly', replay: true, file: 'heli-hover-replay.png' },
      { run: 'heli-maneuver', replay: true, file: 'fig-5-10-maneuver-replay.png' },
      { run: 'heli-maneuver', chart: 'seen from above', file: 'fig-5-10-maneuver-from-above.png' },
    ],
  },
];

fs.mkdirSync(out, { recursive: true });
fs.mkdirSync(runsDir, { recursive: true });
const chosen = figures.filter((f) => !only || f.name === only);
for (const f of chosen) {
  console.log(`${f.name}:`);
  if (!noRun) {
    f.make();
  } else {
    for (const run of new Set(f.shots.map((s) => s.run))) pegasus(['report', dir(run)]);
  }
}

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'pegasus-figures-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: chromiumPath,
  headless: true,
  viewport: { width: 1100, height: 900 },
  deviceScaleFactor: 1.5,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader',
    '--use-angle=swiftshader'],
});
for (const f of chosen) {
  for (const shot of f.shots) {
    const page = await context.newPage();
    await page.goto(`file://${path.join(dir(shot.run), 'report.html')}`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.pegasusReport && window.pegasusReport.ready, null, { timeout: 60000 });
    let target;
    if (shot.section) {
      target = page.locator(`section#${shot.section}`);
    } else if (shot.replay) {
      // A moment into the flight, so that the aircraft is away from the start.
      await page.evaluate(() => {
        const s = document.querySelector('.replay-slider');
        s.value = String(Math.floor(Number(s.max) * 0.4));
        s.dispatchEvent(new Event('input', { bubbles: true }));
      });
      target = page.locator('.chart[data-kind="replay"]').first();
    } else {
      const id = await page.evaluate((title) => {
        const data = window.pegasusReport.data;
        const c = data.charts.find((x) => x.title === title) || data.charts.find((x) => (x.title || '').includes(title));
        return c ? c.id : null;
      }, shot.chart);
      if (!id) throw new Error(`${shot.run}: no chart titled ${shot.chart}`);
      target = page.locator(`#${id}`);
    }
    await target.scrollIntoViewIfNeeded();
    await page.waitForTimeout(300);
    await target.screenshot({ path: path.join(out, shot.file) });
    console.log(`  ${path.relative(source, path.join(out, shot.file))}`);
    await page.close();
  }
}
await context.close();
fs.rmSync(profile, { recursive: true, force: true });
