// app.js - the page's wiring: the cases list and its commands, submitting
// and cloning, and which case is viewed. The views (view2d.js, view3d.js),
// the frame (mesh.js), the plots (plots.js) and the daemon (api.js) each
// have their own file.

import * as api from "./api.js";
import { CaseView } from "./caseview.js";
import { Compare } from "./compare.js";
import { changes, describe, mergePatch } from "./diff.js";

const $ = id => document.getElementById(id);
const cases = new Map(); // id -> status, in the daemon's order
const PARENTS_KEY = "fdemd.parents"; // clones made in this tab: id -> parent id
let live = null, view = null, compare = null;

// ------------------------------------------------------------- the token

function askToken(message) {
  if (live) live.stop();
  live = null;
  $("token-panel").hidden = false;
  $("token-error").textContent = message || "";
  $("token-input").focus();
}

function startLive() {
  $("token-panel").hidden = true;
  $("forget-token").hidden = !api.token();
  live = new api.Live({
    list: list => { cases.clear(); list.forEach(s => cases.set(s.id, s)); renderCases(); },
    status: s => { cases.set(s.id, s); renderCases(); },
    snapshot: ev => { if (view && view.id === ev.id) view.snapshotArrived(ev.index); },
    deleted: ev => { cases.delete(ev.id); renderCases(); },
    mode: m => { $("mode").textContent = m === "stream" ? "live (stream)" : "live (polling every 1 s)"; },
    unauthorized: () => askToken(api.token() ? "the daemon refused this token" : ""),
  });
  live.start();
}

// Any request answered 401 sends the user back to the token prompt.
async function guarded(fn) {
  try { return await fn(); } catch (e) {
    if (e instanceof api.Unauthorized) { askToken("the daemon refused this token"); return undefined; }
    throw e;
  }
}

// --------------------------------------------------------------- the list

function eta(s) {
  if (typeof s.eta === "number") return s.eta;
  if (s.state !== "running" || !(s.steps_per_second > 0) || !(s.dt > 0)) return null;
  return (s.end_time - s.time) / s.dt / s.steps_per_second;
}

function formatSeconds(t) {
  if (t === null || t === undefined || !isFinite(t)) return "";
  if (t < 90) return t.toFixed(0) + " s";
  if (t < 5400) return (t / 60).toFixed(0) + " min";
  return (t / 3600).toFixed(1) + " h";
}

const COMMANDS = {
  start: ["created", "paused"], pause: ["running", "queued"], stop: ["created", "queued", "running", "paused"],
  extend: ["finished", "paused"], clone: null, delete: null,
};

function button(label, onClick, name) {
  const b = document.createElement("button");
  b.textContent = label;
  if (name) b.dataset.command = name;
  b.addEventListener("click", ev => { ev.stopPropagation(); onClick(); });
  return b;
}

function renderCases() {
  const body = $("cases").querySelector("tbody"), seen = new Set();
  for (const s of cases.values()) {
    seen.add(s.id);
    let tr = body.querySelector(`tr[data-id="${s.id}"]`);
    if (!tr) {
      tr = document.createElement("tr");
      tr.dataset.id = s.id;
      tr.innerHTML = "<td><input type=checkbox title='compare'></td><td class=name></td><td class=id></td>" +
        "<td class=state></td><td class=progress><progress max=1></progress> <span></span></td>" +
        "<td class=speed></td><td class=cpu></td><td class=eta></td><td class=stage></td><td class=commands></td><td class=files></td>";
      tr.addEventListener("click", () => openCase(s.id));
      tr.querySelector("input").addEventListener("click", ev => { ev.stopPropagation(); if (compare) compare.refresh(); });
      const files = tr.querySelector(".files");
      for (const [label, file] of [["result.h5", "result.h5"], ["xdmf", "result.xdmf"], ["case", "case"]])
        files.appendChild(button(label, () => guarded(() => api.download(`/cases/${s.id}/${file}`,
          file === "case" ? `${s.id}.json` : `${s.id}-${file}`)).catch(showError)));
      body.appendChild(tr);
    }
    fillRow(tr, s);
  }
  for (const tr of [...body.querySelectorAll("tr")]) if (!seen.has(tr.dataset.id)) tr.remove();
  $("cases-empty").hidden = cases.size > 0;
  if (view && cases.has(view.id)) view.statusArrived(cases.get(view.id));
}

function fillRow(tr, s) {
  tr.querySelector(".name").textContent = s.name;
  tr.querySelector(".id").textContent = s.id;
  tr.querySelector(".state").textContent = s.state + (s.error ? ": " + s.error : "");
  tr.querySelector("progress").value = s.progress || 0;
  tr.querySelector(".progress span").textContent = ((s.progress || 0) * 100).toFixed(1) + " %";
  tr.querySelector(".speed").textContent = s.steps_per_second ? Math.round(s.steps_per_second) : "";
  tr.querySelector(".cpu").textContent = typeof s.cpu_share === "number" ? Math.round(s.cpu_share * 100) + " %" : "";
  tr.querySelector(".eta").textContent = formatSeconds(eta(s));
  tr.querySelector(".stage").textContent = s.stage ? `${s.stage.index} ${s.stage.name}` : "";
  tr.classList.toggle("selected", !!(view && view.id === s.id));
  const cmds = tr.querySelector(".commands"), key = s.state;
  if (cmds.dataset.state === key) return;
  cmds.dataset.state = key;
  cmds.textContent = "";
  for (const [name, states] of Object.entries(COMMANDS)) {
    if (states && !states.includes(s.state)) continue;
    cmds.appendChild(button(name, () => command(s.id, name), name));
  }
}

async function command(id, name) {
  try {
    if (name === "delete") {
      if (!confirm(`Delete case ${id} and its files?`)) return;
      await guarded(() => api.json("DELETE", `/cases/${id}`));
      cases.delete(id);
      if (view && view.id === id) closeView();
    } else if (name === "extend") {
      const s = cases.get(id), end = prompt("New end time (s)", String(2 * s.end_time));
      if (!end) return;
      const st = await guarded(() => api.json("POST", `/cases/${id}/extend`, { end: Number(end) }));
      if (st) cases.set(id, st);
    } else if (name === "clone") {
      return openClone(id);
    } else {
      const st = await guarded(() => api.json("POST", `/cases/${id}/${name}`));
      if (st) cases.set(id, st);
    }
    renderCases();
    if (live) live.nudge();
  } catch (e) { showError(e); }
}

function problemText(e) {
  if (!(e instanceof api.ApiError)) return String(e);
  const p = e.problem || {};
  return [`${e.status} ${p.title || ""}: ${p.detail || e.message}`]
    .concat((p.errors || []).map(x => `  ${x.pointer || "(document)"}: ${x.message}`)).join("\n");
}

function showError(e) { $("cases-error").textContent = problemText(e); }

// ------------------------------------------------------------ one case

function openCase(id) {
  $("clone-panel").hidden = true;
  if (view && view.id === id) return;
  if (view) view.close();
  view = new CaseView(id, cases.get(id), parentOf(id), guarded);
  $("case-view").hidden = false;
  renderCases();
}

function closeView() {
  if (view) view.close();
  view = null;
  $("case-view").hidden = true;
}

function parentOf(id) {
  try { return JSON.parse(sessionStorage.getItem(PARENTS_KEY) || "{}")[id] || null; } catch (e) { return null; }
}

function rememberParent(id, parent) {
  let map = {};
  try { map = JSON.parse(sessionStorage.getItem(PARENTS_KEY) || "{}"); } catch (e) { /* a fresh map */ }
  map[id] = parent;
  sessionStorage.setItem(PARENTS_KEY, JSON.stringify(map));
}

// ---------------------------------------------------------------- clone

let cloneParent = null, cloneDocument = null;

async function openClone(id) {
  const doc = await guarded(() => api.json("GET", `/cases/${id}/case`));
  if (!doc) return;
  closeView();
  cloneParent = id;
  cloneDocument = doc;
  $("clone-title").textContent = `Clone of ${cases.get(id).name} (${id})`;
  $("clone-text").value = JSON.stringify(doc, null, 2);
  $("clone-result").textContent = "";
  $("clone-panel").hidden = false;
  showCloneDiff();
}

function cloneEdit() {
  const after = JSON.parse($("clone-text").value);
  const problems = [], patch = mergePatch(cloneDocument, after, problems);
  if (problems.length) throw new Error("a merge patch cannot set null: " + problems.join(", "));
  return { after, patch };
}

function showCloneDiff() {
  try {
    const { after } = cloneEdit(), list = describe(changes(cloneDocument, after));
    $("clone-diff").textContent = list.length ? list.join("\n") : "no change yet";
  } catch (e) { $("clone-diff").textContent = "not valid JSON yet: " + e.message; }
}

async function sendClone(mode) {
  try {
    const { patch } = cloneEdit();
    const query = mode === "dry" ? "?dry_run=true" : mode === "start" ? "?start=true" : "";
    const r = await guarded(() => api.json("POST", `/cases/${cloneParent}/clone${query}`, patch));
    if (!r) return;
    if (mode === "dry") { $("clone-result").textContent = sizing(r); return; }
    rememberParent(r.id, cloneParent);
    cases.set(r.id, r);
    $("clone-panel").hidden = true;
    renderCases();
    openCase(r.id);
  } catch (e) { $("clone-result").textContent = problemText(e); }
}

// --------------------------------------------------------------- submit

function sizing(d) {
  const mb = b => (b / 1048576).toFixed(1) + " MiB";
  const lines = [`${d.nodes} nodes, ${d.elements} elements, ${d.joints} joints`,
    `${d.steps} steps of ${d.dt.toExponential(3)} s, ${d.snapshots} snapshots`,
    `memory ${mb(d.memory_bytes)}, result file ${mb(d.result_bytes)}`,
    `estimated ${formatSeconds(d.estimated_seconds)} (${d.estimated_seconds} s)`];
  if (d.warning) lines.push("warning: " + d.warning);
  (d.warnings || []).forEach(w => lines.push(`warning ${w.pointer}: ${w.message}`));
  return lines.join("\n");
}

let dryRanText = null;

async function submit(mode) {
  const text = $("submit-text").value;
  try {
    if (mode === "dry") {
      const d = await guarded(() => api.json("POST", "/cases?dry_run=true", text));
      if (!d) return;
      $("submit-result").textContent = "dry run:\n" + sizing(d);
      dryRanText = text;
    } else {
      const s = await guarded(() => api.json("POST", "/cases" + (mode === "start" ? "?start=true" : ""), text));
      if (!s) return;
      cases.set(s.id, s);
      $("submit-result").textContent = `stored as ${s.id} (${s.state})`;
      renderCases();
      if (live) live.nudge();
    }
  } catch (e) {
    $("submit-result").textContent = problemText(e);
    dryRanText = null;
  }
  $("submit-go").disabled = $("submit-go-start").disabled = dryRanText !== $("submit-text").value;
}

// ----------------------------------------------------------------- tabs

function showTab(name) {
  for (const p of document.querySelectorAll(".tab-panel")) p.hidden = p.id !== "tab-" + name;
  if (name === "compare") compare.refresh();
}

function checkedIds() {
  return [...document.querySelectorAll("#cases tbody tr")]
    .filter(tr => tr.querySelector("input").checked).map(tr => tr.dataset.id);
}

function init() {
  for (const b of document.querySelectorAll("button.tab")) b.addEventListener("click", () => showTab(b.dataset.tab));
  $("token-form").addEventListener("submit", ev => {
    ev.preventDefault();
    api.setToken($("token-input").value);
    $("token-input").value = "";
    startLive();
  });
  $("forget-token").addEventListener("click", () => { api.setToken(""); askToken(""); });
  $("submit-dry").addEventListener("click", () => submit("dry"));
  $("submit-go").addEventListener("click", () => submit("create"));
  $("submit-go-start").addEventListener("click", () => submit("start"));
  $("submit-text").addEventListener("input", () => {
    $("submit-go").disabled = $("submit-go-start").disabled = dryRanText !== $("submit-text").value;
  });
  $("submit-file").addEventListener("change", async ev => {
    const file = ev.target.files[0];
    if (file) { $("submit-text").value = await file.text(); $("submit-text").dispatchEvent(new Event("input")); }
  });
  $("clone-text").addEventListener("input", showCloneDiff);
  $("clone-dry").addEventListener("click", () => sendClone("dry"));
  $("clone-go").addEventListener("click", () => sendClone("create"));
  $("clone-go-start").addEventListener("click", () => sendClone("start"));
  $("clone-cancel").addEventListener("click", () => { $("clone-panel").hidden = true; });
  compare = new Compare(checkedIds, id => cases.get(id), guarded);
  startLive();
}

init();
