// The page: the run's title and figures, the view, the linked panels and the player (time slider,
// play/pause, speed, toggles). window.tmemViewer exposes what is shown, for scripts and tests.
import { decode, frameAt, FLYING, REMOVED } from 'tmem/run';
import { Charts } from 'tmem/charts';
import { WebGLRenderer } from 'three';
import { COLOURS, Scene } from 'tmem/scene';
import { niceStep } from 'tmem/axes';

const $ = (id) => document.getElementById(id);
const timing = { scripts: performance.now() }; // ms from the start of navigation
const run = decode($('tmem-run').textContent);
// Playback speeds, in simulated seconds per second.
const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10, 20, 50, 100];

function fillHeader() {
  $('title').textContent = run.name ? `${run.name}: ${run.D}-D run` : `${run.D}-D run`;
  for (const [label, value] of run.headline) {
    const dt = document.createElement('dt');
    const dd = document.createElement('dd');
    dt.textContent = label;
    dd.textContent = value;
    $('headline').append(dt, dd);
  }
  $('caveat').textContent = run.caveat;
  $('caveat').hidden = !run.caveat;
  $('note').textContent = run.note;
  $('note').hidden = !run.note;
  $('sphere-label').textContent = `interaction ${run.D === 3 ? 'spheres' : 'circles'} (R = ${run.radius} m)`;
}

function fillLegend() {
  const pct = (s) => `${(100 * s).toPrecision(2)} %`;
  const gradient = `linear-gradient(to right, ${COLOURS.closer}, ${COLOURS.atSet}, ${COLOURS.farther})`;
  $('legend-agent').style.background = COLOURS.agent;
  $('legend-removed').style.color = COLOURS.removed;
  $('legend-removed').parentElement.hidden = !run.status.includes(REMOVED);
  $('legend-obstacle').hidden = !run.space.obstacles.length;
  Object.assign($('legend-obstacle').firstElementChild.style, { background: COLOURS.obstacle, opacity: 0.35 });
  $('legend-route').hidden = !run.route;
  $('legend-route').firstElementChild.style.background = COLOURS.route;
  $('legend-goal').hidden = !run.route?.goal;
  $('legend-goal').firstElementChild.style.borderColor = COLOURS.goal;
  $('legend-strain').hidden = run.E === 0;
  $('strain-bar').style.background = gradient;
  $('strain-low').textContent = `−${pct(run.strainScale)}`;
  $('strain-high').textContent = `+${pct(run.strainScale)}`;
}

function makeScene() {
  let renderer;
  try {
    renderer = new WebGLRenderer({ antialias: true });
  } catch (error) {
    $('no-webgl').hidden = false;
    $('no-webgl').textContent = `The view needs WebGL, which this browser could not start (${error.message}). The panels still work.`;
    return null;
  }
  return new Scene(renderer, $('view'), $('labels'), run);
}

function describe(a, f) {
  const { A, D, position, speed, status, axes, agents } = run;
  const where = axes.map((name, d) => `${name} ${position[(f * A + a) * D + d].toFixed(1)}`).join(', ');
  const state = status[f * A + a] === REMOVED ? 'removed' : `${speed[f * A + a].toFixed(2)} m/s`;
  return `agent ${agents[a]} · ${where} m · ${state}`;
}

class Player {
  constructor(scene, charts) {
    Object.assign(this, { scene, charts, frame: 0, playing: false, t: run.time[0] });
    const slider = $('time');
    slider.max = run.F - 1;
    slider.addEventListener('input', () => this.show(Number(slider.value)));
    $('play').addEventListener('click', () => this.toggle());
    const duration = run.time[run.F - 1] - run.time[0];
    this.speed = SPEEDS.find((s) => s >= duration / 20) ?? SPEEDS[SPEEDS.length - 1];
    for (const s of SPEEDS) $('speed').add(new Option(`${s}×`, s, false, s === this.speed));
    $('speed').addEventListener('change', () => { this.speed = Number($('speed').value); });
    document.addEventListener('keydown', (e) => {
      if (e.key === ' ' && e.target.tagName !== 'BUTTON' && e.target.tagName !== 'SELECT') { e.preventDefault(); this.toggle(); }
    });
  }

  show(f) {
    this.frame = f;
    this.t = run.time[f];
    $('time').value = f;
    $('clock').textContent = `t = ${this.t.toFixed(2)} s`;
    this.scene?.setFrame(f);
    this.charts.setTime(this.t);
  }

  seek(t) {
    this.t = t;
    this.show(frameAt(run, t));
  }

  toggle() {
    this.playing = !this.playing;
    $('play').textContent = this.playing ? '❚❚ pause' : '▶ play';
    if (!this.playing) return;
    if (this.frame === run.F - 1) this.seek(run.time[0]);
    let last = performance.now();
    const step = (now) => {
      if (!this.playing) return;
      const t = this.t + ((now - last) / 1000) * this.speed;
      last = now;
      if (t >= run.time[run.F - 1]) { this.show(run.F - 1); this.toggle(); return; }
      const f = frameAt(run, t);
      if (f !== this.frame) this.show(f);
      this.t = t;
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }
}

function wireToggles(scene) {
  const toggles = { 'show-spheres': 'setSpheres', 'show-edges': 'setEdges', 'show-labels': 'setLabels', follow: 'setFollow' };
  for (const [id, method] of Object.entries(toggles)) {
    $(id).disabled = !scene;
    $(id).addEventListener('change', () => scene?.[method]($(id).checked));
  }
  $('show-edges').closest('label').hidden = run.E === 0;
  $('show-labels').closest('label').hidden = !scene?.labels.length;
}

function wirePointer(scene, player) {
  const tip = $('tooltip');
  scene.renderer.domElement.addEventListener('pointermove', (e) => {
    const a = scene.pick(e.offsetX, e.offsetY);
    tip.hidden = a < 0;
    if (a < 0) return;
    tip.textContent = describe(a, player.frame);
    tip.style.transform = `translate(${e.offsetX + 14}px, ${e.offsetY + 10}px)`;
  });
  scene.renderer.domElement.addEventListener('pointerleave', () => { tip.hidden = true; });
}

function scaleBar(scene) {
  if (run.D === 3) return;
  const metres = niceStep(100 * scene.metresPerPixel());
  $('scale').hidden = false;
  $('scale').style.width = `${metres / scene.metresPerPixel()}px`;
  $('scale').firstElementChild.textContent = `${metres} m`;
}

const scene = makeScene();
timing.view = performance.now();
fillHeader();
fillLegend();
const charts = new Charts($('chart-rms'), $('chart-pairs'), run, (t) => player.seek(t));
timing.panels = performance.now();
const player = new Player(scene, charts);
wireToggles(scene);
if (scene) {
  wirePointer(scene, player);
  scene.onRender = () => scaleBar(scene);
}
new ResizeObserver(() => charts.resize()).observe($('charts'));
player.show(0);

window.tmemViewer = {
  run,
  player,
  webgl: Boolean(scene),
  // Each agent drawn at the frame shown: its number, state and world position (what the view holds).
  drawn() {
    if (!scene) return [];
    return Array.from(scene.shown.subarray(0, scene.shownCount), (a) => {
      const p = scene.at(player.frame, a);
      return { agent: run.agents[a], flying: run.status[player.frame * run.A + a] === FLYING, position: [p.x, p.y, p.z].slice(0, run.D) };
    });
  },
  // Screen positions (px in the view) of the agents drawn.
  screen() { return scene ? Array.from(scene.shown.subarray(0, scene.shownCount), (a) => scene.screen(a).slice(0, 2)) : []; },
  // The axes' text drawn over the view: {axis, value (null for a name), text, x, y} (px in the view).
  axes() { return scene ? scene.axisTexts.map((t) => ({ ...t })) : []; },
  spheresShown() { return Boolean(scene?.spheres.visible && scene.spheres.count); },
  // Screen position (px in the view) of a world point, given by its coordinates (one per axis).
  project(values) { return scene ? scene.project(values) : null; },
  cursors() { return charts.cursorPositions(); },
  timing,
  readyMs: performance.now(),
};
document.body.dataset.ready = 'true';
