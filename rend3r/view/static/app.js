// rend3r view: the page. Talks to the JSON endpoints of docs/view.md; nothing is fetched
// from anywhere else.
"use strict";

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("token");
let state = null;        // the last /api/status (or websocket message)
let picked = null;       // the clicked pixel [x, y]
let frameInfo = null;    // the last /api/frame

function url(path, params = {}) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) {
    for (const one of Array.isArray(v) ? v : [v]) if (one !== "" && one !== null && one !== undefined) q.append(k, one);
  }
  if (token) q.set("token", token);
  const s = q.toString();
  return path + (s ? "?" + s : "");
}

async function getJSON(path, params) {
  const r = await fetch(url(path, params));
  const body = await r.json();
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}

function showError(text) {
  $("error").hidden = !text;
  $("error").textContent = text || "";
}

function emuParams() {
  const quirks = [...document.querySelectorAll("#quirks input:checked")].map((e) => e.value);
  return { precision: $("precision").value.trim(), subnormals: $("subnormals").value, depth: $("depth").value,
           profile: $("profile").value, quirk: quirks, frame: $("frame").value };
}

function svoParams() {
  return { azimuth: $("azimuth").value, elevation: $("elevation").value, distance: $("distance").value,
           stack: $("stack").value, float: $("float").checked ? "1" : "0" };
}

function showStatus(st) {
  state = st;
  $("program").textContent = st.program;
  const badge = $("state");
  badge.textContent = st.ok ? `version ${st.version}` : (st.loaded ? `broken (showing version ${st.version})` : "broken");
  badge.className = "badge " + (st.ok ? "ok" : "broken");
  $("diagnostics").hidden = st.ok;
  $("diagnostics").textContent = st.message;
  $("rend3r-controls").hidden = st.kind !== "rend3r";
  $("svo-controls").hidden = st.kind !== "svo";
  $("fig-c").hidden = st.kind === "svo";
}

function setupControls(st) {
  const profile = $("profile");
  for (const p of st.profiles) profile.add(new Option(p, p));
  const quirks = $("quirks");
  for (const [name, summary] of Object.entries(st.quirks)) {
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "checkbox";
    box.value = name;
    label.append(box, " " + name);
    label.title = summary;
    quirks.append(label);
  }
  for (const el of document.querySelectorAll(".controls input, .controls select")) {
    el.addEventListener("change", () => refresh());
  }
  $("frame").addEventListener("input", () => { $("frame-number").textContent = $("frame").value; });
  for (const id of ["img-a", "img-b", "img-c"]) $(id).addEventListener("click", (ev) => pick(ev));
  window.addEventListener("resize", mark);
}

function loadImage(img, src) {
  return new Promise((resolve) => {
    const next = new Image();
    next.onload = () => { img.src = next.src; resolve(true); };
    next.onerror = () => resolve(false);
    next.src = src;
  });
}

async function refresh() {
  if (!state || !state.loaded) return;
  showError("");
  try {
    if (state.kind === "svo") await refreshSvo(); else await refreshFrames();
    mark();
    if (picked) await showPixel();
  } catch (e) {
    showError(e.message);
  }
}

async function refreshFrames() {
  const params = emuParams();
  const info = await getJSON("/api/frame", params);
  frameInfo = info;
  $("frame").max = info.frames - 1;
  $("frame-number").textContent = `${info.frame} of ${info.frames}`;
  const p = { ...params, frame: info.frame, v: info.version };
  await Promise.all([loadImage($("img-a"), url("/api/image/frame.png", p)),
                     loadImage($("img-b"), url("/api/image/fp64.png", p)),
                     loadImage($("img-c"), url("/api/image/diff.png", p))]);
  $("img-a").dataset.version = info.version;
  $("cap-a").textContent = `${info.label}, frame ${info.frame}`;
  $("cap-b").textContent = "fp64";
  $("cap-c").textContent = `difference: ${info.differing_pixels} of ${info.pixels} pixels, largest ${info.max_difference}`;
}

async function refreshSvo() {
  const p = { ...svoParams(), v: state.version };
  await Promise.all([loadImage($("img-a"), url("/api/svo/image/render.png", p)),
                     loadImage($("img-b"), url("/api/svo/image/cost.png", p))]);
  $("img-a").dataset.version = state.version;
  $("cap-a").textContent = "render";
  $("cap-b").textContent = "cost: memory requests per ray (white: the most)";
}

function pick(ev) {
  const img = ev.currentTarget;
  const r = img.getBoundingClientRect();  // the image's content box: inside its border
  const x = Math.floor((ev.clientX - r.left - img.clientLeft) * img.naturalWidth / img.clientWidth);
  const y = Math.floor((ev.clientY - r.top - img.clientTop) * img.naturalHeight / img.clientHeight);
  picked = [Math.min(Math.max(x, 0), img.naturalWidth - 1), Math.min(Math.max(y, 0), img.naturalHeight - 1)];
  mark();
  showPixel().catch((e) => showError(e.message));
}

function mark() {
  // outline the picked pixel on each image (shown at whatever scale the page gives it)
  for (const img of document.querySelectorAll("#images img")) {
    const marker = img.nextElementSibling;
    marker.hidden = !picked || !img.naturalWidth || img.parentElement.hidden;
    if (marker.hidden) continue;
    const sx = img.clientWidth / img.naturalWidth, sy = img.clientHeight / img.naturalHeight;
    marker.style.left = `${img.offsetLeft + img.clientLeft + picked[0] * sx}px`;
    marker.style.top = `${img.offsetTop + img.clientTop + picked[1] * sy}px`;
    marker.style.width = `${sx}px`;
    marker.style.height = `${sy}px`;
  }
}

function cell(row, text) {
  const td = document.createElement("td");
  td.textContent = text === null || text === undefined ? "" : String(text);
  row.append(td);
}

function table(headers, rows) {
  const t = $("history");
  t.hidden = false;
  t.tHead.replaceChildren();
  const hr = t.tHead.insertRow();
  for (const h of headers) { const th = document.createElement("th"); th.textContent = h; hr.append(th); }
  t.tBodies[0].replaceChildren(...rows);
}

async function showPixel() {
  const [x, y] = picked;
  if (state.kind === "svo") return showRay(x, y);
  const h = await getJSON("/api/pixel", { ...emuParams(), x, y, shapes: $("all-shapes").checked ? "all" : "" });
  $("pixel-title").textContent = `pixel ${x},${y}, frame ${h.frame}`;
  const first = h.first_divergence === null ? "none" : describe(h.records[h.first_divergence]);
  const decision = h.first_decision === null ? "none" : describe(h.records[h.first_decision]);
  $("pixel-summary").textContent = `${h.label} against fp64. Shapes: ${h.shapes} considered, ${h.shapes_shown} shown. ` +
    `First divergence: ${first}. First different decision: ${decision}. ` + hitsText(h);
  let inPixel = false;
  const rows = h.records.map((r, i) => {
    const tr = document.createElement("tr");
    tr.dataset.index = i;
    tr.dataset.stage = r.stage;
    tr.dataset.shape = r.shape === null ? "" : r.shape;
    if (r.diverges) tr.classList.add("diverges");
    if (i === h.first_divergence) tr.classList.add("first");
    if (i === h.first_decision) tr.classList.add("decision");
    if (r.stage === "nearest") inPixel = true;
    if (inPixel) tr.classList.add("pixel");
    for (const v of [r.shape, r.stage, r.hex, r.dec, r.fp64 && r.fp64.hex, r.fp64 && r.fp64.dec]) cell(tr, v);
    return tr;
  });
  table(["shape", "stage", "hex", "dec", "fp64 hex", "fp64 dec"], rows);
}

function hitsText(h) {
  if (h.hits === null) return `Nearest: ${h.tie_rule}.`;
  if (!h.hits.length) return "No shape hit.";
  const shown = h.hits.slice(0, 12).map((x) => `${x.shape} (sq_dist ${x.sq_dist}, fp64 ${x.fp64_sq_dist ?? "no hit"})`);
  const more = h.hits.length > 12 ? `, and ${h.hits.length - 12} more` : "";
  return `Hits, nearest first: ${shown.join(", ")}${more}. Rule: ${h.tie_rule}.`;
}

function describe(r) {
  return `${r.shape === null ? "pixel" : "shape " + r.shape} ${r.stage}: ${r.dec} (fp64 ${r.fp64 ? r.fp64.dec : "absent"})`;
}

async function showRay(x, y) {
  const r = await getJSON("/api/svo/ray", { ...svoParams(), x, y });
  $("pixel-title").textContent = `ray ${x},${y}`;
  $("pixel-summary").textContent = (r.hit ? `hit voxel ${r.voxel.join(",")} at distance ${r.distance.toPrecision(6)}` : "miss") +
    `; ${r.requests} memory requests, ${r.steps} steps, ${r.pushes} pushes, ${r.pops} pops, ${r.restarts} restarts, ` +
    `deepest level ${r.max_level}, most stack entries ${r.max_stack}` + (r.nodes_cut ? ` (${r.nodes_cut} requests not listed)` : "");
  const rows = r.nodes.map((n, i) => {
    const tr = document.createElement("tr");
    for (const v of [i, n.address, n.level]) cell(tr, v);
    return tr;
  });
  table(["request", "word address", "level"], rows);
}

function connect() {
  const ws = new WebSocket(url(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/api/live`));
  ws.onmessage = (ev) => {
    const st = JSON.parse(ev.data);
    const changed = !state || st.version !== state.version;
    showStatus(st);
    if (changed) refresh();
  };
  ws.onclose = () => setTimeout(connect, 1000);
}

async function main() {
  try {
    const st = await getJSON("/api/status");
    showStatus(st);
    setupControls(st);
    await refresh();
  } catch (e) {
    showError(e.message);
  }
  connect();
}

main();
