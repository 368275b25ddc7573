// view3d.js - a 3D snapshot in WebGL through three.js: the outer faces of
// the tetrahedra and the faces of broken joints (the crack surfaces),
// flat-coloured by their element, lit so the shape reads, with the edges of
// the crack faces drawn black; the camera orbits with the mouse.
//
// The daemon sends only those faces (GET /cases/ID/mesh.bin?surface=true:
// ~2 % of the faces of a 1e5-tetrahedron fracturing block, ~1 MB instead
// of 20), so the page neither receives nor searches the inside of the
// mesh: before that, finding the surface here took most of the 3.4-4.6 s a
// frame took to show in a headless browser. Choosing a fluid field (fluid
// pressure, aperture) colours the crack faces by their own joint and shows
// the rest of the surface as a grey veil, so the cracks inside show.
// The drawing buffer is kept so the page's tests can read its pixels.

import * as THREE from "./vendor/three/three.module.js";
import { OrbitControls } from "./vendor/three/OrbitControls.js";
import { NONE, deformedPositions, elementColours, range, viridis } from "./mesh.js";

// The joint fields drawn on the crack faces themselves (damage colours
// each element by its most damaged joint, as in 2D, where it shows).
const CRACK_FIELDS = ["fluid_pressure", "aperture"];

export class View3D {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setSize(canvas.width, canvas.height, false);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xffffff);
    this.camera = new THREE.PerspectiveCamera(35, canvas.width / canvas.height, 1e-3, 1e3);
    this.camera.up.set(0, 0, 1); // z up, as the cases are written; before the controls read it
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    this.light = new THREE.DirectionalLight(0xffffff, 0.6);
    this.scene.add(this.light);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener("change", () => this.render());
    this.mesh = this.veil = this.cracks = null;
    this.framed = false;
  }

  dispose() {
    this.clear();
    this.controls.dispose();
    this.renderer.dispose();
  }

  clear() {
    for (const o of [this.mesh, this.veil, this.cracks]) {
      if (!o) continue;
      this.scene.remove(o);
      o.geometry.dispose();
      o.material.dispose();
    }
    this.mesh = this.veil = this.cracks = null;
  }

  render() {
    this.light.position.copy(this.camera.position);
    this.renderer.render(this.scene, this.camera);
  }

  draw(f, key, scale) {
    if (!f.faceNodes) throw new Error("a 3D frame without its surface (ask ?surface=true)");
    const x = deformedPositions(f, scale), joints = CRACK_FIELDS.includes(key);
    const col = joints ? this.jointColours(f, key) : elementColours(f, key);
    const S = f.faces, fn = f.faceNodes, fe = f.faceElement, fj = f.faceJoint;
    const pos = new Float32Array(S * 9), rgb = new Uint8Array(S * 9);
    const veil = [];
    let o = 0;
    for (let i = 0; i < S; i++) {
      const c = joints ? (fj[i] === NONE ? null : col.joint[fj[i]]) : 3 * fe[i];
      for (let k = 0; k < 3; k++) {
        const n = fn[3 * i + k];
        pos[o] = x[3 * n]; pos[o + 1] = x[3 * n + 1]; pos[o + 2] = x[3 * n + 2];
        if (c !== null) { rgb[o] = col.rgb[c]; rgb[o + 1] = col.rgb[c + 1]; rgb[o + 2] = col.rgb[c + 2]; }
        o += 3;
      }
      if (c === null) veil.push(i);
    }
    this.clear();
    const solid = joints ? this.keep(pos, rgb, veil, false) : { pos, rgb };
    this.mesh = this.surfaceMesh(solid.pos, solid.rgb, 1);
    if (joints && veil.length) {
      const v = this.keep(pos, rgb, veil, true);
      this.veil = this.surfaceMesh(v.pos, null, 0.15);
    }
    this.cracks = this.crackLines(f, x);
    for (const m of [this.mesh, this.veil, this.cracks]) if (m) this.scene.add(m);
    if (!this.framed) this.frame(x);
    this.render();
    return col;
  }

  // The faces listed in `which` (keep true) or all the others (false).
  keep(pos, rgb, which, keep) {
    const mark = new Uint8Array(pos.length / 9);
    for (const i of which) mark[i] = 1;
    const n = keep ? which.length : mark.length - which.length;
    const p = new Float32Array(9 * n), c = new Uint8Array(9 * n);
    let o = 0;
    for (let i = 0; i < mark.length; i++) {
      if (mark[i] !== (keep ? 1 : 0)) continue;
      p.set(pos.subarray(9 * i, 9 * i + 9), o);
      c.set(rgb.subarray(9 * i, 9 * i + 9), o);
      o += 9;
    }
    return { pos: p, rgb: c };
  }

  surfaceMesh(pos, rgb, opacity) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
    if (rgb) geometry.setAttribute("color", new THREE.BufferAttribute(rgb, 3, true));
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial(rgb ? { vertexColors: true }
      : { color: 0x9a9a9a, transparent: true, opacity, depthWrite: false });
    return new THREE.Mesh(geometry, material);
  }

  // Colours of the joints a joint field gives: {rgb (3 per joint), joint
  // (its offset in rgb), lo, hi}.
  jointColours(f, key) {
    const values = f.fields[key].data, [lo, hi] = range(values), rgb = new Uint8Array(3 * f.joints);
    const joint = new Int32Array(f.joints);
    for (let j = 0; j < f.joints; j++) {
      const c = viridis((values[j] - lo) / (hi - lo));
      rgb[3 * j] = c[0]; rgb[3 * j + 1] = c[1]; rgb[3 * j + 2] = c[2];
      joint[j] = 3 * j;
    }
    return { rgb, joint, lo, hi, categorical: false };
  }

  // The edges of the faces on broken joints (both sides), in black.
  crackLines(f, x) {
    const fj = f.faceJoint, damage = f.fields.damage ? f.fields.damage.data : null, list = [];
    for (let i = 0; i < f.faces; i++)
      if (fj[i] !== NONE && (!damage || damage[fj[i]] >= 1)) list.push(i);
    if (!list.length) return null;
    const pos = new Float32Array(list.length * 18), fn = f.faceNodes;
    let o = 0;
    for (const i of list)
      for (const [p, q] of [[0, 1], [1, 2], [2, 0]])
        for (const n of [fn[3 * i + p], fn[3 * i + q]]) {
          pos[o++] = x[3 * n]; pos[o++] = x[3 * n + 1]; pos[o++] = x[3 * n + 2];
        }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
    return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0x000000 }));
  }

  // Points the camera at the model once; later frames keep the user's view.
  frame(x) {
    const sphere = new THREE.Sphere().setFromPoints(Array.from({ length: x.length / 3 },
      (_, n) => new THREE.Vector3(x[3 * n], x[3 * n + 1], x[3 * n + 2])));
    const { center, radius } = sphere;
    const r = Math.max(radius, 1e-6);
    this.camera.near = r / 100;
    this.camera.far = r * 100;
    this.camera.position.set(center.x + 2.2 * r, center.y - 2.6 * r, center.z + 1.8 * r);
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
    this.framed = true;
  }
}
