// Browser test of the HTML run reports (registered in ctest by web/CMakeLists.txt as browser.Reports).
//
// Runs every kind of pegasus command on a tiny setting (plus synthetic run directories in the file formats
// of the helicopter hover/fly/manoeuvre commands, web/../notes: flights.csv, pilot_flights.csv,
// ideal_path.csv, progress.csv), then opens each report.html in Debian's headless chromium driven by
// playwright-core and checks: no console errors and no network requests (the page is offline), every chart
// has drawn content, and moving the replay's time slider moves the aircraft (and the picture).
//
//   node tests/browser/reports_test.mjs --cli BUILD/pegasus --node-modules BUILD/web/node_modules --source .
//
// Exit 0: passed; 1: failed; 77: skipped (no chromium, or no playwright-core), with a message saying so.
// PEGASUS_CHROMIUM overrides /usr/bin/chromium; --keep leaves the run directories in place.
import { createRequire } from 'node:module';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const cli = path.resolve(option('--cli', 'build/pegasus'));
const nodeModules = path.resolve(option('--node-modules', 'build/web/node_modules'));
const source = path.resolve(option('--source', '.'));
const only = option('--only', '');
const keep = args.includes('--keep');
const chromiumPath = process.env.PEGASUS_CHROMIUM || '/usr/bin/chromium';

function skip(why) {
  console.log(`SKIPPED browser.Reports: ${why}`);
  process.exit(77);
}
if (!fs.existsSync(chromiumPath)) skip(`no chromium at ${chromiumPath} (scripts/install-deps.sh installs Debian's)`);
let chromium;
try {
  ({ chromium } = createRequire(path.join(nodeModules, 'noop.js'))('playwright-core'));
} catch (e) {
  skip(`playwright-core not installed in ${nodeModules} (the build runs npm ci there): ${e.message}`);
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'pegasus-browser-'));
const failures = [];
const fail = (what) => { failures.push(what); console.log(`FAIL ${what}`); };

function pegasus(argv) {
  try {
    return execFileSync(cli, argv, { cwd: source, stdio: ['ignore', 'pipe', 'pipe'], encoding: 'utf8' });
  } catch (e) {
    throw new Error(`pegasus ${argv.join(' ')} failed (${e.status}): ${e.stderr || e.message}`);
  }
}

// --- run directories ------------------------------------------------------------------------------------
const runs = [];  // [name, dir, expectations]
function run(name, argv, expect = {}) {
  if (only && !name.includes(only)) return;
  const dir = path.join(work, name);
  pegasus([...argv, '--out', dir, '--quiet', '--threads', '2']);
  runs.push([name, dir, expect]);
}

const FLIGHT_HEADER = 'flight,t,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4,' +
  'target_x,target_y,target_z,target_yaw';
// A smooth synthetic flight: hover wobble (amplitude `wobble`) or a circle of radius `radius` round (0, 0).
function flightRows(flight, seconds, { wobble = 0.3, radius = 0, phase = 0 } = {}) {
  const rows = [];
  for (let k = 0; k * 0.02 <= seconds + 1e-9; k++) {
    const t = k * 0.02;
    const w = 2 * Math.PI * t / seconds;
    const x = radius * Math.cos(w) + wobble * Math.sin(1.3 * t + phase);
    const y = radius * Math.sin(w) + wobble * Math.cos(0.7 * t + phase);
    const z = -10 - 0.2 * Math.sin(0.5 * t + phase);
    const xdot = -radius * Math.sin(w) * 2 * Math.PI / seconds + 1.3 * wobble * Math.cos(1.3 * t + phase);
    const ydot = radius * Math.cos(w) * 2 * Math.PI / seconds - 0.7 * wobble * Math.sin(0.7 * t + phase);
    const zdot = -0.1 * Math.cos(0.5 * t + phase);
    const yaw = radius ? Math.atan2(-y, -x) : 0.1 * Math.sin(0.3 * t);
    rows.push([flight, t.toFixed(2), x, y, z, 0.05 * Math.sin(t), 0.04 * Math.cos(t), yaw, xdot, ydot, zdot,
      0, 0, 0, 0.1, -0.1, 0.2, 0.05, radius ? radius * Math.cos(w) : 0, radius ? radius * Math.sin(w) : 0, -10,
      yaw].join(','));
  }
  return rows;
}
function writeRun(name, files, expect = {}) {
  if (only && !name.includes(only)) return;
  const dir = path.join(work, name);
  fs.mkdirSync(dir, { recursive: true });
  for (const [file, text] of Object.entries(files)) fs.writeFileSync(path.join(dir, file), text);
  pegasus(['report', dir]);
  runs.push([name, dir, expect]);
}
// charts.json (include/pegasus/runs/charts.hpp) of a synthetic run: optimizer progress, the first flight's
// traces and the 3-D replay of the flights (against the ideal path when given).
function chartsJson({ pilot = false, ideal = false } = {}) {
  const files = [{ file: 'flights.csv', name: 'policy flight' }];
  if (pilot) files.push({ file: 'pilot_flights.csv', name: 'pilot flight' });
  const traces = (y, factor = 1) => files.map((f, i) => ({ file: f.file, x: 't', y, group_by: ['flight'], name: f.name,
    y_factor: factor, max_groups: 1, dash: i ? 'dash' : '' }));
  const sections = [
    { id: 'progress', title: 'Optimizer progress', intro: '', charts: ['iteration', 'evaluations', 'seconds'].map((x) => ({
      kind: 'xy', title: `U-hat against ${x}`, x: { title: x }, y: { title: 'U-hat' },
      traces: [{ file: 'progress.csv', x, y: 'objective', mode: 'lines+markers' }] })) },
    { id: 'hover', title: 'Flight traces', intro: '', charts: [['xdot', 1], ['y', 1], ['z', -1]].map(([y, f]) => ({
      kind: 'xy', title: y, x: { title: 'time (s)' }, y: { title: y }, traces: traces(y, f), size: 'small' })) },
    { id: 'replay', title: '3-D replay', intro: '', charts: [{ kind: 'replay', title: '3-D replay',
      traces: files.map((f) => ({ file: f.file, x: 't', group_by: ['flight'], name: f.name })), size: 'wide',
      ...(ideal ? { path: 'ideal_path.csv' } : {}) }] },
  ];
  return JSON.stringify({ format: 'pegasus.charts', version: 1, sections });
}
function progressCsv(n) {
  const lines = ['iteration,evaluations,seconds,objective'];
  for (let i = 1; i <= n; i++) lines.push(`${i},${60 * i},${(0.2 * i).toFixed(1)},${(-50 / i).toFixed(6)}`);
  return lines.join('\n') + '\n';
}

const started = Date.now();
run('horizon', ['horizon']);
run('pomdp', ['pomdp-gridworld', '--scenarios', '1,2,4', '--trials', '2', '--horizon', '20',
  '--montecarlo-max-m', '2']);
run('shaping-gridworld', ['shaping', 'gridworld', '--size', '5', '--runs', '3', '--trials', '60']);
run('shaping-flags', ['shaping', 'flags', '--size', '5', '--runs', '2', '--trials', '40']);
run('shaping-progress-bonus', ['shaping', 'progress-bonus', '--size', '5', '--episodes', '100']);
run('shaping-audit', ['shaping', 'audit', '--mdp', 'experiments/audit/gridworld-4x4.mdp.json', '--shaping',
  'experiments/audit/gridworld-4x4-phi0.shaping.json']);
run('bicycle-experiment', ['bicycle', 'experiment', '--trials', '2', '--lesson-trials', '0', '--scenarios', '4',
  '--horizon', '100', '--optimizer.gradient.max-iterations', '2', '--rides', '2', '--goal-km', '0.05', '--max-km', '0.1']);
run('bicycle-train', ['bicycle', 'train', '--scenarios', '4', '--horizon', '100', '--optimizer.gradient.max-iterations', '2', '--rides',
  '2', '--goal-km', '0.05', '--max-km', '0.1']);
if (fs.existsSync(path.join(work, 'bicycle-train', 'policy.json'))) {
  run('bicycle-ride', ['bicycle', 'ride', '--policy', path.join(work, 'bicycle-train', 'policy.json'), '--rides',
    '2', '--goal-km', '0.05', '--max-km', '0.1']);
  run('bicycle-variance', ['bicycle', 'variance', '--policy', path.join(work, 'bicycle-train', 'policy.json'),
    '--sets', '3', '--scenarios', '3', '--horizon', '50']);
}
run('heli-pilot', ['heli', 'pilot', '--seconds', '12', '--hover-seconds', '2'], { replay: 1 });
if (!only || 'heli-identify'.includes(only)) {
  const test = path.join(work, 'heli-pilot-test');
  pegasus(['heli', 'pilot', '--seconds', '8', '--hover-seconds', '2', '--seed', '2', '--out', test, '--quiet']);
  run('heli-identify', ['heli', 'identify', '--train', path.join(work, 'heli-pilot', 'log.csv'), '--test',
    path.join(test, 'log.csv'), '--cv-points', '30', '--scale-grid', '1,2', '--coordinate-passes', '0',
    '--horizon-s', '1', '--window-s', '1', '--start-spacing-s', '1', '--variants=false']);
}
if (fs.existsSync(path.join(work, 'heli-identify', 'model.json'))) {
  // A model of 12 s of logs does not hold the aircraft: the report needs a hover run all the same.
  run('heli-hover', ['heli', 'hover', '--model', path.join(work, 'heli-identify', 'model.json'), '--scenarios', '2',
    '--seconds', '2', '--optimizer.gradient.max-iterations', '1', '--optimizer.hill-climbing.max-iterations', '1',
    '--max-start-crash-fraction', '1']);
  run('heli-fly', ['heli', 'fly', '--policy', path.join(work, 'heli-hover', 'policy.json'), '--compare-pilot',
    '--flights', '2', '--seconds', '5'], { replay: 1 });
  run('heli-maneuver', ['heli', 'maneuver', '--config', 'experiments/heli-maneuver-demo.toml', '--model',
    path.join(work, 'heli-identify', 'model.json'), '--scenarios', '1', '--optimizer.gradient.max-iterations', '1',
    '--optimizer.hill-climbing.proposals-per-iteration', '2', '--flights', '2', '--trace-flights', '2'], { replay: 1 });
}
// MuJoCo (when the build has it): a short cart-pole training and the rollout of its policy, each with the
// 3-D replay of its geoms (replay.json).
if (/^  mujoco /m.test(pegasus(['--help']))) {
  run('mujoco-train', ['mujoco', 'train', '--model', 'experiments/mujoco/cartpole.xml', '--task',
    'experiments/mujoco/cartpole_swingup.toml', '--policy', 'mlp', '--hidden', '4', '--scenarios', '2',
    '--optimizer.ars.max-iterations', '2', '--evaluation-episodes', '2'], { replay: 1 });
  if (fs.existsSync(path.join(work, 'mujoco-train', 'policy.json'))) {
    run('mujoco-rollout', ['mujoco', 'rollout', '--policy', path.join(work, 'mujoco-train', 'policy.json'),
      '--episodes', '2'], { replay: 1 });
  }
}
// The file formats of the helicopter commands (notes/heli_conventions.md), synthetic, with the charts.json
// that describes them: a hover run and a manoeuvre run with its ideal path.
writeRun('heli-hover-synthetic', {
  'summary.json': JSON.stringify({ experiment: 'heli hover', flights: 3, rms_position_error_m: 0.21 }),
  'config.toml': 'scenarios = 30\ngamma = 0.9995\n',
  'progress.csv': progressCsv(25),
  'flights.csv': [FLIGHT_HEADER, ...[0, 1, 2].flatMap((f) => flightRows(f, 6, { wobble: 0.2, phase: f }))].join('\n') + '\n',
  'pilot_flights.csv': [FLIGHT_HEADER, ...[0, 1].flatMap((f) => flightRows(f, 6, { wobble: 0.6, phase: 2 + f }))].join('\n') + '\n',
  'charts.json': chartsJson({ pilot: true }),
}, { replay: 1 });
const idealLines = ['t,x,y,z,yaw'];
for (let k = 0; k <= 200; k++) {
  const t = k * 0.05, w = 2 * Math.PI * t / 10;
  idealLines.push(`${t.toFixed(2)},${8 * Math.cos(w)},${8 * Math.sin(w)},-10,${Math.atan2(-Math.sin(w), -Math.cos(w))}`);
}
writeRun('heli-maneuver-synthetic', {
  'summary.json': JSON.stringify({ experiment: 'heli maneuver', maneuver: 'III.2 nose-in circle', rms_path_error_m: 0.8 }),
  'config.toml': 'maneuver = "nose-in-circle"\n',
  'progress.csv': progressCsv(12),
  'flights.csv': [FLIGHT_HEADER, ...[0, 1].flatMap((f) => flightRows(f, 10, { wobble: 0.3, radius: 8, phase: f }))].join('\n') + '\n',
  'ideal_path.csv': idealLines.join('\n') + '\n',
  'charts.json': chartsJson({ ideal: true }),
}, { replay: 1 });
// As large as the demo's flights (10 policy and 10 pilot flights of 60 s at 50 Hz): the page keeps fewer rows
// per series so that it stays within 1.5 MB, and still draws every chart and the replay.
writeRun('heli-fly-large-synthetic', {
  'summary.json': JSON.stringify({ experiment: 'heli fly', flights: 10 }),
  'progress.csv': progressCsv(400),
  'flights.csv': [FLIGHT_HEADER, ...[...Array(10).keys()].flatMap((f) => flightRows(f, 60, { wobble: 0.3, phase: f }))].join('\n') + '\n',
  'pilot_flights.csv': [FLIGHT_HEADER, ...[...Array(10).keys()].flatMap((f) => flightRows(f, 60, { wobble: 0.7, phase: 1 + f }))].join('\n') + '\n',
  'charts.json': chartsJson({ pilot: true }),
}, { replay: 1 });
console.log(`made ${runs.length} run directories in ${((Date.now() - started) / 1000).toFixed(1)} s`);

// --- the browser ----------------------------------------------------------------------------------------
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'pegasus-chromium-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: chromiumPath,
  headless: true,
  viewport: { width: 1280, height: 900 },
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    // WebGL on the CPU (SwiftShader) for the 3-D replay: headless, without a GPU.
    '--enable-unsafe-swiftshader', '--use-angle=swiftshader'],
});

// Pixels of a canvas that differ from its background colour, and a fingerprint of the picture.
async function canvasPixels(page, id) {
  return page.evaluate((chartId) => {
    const source = document.querySelector(`#${chartId} canvas`);
    if (!source) return { drawn: 0, hash: 0 };
    const c = document.createElement('canvas');
    c.width = source.width; c.height = source.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(source, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const [r0, g0, b0] = [d[0], d[1], d[2]];
    let drawn = 0, hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - r0) + Math.abs(d[i + 1] - g0) + Math.abs(d[i + 2] - b0) > 30) drawn++;
      hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    return { drawn, hash };
  }, id);
}

for (const [name, dir, expect] of runs) {
  const file = path.join(dir, 'report.html');
  if (!fs.existsSync(file)) { fail(`${name}: no report.html`); continue; }
  // Every report at most 1.5 MB (include/pegasus/report/report.hpp, kMaxReportBytes).
  const bytes = fs.statSync(file).size;
  if (bytes > 1500000) fail(`${name}: report.html is ${bytes} bytes, more than 1.5 MB`);
  const page = await context.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('request', (r) => {
    const url = r.url();
    if (!url.startsWith('file:') && !url.startsWith('data:') && !url.startsWith('blob:')) errors.push(`network request: ${url}`);
  });
  const t0 = Date.now();
  await page.goto(`file://${file}`, { waitUntil: 'load' });
  try {
    await page.waitForFunction(() => window.pegasusReport && window.pegasusReport.ready, null, { timeout: 60000 });
  } catch (e) {
    fail(`${name}: the page code never finished (${e.message.split('\n')[0]})`);
  }
  const status = await page.evaluate(() => {
    const out = { charts: [], errors: (window.pegasusReport || {}).errors || [] };
    for (const div of document.querySelectorAll('.chart')) {
      const kind = div.dataset.kind;
      let content = 0;
      if (kind === 'replay' || kind === 'mujoco_replay') {
        content = div.querySelector('canvas') ? 1 : 0;
      } else {
        // Drawn marks: line paths with geometry, markers, boxes, bars.
        for (const p of div.querySelectorAll('g.trace path')) {
          if ((p.getAttribute('d') || '').length > 8) content++;
        }
      }
      out.charts.push({ id: div.id, kind, plotly: div.classList.contains('js-plotly-plot'), content });
    }
    return out;
  });
  const summary = { charts: status.charts.length, ms: Date.now() - t0 };
  for (const e of status.errors) fail(`${name}: ${e}`);
  if (status.charts.length === 0 && !['horizon'].includes(name)) fail(`${name}: no charts`);
  for (const c of status.charts) {
    if (!c.kind.endsWith('replay') && !c.plotly) fail(`${name}: ${c.id} (${c.kind}) was not drawn by plotly`);
    if (c.content === 0) fail(`${name}: ${c.id} (${c.kind}) has no drawn content`);
  }
  const replays = status.charts.filter((c) => c.kind.endsWith('replay'));
  if ((expect.replay || 0) !== replays.length) fail(`${name}: ${replays.length} replays, expected ${expect.replay || 0}`);
  for (const [i, r] of replays.entries()) {
    // The aircraft's NED position, or the world positions of every MuJoCo geom.
    const position = (k) => {
      const replay = window.pegasusReport.replays[k];
      return replay.aircraftPosition ? replay.aircraftPosition() : replay.positions();
    };
    const before = await page.evaluate(position, i);
    const pixelsBefore = await canvasPixels(page, r.id);
    if (pixelsBefore.drawn < 500) fail(`${name}: the replay canvas is (nearly) empty: ${pixelsBefore.drawn} pixels drawn`);
    // Move the slider as a user would: focus it, press End (to the last sample).
    const slider = page.locator(`#${r.id} .replay-slider`);
    await slider.focus();
    await page.keyboard.press('End');
    const after = await page.evaluate(position, i);
    const moved = Math.hypot(...after.map((x, k) => x - before[k]));
    if (!(moved > 1e-3)) fail(`${name}: moving the slider did not move the aircraft (${before} -> ${after})`);
    const pixelsAfter = await canvasPixels(page, r.id);
    if (pixelsAfter.hash === pixelsBefore.hash) fail(`${name}: moving the slider did not change the picture`);
    const label = await page.locator(`#${r.id} .replay-time`).textContent();
    if (label === 't = 0.00 s') fail(`${name}: the time label did not follow the slider`);
    // Play from the start for a moment, then pause.
    await page.keyboard.press('Home');
    await page.locator(`#${r.id} .replay-play`).click();
    await page.waitForTimeout(600);
    await page.locator(`#${r.id} .replay-play`).click();
    const index = await page.evaluate((k) => window.pegasusReport.replays[k].index, i);
    if (!(index > 0)) fail(`${name}: Play did not advance the replay`);
    summary.moved_m = Number(moved.toFixed(3));
  }
  for (const e of errors) fail(`${name}: ${e}`);
  console.log(`${failures.length ? '    ' : 'ok  '}${name}: ${JSON.stringify(summary)}`);
  await page.close();
}
await context.close();
fs.rmSync(profile, { recursive: true, force: true });
if (!keep) fs.rmSync(work, { recursive: true, force: true });
else console.log(`run directories kept in ${work}`);
console.log(failures.length ? `${failures.length} failures` : `all ${runs.length} reports passed`);
process.exit(failures.length ? 1 : 0);
