// The linked panels, drawn with uPlot: the RMS velocity and the pair distances against time, each
// with a cursor at the time shown. A click on a panel shows that time; a drag zooms its time axis
// (a double click zooms back out); the line under the pointer is named below the panel.
/* global uPlot */

const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];

function finite(values) {
  return Array.from(values, (v) => (Number.isFinite(v) ? v : null));
}

class Panel {
  constructor(element, { title, unit, time, series, references, onSeek }) {
    this.element = element;
    this.unit = unit;
    const x = Array.from(time);
    const lines = [...series, ...references.map((r) => ({ ...r, values: x.map(() => r.value), dash: [6, 4] }))];
    const readout = document.createElement('div');
    readout.className = 'readout';
    let focused = null;
    const options = {
      title,
      ...this.#size(),
      scales: { x: { time: false } },
      axes: [{ label: 'time, s' }, { label: `${title}, ${unit}` }],
      legend: { show: false },
      cursor: { focus: { prox: 16 }, drag: { x: true, y: false } },
      focus: { alpha: 0.3 },
      series: [{ label: 'time' }, ...lines.map((s) => ({ label: s.label, stroke: s.colour, width: s.width ?? 1, dash: s.dash }))],
      hooks: {
        setSeries: [(u, i, how) => { if (how && 'focus' in how) focused = i; }],
        setCursor: [(u) => this.#read(u, readout, lines.length === 1 ? 1 : focused)],
        setScale: [() => this.setTime(this.t)],
      },
    };
    this.plot = new uPlot(options, [x, ...lines.map((s) => finite(s.values))], element);
    element.append(readout);
    this.cursor = document.createElement('div');
    this.cursor.className = 'time-cursor';
    this.plot.over.append(this.cursor);
    let down = null;
    this.plot.over.addEventListener('mousedown', (e) => { down = e.offsetX; });
    this.plot.over.addEventListener('mouseup', (e) => {
      if (down !== null && Math.abs(e.offsetX - down) < 3) onSeek(this.plot.posToVal(e.offsetX, 'x'));
      down = null;
    });
  }

  #size() {
    return { width: this.element.clientWidth, height: Math.max(160, this.element.clientHeight - 24) };
  }

  #read(u, readout, s) {
    const k = u.cursor.idx;
    if (k == null || s == null) { readout.textContent = '\u00a0'; return; }
    const value = u.data[s][k];
    const shown = value == null ? '—' : `${value.toPrecision(5)} ${this.unit}`;
    readout.textContent = `${u.series[s].label}: ${shown} at t = ${u.data[0][k].toFixed(2)} s`;
  }

  setTime(t) {
    this.t = t;
    if (t === undefined) return;
    const left = this.plot.valToPos(t, 'x');
    this.cursor.hidden = !(left >= 0 && left <= this.plot.over.clientWidth);
    this.cursor.style.left = `${left}px`;
  }

  resize() {
    this.plot.setSize(this.#size());
    this.setTime(this.t);
  }
}

export class Charts {
  constructor(rmsElement, pairsElement, run, onSeek) {
    this.panels = [new Panel(rmsElement, {
      title: 'RMS velocity', unit: 'm/s', time: run.time, onSeek, references: [],
      series: [{ label: 'RMS velocity', colour: '#000000', width: 1.5, values: run.rms }],
    })];
    if (run.S === 0) {
      pairsElement.classList.add('empty');
      pairsElement.textContent = 'No formation pairs in this run: no pair distances to plot.';
    } else {
      const { S, F, pairDistance } = run;
      const series = run.pairLabels.map((label, s) => ({
        label, colour: PALETTE[s % PALETTE.length], values: Float32Array.from({ length: F }, (_, f) => pairDistance[f * S + s]),
      }));
      const references = [
        ...run.dT.map((value) => ({ label: `d_t = ${value} m`, colour: '#808000', value })),
        { label: `R + R_j = ${run.reach} m`, colour: '#9467bd', value: run.reach },
      ];
      this.panels.push(new Panel(pairsElement, { title: 'pair distance', unit: 'm', time: run.time, series, references, onSeek }));
    }
  }

  setTime(t) { this.panels.forEach((p) => p.setTime(t)); }

  resize() { this.panels.forEach((p) => p.resize()); }

  // The cursor's left edge (px) in each panel, for the tests.
  cursorPositions() { return this.panels.map((p) => (p.cursor.hidden ? null : parseFloat(p.cursor.style.left))); }
}
