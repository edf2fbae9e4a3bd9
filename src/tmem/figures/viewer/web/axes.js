// The axes of the view: in 1-D and 2-D a grid whose step follows the zoom, with its values along the
// bottom (x) and left (y) edges of the view and the axes' names; in 3-D each axis named with its
// range at the middle of one edge of the frame around the run.
import * as THREE from 'three';

// How the axes' texts sit on their point: x values centred on their grid line, y values beside theirs.
const SHIFT = { 'tick x': ' translateX(-50%)', 'tick y': ' translateY(-50%)' };

// A value as the axes write it: `digits` decimals, and 0 rather than -0.
function formatted(value, digits = 0) {
  const text = value.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}

// A step of 1, 2 or 5 times a power of ten near `span`.
export function niceStep(span) {
  const p = 10 ** Math.floor(Math.log10(span));
  return [1, 2, 5, 10].map((m) => m * p).find((s) => s >= span) ?? 10 * p;
}

// The world rectangle an orthographic camera shows, and the grid's step for it (about 8 lines across).
export function visibleArea(camera) {
  const halfW = (camera.right - camera.left) / 2 / camera.zoom, halfH = (camera.top - camera.bottom) / 2 / camera.zoom;
  const area = { x0: camera.position.x - halfW, x1: camera.position.x + halfW, y0: camera.position.y - halfH, y1: camera.position.y + halfH };
  return { ...area, step: niceStep((area.x1 - area.x0) / 8) };
}

// The area the grid covers for the view `v`: `drawn` if it still does (same step, view inside it),
// else three times the view's area at its step.
export function gridArea(v, drawn) {
  if (drawn && drawn.step === v.step && v.x0 >= drawn.x0 && v.x1 <= drawn.x1 && v.y0 >= drawn.y0 && v.y1 <= drawn.y1) return drawn;
  const [w, h] = [v.x1 - v.x0, v.y1 - v.y0];
  return { x0: v.x0 - w, x1: v.x1 + w, y0: v.y0 - h, y1: v.y1 + h, step: v.step };
}

// The ends of the grid's lines over `area`, below the plane of the agents.
export function gridPoints(area) {
  const s = area.step;
  const points = [];
  for (let x = Math.ceil(area.x0 / s) * s; x <= area.x1; x += s) points.push(new THREE.Vector3(x, area.y0, -1), new THREE.Vector3(x, area.y1, -1));
  for (let y = Math.ceil(area.y0 / s) * s; y <= area.y1; y += s) points.push(new THREE.Vector3(area.x0, y, -1), new THREE.Vector3(area.x1, y, -1));
  return points;
}

// The axes' texts {axis, value (null for a name), text, x, y (px in the view), cls}: in 3-D at the
// middle of the frame's edges from its low corner (`onScreen(p)` gives a world point's [x, y, depth]),
// in 1-D and 2-D along the edges of the view `v` of w x h px.
export function axisTexts(run, bounds, v, w, h, onScreen) {
  const texts = [];
  if (run.D === 3) {
    const { min, max } = bounds;
    const p = new THREE.Vector3();
    run.axes.forEach((name, k) => {
      p.copy(min).setComponent(k, (min.getComponent(k) + max.getComponent(k)) / 2);
      const [x, y, z] = onScreen(p);
      const range = `${name}, m: ${formatted(min.getComponent(k))} to ${formatted(max.getComponent(k))}`;
      if (z < 1) texts.push({ axis: name, value: null, text: range, x, y, cls: 'axis-name' });
    });
    return texts;
  }
  const digits = Math.max(0, -Math.floor(Math.log10(v.step)));
  const ticks = (axis, low, high, place) => {
    for (let k = Math.ceil(low / v.step); k * v.step <= high; k++) {
      const value = k * v.step;
      texts.push({ axis, value, text: formatted(value, digits), ...place(value), cls: `tick ${axis}` });
    }
  };
  ticks('x', v.x0, v.x1, (value) => ({ x: (value - v.x0) / (v.x1 - v.x0) * w, y: h - 16 }));
  texts.push({ axis: 'x', value: null, text: 'x, m', x: w - 34, y: h - 32, cls: 'axis-name' });
  if (run.D === 2) {
    ticks('y', v.y0, v.y1, (value) => ({ x: 3, y: (v.y1 - value) / (v.y1 - v.y0) * h }));
    texts.push({ axis: 'y', value: null, text: 'y, m', x: 3, y: 4, cls: 'axis-name' });
  }
  return texts;
}

// Show `texts` in `layer`, one div each, reusing the divs already there and hiding the rest.
export function placeTexts(layer, texts) {
  const pool = layer.children;
  while (pool.length < texts.length) layer.append(document.createElement('div'));
  Array.from(pool).forEach((div, k) => {
    div.hidden = k >= texts.length;
    if (div.hidden) return;
    const t = texts[k];
    div.className = t.cls;
    div.textContent = t.text;
    div.style.transform = `translate(${t.x}px, ${t.y}px)${SHIFT[t.cls] ?? ''}`;
  });
}
