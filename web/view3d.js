// view3d.js - a 3D snapshot in WebGL through three.js: every face of every
// tetrahedron, flat-coloured by its element, lit so the shape reads, with
// broken joints outlined as cracks; the camera orbits with the mouse.
//
// Every face is drawn rather than only the outer skin: a fracturing part
// has its own nodes per tetrahedron, so the skin cannot be told from node
// ids, and a crack that opens should show the faces inside it. The depth
// test hides the rest (4e5 triangles for 1e5 tetrahedra, easy for a GPU).
// The drawing buffer is kept so the page's tests can read its pixels.

import * as THREE from "./vendor/three/three.module.js";
import { OrbitControls } from "./vendor/three/OrbitControls.js";
import { brokenJoints, deformedPositions, elementColours } from "./mesh.js";

const FACES = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]; // outward for positive volume

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

  draw(f, key, scale) {
    const x = deformedPositions(f, scale), col = elementColours(f, key);
    const pos = new Float32Array(f.elements * 36), rgb = new Float32Array(f.elements * 36);
    let o = 0;
    for (let e = 0; e < f.elements; e++) {
      const r = col.rgb[3 * e] / 255, g = col.rgb[3 * e + 1] / 255, b = col.rgb[3 * e + 2] / 255;
      for (const face of FACES)
        for (const v of face) {
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
    this.cracks = this.crackLines(f, x);
    if (this.cracks) this.scene.add(this.cracks);
    if (!this.framed) this.frame(geometry);
    this.render();
    return col;
  }

  // The edges of each broken joint's first face, in black.
  crackLines(f, x) {
    const broken = brokenJoints(f);
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
