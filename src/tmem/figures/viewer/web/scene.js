// The swarm drawn with three.js: agents, interaction spheres (circles in 1-D and 2-D) of radius R,
// formation edges coloured by strain, removed agents, the box and obstacles, a mission's route and
// goal; orbit (3-D) or pan (1-D, 2-D) and zoom; agent numbers and the agent under the pointer; the
// axes: in 1-D and 2-D a grid with its values along the edges of the view, in 3-D each axis named
// along the frame.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls';
import { edgeQuads, STRAIN_COLOURS, strainColour } from 'tmem/edges';
import { FLYING, REMOVED, WAITING } from 'tmem/run';
import { ROUTE_COLOURS, routeObjects, routePoints } from 'tmem/route';
import { axisTexts, gridArea, gridPoints, placeTexts, visibleArea } from 'tmem/axes';

export const COLOURS = {
  agent: '#1f77b4', removed: '#7f7f7f', sphere: '#1f77b4', frame: '#b8b8b8', box: '#555555', obstacle: '#999999',
  ...ROUTE_COLOURS,
  ...STRAIN_COLOURS,
};
// Most agents labelled with their numbers.
const MAX_LABELS = 60;
// How near the pointer (px) an agent must be to be named.
const PICK_PX = 12;

function sprite(draw) {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = 64;
  const g = canvas.getContext('2d');
  g.strokeStyle = g.fillStyle = '#ffffff';
  draw(g);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  return texture;
}

const DOT = () => sprite((g) => { g.beginPath(); g.arc(32, 32, 28, 0, 2 * Math.PI); g.fill(); });
const RING = () => sprite((g) => {
  g.lineWidth = 10;
  g.beginPath(); g.arc(32, 32, 25, 0, 2 * Math.PI); g.stroke();
  g.beginPath(); g.arc(32, 32, 8, 0, 2 * Math.PI); g.fill();
});
const CROSS = () => sprite((g) => {
  g.lineWidth = 12;
  g.beginPath(); g.moveTo(10, 10); g.lineTo(54, 54); g.moveTo(54, 10); g.lineTo(10, 54); g.stroke();
});

function points(count, size, texture, colour) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * count), 3));
  const material = new THREE.PointsMaterial({ size, sizeAttenuation: false, map: texture, alphaTest: 0.5, color: colour });
  return new THREE.Points(geometry, material);
}

function lines(vertices, colour) {
  const geometry = new THREE.BufferGeometry().setFromPoints(vertices);
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: colour }));
}

export class Scene {
  constructor(renderer, container, labels, run) {
    this.run = run;
    this.container = container;
    this.labelsLayer = labels;
    this.renderer = renderer;
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.prepend(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color('#ffffff');
    this.frame = 0;
    this.shownCount = 0;
    this.follow = false;
    this.labels = [];
    this.axesLayer = document.createElement('div');
    this.axesLayer.id = 'axes';
    container.append(this.axesLayer);
    this.bounds = this.#bounds();
    this.#camera();
    this.#drawStatic();
    this.#drawMoving();
    this.#makeLabels();
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  // World coordinates of agent column a at frame f (1-D and 2-D on the plane z = 0).
  at(f, a, out = new THREE.Vector3()) {
    const { D, A, position } = this.run;
    const k = (f * A + a) * D;
    return out.set(position[k], D > 1 ? position[k + 1] : 0, D > 2 ? position[k + 2] : 0);
  }

  #bounds() {
    const { F, A, status, radius, space } = this.run;
    const box = new THREE.Box3();
    const p = new THREE.Vector3();
    for (let f = 0; f < F; f++) for (let a = 0; a < A; a++) if (status[f * A + a] !== WAITING) box.expandByPoint(this.at(f, a, p));
    if (space.box) box.expandByPoint(new THREE.Vector3()).expandByPoint(this.#point(space.box));
    for (const o of space.obstacles) box.expandByPoint(this.#point(o.center));
    for (const p of routePoints(this.run.route)) box.expandByPoint(this.#point(p));
    if (box.isEmpty()) box.expandByPoint(new THREE.Vector3());
    return box.expandByScalar(radius);
  }

  #point(values) {
    return new THREE.Vector3(values[0], values[1] ?? 0, values[2] ?? 0);
  }

  #camera() {
    const centre = this.bounds.getCenter(new THREE.Vector3());
    const size = this.bounds.getSize(new THREE.Vector3());
    if (this.run.D === 3) {
      this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1);
      this.camera.up.set(0, 0, 1);
      const distance = size.length() / 2 / Math.sin(THREE.MathUtils.degToRad(20));
      this.camera.position.copy(centre).add(new THREE.Vector3(0.55, -0.75, 0.4).normalize().multiplyScalar(distance));
      this.camera.near = distance / 1000;
      this.camera.far = distance * 10;
    } else {
      this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 1e7);
      this.camera.position.set(centre.x, centre.y, 1e6);
    }
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.copy(centre);
    if (this.run.D < 3) {
      this.controls.enableRotate = false;
      this.controls.mouseButtons.LEFT = THREE.MOUSE.PAN;
      this.controls.touches.ONE = THREE.TOUCH.PAN;
    }
    this.controls.addEventListener('change', () => this.render());
    this.controls.update();
  }

  #drawStatic() {
    const { D, space, radius } = this.run;
    const b = this.bounds;
    if (D === 3) {
      this.scene.add(new THREE.Box3Helper(b, COLOURS.frame));
      this.scene.add(new THREE.AmbientLight('#ffffff', 1.6));
      const light = new THREE.DirectionalLight('#ffffff', 1.6);
      light.position.set(1, -1, 2);
      this.scene.add(light);
    }
    if (space.box) {
      const box = new THREE.Box3(new THREE.Vector3(), this.#point(space.box));
      if (D === 3) this.scene.add(new THREE.Box3Helper(box, COLOURS.box));
      else this.scene.add(lines(this.#rectangle(box), COLOURS.box));
    }
    for (const o of space.obstacles) {
      const geometry = D === 3 ? new THREE.SphereGeometry(o.radius, 32, 16) : new THREE.CircleGeometry(o.radius, 64);
      const mesh = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ color: COLOURS.obstacle, transparent: true, opacity: 0.35 }));
      mesh.position.copy(this.#point(o.center));
      this.scene.add(mesh);
    }
    this.sphereGeometry = D === 3 ? new THREE.SphereGeometry(radius, 24, 16) : new THREE.CircleGeometry(radius, 64);
    if (this.run.route) this.#drawRoute(this.run.route);
  }

  // The route: in 1-D and 2-D below the agents and their edges.
  #drawRoute(route) {
    const at = (values) => this.#point(values).setZ(this.run.D === 3 ? values[2] : -0.3);
    const marks = (count, size, ring, colour) => points(count, size, ring ? RING() : DOT(), colour);
    const objects = routeObjects(route, at, marks);
    this.routeLines = objects[0];
    this.scene.add(...objects);
  }

  #rectangle(box) {
    const [a, b] = [box.min, box.max];
    const c = [[a.x, a.y], [b.x, a.y], [b.x, b.y], [a.x, b.y]].map(([x, y]) => new THREE.Vector3(x, y, -0.5));
    return [c[0], c[1], c[1], c[2], c[2], c[3], c[3], c[0]];
  }

  #drawMoving() {
    const { A, E, D } = this.run;
    const size = A <= 100 ? 11 : A <= 1000 ? 6 : 4;
    this.agents = points(A, size, DOT(), COLOURS.agent);
    this.agents.renderOrder = 3;
    this.removed = points(A, size + 2, CROSS(), COLOURS.removed);
    this.coupledEdges = edgeQuads(E, 1);
    this.looseEdges = edgeQuads(E, 0.35);
    const material = D === 3
      ? new THREE.MeshLambertMaterial({ color: COLOURS.sphere, transparent: true, opacity: 0.12, depthWrite: false })
      : new THREE.MeshBasicMaterial({ color: COLOURS.sphere, transparent: true, opacity: 0.1, depthWrite: false });
    this.spheres = new THREE.InstancedMesh(this.sphereGeometry, material, A);
    this.spheres.visible = false;
    this.spheres.frustumCulled = this.agents.frustumCulled = this.removed.frustumCulled = false;
    this.scene.add(this.spheres, this.looseEdges, this.coupledEdges, this.removed, this.agents);
    this.shown = new Int32Array(A); // the agent column of each drawn point, flying then removed
  }

  #makeLabels() {
    this.labels = [];
    if (this.run.A > MAX_LABELS) return;
    for (const number of this.run.agents) {
      const div = document.createElement('div');
      div.className = 'agent-label';
      div.textContent = number;
      this.labelsLayer.append(div);
      this.labels.push(div);
    }
  }

  setFrame(f) {
    const { A, status } = this.run;
    const p = new THREE.Vector3();
    const flying = this.agents.geometry.attributes.position;
    const removed = this.removed.geometry.attributes.position;
    const matrix = new THREE.Matrix4();
    let n = 0, r = 0;
    const centre = new THREE.Vector3();
    for (let a = 0; a < A; a++) {
      const state = status[f * A + a];
      if (state === WAITING) continue;
      this.at(f, a, p);
      if (state === FLYING) {
        flying.setXYZ(n, p.x, p.y, p.z);
        this.spheres.setMatrixAt(n, matrix.makeTranslation(p.x, p.y, this.run.D === 3 ? p.z : -0.2));
        centre.add(p);
        this.shown[n++] = a;
      } else if (state === REMOVED) {
        removed.setXYZ(r++, p.x, p.y, p.z);
      }
    }
    this.#shownRemoved(f, n);
    this.agents.geometry.setDrawRange(0, n);
    this.removed.geometry.setDrawRange(0, r);
    flying.needsUpdate = removed.needsUpdate = true;
    this.spheres.count = n;
    this.spheres.instanceMatrix.needsUpdate = true;
    this.#edges(f);
    if (this.follow && n > 0) this.#followTo(centre.divideScalar(n));
    this.frame = f;
    this.render();
  }

  // Columns of the removed agents, after the flying ones, for picking and labels.
  #shownRemoved(f, n) {
    const { A, status } = this.run;
    let k = n;
    for (let a = 0; a < A; a++) if (status[f * A + a] === REMOVED) this.shown[k++] = a;
    this.shownCount = k;
  }

  #edges(f) {
    const { A, E, edges, status, strain, coupled, drawn, strainScale, space } = this.run;
    const objects = [this.coupledEdges, this.looseEdges];
    const counts = [0, 0];
    const p = new THREE.Vector3(), q = new THREE.Vector3(), colour = new THREE.Color();
    const half = space.periodic ? this.#point(space.box).multiplyScalar(0.5) : null;
    const below = this.run.D === 3 ? 0 : 0.1; // in the plane, edges under the agents
    for (let e = 0; e < E; e++) {
      const [i, j] = [edges[2 * e], edges[2 * e + 1]];
      if (status[f * A + i] !== FLYING || status[f * A + j] !== FLYING || !drawn[f * E + e]) continue;
      this.at(f, i, p);
      this.at(f, j, q);
      if (half && (Math.abs(p.x - q.x) > half.x || Math.abs(p.y - q.y) > half.y || Math.abs(p.z - q.z) > half.z)) continue;
      const which = coupled[f * E + e] ? 0 : 1;
      const k = counts[which]++;
      const { instanceStart, instanceEnd, instanceColour } = objects[which].geometry.attributes;
      instanceStart.setXYZ(k, p.x, p.y, p.z - below);
      instanceEnd.setXYZ(k, q.x, q.y, q.z - below);
      const c = strainColour(strain[f * E + e], strainScale, colour);
      instanceColour.setXYZ(k, c.r, c.g, c.b);
    }
    objects.forEach((o, w) => {
      o.geometry.instanceCount = counts[w];
      for (const name of ['instanceStart', 'instanceEnd', 'instanceColour']) o.geometry.attributes[name].needsUpdate = true;
    });
  }

  #followTo(centre) {
    if (this.lastCentre) {
      const delta = centre.clone().sub(this.lastCentre);
      this.camera.position.add(delta);
      this.controls.target.add(delta);
      this.controls.update();
    }
    this.lastCentre = centre.clone();
  }

  setFollow(on) {
    this.follow = on;
    this.lastCentre = null;
    if (on) this.setFrame(this.frame);
  }

  setSpheres(on) { this.spheres.visible = on; this.render(); }

  setEdges(on) { this.coupledEdges.visible = this.looseEdges.visible = on; this.render(); }

  setLabels(on) { this.labelsLayer.hidden = !on; this.render(); }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (!w || !h) return;
    this.renderer.setSize(w, h);
    const pixels = this.renderer.getDrawingBufferSize(new THREE.Vector2());
    for (const edges of [this.coupledEdges, this.looseEdges, this.routeLines].filter(Boolean)) {
      edges.material.uniforms.resolution.value.copy(pixels);
      edges.material.uniforms.width.value = 2.5 * this.renderer.getPixelRatio();
    }
    if (this.run.D === 3) {
      this.camera.aspect = w / h;
    } else {
      const size = this.bounds.getSize(new THREE.Vector3());
      const half = Math.max(size.y / 2, size.x / 2 / (w / h));
      Object.assign(this.camera, { left: -half * w / h, right: half * w / h, top: half, bottom: -half });
    }
    this.camera.updateProjectionMatrix();
    this.render();
  }

  // Screen position (CSS px in the canvas) of a world point given by its coordinates (one per axis).
  project(values) {
    return this.#onScreen(this.#point(values)).slice(0, 2);
  }

  // Screen position (CSS px in the canvas) of agent column a at the frame shown.
  screen(a, out = new THREE.Vector3()) {
    return this.#onScreen(this.at(this.frame, a, out));
  }

  // The agent column drawn nearest (x, y), within PICK_PX, or -1.
  pick(x, y) {
    let best = -1, bestD = PICK_PX * PICK_PX;
    for (let k = 0; k < this.shownCount; k++) {
      const [sx, sy, sz] = this.screen(this.shown[k]);
      const d = (sx - x) ** 2 + (sy - y) ** 2;
      if (sz < 1 && d < bestD) { best = this.shown[k]; bestD = d; }
    }
    return best;
  }

  render() {
    if (this.run.D < 3) this.#grid();
    this.renderer.render(this.scene, this.camera);
    this.#placeLabels();
    this.#placeAxes();
    this.onRender?.();
  }

  // The world rectangle the orthographic view (1-D, 2-D) shows, and the grid's step for it.
  visible() { return visibleArea(this.camera); }

  // Grid lines at the step of the view shown, over three times its area, drawn again when the step
  // changes or the view leaves that area.
  #grid() {
    const area = gridArea(this.visible(), this.gridArea);
    if (area === this.gridArea) return;
    if (this.gridLines) { this.scene.remove(this.gridLines); this.gridLines.geometry.dispose(); }
    this.gridLines = lines(gridPoints(area), '#eeeeee');
    this.scene.add(this.gridLines);
    this.gridArea = area;
  }

  #placeAxes() {
    const { clientWidth: w, clientHeight: h } = this.container;
    this.axisTexts = axisTexts(this.run, this.bounds, this.visible(), w, h, (p) => this.#onScreen(p));
    placeTexts(this.axesLayer, this.axisTexts);
  }

  // Screen position (CSS px in the canvas) and depth of world point p.
  #onScreen(p) {
    const { clientWidth: w, clientHeight: h } = this.renderer.domElement;
    const q = p.clone().project(this.camera);
    return [(q.x + 1) / 2 * w, (1 - q.y) / 2 * h, q.z];
  }

  #placeLabels() {
    if (!this.labels.length || this.labelsLayer.hidden) return;
    const { A, status } = this.run;
    this.labels.forEach((div, a) => {
      const state = status[this.frame * A + a];
      div.hidden = state === WAITING;
      if (div.hidden) return;
      const [x, y] = this.screen(a);
      div.style.transform = `translate(${x + 6}px, ${y - 18}px)`;
      div.classList.toggle('removed', state === REMOVED);
    });
  }

  // World units per CSS pixel of the orthographic view (1-D, 2-D), for the scale bar.
  metresPerPixel() {
    return (this.camera.right - this.camera.left) / this.camera.zoom / this.renderer.domElement.clientWidth;
  }
}
