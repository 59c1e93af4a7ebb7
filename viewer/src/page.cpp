#include "page.h"

namespace viewer {

// Drag rotates the environment (shift-drag, or the "camera" drag mode, orbits the camera),
// the wheel zooms. A surface light field (/api/info's kind "slf") has its lighting baked: the
// page hides what only PRT can change (environment, probe, modes, overlays, compressions),
// drag and the arrow keys orbit the camera, and requests carry only what it can show. One request
// at a time: input while a frame is on its way only marks the view dirty, and the next request
// carries the newest state (the server coalesces too). Latency per frame = queue + render + overlay
// + encode (the server's X-Prtr-Frame header)
// + transfer (the rest of the time from sending the request to the decoded image).
const char* view_page_html() {
  return R"PAGE(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>prtr view</title>
<style>
body { font: 13px sans-serif; margin: 0; display: flex; background: #222; color: #ddd; }
#view { flex: none; padding: 8px; }
#frame { display: block; background: #000; cursor: grab; user-select: none; }
#panel { padding: 8px 12px; min-width: 300px; max-height: 100vh; overflow-y: auto;
  box-sizing: border-box; }
fieldset { border: 1px solid #555; margin: 0 0 8px 0; }
label { display: block; margin: 3px 0; }
table { border-collapse: collapse; }
td { padding: 1px 6px 1px 0; vertical-align: top; }
td:first-child { color: #999; }
#stat-error, .refused { color: #f77; }
.slf-only, body.slf .prt-only { display: none; }
body.slf .slf-only { display: revert; }
#about { margin: 0 0 8px 0; }
</style></head>
<body>
<div id="view"><img id="frame" alt="relit mesh" draggable="false"></div>
<div id="panel">
<fieldset class="slf-only"><legend>About</legend><div id="about"></div></fieldset>
<fieldset><legend>Interaction</legend>
<label class="prt-only"><input type="radio" name="drag" value="env" id="drag-env" checked> drag rotates the environment</label>
<label class="prt-only"><input type="radio" name="drag" value="cam" id="drag-cam"> drag orbits the camera</label>
<div><span class="prt-only">shift-drag does the other;</span><span class="slf-only">drag orbits
the camera (the lighting is baked);</span> the wheel zooms. <button id="reset">reset view</button></div>
<label class="prt-only"><input type="checkbox" id="autorotate"> auto-rotate the environment</label>
<div class="prt-only">keys: arrows turn the environment (shift: orbit the camera), + and - zoom, space
auto-rotates, r resets</div>
<div class="slf-only">keys: arrows orbit the camera, + and - zoom, r resets</div>
</fieldset>
<fieldset><legend>Rendering</legend>
<div class="prt-only">
<label>mode <select id="mode"></select></label>
<label>super-clusters <select id="strategy"></select></label>
<label>register budget <input id="budget" type="number" min="0" step="1" value="0"> (0: the context's)</label>
<div class="refused" id="refused-budget"></div>
<label>clusters per pass <input id="cpp" type="number" min="0" step="1" value="0"> (0: all that fit)</label>
<div class="refused" id="refused-cpp"></div>
<label>clusters <input id="clusters" type="number" min="1" step="1"> PCs <input id="pcs" type="number" min="1" step="1"> SH order <input id="order" type="number" min="1" step="1"></label>
<div class="refused" id="refused-clusters"></div><div class="refused" id="refused-pcs"></div><div class="refused" id="refused-order"></div>
<div id="compress-status"></div>
</div>
<label>size <select id="size"></select></label>
<label><input type="checkbox" id="antialias" checked> anti-alias the still image (<span id="antialias-samples">2 × 2</span> samples once the view stops)</label>
<div class="refused" id="refused-size"></div>
</fieldset>
<fieldset><legend>Lighting</legend>
<label class="prt-only">probe <select id="probe"></select></label>
<div class="slf-only">probe <span id="slf-probe"></span> (baked into the light field)</div>
<label>exposure <input id="exposure" type="range" min="-6" max="6" step="0.25" value="0"> <span id="exposure-value">0</span></label>
</fieldset>
<fieldset class="prt-only" id="overlays"><legend>Overlays</legend>
<label><input type="checkbox" id="overlay-overdraw"> overdraw (passes per triangle)</label>
<label><input type="checkbox" id="overlay-clusters"> clusters</label>
<label><input type="checkbox" id="overlay-difference"> difference from the uncompressed transfer (red: 10 % or more)</label>
</fieldset>
<fieldset><legend>Statistics</legend><table>
<tr><td>render FPS</td><td id="stat-render-fps">-</td></tr>
<tr><td>end-to-end FPS</td><td id="stat-e2e-fps">-</td></tr>
<tr><td>latency (ms)</td><td id="stat-latency">-</td></tr>
<tr class="prt-only"><td>environment</td><td id="stat-env">-</td></tr>
<tr><td>camera</td><td id="stat-cam">-</td></tr>
<tr class="prt-only"><td>mode</td><td id="stat-mode">-</td></tr>
<tr><td>samples per pixel</td><td id="stat-aa">-</td></tr>
<tr class="prt-only"><td>passes</td><td id="stat-passes">-</td></tr>
<tr class="prt-only"><td>average overdraw</td><td id="stat-overdraw">-</td></tr>
<tr class="prt-only"><td>clusters per pass</td><td id="stat-cpp">-</td></tr>
<tr class="prt-only"><td>register budget</td><td id="stat-budget">-</td></tr>
<tr><td>clusters</td><td id="stat-clusters">-</td></tr>
<tr><td><span class="prt-only">PCs</span><span class="slf-only">PCA terms (k)</span></td><td id="stat-pcs">-</td></tr>
<tr class="prt-only"><td>order</td><td id="stat-order">-</td></tr>
<tr class="prt-only"><td>Average SE</td><td id="stat-se">-</td></tr>
<tr class="prt-only"><td>difference</td><td id="stat-difference">-</td></tr>
<tr><td>mesh</td><td id="stat-mesh">-</td></tr>
<tr><td>renderer</td><td id="stat-gl">-</td></tr>
<tr><td>llvmpipe threads</td><td id="stat-threads">-</td></tr>
<tr><td>frames shown</td><td id="stat-frames">0</td></tr>
<tr><td>error</td><td id="stat-error"></td></tr>
</table></fieldset>
</div>
<script>
"use strict";
const $ = (id) => document.getElementById(id);
const client = "c" + Math.random().toString(36).slice(2, 12);
const urlParams = new URLSearchParams(location.search);
const state = { w: 960, h: 710, env_yaw: 0, env_pitch: 0, cam_yaw: 0, cam_pitch: 0, zoom: 1,
  mode: "decoupled", strategy: "greedy-refine", budget: 0, cpp: 0, probe: 0, exposure: 0,
  overlay: "none", aa: 1, clusters: 0, pcs: 0, order: 0 };
let seq = 0, inflight = false, dirty = true, shown = 0, objectUrl = null;
let slf = false;         // a surface light field: the camera is all that moves
// What a surface light field's request carries: the rest is PRT's (the server refuses it).
const slfKeys = ["w", "h", "cam_yaw", "cam_pitch", "zoom", "exposure", "aa"];
let good = null;         // the last state that rendered: a refused setting falls back to it
let stillSamples = 2;    // prtr view --supersample: samples per pixel of a still view
// Which control sets a query parameter, so that a refusal is shown beside it.
const controlOf = { budget: "budget", cpp: "cpp", w: "size", h: "size", mode: "mode",
  strategy: "strategy", probe: "probe", exposure: "exposure", clusters: "clusters", pcs: "pcs",
  order: "order" };
let launch = null;       // the launch compression's clusters, PCs and Average SE (/api/info)
const log = [];          // per frame: {sent, shown, queue, render, overlay, encode, transfer}
window.prtrLog = log;    // read by the measurement script

const sizes = [[320, 237], [480, 355], [640, 474], [960, 710], [1280, 948]];
function wrap(a) { a = ((a + 180) % 360 + 360) % 360 - 180; return Math.round(a * 100) / 100; }
function clamp(x, lo, hi) { return Math.min(hi, Math.max(lo, x)); }
// Any change renders one sample per pixel at once; when the view has stopped, the same view
// is rendered again anti-aliased (4x the render, once).
function changed() { state.aa = 1; dirty = true; pump(); }

function query() {
  const q = new URLSearchParams({ client: client, seq: String(++seq) });
  for (const [k, v] of Object.entries(state))
    if (!slf || slfKeys.includes(k)) q.set(k, String(v));
  return q.toString();
}

// Shows a control's value as the state holds it (a typed -5 becomes the 0 in use).
function syncControl(id) {
  if (id === "size") $("size").value = fitWindow ? "window" : state.w + "x" + state.h;
  else if (id === "exposure") { $("exposure").value = state.exposure; $("exposure-value").textContent = state.exposure.toFixed(2); }
  else if (id in state) $(id).value = String(state[id]);
}

// A 400 names the parameter first ("budget=100: ..."): that setting goes back to the last
// one that rendered, its control says why beside it, and the view carries on.
function refuse(status, message, sentState) {
  const key = (message.match(/^([a-z_]+)=/) || [])[1];
  const id = controlOf[key];
  if (status !== 400 || !good || !id || state[key] !== sentState[key]) {
    $("stat-error").textContent = status + ": " + message;
    return;
  }
  for (const k of Object.keys(controlOf)) if (controlOf[k] === id) state[k] = good[k];
  syncControl(id);
  const place = $("refused-" + id) || $("stat-error");
  place.textContent = message.replace(/^[a-z_]+=/, "").replace(/\n$/, "") +
      " (back to " + (id === "size" ? state.w + " x " + state.h : state[key]) + ")";
  dirty = true;
}

async function pump() {
  if (inflight || !dirty) return;
  dirty = false; inflight = true;
  const sent = performance.now();
  const sentState = Object.assign({}, state);
  try {
    const r = await fetch("/frame?" + query(), { cache: "no-store" });
    if (!r.ok) refuse(r.status, await r.text(), sentState);
    else {
      good = sentState;
      const f = JSON.parse(r.headers.get("X-Prtr-Frame"));
      const blob = await r.blob();
      const url = URL.createObjectURL(blob);
      const img = $("frame");
      img.src = url;
      await img.decode();
      if (objectUrl) URL.revokeObjectURL(objectUrl);
      objectUrl = url;
      const now = performance.now();
      const server = f.queue_ms + f.render_ms + f.overlay_ms + f.encode_ms;
      log.push({ sent: sent, shown: now, queue: f.queue_ms, render: f.render_ms,
                 frame: f.frame_ms, readback: f.readback_ms, overlay: f.overlay_ms, encode: f.encode_ms,
                 transfer: Math.max(0, now - sent - server), total: now - sent });
      if (log.length > 2000) log.splice(0, 1000);
      showStats(f, now - sent, server);
      showCompression(f);
      $("stat-error").textContent = "";
    }
  } catch (e) { $("stat-error").textContent = String(e); }
  inflight = false;
  if (dirty) pump();
  else refineStill();
}

// The view has stopped (nothing in flight or waiting, no drag, no auto-rotation): render the
// last frame's view again with 2 x 2 samples per pixel, once.
function refineStill() {
  if (inflight || dirty || !good || good.aa !== 1 || state.aa !== 1 || drag ||
      !$("antialias").checked || $("autorotate").checked) return;
  state.aa = stillSamples;
  dirty = true;
  pump();
}

// Another compression is made in the background while the last ready one stays on screen:
// its progress is shown, and the view is asked for again until it arrives.
let compressPoll = null;
function showCompression(f) {
  $("stat-clusters").textContent = String(f.clusters);
  $("stat-pcs").textContent = String(f.pcs);
  $("stat-order").textContent = String(f.order);
  const atLaunch = launch && f.clusters === launch.clusters && f.pcs === launch.pcs &&
      f.order === launch.order;
  $("stat-se").textContent = atLaunch ? launch.average_se.toPrecision(4) : "-";
  const asked = (state.clusters || f.clusters) + " × " + (state.pcs || f.pcs) + ", order " +
      (state.order || f.order);
  // Another order bakes before it compresses.
  $("compress-status").textContent = f.compressing
      ? (state.order && state.order !== f.order ? "baking and compressing " : "compressing ") +
        asked + ": " + Math.round(100 * f.compress_progress) + " % (showing " + f.clusters +
        " × " + f.pcs + ", order " + f.order + ")" : "";
  // Cleared when the field changes, so a refusal the server gave stays readable meanwhile.
  if (f.compress_error) $("refused-clusters").textContent = asked + ": " + f.compress_error;
  if (f.compressing && !compressPoll)
    compressPoll = setTimeout(() => { compressPoll = null; dirty = true; pump(); }, 400);
}

function showStats(f, total, server) {
  shown += 1;
  $("stat-frames").textContent = String(shown);
  $("stat-render-fps").textContent = (1000 / Math.max(f.frame_ms, 1e-3)).toFixed(1) +
      " (frame " + f.frame_ms.toFixed(1) + " ms)";
  const now = performance.now();
  const recent = log.filter((e) => now - e.shown < 2000);
  const span = recent.length > 1 ? (recent[recent.length - 1].shown - recent[0].shown) : 0;
  $("stat-e2e-fps").textContent = span > 0 ? ((recent.length - 1) * 1000 / span).toFixed(1) : "-";
  $("stat-latency").textContent = total.toFixed(0) + " = queue " + f.queue_ms.toFixed(0) +
      " + render " + f.render_ms.toFixed(0) + " + overlay " + f.overlay_ms.toFixed(0) +
      " + encode " + f.encode_ms.toFixed(0) + " + transfer " + Math.max(0, total - server).toFixed(0);
  $("stat-env").textContent = "yaw " + f.env_yaw.toFixed(1) + "°, pitch " + f.env_pitch.toFixed(1) + "°";
  $("stat-cam").textContent = "yaw " + f.cam_yaw.toFixed(1) + "°, pitch " + f.cam_pitch.toFixed(1) +
      "°, zoom " + f.zoom.toFixed(2);
  $("stat-mode").textContent = f.mode + (f.mode === "multipass" || f.mode === "decoupled" ? " / " + f.strategy : "");
  $("stat-passes").textContent = String(f.passes);
  $("stat-aa").textContent = f.aa + " × " + f.aa;
  $("stat-difference").textContent = f.overlay === "difference"
      ? "RMS " + (100 * f.difference_rms).toFixed(2) + " %, max " + (100 * f.difference_max).toFixed(1) + " %"
      : "-";
  $("stat-overdraw").textContent = f.average_overdraw.toFixed(3);
  $("stat-cpp").textContent = String(f.clusters_per_pass);
  $("stat-budget").textContent = String(f.register_budget);
}

let drag = null;
$("frame").addEventListener("mousedown", (e) => {
  e.preventDefault();
  const camera = slf || $("drag-cam").checked !== e.shiftKey;
  drag = { x: e.clientX, y: e.clientY, camera: camera };
});
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.camera) {
    state.cam_yaw = wrap(state.cam_yaw - dx * 0.4);
    state.cam_pitch = clamp(Math.round((state.cam_pitch + dy * 0.4) * 100) / 100, -89, 89);
  } else {
    state.env_yaw = wrap(state.env_yaw + dx * 0.4);
    state.env_pitch = wrap(state.env_pitch + dy * 0.4);
  }
  changed();
});
window.addEventListener("mouseup", () => { drag = null; refineStill(); });
$("antialias").addEventListener("change", () => { if (!$("antialias").checked) changed(); else refineStill(); });

// Auto-rotation turns the environment 30 degrees a second of wall time, one step per
// animation frame; the page still sends a request only when the last image is shown.
let lastTick = performance.now();
function tick(now) {
  const dt = Math.min(0.1, Math.max(0, now - lastTick) / 1000);
  lastTick = now;
  if ($("autorotate").checked && !drag && !slf) {
    state.env_yaw = wrap(state.env_yaw + 30 * dt);
    changed();
  }
  requestAnimationFrame(tick);
}
requestAnimationFrame(tick);

window.addEventListener("keydown", (e) => {
  const tag = e.target && e.target.tagName;
  if (tag === "INPUT" || tag === "SELECT" || tag === "BUTTON") return;
  const step = e.key === "ArrowLeft" || e.key === "ArrowUp" ? -5 : 5;
  const camera = e.shiftKey || slf;
  switch (e.key) {
    case "ArrowLeft": case "ArrowRight":
      if (camera) state.cam_yaw = wrap(state.cam_yaw - step);
      else state.env_yaw = wrap(state.env_yaw + step);
      break;
    case "ArrowUp": case "ArrowDown":
      if (camera) state.cam_pitch = clamp(state.cam_pitch + step, -89, 89);
      else state.env_pitch = wrap(state.env_pitch + step);
      break;
    case "+": case "=": state.zoom = clamp(Math.round(state.zoom * 1100) / 1000, 0.1, 20); break;
    case "-": case "_": state.zoom = clamp(Math.round(state.zoom / 1.1 * 1000) / 1000, 0.1, 20); break;
    case " ": if (slf) return; $("autorotate").checked = !$("autorotate").checked; break;  // changed() below
    case "r": $("reset").click(); break;
    default: return;
  }
  e.preventDefault();
  changed();
});
$("frame").addEventListener("wheel", (e) => {
  e.preventDefault();
  state.zoom = clamp(Math.round(state.zoom * Math.exp(-e.deltaY * 0.001) * 1000) / 1000, 0.1, 20);
  changed();
}, { passive: false });
$("reset").addEventListener("click", () => {
  Object.assign(state, { env_yaw: 0, env_pitch: 0, cam_yaw: 0, cam_pitch: 0, zoom: 1 });
  changed();
});

function bindSelect(id, key, parse) {
  $(id).addEventListener("change", () => { state[key] = parse($(id).value); changed(); });
}
bindSelect("mode", "mode", String);
bindSelect("strategy", "strategy", String);
bindSelect("probe", "probe", Number);
for (const [id, key] of [["budget", "budget"], ["cpp", "cpp"], ["clusters", "clusters"], ["pcs", "pcs"],
                         ["order", "order"]])
  $(id).addEventListener("change", () => {
    const least = key === "clusters" || key === "pcs" || key === "order" ? 1 : 0;
    state[key] = Math.max(least, Math.floor(Number($(id).value) || 0));
    $(id).value = String(state[key]);
    $("refused-" + id).textContent = "";
    changed();
  });
// "fit the window": the frame fills what the panel leaves, at the device pixel ratio, within
// the server's 4096-pixel sides and 8 M pixels; it follows every resize.
let fitWindow = false;
function fitSize() {
  const dpr = window.devicePixelRatio || 1;
  const cssW = Math.max(16, window.innerWidth - $("panel").offsetWidth - 16);
  const cssH = Math.max(16, window.innerHeight - 16);
  let w = Math.round(cssW * dpr), h = Math.round(cssH * dpr);
  const s = Math.min(1, 4096 / w, 4096 / h, Math.sqrt(4096 * 2048 / (w * h)));
  w = Math.max(16, Math.floor(w * s)); h = Math.max(16, Math.floor(h * s));
  $("frame").style.width = cssW + "px"; $("frame").style.height = cssH + "px";
  if (w !== state.w || h !== state.h) { state.w = w; state.h = h; changed(); }
}
window.addEventListener("resize", () => { if (fitWindow) fitSize(); });
function chooseSize(value) {
  fitWindow = value === "window";
  $("refused-size").textContent = "";
  if (fitWindow) { fitSize(); return; }
  $("frame").style.width = ""; $("frame").style.height = "";
  const [w, h] = value.split("x").map(Number);
  state.w = w; state.h = h; changed();
}
$("size").addEventListener("change", () => chooseSize($("size").value));
$("exposure").addEventListener("input", () => {
  state.exposure = Number($("exposure").value);
  $("exposure-value").textContent = state.exposure.toFixed(2);
  changed();
});
// One overlay at a time: checking one unchecks the others.
const overlays = ["overdraw", "clusters", "difference"];
for (const name of overlays)
  $("overlay-" + name).addEventListener("change", () => {
    for (const other of overlays) if (other !== name) $("overlay-" + other).checked = false;
    state.overlay = $("overlay-" + name).checked ? name : "none";
    changed();
  });

function fill(id, values, selected) {
  const sel = $(id);
  values.forEach((v, i) => {
    const o = document.createElement("option");
    o.value = Array.isArray(v) ? v[0] : v; o.textContent = Array.isArray(v) ? v[1] : v;
    if (o.value === String(selected)) o.selected = true;
    sel.appendChild(o);
  });
}

// A surface light field: the PRT controls are hidden and disabled, dragging orbits the
// camera, and the about box says what was baked.
function startSlf(info) {
  slf = true;
  document.body.classList.add("slf");
  $("drag-cam").checked = true;
  $("autorotate").checked = false;
  for (const id of ["drag-env", "autorotate", "mode", "strategy", "budget", "cpp", "clusters", "pcs",
                    "order", "probe", "overlay-overdraw", "overlay-clusters", "overlay-difference"])
    $(id).disabled = true;
  $("about").textContent = "surface light field " + info.slfc + " of " + info.mesh + ": k = " +
      info.components + " PCA terms, " + info.clusters + " clusters, " + info.texels +
      " texels (" + info.atlas_width + " × " + info.atlas_height + " atlas), " +
      info.directions + " " + info.direction_space + " directions (" + info.azimuth + " × " +
      info.elevation + ")";
  $("slf-probe").textContent = info.probe_name;
  $("stat-clusters").textContent = String(info.clusters);
  $("stat-pcs").textContent = String(info.components);
}

function startPrt(info) {
  state.mode = info.defaults.mode; state.strategy = info.defaults.strategy;
  if (urlParams.has("mode")) state.mode = urlParams.get("mode");
  fill("mode", info.modes, state.mode);
  fill("strategy", info.strategies, state.strategy);
  fill("probe", info.probes.map((p, i) => [String(i), p]), state.probe);
  $("stat-clusters").textContent = String(info.clusters);
  $("stat-pcs").textContent = String(info.pcs);
  launch = { clusters: info.clusters, pcs: info.pcs, order: info.order,
    average_se: info.average_se };
  state.clusters = info.clusters; state.pcs = info.pcs; state.order = info.order;
  $("clusters").value = String(info.clusters); $("pcs").value = String(info.pcs);
  $("order").value = String(info.order);
  $("clusters").max = String(info.max_clusters); $("pcs").max = String(info.max_pcs);
  $("order").max = String(info.max_order);
  $("stat-order").textContent = String(info.order);
  $("stat-se").textContent = info.average_se.toPrecision(4);
}

async function start() {
  const info = await (await fetch("/api/info")).json();
  state.probe = info.defaults.probe; state.exposure = info.defaults.exposure;
  state.w = info.defaults.width; state.h = info.defaults.height;
  stillSamples = info.still_samples;
  if (stillSamples < 2) { $("antialias").checked = false; $("antialias").disabled = true; }
  $("antialias-samples").textContent = stillSamples + " × " + stillSamples;
  if (urlParams.has("w")) state.w = Number(urlParams.get("w"));
  if (urlParams.has("h")) state.h = Number(urlParams.get("h"));
  if (info.kind === "slf") startSlf(info);
  else startPrt(info);
  const s = [["window", "fit the window"]].concat(sizes.map(([w, h]) => [w + "x" + h, w + " × " + h]));
  if (!sizes.some(([w, h]) => w === state.w && h === state.h))
    s.unshift([state.w + "x" + state.h, state.w + " × " + state.h]);
  fill("size", s, state.w + "x" + state.h);
  $("exposure").value = String(state.exposure);
  $("exposure-value").textContent = state.exposure.toFixed(2);
  $("stat-mesh").textContent = info.mesh + " (" + info.vertices + " vertices)";
  $("stat-gl").textContent = info.gl_renderer;
  $("stat-threads").textContent = info.llvmpipe_threads + " (" + info.llvmpipe_threads_source + ")";
  if (urlParams.get("size") === "window") { $("size").value = "window"; chooseSize("window"); }
  changed();
}
start().catch((e) => { $("stat-error").textContent = String(e); });
</script>
</body></html>
)PAGE";
}

}  // namespace viewer
