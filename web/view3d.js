// view3d.js - a 3D snapshot in WebGL through three.js: the outer faces of
// the tetrahedra and the faces of broken joints (the crack surfaces),
// flat-coloured by their element, lit so the shape reads, with broken
// joints outlined as cracks; the camera orbits with the mouse.
//
// A fracturing part has nodes of its own per tetrahedron, so the skin
// cannot be told from node ids: nodes that started at one point are first
// made one vertex (a hash of their initial coordinates' bits), and a face
// is outer when no other tetrahedron has the same three vertices. For
// 1e5 tetrahedra that leaves ~2 % of the 4e5 faces, which is what makes
// a software-rendered (headless) frame take a second instead of several.
// The drawing buffer is kept so the page's tests can read its pixels.

import * as THREE from "./vendor/three/three.module.js";
import { OrbitControls } from "./vendor/three/OrbitControls.js";
import { brokenJoints, deformedPositions, elementColours } from "./mesh.js";

const FACES = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]; // outward for positive volume

// One vertex id per initial position: nodes with the same initial
// coordinates (bit for bit) share it. Open addressing on the bits.
function vertexIds(f) {
  const n = f.nodes, bits = new Uint32Array(f.position0.buffer, f.position0.byteOffset, 3 * n);
  let size = 1;
  while (size < 2 * n) size <<= 1;
  const table = new Int32Array(size).fill(-1), id = new Int32Array(n);
  let count = 0;
  for (let i = 0; i < n; i++) {
    const a = bits[3 * i], b = bits[3 * i + 1], c = bits[3 * i + 2];
    let h = (Math.imul(a, 0x9e3779b1) ^ Math.imul(b, 0x85ebca77) ^ Math.imul(c, 0xc2b2ae3d)) & (size - 1);
    for (;;) {
      const j = table[h];
      if (j < 0) { table[h] = i; id[i] = count++; break; }
      if (bits[3 * j] === a && bits[3 * j + 1] === b && bits[3 * j + 2] === c) { id[i] = id[j]; break; }
      h = (h + 1) & (size - 1);
    }
  }
  return { id, count };
}

// A face's key from its three vertex ids, the same whatever their order.
function faceKey(v, count, a, b, c) {
  let p = v[a], q = v[b], r = v[c], t;
  if (p > q) { t = p; p = q; q = t; }
  if (q > r) { t = q; q = r; r = t; }
  if (p > q) { t = p; p = q; q = t; }
  return (p * count + q) * count + r;
}

// [element, face] pairs of the outer faces (every face when the keys would
// not be exact doubles, past 2e5 distinct vertices).
function outerFaces(f) {
  const { id, count } = vertexIds(f), E = f.elements, out = [];
  if (count ** 3 > Number.MAX_SAFE_INTEGER) {
    for (let e = 0; e < E; e++) for (let k = 0; k < 4; k++) out.push(e, k);
    return { faces: Int32Array.from(out), id, count };
  }
  const seen = new Map();
  for (let e = 0; e < E; e++)
    for (let k = 0; k < 4; k++) {
      const F = FACES[k], key = faceKey(id, count, f.cells[4 * e + F[0]], f.cells[4 * e + F[1]], f.cells[4 * e + F[2]]);
      seen.set(key, seen.has(key) ? -1 : 4 * e + k);
    }
  for (const v of seen.values()) if (v >= 0) out.push(v >> 2, v & 3);
  return { faces: Int32Array.from(out), id, count };
}

// [element, face] pairs of the faces on broken joints (both sides).
function crackFaces(f, skin, broken) {
  if (!broken.length || skin.count ** 3 > Number.MAX_SAFE_INTEGER) return new Int32Array(0);
  const keys = new Set(), out = [];
  for (const j of broken) {
    const a = f.jointNodes.subarray(6 * j, 6 * j + 3);
    keys.add(faceKey(skin.id, skin.count, a[0], a[1], a[2]));
  }
  for (let e = 0; e < f.elements; e++)
    for (let k = 0; k < 4; k++) {
      const F = FACES[k];
      if (keys.has(faceKey(skin.id, skin.count, f.cells[4 * e + F[0]], f.cells[4 * e + F[1]], f.cells[4 * e + F[2]])))
        out.push(e, k);
    }
  return Int32Array.from(out);
}

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
    this.mesh = null;
    this.cracks = null;
    this.framed = false;
  }

  dispose() {
    this.clear();
    this.controls.dispose();
    this.renderer.dispose();
  }

  clear() {
    for (const o of [this.mesh, this.cracks]) {
      if (!o) continue;
      this.scene.remove(o);
      o.geometry.dispose();
      o.material.dispose();
    }
    this.mesh = this.cracks = null;
  }

  render() {
    this.light.position.copy(this.camera.position);
    this.renderer.render(this.scene, this.camera);
  }

  // The outer faces depend on the mesh only: kept while it stays the same.
  skin(f) {
    const key = `${f.nodes}:${f.elements}`;
    if (!this.skinCache || this.skinCache.key !== key) this.skinCache = { key, skin: outerFaces(f) };
    return this.skinCache.skin;
  }

  draw(f, key, scale) {
    const x = deformedPositions(f, scale), col = elementColours(f, key), skin = this.skin(f);
    const broken = brokenJoints(f), cracked = crackFaces(f, skin, broken);
    const faces = skin.faces.length + cracked.length;
    const pos = new Float32Array(faces / 2 * 9), rgb = new Float32Array(faces / 2 * 9);
    let o = 0;
    for (const list of [skin.faces, cracked])
      for (let i = 0; i < list.length; i += 2) {
        const e = list[i], r = col.rgb[3 * e] / 255, g = col.rgb[3 * e + 1] / 255, b = col.rgb[3 * e + 2] / 255;
        for (const v of FACES[list[i + 1]]) {
          const n = f.cells[4 * e + v];
          pos[o] = x[3 * n]; pos[o + 1] = x[3 * n + 1]; pos[o + 2] = x[3 * n + 2];
          rgb[o] = r; rgb[o + 1] = g; rgb[o + 2] = b;
          o += 3;
        }
      }
    this.clear();
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
    geometry.setAttribute("color", new THREE.BufferAttribute(rgb, 3));
    geometry.computeVertexNormals();
    this.mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ vertexColors: true }));
    this.scene.add(this.mesh);
    this.cracks = this.crackLines(f, x, broken);
    if (this.cracks) this.scene.add(this.cracks);
    if (!this.framed) this.frame(geometry);
    this.render();
    return col;
  }

  // The edges of each broken joint's first face, in black.
  crackLines(f, x, broken) {
    if (!broken.length) return null;
    const pos = new Float32Array(broken.length * 18);
    let o = 0;
    for (const j of broken) {
      const a = f.jointNodes.subarray(6 * j, 6 * j + 3);
      for (const [p, q] of [[0, 1], [1, 2], [2, 0]])
        for (const n of [a[p], a[q]]) {
          pos[o++] = x[3 * n]; pos[o++] = x[3 * n + 1]; pos[o++] = x[3 * n + 2];
        }
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
    return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0x000000 }));
  }

  // Points the camera at the model once; later frames keep the user's view.
  frame(geometry) {
    geometry.computeBoundingSphere();
    const { center, radius } = geometry.boundingSphere;
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
