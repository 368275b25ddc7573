// view2d.js - a 2D snapshot on a canvas: triangles filled by the colour of
// their element, broken joints drawn as black cracks.
//
// Filling 1e5 triangles one by one with their own fillStyle costs a style
// change per triangle; the colours are instead quantised to 64 levels (a
// categorical field keeps its own colours) and each level is one path, so
// a frame is 64 fills whatever the mesh size.

import { brokenJoints, deformedPositions, elementColours } from "./mesh.js";

const LEVELS = 64;

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

  draw(f, key, scale) {
    const ctx = this.ctx, x = deformedPositions(f, scale), [s, ox, oy] = this.transform(x);
    const col = elementColours(f, key);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    const paths = new Map();
    for (let e = 0; e < f.elements; e++) {
      let r = col.rgb[3 * e], g = col.rgb[3 * e + 1], b = col.rgb[3 * e + 2];
      if (!col.categorical) { // one of LEVELS levels: the nearest multiple
        const q = 255 / (LEVELS - 1);
        r = Math.round(r / q) * q; g = Math.round(g / q) * q; b = Math.round(b / q) * q;
      }
      const style = `rgb(${r | 0},${g | 0},${b | 0})`;
      let p = paths.get(style);
      if (!p) { p = new Path2D(); paths.set(style, p); }
      const a = f.cells[3 * e], bb = f.cells[3 * e + 1], c = f.cells[3 * e + 2];
      p.moveTo(ox + s * x[2 * a], oy - s * x[2 * a + 1]);
      p.lineTo(ox + s * x[2 * bb], oy - s * x[2 * bb + 1]);
      p.lineTo(ox + s * x[2 * c], oy - s * x[2 * c + 1]);
      p.closePath();
    }
    for (const [style, p] of paths) {
      ctx.fillStyle = style;
      ctx.strokeStyle = style; // closes the hairline gaps between neighbours
      ctx.lineWidth = 0.5;
      ctx.fill(p);
      ctx.stroke(p);
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
    return col;
  }
}
