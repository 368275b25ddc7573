// view2d.js - a 2D snapshot on a canvas: triangles filled by the colour of
// their element, broken joints drawn as black cracks. A fluid field (fluid
// pressure, aperture: one value per joint) colours the lines of the joints
// the fluid can flow through (damaged or broken, or holding pressure) on a
// grey mesh.
//
// The triangles are filled into the pixels directly (edge functions over
// each triangle's bounding box): Path2D fills of 1e5 triangles took 30 s
// in headless Chromium, the pixel loop takes tens of milliseconds, since
// the work is the canvas' area plus a few operations per triangle. Element
// edges are stroked only on meshes small enough for them to be seen.

import { brokenJoints, deformedPositions, elementColours, range, viridis } from "./mesh.js";

const EDGES_BELOW = 5000; // elements; above this the edges would be a grey wash
const CRACK_FIELDS = ["fluid_pressure", "aperture"];
const BINS = 32; // colour steps of the joint lines: one stroke each

export class View2D {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
  }

  dispose() {}

  // Fits the deformed mesh into the canvas with a margin, y up.
  transform(x) {
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (let i = 0; i < x.length; i += 2) {
      if (x[i] < x0) x0 = x[i]; if (x[i] > x1) x1 = x[i];
      if (x[i + 1] < y0) y0 = x[i + 1]; if (x[i + 1] > y1) y1 = x[i + 1];
    }
    const w = this.canvas.width, h = this.canvas.height, m = 10;
    const s = Math.min((w - 2 * m) / Math.max(x1 - x0, 1e-30), (h - 2 * m) / Math.max(y1 - y0, 1e-30));
    const ox = (w - s * (x1 - x0)) / 2 - s * x0, oy = (h + s * (y1 - y0)) / 2 + s * y0;
    return [s, ox, oy];
  }

  // Fills triangle (x0,y0)-(x1,y1)-(x2,y2) (pixels) with one colour: the
  // pixels whose centre is inside, or within half a pixel of an edge (so
  // neighbours meet without a gap); the edge functions step by addition.
  static fill(pixels, w, h, x0, y0, x1, y1, x2, y2, rgba) {
    const area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if (!(area !== 0)) return; // degenerate, or not finite
    if (area < 0) { let t = x1; x1 = x2; x2 = t; t = y1; y1 = y2; y2 = t; }
    const A0 = y1 - y2, B0 = x2 - x1, C0 = -(A0 * x1 + B0 * y1), T0 = 0.5 * Math.hypot(A0, B0);
    const A1 = y2 - y0, B1 = x0 - x2, C1 = -(A1 * x2 + B1 * y2), T1 = 0.5 * Math.hypot(A1, B1);
    const A2 = y0 - y1, B2 = x1 - x0, C2 = -(A2 * x0 + B2 * y0), T2 = 0.5 * Math.hypot(A2, B2);
    const i0 = Math.max(0, Math.floor(Math.min(x0, x1, x2))), i1 = Math.min(w - 1, Math.ceil(Math.max(x0, x1, x2)));
    const j0 = Math.max(0, Math.floor(Math.min(y0, y1, y2))), j1 = Math.min(h - 1, Math.ceil(Math.max(y0, y1, y2)));
    for (let j = j0; j <= j1; j++) {
      const px = i0 + 0.5, py = j + 0.5;
      let e0 = A0 * px + B0 * py + C0 + T0, e1 = A1 * px + B1 * py + C1 + T1, e2 = A2 * px + B2 * py + C2 + T2;
      for (let i = i0, o = j * w + i0; i <= i1; i++, o++) {
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) pixels[o] = rgba;
        e0 += A0; e1 += A1; e2 += A2;
      }
    }
  }

  draw(f, key, scale) {
    const ctx = this.ctx, x = deformedPositions(f, scale), [s, ox, oy] = this.transform(x);
    const fluid = CRACK_FIELDS.includes(key) && f.fields[key];
    const col = fluid ? grey(f) : elementColours(f, key), w = this.canvas.width, h = this.canvas.height;
    const image = ctx.createImageData(w, h), pixels = new Uint32Array(image.data.buffer);
    pixels.fill(0xffffffff);
    const X = n => ox + s * x[2 * n], Y = n => oy - s * x[2 * n + 1];
    for (let e = 0; e < f.elements; e++) {
      const a = f.cells[3 * e], b = f.cells[3 * e + 1], c = f.cells[3 * e + 2];
      const rgba = (255 << 24 | col.rgb[3 * e + 2] << 16 | col.rgb[3 * e + 1] << 8 | col.rgb[3 * e]) >>> 0;
      View2D.fill(pixels, w, h, X(a), Y(a), X(b), Y(b), X(c), Y(c), rgba);
    }
    ctx.putImageData(image, 0, 0);
    if (f.elements < EDGES_BELOW) {
      const edges = new Path2D();
      for (let e = 0; e < f.elements; e++) {
        const a = f.cells[3 * e], b = f.cells[3 * e + 1], c = f.cells[3 * e + 2];
        edges.moveTo(X(a), Y(a)); edges.lineTo(X(b), Y(b)); edges.lineTo(X(c), Y(c)); edges.closePath();
      }
      ctx.strokeStyle = "rgba(0,0,0,0.25)";
      ctx.lineWidth = 0.5;
      ctx.stroke(edges);
    }
    const cracks = new Path2D();
    for (const j of brokenJoints(f)) {
      const a = f.jointNodes[4 * j], b = f.jointNodes[4 * j + 1];
      cracks.moveTo(ox + s * x[2 * a], oy - s * x[2 * a + 1]);
      cracks.lineTo(ox + s * x[2 * b], oy - s * x[2 * b + 1]);
    }
    ctx.strokeStyle = "#000000";
    ctx.lineWidth = 1.5;
    ctx.stroke(cracks);
    return fluid ? this.jointLines(f, f.fields[key].data, x, s, ox, oy) : col;
  }

  // The joints of the flow network coloured by their value, in BINS strokes.
  jointLines(f, values, x, s, ox, oy) {
    const damage = f.fields.damage ? f.fields.damage.data : null;
    const pressure = f.fields.fluid_pressure ? f.fields.fluid_pressure.data : null;
    const net = [];
    for (let j = 0; j < f.joints; j++)
      if ((damage && damage[j] > 0) || (pressure && pressure[j] !== 0)) net.push(j);
    const [lo, hi] = range(net.map(j => values[j])), paths = [];
    for (let b = 0; b < BINS; b++) paths.push(new Path2D());
    for (const j of net) {
      const b = Math.min(BINS - 1, Math.floor((values[j] - lo) / (hi - lo) * BINS));
      const a = f.jointNodes[4 * j], c = f.jointNodes[4 * j + 1];
      paths[b].moveTo(ox + s * x[2 * a], oy - s * x[2 * a + 1]);
      paths[b].lineTo(ox + s * x[2 * c], oy - s * x[2 * c + 1]);
    }
    this.ctx.lineWidth = 3;
    paths.forEach((p, b) => {
      const c = viridis((b + 0.5) / BINS);
      this.ctx.strokeStyle = `rgb(${c[0] | 0},${c[1] | 0},${c[2] | 0})`;
      this.ctx.stroke(p);
    });
    this.jointsDrawn = net.length;
    return { lo, hi, categorical: false };
  }
}

// Every element light grey: the ground the joint lines are drawn on.
function grey(f) {
  return { rgb: new Uint8Array(3 * f.elements).fill(215), lo: 0, hi: 1, categorical: false };
}
