// The run embedded in the page (tmem.viewer.page.page_data): typed arrays decoded from base64,
// and the frame shown at a time.

function bytes(base64) {
  const text = atob(base64);
  const out = new Uint8Array(text.length);
  for (let k = 0; k < text.length; k++) out[k] = text.charCodeAt(k);
  return out;
}

const f32 = (base64) => new Float32Array(bytes(base64).buffer);

// Positions and speeds are stored as 16-bit steps above a low value (per axis for positions).
function dequantised(stored, low, step, width) {
  const q = new Uint16Array(bytes(stored).buffer);
  const out = new Float32Array(q.length);
  for (let k = 0; k < q.length; k++) out[k] = low[k % width] + q[k] * step[k % width];
  return out;
}

export function decode(text) {
  const d = JSON.parse(text);
  const D = d.axes.length;
  return {
    ...d,
    F: d.frames,
    A: d.agents.length,
    D,
    E: d.edges.length / 2,
    S: d.pairLabels.length,
    time: new Float64Array(bytes(d.time).buffer),
    position: dequantised(d.position.data, d.position.low, d.position.step, D),
    speed: dequantised(d.speed.data, [0], [d.speed.step], 1),
    status: bytes(d.status),
    strain: f32(d.strain),
    coupled: bytes(d.coupled),
    drawn: bytes(d.drawn),
    rms: f32(d.rms),
    pairDistance: f32(d.pairDistance),
  };
}

// Agent states, as tmem.viewer.data codes them.
export const WAITING = 0, FLYING = 1, REMOVED = 2;

// The last frame recorded at or before time t (the first frame before the run's start).
export function frameAt(run, t) {
  let lo = 0, hi = run.F - 1;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (run.time[mid] <= t) lo = mid; else hi = mid - 1;
  }
  return lo;
}
