// api.js - the page's only way to the daemon: every request carries the
// token in the Authorization header (never in a URL: URLs end up in logs,
// history and Referer headers), and the live updates come from GET /stream
// when the daemon has it, else from polling GET /cases once a second.
//
// The token lives in sessionStorage: it survives a reload of the tab and
// goes when the tab closes. EventSource cannot send headers, so the stream
// is read with fetch() and parsed here (text/event-stream, WHATWG HTML
// section 9.2).

const TOKEN_KEY = "fdemd.token";

export class Unauthorized extends Error {}

export class ApiError extends Error {
  constructor(status, problem) {
    super(problem && problem.detail ? problem.detail : `HTTP ${status}`);
    this.status = status;
    this.problem = problem;
  }
}

export function token() { return sessionStorage.getItem(TOKEN_KEY) || ""; }
export function setToken(value) {
  if (value) sessionStorage.setItem(TOKEN_KEY, value);
  else sessionStorage.removeItem(TOKEN_KEY);
}

function headers(extra) {
  const h = Object.assign({}, extra || {});
  const t = token();
  if (t) h.Authorization = "Bearer " + t;
  return h;
}

// fetch() with the token; a 401 throws Unauthorized so the page can ask.
export async function request(method, path, body, contentType) {
  const init = { method, headers: headers(), cache: "no-store" };
  if (body !== undefined) {
    init.body = typeof body === "string" ? body : JSON.stringify(body);
    init.headers["Content-Type"] = contentType || "application/json";
  }
  const r = await fetch(path, init);
  if (r.status === 401) throw new Unauthorized();
  return r;
}

async function problemOf(r) {
  try { return await r.json(); } catch (e) { return null; }
}

export async function json(method, path, body, contentType) {
  const r = await request(method, path, body, contentType);
  if (r.status === 204) return null;
  if (!r.ok) throw new ApiError(r.status, await problemOf(r));
  return r.json();
}

export async function bytes(path) {
  const r = await request("GET", path);
  if (!r.ok) throw new ApiError(r.status, await problemOf(r));
  return r.arrayBuffer();
}

// A download with the token: the file is fetched, then handed to the
// browser as a blob URL (a plain link could not carry the header).
export async function download(path, filename) {
  const r = await request("GET", path);
  if (!r.ok) throw new ApiError(r.status, await problemOf(r));
  const url = URL.createObjectURL(await r.blob());
  const a = document.createElement("a");
  a.href = url;
  a.download = filename;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

// ------------------------------------------------------------ live updates

// Parses a text/event-stream body and calls onEvent(type, data, id) for
// each event. Resolves when the stream ends; rejects on a network error.
async function readEvents(body, onEvent, state) {
  const reader = body.pipeThrough(new TextDecoderStream()).getReader();
  let buffer = "", type = "", data = [], id = null;
  for (;;) {
    const { value, done } = await reader.read();
    if (done) return;
    buffer += value;
    let nl;
    while ((nl = buffer.search(/\r\n|\r|\n/)) >= 0) {
      const line = buffer.slice(0, nl);
      buffer = buffer.slice(nl + (buffer.startsWith("\r\n", nl) ? 2 : 1));
      if (line === "") {
        if (data.length) onEvent(type || "message", data.join("\n"), id);
        if (id !== null) state.lastId = id;
        type = ""; data = []; id = null;
        continue;
      }
      if (line.startsWith(":")) continue;
      const colon = line.indexOf(":");
      const field = colon < 0 ? line : line.slice(0, colon);
      let v = colon < 0 ? "" : line.slice(colon + 1);
      if (v.startsWith(" ")) v = v.slice(1);
      if (field === "event") type = v;
      else if (field === "data") data.push(v);
      else if (field === "id") id = v;
    }
  }
}

// Keeps the page current: handlers.status(statusObject),
// handlers.snapshot({id, index, time}), handlers.deleted({id}),
// handlers.list([status...]) (polling), handlers.mode("stream"|"polling").
// Tries the stream first and again every 30 s while polling.
export class Live {
  constructor(handlers) {
    this.h = handlers;
    this.state = { lastId: null };
    this.stopped = false;
    this.pollTimer = null;
    this.retryAt = 0;
  }

  start() { this.loop(); }

  async loop() {
    while (!this.stopped) {
      if (Date.now() >= this.retryAt) {
        if (await this.tryStream()) continue;
        if (this.stopped) return;
        this.retryAt = Date.now() + 30000;
      }
      this.h.mode("polling");
      try { this.h.list((await json("GET", "/cases")).cases); } catch (e) {
        if (e instanceof Unauthorized) { this.stopped = true; this.h.unauthorized(); return; }
      }
      await new Promise(r => { this.wake = r; this.pollTimer = setTimeout(r, 1000); });
      this.pollTimer = null;
    }
  }

  // true when a stream ran (and ended), false when the daemon has none.
  async tryStream() {
    let r;
    try {
      const h = headers({ Accept: "text/event-stream" });
      if (this.state.lastId !== null) h["Last-Event-ID"] = this.state.lastId;
      r = await fetch("/stream", { headers: h, cache: "no-store" });
    } catch (e) { return false; }
    if (r.status === 401) { this.stopped = true; this.h.unauthorized(); return false; }
    const type = r.headers.get("Content-Type") || "";
    if (!r.ok || !type.startsWith("text/event-stream")) {
      try { await r.body.cancel(); } catch (e) { /* nothing to release */ }
      return false;
    }
    this.h.mode("stream");
    // The stream says what changes; one list first gives the starting point.
    try { this.h.list((await json("GET", "/cases")).cases); } catch (e) { /* the stream follows */ }
    try {
      await readEvents(r.body, (ev, data, id) => {
        let o;
        try { o = JSON.parse(data); } catch (e) { return; }
        if (ev === "status") this.h.status(o);
        else if (ev === "snapshot") this.h.snapshot(o);
        else if (ev === "deleted") this.h.deleted(o);
      }, this.state);
    } catch (e) { /* cut: reconnect with Last-Event-ID below */ }
    await new Promise(res => setTimeout(res, 500));
    return true;
  }

  // Polling asks again now (after a command), instead of within a second.
  nudge() {
    if (!this.pollTimer) return;
    clearTimeout(this.pollTimer);
    this.pollTimer = null;
    this.wake();
  }

  stop() { this.stopped = true; this.nudge(); }
}
