// diff.js - what a clone changes in its parent's document: the list of
// changes by JSON Pointer (what the page shows) and the JSON Merge Patch
// (RFC 7396) that POST /cases/ID/clone takes to make them.

function isObject(v) { return v !== null && typeof v === "object" && !Array.isArray(v); }

function escape(key) { return String(key).replace(/~/g, "~0").replace(/\//g, "~1"); }

// [{pointer, op: "add"|"remove"|"replace", from, to}] in document order.
export function changes(before, after, pointer = "", out = []) {
  if (isObject(before) && isObject(after)) {
    for (const k of Object.keys(before)) {
      const p = pointer + "/" + escape(k);
      if (!(k in after)) out.push({ pointer: p, op: "remove", from: before[k] });
      else changes(before[k], after[k], p, out);
    }
    for (const k of Object.keys(after))
      if (!(k in before)) out.push({ pointer: pointer + "/" + escape(k), op: "add", to: after[k] });
    return out;
  }
  if (Array.isArray(before) && Array.isArray(after) && before.length === after.length) {
    before.forEach((v, i) => changes(v, after[i], pointer + "/" + i, out));
    return out;
  }
  if (JSON.stringify(before) !== JSON.stringify(after))
    out.push({ pointer: pointer || "/", op: "replace", from: before, to: after });
  return out;
}

// The merge patch that turns `before` into `after`. Arrays are replaced
// whole (RFC 7396 has no array edits); a null value in `after` cannot be
// expressed by a merge patch and is reported in `problems`.
export function mergePatch(before, after, problems = [], pointer = "") {
  if (!isObject(before) || !isObject(after)) return after;
  const patch = {};
  for (const k of Object.keys(before))
    if (!(k in after)) patch[k] = null;
  for (const k of Object.keys(after)) {
    const p = pointer + "/" + escape(k);
    if (after[k] === null) { problems.push(p); continue; }
    if (!(k in before)) patch[k] = after[k];
    else if (JSON.stringify(before[k]) !== JSON.stringify(after[k]))
      patch[k] = mergePatch(before[k], after[k], problems, p);
  }
  return patch;
}

function show(v) {
  const s = JSON.stringify(v);
  return s.length > 80 ? s.slice(0, 77) + "..." : s;
}

// One line per change, as the page lists them.
export function describe(list) {
  return list.map(c => c.op === "add" ? `+ ${c.pointer}: ${show(c.to)}`
    : c.op === "remove" ? `- ${c.pointer}: ${show(c.from)}`
    : `~ ${c.pointer}: ${show(c.from)} -> ${show(c.to)}`);
}
