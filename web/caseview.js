// caseview.js - one case on the page: its mesh (2D canvas or 3D WebGL)
// coloured by the chosen field at the chosen snapshot, redrawn as new
// snapshots arrive; its plots (load against displacement, energies and
// residual, fracture events over time, sieve curve), its fracture events,
// and for a clone made in this tab the changes against its parent.

import * as api from "./api.js";
import { changes, describe } from "./diff.js";
import { decodeFrame, fieldChoices } from "./mesh.js";
import { Plot, energies, eventCount, loadDisplacement, sieve, sourcePressure } from "./plots.js";
import { View2D } from "./view2d.js";
import { View3D } from "./view3d.js";

const $ = id => document.getElementById(id);
const MODES = { 1: "tensile", 2: "shear", 3: "mixed" };
const PLOT_EVERY_MS = 1000; // plots follow a running case at most once a second

export class CaseView {
  constructor(id, status, parent, guarded) {
    this.id = id;
    this.status = status;
    this.guarded = guarded;
    this.frame = null;
    this.loading = false;
    this.pending = null;        // a snapshot index asked for while one was loading
    this.snapshots = status.snapshots || 0;
    this.history = { names: [], rows: [] };
    this.events = [];
    this.plotsAt = 0;
    this.closed = false;
    this.available = null;      // the fields the case writes, from the first frame
    $("view-title").textContent = `${status.name} (${id}), ${status.dimension}D`;
    const three = status.dimension === 3;
    $("view2d").hidden = three;
    $("view3d").hidden = !three;
    try {
      this.view = three ? new View3D($("view3d")) : new View2D($("view2d"));
    } catch (e) {
      this.view = null;
      $("frame-info").textContent = "this browser cannot draw the view: " + e.message;
    }
    this.plots = {
      load: new Plot($("plot-load"), "Load against displacement", "displacement (m)", "force"),
      energy: new Plot($("plot-energy"), "Energies and residual", "time (s)", "energy"),
      events: new Plot($("plot-events"), "Fracture events", "time (s)", "broken joints"),
      sieve: new Plot($("plot-sieve"), "Sieve curve", "diameter (m)", "passing", { logX: true }),
      fluid: new Plot($("plot-fluid"), "Fluid: source pressure", "time (s)", "pressure (Pa)"),
    };
    $("plot-fluid").hidden = true;
    this.listeners = [
      [$("field"), "change", () => this.fieldChanged()],
      [$("scale"), "change", () => this.redraw()],
      [$("snapshot"), "change", () => { $("follow").checked = false; this.load(Number($("snapshot").value)); }],
      [$("follow"), "change", () => { if ($("follow").checked) this.load(-1); }],
    ];
    for (const [el, ev, fn] of this.listeners) el.addEventListener(ev, fn);
    $("events").querySelector("tbody").textContent = "";
    for (const k of ["frameDrawn", "frameField", "frameShownMs", "frameShape"]) delete document.body.dataset[k];
    $("field").textContent = "";
    this.showParentDiff(parent);
    // the frame first: the sieve curve of a case that is not running
    // rebuilds its model, which would compete with it for the machine
    this.start().then(() => this.refreshPlots(true));
  }

  // Which fields the case writes: those of a frame, and velocity when the
  // document asks for it (its output.fields, ["position", "velocity"] by
  // default); the first frame then carries all but velocity, 5 MB of a
  // 1e5-tetrahedron frame that only one colour needs.
  async start() {
    let velocity = true;
    try {
      const doc = await this.guarded(() => api.json("GET", `/cases/${this.id}/case`));
      const fields = doc && doc.output && doc.output.fields;
      velocity = !Array.isArray(fields) || fields.includes("velocity");
    } catch (e) { /* a frame with every field tells */ }
    this.velocity = velocity;
    await this.load(-1);
  }

  close() {
    this.closed = true;
    for (const [el, ev, fn] of this.listeners) el.removeEventListener(ev, fn);
    if (this.view) this.view.dispose();
    for (const p of Object.values(this.plots)) if (p.plot) p.plot.destroy();
  }

  // ------------------------------------------------------------ the mesh

  async load(index) {
    if (this.loading) { this.pending = index; return; }
    this.loading = true;
    try {
      const t0 = performance.now();
      const buffer = await this.guarded(() => api.bytes(this.frameUrl(index)));
      if (buffer && !this.closed) {
        const t1 = performance.now();
        this.frame = decodeFrame(buffer, this.frame);
        if (!this.available) {
          this.available = Object.keys(this.frame.fields);
          if (this.velocity && !this.available.includes("velocity")) this.available.push("velocity");
        }
        this.fillFieldMenu();
        const t2 = performance.now();
        const drawn = this.redraw();
        const t3 = performance.now();
        const f = this.frame;
        $("frame-info").textContent = `snapshot ${f.index} of ${f.snapshots - 1}, t = ${f.time.toPrecision(4)} s, ` +
          `step ${f.step}; ${(buffer.byteLength / 1048576).toFixed(2)} MiB loaded in ${(t1 - t0).toFixed(0)} ms, ` +
          `drawn in ${(t3 - t1).toFixed(0)} ms` + (f.surface ? `; ${f.faces} faces shown` : "");
        // the figures the page's tests read (fetch, decode, draw, in ms)
        const data = document.body.dataset;
        data.frameMs = (t3 - t0).toFixed(1);
        data.frameFetchMs = (t1 - t0).toFixed(1);
        data.frameDecodeMs = (t2 - t1).toFixed(1);
        data.frameDrawMs = (t3 - t2).toFixed(1);
        data.frameBytes = String(buffer.byteLength);
        data.frameShape = f.shapeKept ? "kept" : "sent";
        data.frameIndex = String(f.index);
        data.frameDrawn = drawn ? "yes" : "no";
        // shown: the next animation frame, once the browser has painted it
        delete data.frameShownMs;
        requestAnimationFrame(() => { data.frameShownMs = (performance.now() - t0).toFixed(1); });
        $("snapshot").max = String(f.snapshots - 1);
        $("snapshot").value = String(f.index);
      }
    } catch (e) {
      $("frame-info").textContent = e.message;
    } finally {
      this.loading = false;
    }
    if (this.pending !== null && !this.closed) {
      const next = this.pending;
      this.pending = null;
      this.load(next);
    }
  }

  // The first frame carries every field, to learn which the case writes;
  // later ones only what the chosen colour needs, with the damage (cracks)
  // and fragment ids: a 1e5-tetrahedron velocity field alone is 5 MB.
  frameUrl(index) {
    const q = [];
    if (index >= 0) q.push(`snapshot=${index}`);
    if (!this.available)
      q.push("fields=stress,principal_stress,damage,fragment,fluid_pressure,aperture");
    else {
      const key = $("field").value, want = new Set(["damage", "fragment"]);
      if (key === "vonmises" || key.startsWith("stress:")) want.add("stress");
      if (key.startsWith("principal:")) want.add("principal_stress");
      if (["velocity", "fluid_pressure", "aperture"].includes(key)) want.add(key);
      q.push("fields=" + [...want].filter(n => this.available.includes(n)).join(","));
    }
    // 3D: only the faces that show; and the shape (mesh, surface) is not
    // sent again while it stays the one the page holds
    if (this.status.dimension === 3) q.push("surface=true");
    if (this.frame) q.push("shape=" + this.frame.key);
    return `/cases/${this.id}/mesh.bin` + (q.length ? "?" + q.join("&") : "");
  }

  fillFieldMenu() {
    if (this.menuFilled) return; // later frames carry fewer fields: keep the first's menu
    this.menuFilled = true;
    const menu = $("field"), keep = menu.value, choices = fieldChoices(this.frame, this.available);
    const current = [...menu.options].map(o => o.value).join(",");
    if (current === choices.map(c => c.key).join(",")) return;
    menu.textContent = "";
    for (const c of choices) menu.add(new Option(c.label, c.key));
    const preferred = choices.some(c => c.key === keep) ? keep
      : choices.some(c => c.key === "vonmises") ? "vonmises" : choices[0].key;
    menu.value = preferred;
  }

  // A colour the frame in hand cannot give (its fields were narrowed to the
  // previous choice) needs the frame again with that field.
  fieldChanged() {
    const key = $("field").value, f = this.frame;
    const need = key === "vonmises" || key.startsWith("stress:") ? "stress"
      : key.startsWith("principal:") ? "principal_stress"
      : ["velocity", "fluid_pressure", "aperture"].includes(key) ? key : null;
    if (f && need && !f.fields[need]) this.load($("follow").checked ? -1 : f.index);
    else this.redraw();
  }

  redraw() {
    if (!this.frame || !this.view) return false;
    const scale = Number($("scale").value);
    const col = this.view.draw(this.frame, $("field").value, isFinite(scale) ? scale : 1);
    $("legend-lo").textContent = col.categorical ? "ids" : col.lo.toPrecision(3);
    $("legend-hi").textContent = col.categorical ? "" : col.hi.toPrecision(3);
    document.body.dataset.frameField = $("field").value; // what the view shows, for the tests
    return true;
  }

  // ------------------------------------------------------------- updates

  statusArrived(s) {
    this.status = s;
    if ((s.snapshots || 0) > this.snapshots) {
      this.snapshots = s.snapshots;
      if ($("follow").checked) this.load(-1);
      this.refreshPlots(true);
    } else if (s.state === "running") {
      this.refreshPlots(false);
    }
  }

  snapshotArrived(index) {
    this.snapshots = Math.max(this.snapshots, index + 1);
    if ($("follow").checked) this.load(index);
    this.refreshPlots(true);
  }

  // History and events since the last rows seen; the sieve curve (a
  // model read) only at snapshots.
  async refreshPlots(withFragments) {
    const now = Date.now();
    if (this.plotting || (!withFragments && now - this.plotsAt < PLOT_EVERY_MS)) return;
    this.plotting = true;
    this.plotsAt = now;
    try {
      const rows = this.history.rows, since = rows.length ? `?since=${rows[rows.length - 1].time}` : "";
      const h = await this.guarded(() => api.json("GET", `/cases/${this.id}/history${since}`));
      if (h && !this.closed) {
        this.history.names = h.names;
        this.history.rows = rows.concat(h.rows);
        this.plots.load.set(loadDisplacement(this.history));
        this.plots.energy.set(energies(this.history));
        const fluid = sourcePressure(this.history);
        $("plot-fluid").hidden = !fluid.length; // shown only when the case has such a series
        if (fluid.length) this.plots.fluid.set(fluid);
      }
      const ev = this.events, evSince = ev.length ? `?since=${ev[ev.length - 1].time}` : "";
      const e = await this.guarded(() => api.json("GET", `/cases/${this.id}/events${evSince}`));
      if (e && !this.closed) {
        this.events = ev.concat(e.events);
        this.plots.events.set(eventCount(this.events));
        this.showEvents();
      }
      if (withFragments && !this.closed) {
        const fr = await this.guarded(() => api.json("GET", `/cases/${this.id}/fragments`));
        if (fr && !this.closed) this.plots.sieve.set(sieve(fr));
      }
    } catch (err) {
      $("frame-info").textContent = err.message;
    } finally {
      this.plotting = false;
    }
  }

  showEvents() {
    const n = this.events.length, total = this.events.reduce((s, e) => s + e.energy, 0);
    $("events-summary").textContent = `${n} joints broken, ${total.toPrecision(3)} dissipated` +
      (n > 50 ? "; the last 50:" : "");
    const body = $("events").querySelector("tbody");
    body.textContent = "";
    for (const e of this.events.slice(-50).reverse()) {
      const tr = body.insertRow();
      for (const v of [e.time.toPrecision(5), e.joint, MODES[e.mode] || e.mode, e.energy.toPrecision(3)])
        tr.insertCell().textContent = v;
    }
  }

  async showParentDiff(parent) {
    if (!parent) { $("parent-diff").textContent = "not a clone made in this tab"; return; }
    try {
      const [a, b] = await Promise.all([api.json("GET", `/cases/${parent}/case`),
        api.json("GET", `/cases/${this.id}/case`)]);
      const list = describe(changes(a, b));
      $("parent-diff").textContent = `against ${parent}:\n` + (list.join("\n") || "no change");
    } catch (e) {
      $("parent-diff").textContent = `the parent ${parent} cannot be read: ${e.message}`;
    }
  }
}
