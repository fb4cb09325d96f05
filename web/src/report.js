// The page code of a Pegasus run report. `pegasus report` writes the HTML skeleton (headline figures,
// configuration, one empty <div class="chart"> per chart) and a JSON block with the data of every chart
// (<script type="application/gzip" id="pegasus-data" data-encoding="gzip+base64">: the JSON, gzip-compressed and
// base64-encoded, which window.pegasusInflate of the bundle's loader unpacks; web/build.mjs); this code draws
// each chart with plotly.js, and the helicopter flight replay with three.js. Chart kinds:
//   xy     lines/markers; optional error bars (error), shaded bands (lower/upper), horizontal reference lines
//   box    box plots of groups of values
//   bar    a bar chart
//   replay 3-D replay of flights (NED positions and Euler angles) against an ideal path, with play/pause
//          and a time slider
//   mujoco_replay  3-D replay of a MuJoCo rollout (replay.json): every geom as a three.js primitive
// window.pegasusReport exposes what the browser test checks (charts drawn, replay aircraft position) and the
// page's data.
import Plotly from 'plotly.js-cartesian-dist-min';
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f',
  '#bcbd22', '#17becf'];

function rgba(hex, alpha) {
  const n = parseInt(hex.slice(1), 16);
  return `rgba(${(n >> 16) & 255}, ${(n >> 8) & 255}, ${n & 255}, ${alpha})`;
}

function finite(values) {
  return values.filter((v) => v !== null && Number.isFinite(v));
}

function axis(title, log, extra) {
  return Object.assign({ title: { text: title || '' }, type: log ? 'log' : 'linear', zeroline: false,
    automargin: true }, extra || {});
}

function baseLayout(spec) {
  return {
    title: { text: spec.title || '', font: { size: 15 }, y: 0.98, yanchor: 'top' },
    margin: { l: 60, r: 20, t: spec.title ? 70 : 40, b: 50 },
    // The legend sits between the title and the plot, where it never covers the axis titles.
    legend: { orientation: 'h', x: 0, xanchor: 'left', y: 1.0, yanchor: 'bottom' },
    hovermode: 'closest',
    colorway: PALETTE,
  };
}

const plotConfig = { responsive: true, displaylogo: false };

function drawXY(div, spec) {
  const traces = [];
  let xmin = Infinity, xmax = -Infinity;
  spec.traces.forEach((t, i) => {
    const color = t.color || PALETTE[i % PALETTE.length];
    for (const x of finite(t.x)) { xmin = Math.min(xmin, x); xmax = Math.max(xmax, x); }
    if (t.lower && t.upper) {
      traces.push({
        x: t.x.concat(t.x.slice().reverse()),
        y: t.upper.concat(t.lower.slice().reverse()),
        fill: 'toself', fillcolor: rgba(color, 0.18), line: { width: 0, color }, hoverinfo: 'skip',
        name: t.band_name || `${t.name} band`, showlegend: false, legendgroup: t.name, type: 'scatter',
      });
    }
    const trace = {
      x: t.x, y: t.y, name: t.name, type: 'scatter', mode: t.mode || 'lines', legendgroup: t.name,
      line: { color, width: t.width || 1.8, dash: t.dash || 'solid' }, marker: { color, size: 6 },
      visible: t.hidden ? 'legendonly' : true,
    };
    if (t.error) trace.error_y = { type: 'data', array: t.error, visible: true, color };
    traces.push(trace);
  });
  for (const [i, h] of (spec.hlines || []).entries()) {
    const x0 = Number.isFinite(xmin) ? xmin : 0, x1 = Number.isFinite(xmax) ? xmax : 1;
    traces.push({ x: [x0, x1], y: [h.y, h.y], name: h.name, type: 'scatter', mode: 'lines',
      line: { color: h.color || '#000000', width: 1.5, dash: h.dash || 'dash' }, legendgroup: `hline${i}` });
  }
  const layout = baseLayout(spec);
  layout.xaxis = axis(spec.x_title, spec.x_log);
  layout.yaxis = axis(spec.y_title, spec.y_log, spec.equal_aspect ? { scaleanchor: 'x', scaleratio: 1 } : {});
  if (spec.x_log && spec.x_log_base === 2) layout.xaxis.dtick = Math.log10(2);
  return Plotly.newPlot(div, traces, layout, plotConfig);
}

function drawBox(div, spec) {
  const traces = spec.groups.map((g, i) => ({
    y: g.values, name: g.name, type: 'box', boxpoints: 'all', jitter: 0.4, pointpos: 0,
    marker: { color: PALETTE[i % PALETTE.length], size: 4 }, boxmean: true,
  }));
  const layout = baseLayout(spec);
  layout.showlegend = false;
  layout.yaxis = axis(spec.y_title, spec.y_log);
  layout.xaxis = axis(spec.x_title, false, { type: 'category' });
  return Plotly.newPlot(div, traces, layout, plotConfig);
}

function drawBar(div, spec) {
  const layout = baseLayout(spec);
  layout.showlegend = false;
  layout.xaxis = axis(spec.x_title, false, { type: spec.categorical ? 'category' : 'linear' });
  layout.yaxis = axis(spec.y_title, spec.y_log);
  return Plotly.newPlot(div, [{ x: spec.x, y: spec.y, type: 'bar', marker: { color: PALETTE[0] } }], layout,
    plotConfig);
}

// --- 3-D replay -----------------------------------------------------------------------------------------
// Positions are NED (x north, y east, z down). three.js is y-up: X = east, Y = up, Z = south, so
// three = M ned with M = [[0,1,0],[0,0,-1],[-1,0,0]] (both frames right-handed), and an attitude R_WB
// becomes M R_WB M^T.
function nedToThree(x, y, z) { return new THREE.Vector3(y, -z, -x); }

function attitudeQuaternion(roll, pitch, yaw) {
  const cr = Math.cos(roll), sr = Math.sin(roll), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const cy = Math.cos(yaw), sy = Math.sin(yaw);
  // R_WB = Rz(yaw) Ry(pitch) Rx(roll), body x forward, y right, z down.
  const R = [
    [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
    [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
    [-sp, cp * sr, cp * cr],
  ];
  const M = [[0, 1, 0], [0, 0, -1], [-1, 0, 0]];
  const mul = (A, B) => A.map((row) => [0, 1, 2].map((j) => row[0] * B[0][j] + row[1] * B[1][j] + row[2] * B[2][j]));
  const Mt = [[0, 0, -1], [1, 0, 0], [0, -1, 0]];
  const Q = mul(mul(M, R), Mt);
  const m4 = new THREE.Matrix4().set(Q[0][0], Q[0][1], Q[0][2], 0, Q[1][0], Q[1][1], Q[1][2], 0,
    Q[2][0], Q[2][1], Q[2][2], 0, 0, 0, 0, 1);
  return new THREE.Quaternion().setFromRotationMatrix(m4);
}

// A helicopter about the size of the Yamaha R-50 (3.6 m with rotors), built in three's axes for the body at
// zero attitude: nose towards -Z, right towards +X, up towards +Y.
function makeAircraft() {
  const group = new THREE.Group();
  const body = new THREE.Mesh(new THREE.SphereGeometry(0.5, 20, 14),
    new THREE.MeshStandardMaterial({ color: 0xd62728, roughness: 0.6 }));
  body.scale.set(0.7, 0.8, 1.5);
  group.add(body);
  const boom = new THREE.Mesh(new THREE.CylinderGeometry(0.06, 0.09, 1.8, 10),
    new THREE.MeshStandardMaterial({ color: 0x444444 }));
  boom.rotation.x = Math.PI / 2;
  boom.position.set(0, 0.1, 1.5);
  group.add(boom);
  const fin = new THREE.Mesh(new THREE.BoxGeometry(0.04, 0.5, 0.3), new THREE.MeshStandardMaterial({ color: 0x444444 }));
  fin.position.set(0, 0.3, 2.35);
  group.add(fin);
  const rotor = new THREE.Mesh(new THREE.CylinderGeometry(1.5, 1.5, 0.02, 40),
    new THREE.MeshStandardMaterial({ color: 0x1f77b4, transparent: true, opacity: 0.35 }));
  rotor.position.set(0, 0.65, 0);
  group.add(rotor);
  const mast = new THREE.Mesh(new THREE.CylinderGeometry(0.04, 0.04, 0.3, 8), new THREE.MeshStandardMaterial({ color: 0x444444 }));
  mast.position.set(0, 0.5, 0);
  group.add(mast);
  const nose = new THREE.Mesh(new THREE.ConeGeometry(0.15, 0.4, 12), new THREE.MeshStandardMaterial({ color: 0xffcc00 }));
  nose.rotation.x = -Math.PI / 2;
  nose.position.set(0, 0, -0.85);
  group.add(nose);
  const dark = new THREE.MeshStandardMaterial({ color: 0x333333 });
  for (const side of [-1, 1]) {
    const skid = new THREE.Mesh(new THREE.CylinderGeometry(0.03, 0.03, 1.5, 8), dark);
    skid.rotation.x = Math.PI / 2;
    skid.position.set(0.38 * side, -0.62, 0);
    group.add(skid);
    for (const z of [-0.35, 0.35]) {
      const strut = new THREE.Mesh(new THREE.CylinderGeometry(0.02, 0.02, 0.3, 6), dark);
      strut.position.set(0.3 * side, -0.48, z);
      strut.rotation.z = 0.4 * side;
      group.add(strut);
    }
  }
  return group;
}

function pathLine(points, color, dashed) {
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  const material = dashed ? new THREE.LineDashedMaterial({ color, dashSize: 0.6, gapSize: 0.4 })
    : new THREE.LineBasicMaterial({ color });
  const line = new THREE.Line(geometry, material);
  if (dashed) line.computeLineDistances();
  return line;
}

function webglAvailable() {
  try {
    const canvas = document.createElement('canvas');
    return !!(canvas.getContext('webgl2') || canvas.getContext('webgl'));
  } catch (e) {
    return false;
  }
}

function drawReplay(div, spec) {
  const flights = spec.flights;
  const state = { flight: 0, index: 0, time: 0, playing: false, speed: 1, last: null };
  div.classList.add('replay');
  const view = document.createElement('div');
  view.className = 'replay-view';
  const controls = document.createElement('div');
  controls.className = 'replay-controls';
  controls.innerHTML = `<button type="button" class="replay-play">Play</button>
    <input type="range" class="replay-slider" min="0" value="0" step="1" aria-label="time">
    <span class="replay-time">t = 0.00 s</span>
    <label>flight <select class="replay-flight"></select></label>
    <label>speed <select class="replay-speed"><option>0.5</option><option selected>1</option><option>2</option>
    <option>4</option><option>8</option></select></label>
    <label>aircraft <select class="replay-scale"><option value="1">true size</option><option value="0.5">1/2 size</option>
    <option value="0.25">1/4 size</option></select></label>`;
  div.append(view, controls);
  const play = controls.querySelector('.replay-play');
  const slider = controls.querySelector('.replay-slider');
  const timeLabel = controls.querySelector('.replay-time');
  const flightSelect = controls.querySelector('.replay-flight');
  const speedSelect = controls.querySelector('.replay-speed');
  const scaleSelect = controls.querySelector('.replay-scale');
  flights.forEach((f, i) => flightSelect.add(new Option(f.name, String(i))));

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f6fa);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(20, 40, 10);
  scene.add(sun);

  const all = [];
  const lines = flights.map((f, i) => {
    const points = f.t.map((_, k) => nedToThree(f.x[k], f.y[k], f.z[k]));
    all.push(...points);
    const line = pathLine(points, new THREE.Color(PALETTE[i % PALETTE.length]), false);
    line.material.transparent = true;
    scene.add(line);
    return line;
  });
  if (spec.ideal) {
    const p = spec.ideal;
    const points = p.t.map((_, k) => nedToThree(p.x[k], p.y[k], p.z[k]));
    all.push(...points);
    scene.add(pathLine(points, new THREE.Color(0x000000), true));
  }
  const box = new THREE.Box3().setFromPoints(all.length ? all : [new THREE.Vector3()]);
  const center = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 5);
  const ground = new THREE.GridHelper(Math.ceil(size * 1.5), 20, 0x99a3b3, 0xccd3de);
  ground.position.set(center.x, Math.min(0, box.min.y - 1), center.z);
  scene.add(ground);
  scene.add(new THREE.AxesHelper(2));

  const aircraft = makeAircraft();
  scene.add(aircraft);
  // Hover flights stay within a metre or two: there the 3.6 m aircraft would hide them, so it starts smaller.
  const extent = box.getSize(new THREE.Vector3()).length();
  scaleSelect.value = extent < 6 ? '0.25' : extent < 15 ? '0.5' : '1';
  aircraft.scale.setScalar(Number(scaleSelect.value));

  const camera = new THREE.PerspectiveCamera(50, 16 / 9, 0.1, size * 20);
  camera.position.set(center.x + size * 0.45, center.y + size * 0.3, center.z + size * 0.6);
  camera.lookAt(center);

  let renderer = null;
  let orbit = null;
  if (webglAvailable()) {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    view.appendChild(renderer.domElement);
    orbit = new OrbitControls(camera, renderer.domElement);
    orbit.target.copy(center);
    orbit.update();
    orbit.addEventListener('change', () => render());
  } else {
    view.textContent = 'The 3-D replay needs WebGL, which this browser does not offer.';
    console.warn('pegasus report: no WebGL; the 3-D replay is not drawn');
  }

  function resize() {
    if (!renderer) return;
    const width = view.clientWidth || 800;
    const height = Math.round(width * 9 / 16);
    renderer.setSize(width, height, false);
    renderer.domElement.style.width = '100%';
    renderer.domElement.style.height = 'auto';
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
  }
  function render() { if (renderer) renderer.render(scene, camera); }

  function place() {
    const f = flights[state.flight];
    const k = Math.min(state.index, f.t.length - 1);
    aircraft.position.copy(nedToThree(f.x[k], f.y[k], f.z[k]));
    aircraft.quaternion.copy(attitudeQuaternion(f.roll[k], f.pitch[k], f.yaw[k]));
    slider.value = String(k);
    timeLabel.textContent = `t = ${f.t[k].toFixed(2)} s`;
    render();
  }
  function selectFlight(i) {
    state.flight = i;
    // The followed flight stands out; the others stay faint for comparison.
    lines.forEach((line, k) => { line.material.opacity = k === i ? 1 : 0.18; });
    slider.max = String(flights[i].t.length - 1);
    state.index = Math.min(state.index, flights[i].t.length - 1);
    place();
  }
  function tick(now) {
    if (!state.playing) return;
    const f = flights[state.flight];
    if (state.last !== null) {
      state.time += ((now - state.last) / 1000) * state.speed;
      let k = state.index;
      while (k + 1 < f.t.length && f.t[k + 1] <= state.time) k++;
      state.index = k;
      if (k + 1 >= f.t.length) setPlaying(false);
    }
    state.last = now;
    place();
    if (state.playing) requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    state.playing = on;
    play.textContent = on ? 'Pause' : 'Play';
    if (on) {
      const f = flights[state.flight];
      if (state.index + 1 >= f.t.length) state.index = 0;
      state.time = f.t[state.index];
      state.last = null;
      requestAnimationFrame(tick);
    }
  }
  play.addEventListener('click', () => setPlaying(!state.playing));
  slider.addEventListener('input', () => { state.index = Number(slider.value); place(); });
  flightSelect.addEventListener('change', () => selectFlight(Number(flightSelect.value)));
  speedSelect.addEventListener('change', () => { state.speed = Number(speedSelect.value); });
  scaleSelect.addEventListener('change', () => { aircraft.scale.setScalar(Number(scaleSelect.value)); render(); });
  window.addEventListener('resize', () => { resize(); render(); });
  resize();
  selectFlight(0);

  return {
    // NED position of the aircraft as drawn (for tests): [x, y, z].
    aircraftPosition() { const p = aircraft.position; return [-p.z, p.x, -p.y]; },
    get playing() { return state.playing; },
    get index() { return state.index; },
    webgl: !!renderer,
    canvas: renderer ? renderer.domElement : null,
  };
}

// --- MuJoCo 3-D replay --------------------------------------------------------------------------------
// replay.json of `pegasus mujoco train/rollout`: per geom its MuJoCo type, size and colour; per control step
// every geom's world position and orientation (quaternion w, x, y, z) in MuJoCo's z-up world. The geoms
// live in a group turned -90 degrees about x, which maps MuJoCo's z-up frame onto three's y-up one, so
// positions and quaternions are used as they are. Capsules and cylinders lie along their local z in MuJoCo
// and along y in three, hence the rotation of their geometry.
function mujocoGeomMesh(geom, extent) {
  const [a, b, c] = geom.size;
  let geometry = null;
  switch (geom.type) {
    case 'box': geometry = new THREE.BoxGeometry(2 * a, 2 * b, 2 * c); break;
    case 'sphere': geometry = new THREE.SphereGeometry(a, 20, 14); break;
    case 'ellipsoid': geometry = new THREE.SphereGeometry(1, 20, 14).scale(a, b, c); break;
    case 'capsule': geometry = new THREE.CapsuleGeometry(a, 2 * b, 8, 16).rotateX(Math.PI / 2); break;
    case 'cylinder': geometry = new THREE.CylinderGeometry(a, a, 2 * b, 20).rotateX(Math.PI / 2); break;
    case 'plane': {
      // MuJoCo's size of 0 means an infinite plane: draw it large enough for the motion.
      const w = a > 0 ? 2 * a : 4 * extent, h = b > 0 ? 2 * b : 4 * extent;
      geometry = new THREE.PlaneGeometry(w, h);
      break;
    }
    default: return null;  // meshes and height fields are not drawn
  }
  const [r, g, bl, alpha] = geom.rgba;
  const material = new THREE.MeshStandardMaterial({
    color: new THREE.Color(r, g, bl), roughness: 0.6, transparent: alpha < 1, opacity: alpha,
    side: geom.type === 'plane' ? THREE.DoubleSide : THREE.FrontSide,
  });
  return new THREE.Mesh(geometry, material);
}

function drawMujocoReplay(div, spec) {
  const { geoms, t, frames } = spec;
  const state = { index: 0, time: 0, playing: false, speed: 1, last: null };
  div.classList.add('replay');
  const view = document.createElement('div');
  view.className = 'replay-view';
  const controls = document.createElement('div');
  controls.className = 'replay-controls';
  controls.innerHTML = `<button type="button" class="replay-play">Play</button>
    <input type="range" class="replay-slider" min="0" value="0" step="1" aria-label="time">
    <span class="replay-time">t = 0.00 s</span>
    <label>speed <select class="replay-speed"><option>0.25</option><option>0.5</option><option selected>1</option>
    <option>2</option></select></label>`;
  div.append(view, controls);
  const play = controls.querySelector('.replay-play');
  const slider = controls.querySelector('.replay-slider');
  const timeLabel = controls.querySelector('.replay-time');
  const speedSelect = controls.querySelector('.replay-speed');

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f6fa);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(5, 10, 8);
  scene.add(sun);
  const world = new THREE.Group();
  world.rotation.x = -Math.PI / 2;
  scene.add(world);

  // The extent of the motion (MuJoCo frame), from the positions of every geom that is not a plane.
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  frames.forEach((f) => geoms.forEach((g, j) => {
    if (g.type === 'plane') return;
    for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], f[7 * j + k]); hi[k] = Math.max(hi[k], f[7 * j + k]); }
  }));
  if (!Number.isFinite(lo[0])) { lo.fill(-1); hi.fill(1); }
  const extent = Math.max(Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), 2);
  const meshes = geoms.map((g) => {
    const mesh = mujocoGeomMesh(g, extent);
    if (mesh) world.add(mesh);
    return mesh;
  });

  const toThree = (x, y, z) => new THREE.Vector3(x, z, -y);
  const center = toThree((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const camera = new THREE.PerspectiveCamera(50, 16 / 9, 0.01, extent * 50);
  // Planar models move in MuJoCo's x-z plane: look at it from the side (-y in MuJoCo, +z in three).
  camera.position.set(center.x + extent * 0.15, center.y + extent * 0.25, center.z + extent * 1.3);
  camera.lookAt(center);

  let renderer = null;
  if (webglAvailable()) {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    view.appendChild(renderer.domElement);
    const orbit = new OrbitControls(camera, renderer.domElement);
    orbit.target.copy(center);
    orbit.update();
    orbit.addEventListener('change', () => render());
  } else {
    view.textContent = 'The 3-D replay needs WebGL, which this browser does not offer.';
    console.warn('pegasus report: no WebGL; the 3-D replay is not drawn');
  }
  function resize() {
    if (!renderer) return;
    const width = view.clientWidth || 800;
    const height = Math.round(width * 9 / 16);
    renderer.setSize(width, height, false);
    renderer.domElement.style.width = '100%';
    renderer.domElement.style.height = 'auto';
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
  }
  function render() { if (renderer) renderer.render(scene, camera); }
  function place() {
    const k = Math.min(state.index, frames.length - 1);
    const f = frames[k];
    meshes.forEach((mesh, j) => {
      if (!mesh) return;
      mesh.position.set(f[7 * j], f[7 * j + 1], f[7 * j + 2]);
      mesh.quaternion.set(f[7 * j + 4], f[7 * j + 5], f[7 * j + 6], f[7 * j + 3]);  // three: (x, y, z, w)
    });
    slider.value = String(k);
    timeLabel.textContent = `t = ${t[k].toFixed(2)} s`;
    render();
  }
  function tick(now) {
    if (!state.playing) return;
    if (state.last !== null) {
      state.time += ((now - state.last) / 1000) * state.speed;
      let k = state.index;
      while (k + 1 < t.length && t[k + 1] <= state.time) k++;
      state.index = k;
      if (k + 1 >= t.length) setPlaying(false);
    }
    state.last = now;
    place();
    if (state.playing) requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    state.playing = on;
    play.textContent = on ? 'Pause' : 'Play';
    if (on) {
      if (state.index + 1 >= t.length) state.index = 0;
      state.time = t[state.index];
      state.last = null;
      requestAnimationFrame(tick);
    }
  }
  play.addEventListener('click', () => setPlaying(!state.playing));
  slider.addEventListener('input', () => { state.index = Number(slider.value); place(); });
  speedSelect.addEventListener('change', () => { state.speed = Number(speedSelect.value); });
  window.addEventListener('resize', () => { resize(); render(); });
  slider.max = String(Math.max(frames.length - 1, 0));
  resize();
  place();

  return {
    // MuJoCo world positions of the drawn geoms, one after another (for tests): [x0, y0, z0, x1, ...].
    positions() { return meshes.filter((m) => m).flatMap((m) => [m.position.x, m.position.y, m.position.z]); },
    get playing() { return state.playing; },
    get index() { return state.index; },
    webgl: !!renderer,
    canvas: renderer ? renderer.domElement : null,
  };
}

const drawers = { xy: drawXY, box: drawBox, bar: drawBar };

async function main() {
  const block = document.getElementById('pegasus-data');
  const text = block.dataset.encoding === 'gzip+base64' ? await window.pegasusInflate(block.textContent.trim())
    : block.textContent;
  const data = JSON.parse(text);
  const report = { data, charts: {}, replays: [], ready: false, errors: [] };
  window.pegasusReport = report;
  for (const spec of data.charts) {
    const div = document.getElementById(spec.id);
    if (!div) continue;
    try {
      if (spec.kind === 'replay') {
        report.replays.push(drawReplay(div, spec));
      } else if (spec.kind === 'mujoco_replay') {
        report.replays.push(drawMujocoReplay(div, spec));
      } else {
        await drawers[spec.kind](div, spec);
      }
      report.charts[spec.id] = spec.kind;
    } catch (e) {
      report.errors.push(`${spec.id}: ${e.message}`);
      div.textContent = `This chart could not be drawn: ${e.message}`;
      console.error(e);
    }
  }
  report.ready = true;
  document.body.dataset.ready = 'true';
}

main();
