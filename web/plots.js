// plots.js - the page's line plots through uPlot: one helper that draws
// named series (each with its own x values) on one set of axes, and the
// series the case view and the comparison take from the daemon's JSON
// (GET /cases/ID/history, /events, /fragments).

import uPlot from "./vendor/uplot/uPlot.esm.js";

const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
  "#7f7f7f", "#bcbd22", "#17becf", "#000000"];

// Axis numbers in 3 significant digits: uPlot's own format rounds the
// microseconds and millimetres of a small model to 0.
function tick(v) {
  if (v === null || v === undefined) return "";
  const a = Math.abs(v);
  return a === 0 ? "0" : a >= 1e4 || a < 1e-2 ? v.toExponential(1) : String(Number(v.toPrecision(3)));
}
const ticks = (u, splits) => splits.map(tick);
// The x range, widened when it is (nearly) one value: uPlot's tick loop
// never ends on a range below the precision of its numbers (a sieve
// curve of equal fragments threw "Invalid array length").
function xRange(u, min, max) {
  const span = Math.max(Math.abs(min), Math.abs(max));
  if (max - min > 1e-6 * span) return [min, max];
  const d = span > 0 ? 0.05 * span : 1;
  return [min - d, max + d];
}
// A logarithmic x axis drawn as log10 on a linear scale (uPlot's own log
// scale drew nothing for a four-point sieve curve), labelled in decades.
const decadeTicks = (u, splits) => splits.map(v => (v === null || v === undefined ? "" : tick(10 ** v)));

function increasing(xs) {
  for (let i = 1; i < xs.length; i++) if (!(xs[i] >= xs[i - 1])) return false;
  return true;
}

// A plot in `el` that can be given new data: series = [{label, x, y}].
// uPlot wants one x array shared by all series, in increasing order:
// series with different x are joined (uPlot.join fills the gaps with
// null), and a series whose x goes back (a load unloading) is drawn
// against its row number instead, which the x label then says.
export class Plot {
  constructor(el, title, xLabel, yLabel, options) {
    this.el = el;
    this.title = title;
    this.xLabel = xLabel;
    this.yLabel = yLabel;
    this.options = options || {};
    this.plot = null;
    this.key = "";
  }

  set(series) {
    series = series.filter(s => s.x.length > 0);
    if (this.options.logX)
      series = series.map(s => ({ label: s.label, x: s.x.map(Math.log10), y: s.y }));
    let xLabel = series.length && series[0].xLabel ? series[0].xLabel : this.xLabel;
    if (series.some(s => !increasing(s.x))) {
      series = series.map(s => ({ label: s.label, x: s.x.map((_, i) => i), y: s.y }));
      xLabel = "row (x went back: " + xLabel + " is not monotonic)";
    }
    const data = series.length === 0 ? [[], []]
      : series.length === 1 ? [Float64Array.from(series[0].x), Float64Array.from(series[0].y)]
      : uPlot.join(series.map(s => [Float64Array.from(s.x), Float64Array.from(s.y)]));
    const key = xLabel + "|" + this.yLabel + "|" + series.map(s => s.label).join("|");
    const points = String(series.reduce((n, s) => n + s.x.length, 0));
    if (this.plot && key === this.key) {
      this.plot.setData(data);
      this.plot.root.dataset.points = points;
      this.plot.root.dataset.y = this.yLabel;
      return;
    }
    if (this.plot) this.plot.destroy();
    this.key = key;
    const width = Math.max(300, this.el.clientWidth || 480);
    this.plot = new uPlot({
      title: this.title, width, height: this.options.height || 240,
      scales: { x: { time: false, range: xRange } },
      axes: [{ label: xLabel, values: this.options.logX ? decadeTicks : ticks },
             { label: this.yLabel, size: 70, values: ticks }],
      series: [this.xSeries(xLabel)].concat((series.length ? series : [{ label: "no data" }])
        .map((s, i) => ({ label: s.label, stroke: COLOURS[i % COLOURS.length], width: 1.5,
                          spanGaps: true, points: { show: false } }))),
      legend: { live: true },
    }, data, this.el);
    this.plot.root.dataset.points = points;
    this.plot.root.dataset.y = this.yLabel;
  }

  xSeries(label) {
    const s = { label };
    if (this.options.logX) s.value = (u, v) => tick(v === null || v === undefined ? v : 10 ** v);
    return s;
  }

  points() { return this.plot ? Number(this.plot.root.dataset.points) : 0; }
}

// ------------------------------------------------------------ the series

// The load-displacement curve of a test machine's platen: of the
// constraints that move, the component that moves most, its force against
// the mean displacement of its nodes. A model whose constraints all hold
// still (a fixed base) gets the largest force against time instead.
export function loadDisplacement(history) {
  const rows = history.rows;
  if (!rows.length || !rows[0].constraint_force || !rows[0].constraint_force.length) return [];
  let moved = [0, 0], travel = 0, loaded = [0, 0], peak = -1;
  rows.forEach(r => r.constraint_force.forEach((v, c) => v.forEach((f, k) => {
    const u = Math.abs(r.constraint_displacement[c][k]);
    if (u > travel) { travel = u; moved = [c, k]; }
    if (Math.abs(f) > peak) { peak = Math.abs(f); loaded = [c, k]; }
  })));
  const [c, k] = travel > 0 ? moved : loaded, axis = "xyz"[k];
  const y = rows.map(r => r.constraint_force[c][k]);
  if (travel > 0)
    return [{ label: `constraint ${c}: F${axis} against u${axis}`, xLabel: `u${axis} (m)`,
              x: rows.map(r => r.constraint_displacement[c][k]), y }];
  return [{ label: `constraint ${c} (fixed): F${axis}`, xLabel: "time (s)", x: rows.map(r => r.time), y }];
}

// The source pressure of each injection (a constraint that injects fluid,
// contract 6.4) over time, from the history rows' "fluid" member; none
// when the case has no fluid or the daemon writes no such series.
export function sourcePressure(history) {
  const rows = history.rows;
  const first = rows.length && rows[0].fluid && rows[0].fluid.source_pressure;
  if (!Array.isArray(first)) return [];
  const out = [];
  first.forEach((_, c) => {
    const y = rows.map(r => { const v = r.fluid && r.fluid.source_pressure ? r.fluid.source_pressure[c] : null;
      return typeof v === "number" ? v : null; });
    if (y.some(v => v !== null))
      out.push({ label: `constraint ${c}: source pressure`, constraint: c, x: rows.map(r => r.time), y });
  });
  return out;
}

export function energies(history) {
  const rows = history.rows;
  if (!rows.length) return [];
  return Object.keys(rows[0].energy).map(term => ({
    label: term, x: rows.map(r => r.time), y: rows.map(r => r.energy[term]) }));
}

// Fracture events counted over time (a step's events share its time).
export function eventCount(events) {
  const x = [], y = [];
  events.forEach((e, i) => {
    if (x.length && x[x.length - 1] === e.time) y[y.length - 1] = i + 1;
    else { x.push(e.time); y.push(i + 1); }
  });
  return [{ label: "broken joints", x, y }];
}

export function sieve(fragments) {
  const d = fragments.distribution || [];
  return [{ label: "passing (mass fraction)", x: d.map(p => p.diameter), y: d.map(p => p.passing) }];
}

// The comparable series of a history: "energy:<term>", "force:<c>:<k>",
// "point:<p>:<k>" (displacement) with their labels.
export function historyChoices(history) {
  const rows = history.rows, out = [];
  if (!rows.length) return out;
  Object.keys(rows[0].energy).forEach(t => out.push({ key: "energy:" + t, label: "energy " + t }));
  (rows[0].constraint_force || []).forEach((v, c) => v.forEach((_, k) =>
    out.push({ key: `force:${c}:${k}`, label: `constraint ${c} force ${"xyz"[k]}` })));
  sourcePressure(history).forEach(s => out.push({ key: "pressure:" + s.constraint, label: s.label }));
  ((rows[0].points || {}).displacement || []).forEach((v, p) => v.forEach((_, k) =>
    out.push({ key: `point:${p}:${k}`, label: `point ${(history.names || [])[p] || p} displacement ${"xyz"[k]}` })));
  return out;
}

export function historySeries(history, key, label) {
  const rows = history.rows, [kind, a, b] = key.split(":");
  const pick = kind === "energy" ? r => r.energy[a]
    : kind === "pressure" ? r => (r.fluid && r.fluid.source_pressure ? r.fluid.source_pressure[+a] : null)
    : kind === "force" ? r => r.constraint_force[+a][+b]
    : r => r.points.displacement[+a][+b];
  return { label, x: rows.map(r => r.time), y: rows.map(pick) };
}
