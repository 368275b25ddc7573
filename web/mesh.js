// mesh.js - the binary snapshot frame of GET /cases/ID/mesh.bin (layout in
// docs/api.md, "Binary mesh frames") as typed arrays, the scalar fields the
// views colour by, and the colour maps. Shared by the 2D and 3D views, so
// a field means the same in both.

const MAGIC = "FDEMMESH";
const VERSION = 2, HEADER = 80, SECTION_HEADER = 32;
export const AT_NODE = 0, AT_ELEMENT = 1, AT_JOINT = 2, AT_FACE = 3;
export const NONE = 0xffffffff; // a u32 index that points nowhere
const FLAG_SURFACE = 1, FLAG_SHAPE = 2;
// The sections that make the mesh's shape: a frame leaves them out when
// the page said (?shape=KEY) that it holds the shape of that key.
const SHAPE = ["cells", "joints", "joint_elements", "faces", "face_element", "face_joint",
  "node_id", "element_id", "joint_id", "position0"];

// Maps the frame's bytes without copying them (every array is 4-aligned);
// a frame without its shape takes it from `previous`, which must hold the
// same key.
export function decodeFrame(buffer, previous) {
  const dv = new DataView(buffer);
  const magic = new TextDecoder().decode(new Uint8Array(buffer, 0, 8));
  if (magic !== MAGIC) throw new Error("not an fdemd mesh frame");
  const u32 = o => dv.getUint32(o, true), hex = o => u32(o).toString(16).padStart(8, "0");
  if (u32(8) !== VERSION) throw new Error(`mesh frame version ${u32(8)}; this page reads ${VERSION}`);
  const flags = u32(72);
  const f = {
    version: u32(8), dimension: u32(12), nodes: u32(16), elements: u32(20), joints: u32(24),
    index: u32(28), snapshots: u32(32), time: dv.getFloat64(40, true),
    step: Number(dv.getBigInt64(48, true)), deformed: u32(56) === 1, faces: u32(60),
    key: hex(68) + hex(64), surface: (flags & FLAG_SURFACE) !== 0, shapeKept: !(flags & FLAG_SHAPE),
    fields: {}, shape: {},
  };
  const sections = u32(36), names = new TextDecoder();
  let o = HEADER;
  for (let i = 0; i < sections; i++) {
    const name = names.decode(new Uint8Array(buffer, o, 16)).replace(/\0+$/, "");
    const at = u32(o + 16), width = u32(o + 20), type = u32(o + 24), items = u32(o + 28);
    o += SECTION_HEADER;
    const data = type === 1 ? new Uint32Array(buffer, o, items * width) : new Float32Array(buffer, o, items * width);
    o += 4 * items * width;
    if (SHAPE.includes(name)) f.shape[name] = data;
    else if (name === "position") f.position = data;
    else f.fields[name] = { at, width, data };
  }
  if (!(flags & FLAG_SHAPE)) {
    if (!previous || previous.key !== f.key) throw new Error("a frame without the shape the page holds");
    f.shape = previous.shape;
  }
  const s = f.shape;
  f.cells = s.cells; f.jointNodes = s.joints; f.jointElements = s.joint_elements;
  f.faceNodes = s.faces; f.faceElement = s.face_element; f.faceJoint = s.face_joint;
  f.position0 = s.position0;
  return f;
}

// ------------------------------------------------------------- the choices

const STRESS_2D = ["σxx", "σyy", "σxy"];
const STRESS_3D = ["σxx", "σyy", "σzz", "σyz", "σxz", "σxy"];

// What the field menu offers for a frame whose case writes the fields
// `names` (default: those of the frame): [{key, label}], in menu order.
export function fieldChoices(f, names) {
  const out = [], has = n => (names ? names.includes(n) : f.fields[n] !== undefined);
  const components = f.dimension === 3 ? STRESS_3D : STRESS_2D;
  if (has("stress")) {
    out.push({ key: "vonmises", label: f.dimension === 3 ? "von Mises stress" : "von Mises stress (in-plane)" });
    components.forEach((n, c) => out.push({ key: "stress:" + c, label: n }));
  }
  if (has("principal_stress")) {
    const w = f.dimension;
    for (let c = 0; c < w; c++)
      out.push({ key: "principal:" + c, label: `principal stress ${c + 1} of ${w} (tension +)` });
  }
  if (has("damage") && f.joints) out.push({ key: "damage", label: "damage (joints)" });
  if (has("fluid_pressure") && f.joints) out.push({ key: "fluid_pressure", label: "fluid pressure (joints)" });
  if (has("aperture") && f.joints) out.push({ key: "aperture", label: "hydraulic aperture (joints)" });
  out.push({ key: "displacement", label: "displacement magnitude" });
  if (has("velocity")) out.push({ key: "velocity", label: "velocity magnitude" });
  if (has("fragment")) out.push({ key: "fragment", label: "fragment id" });
  return out;
}

// Per element, the largest value of a joint field over its joints.
function jointMax(f, values) {
  const out = new Float32Array(f.elements), je = f.jointElements;
  for (let j = 0; j < f.joints; j++) {
    const v = values[j], a = je[2 * j], b = je[2 * j + 1];
    if (a !== NONE && v > out[a]) out[a] = v;
    if (b !== NONE && v > out[b]) out[b] = v;
  }
  return out;
}

function vonMises(s, e, d) {
  if (d === 2) {
    const a = s[e * 3], b = s[e * 3 + 1], t = s[e * 3 + 2];
    return Math.sqrt(a * a - a * b + b * b + 3 * t * t);
  }
  const o = e * 6, x = s[o], y = s[o + 1], z = s[o + 2], yz = s[o + 3], xz = s[o + 4], xy = s[o + 5];
  return Math.sqrt(0.5 * ((x - y) ** 2 + (y - z) ** 2 + (z - x) ** 2) + 3 * (yz * yz + xz * xz + xy * xy));
}

// Per-node vector magnitude, averaged over each element's nodes (over the
// nodes of its faces shown, in a surface frame, which carries no cells).
function nodeMagnitude(f, get) {
  const d = f.dimension, sum = new Float32Array(f.elements), count = new Float32Array(f.elements);
  const magnitude = n => { let m = 0; for (let c = 0; c < d; c++) m += get(n * d + c) ** 2; return Math.sqrt(m); };
  const [items, per, nodes, owner] = f.cells ? [f.elements, d + 1, f.cells, null]
    : [f.faces, d, f.faceNodes, f.faceElement];
  for (let i = 0; i < items; i++) {
    const e = owner ? owner[i] : i;
    for (let j = 0; j < per; j++) { sum[e] += magnitude(nodes[i * per + j]); count[e]++; }
  }
  for (let e = 0; e < f.elements; e++) sum[e] = count[e] ? sum[e] / count[e] : 0;
  return sum;
}

// The fields that live on joints: an element shows the largest of its joints'.
export const JOINT_FIELDS = ["damage", "fluid_pressure", "aperture"];

// One value per element for the field `key`: {values, categorical}.
export function elementValues(f, key) {
  const E = f.elements, d = f.dimension, out = new Float32Array(E);
  if (key === "vonmises") {
    const s = f.fields.stress.data;
    for (let e = 0; e < E; e++) out[e] = vonMises(s, e, d);
  } else if (key.startsWith("stress:") || key.startsWith("principal:")) {
    const fld = key.startsWith("stress:") ? f.fields.stress : f.fields.principal_stress;
    const c = Number(key.split(":")[1]);
    for (let e = 0; e < E; e++) out[e] = fld.data[e * fld.width + c];
  } else if (JOINT_FIELDS.includes(key)) {
    return { values: jointMax(f, f.fields[key].data), categorical: false };
  } else if (key === "displacement") {
    return { values: nodeMagnitude(f, i => f.position[i] - f.position0[i]), categorical: false };
  } else if (key === "velocity") {
    const v = f.fields.velocity.data;
    return { values: nodeMagnitude(f, i => v[i]), categorical: false };
  } else if (key === "fragment") {
    out.set(f.fields.fragment.data);
    return { values: out, categorical: true };
  }
  return { values: out, categorical: false };
}

export function range(values) {
  let lo = Infinity, hi = -Infinity;
  for (const v of values) { if (v < lo) lo = v; if (v > hi) hi = v; }
  if (!isFinite(lo)) return [0, 1];
  return lo === hi ? [lo, lo + 1] : [lo, hi];
}

// --------------------------------------------------------------- colours

// Viridis as 9 stops, linearly interpolated (perceptually even, readable
// in grey and by most colour-blind users).
const VIRIDIS = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];

export function viridis(t) {
  t = Math.min(1, Math.max(0, isFinite(t) ? t : 0)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(t)), u = t - i, a = VIRIDIS[i], b = VIRIDIS[i + 1];
  return [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2])];
}

// Distinct colours for ids (golden-angle hues), so neighbouring fragments differ.
export function categorical(id) {
  const h = ((id * 137.508) % 360) / 60, s = 0.65, v = 0.9;
  const c = v * s, x = c * (1 - Math.abs((h % 2) - 1)), m = v - c;
  const rgb = h < 1 ? [c, x, 0] : h < 2 ? [x, c, 0] : h < 3 ? [0, c, x] : h < 4 ? [0, x, c] : h < 5 ? [x, 0, c] : [c, 0, x];
  return rgb.map(q => (q + m) * 255);
}

// Element colours as 0..255 triples, and the range they span.
export function elementColours(f, key) {
  const { values, categorical: cat } = elementValues(f, key);
  const [lo, hi] = cat ? [0, 1] : range(values), rgb = new Uint8Array(3 * f.elements);
  for (let e = 0; e < f.elements; e++) {
    const c = cat ? categorical(values[e]) : viridis((values[e] - lo) / (hi - lo));
    rgb[3 * e] = c[0]; rgb[3 * e + 1] = c[1]; rgb[3 * e + 2] = c[2];
  }
  return { rgb, lo, hi, categorical: cat };
}

// Deformed position of node n, component c, with the displacement scaled.
export function deformedPositions(f, scale) {
  if (scale === 1) return f.position;
  const out = new Float32Array(f.position.length);
  for (let i = 0; i < out.length; i++) out[i] = f.position0[i] + scale * (f.position[i] - f.position0[i]);
  return out;
}

// The joints broken in this frame (damage 1): their indices.
export function brokenJoints(f) {
  const dmg = f.fields.damage;
  if (!dmg || !f.joints) return [];
  const out = [];
  for (let j = 0; j < f.joints; j++) if (dmg.data[j] >= 1) out.push(j);
  return out;
}
