// The viewer's one page (HTML, CSS and JavaScript), compiled into the binary so that nothing
// is fetched at view time. It draws the frames the server streams, sends the camera as the
// mouse orbits (drag), pans (right or shift drag) and dollies (wheel), and the controls' values;
// it asks for the next frame only when it has drawn the last. window.envgiTest exposes its
// state to the browser test.
#pragma once

namespace envgi {

inline constexpr const char* kViewerPage = R"envgipage(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>envgi view</title>
<style>
  body { margin: 0; background: #1e1e1e; color: #ddd; font: 13px system-ui, sans-serif; display: flex; }
  #view { flex: 1; display: flex; align-items: center; justify-content: center; height: 100vh; }
  /* Scaled to fit the window whatever the render's size (the resolution control). */
  #frame { width: 100%; height: 100vh; object-fit: contain; cursor: grab; transform-origin: 0 0; }
  #frame.zoomed { image-rendering: pixelated; }
  #panel { width: 250px; padding: 10px; background: #2a2a2a; height: 100vh; box-sizing: border-box; overflow-y: auto; }
  #panel label { display: block; margin-top: 10px; }
  #panel input[type=range], #panel select { width: 100%; }
  #stats { font-family: monospace; white-space: pre; margin-top: 12px; color: #9c9; }
  #message { margin-top: 10px; color: #fc6; word-break: break-all; }
  button { margin-top: 12px; width: 100%; }
  #view { overflow: hidden; position: relative; }
  #progress { width: 100%; height: 6px; margin-top: 10px; }
  #status { margin-top: 10px; color: #8cf; }
  #status button { margin-top: 4px; }
  #pixel { font-family: monospace; white-space: pre; margin-top: 8px; color: #ccc; }
</style>
</head>
<body>
<div id="view"><img id="frame" alt="rendering" draggable="false"></div>
<div id="panel">
  <b id="title">envgi</b>
  <label>Exposure <span id="exposureValue">0</span>
    <input id="exposure" type="range" min="-8" max="8" step="0.1" value="0"></label>
  <label>View <select id="tonemap"><option value="clamp">clamp</option><option value="aces">ACES</option>
    <option value="falsecolor">false colour (log2 luminance)</option></select></label>
  <label>Integrator <select id="integrator"></select></label>
  <label><input id="gridWhileMoving" type="checkbox"> grid while the camera moves</label>
  <label>Strategy <select id="strategy"></select></label>
  <label>Environment rotation <span id="rotationValue">0</span>&deg;
    <input id="rotation" type="range" min="-180" max="180" step="1" value="0"></label>
  <label>Environment scale <input id="envScale" type="number" min="0" step="0.1" value="1"></label>
  <label>Resolution <select id="resolution">
    <option value="0.25">25%</option><option value="0.5">50%</option><option value="1" selected>100%</option><option value="2">200%</option></select></label>
  <label>Noise threshold (0: off) <input id="noiseThreshold" type="number" min="0" max="10" step="0.005" value="0"></label>
  <progress id="progress" max="1" value="0"></progress>
  <button id="pause">Pause</button>
  <button id="save">Save EXR + PNG</button>
  <div id="status"></div>
  <div id="pixel"></div>
  <div id="stats">connecting...</div>
  <div id="message"></div>
</div>
<script>
"use strict";
const T = window.envgiTest = { frames: 0, lastMeta: null, lastHash: 0, errors: [], saved: null, cameraSent: 0, latencyMs: null,
                               latencies: [], frameTimes: [], status: null, connects: 0, opened: performance.now() };
window.addEventListener("error", e => T.errors.push(String(e.message)));
const $ = id => document.getElementById(id);
const img = $("frame");
let ws, hello, cam, version = 0, pendingMeta = null, sendTimes = {}, lastUrl = null, cameraQueued = false, takenOver = false;

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = a => mul(a, 1 / Math.hypot(a[0], a[1], a[2]));
// Rodrigues: v rotated by angle about unit axis k.
const rot = (v, k, a) => add(add(mul(v, Math.cos(a)), mul(cross(k, v), Math.sin(a))), mul(k, dot(k, v) * (1 - Math.cos(a))));

function send(obj) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(obj)); }
function showMessage(text) { $("message").textContent = text; }

// With "grid while the camera moves": the fast grid method during a move, the chosen
// integrator again 300 ms after the last one (the server keeps both prepared).
let moving = false, stopTimer = null;
function noteMove() {
  if (!$("gridWhileMoving").checked || $("integrator").value === "grid") return;
  if (!moving) { moving = true; send({ type: "integrator", value: "grid" }); }
  clearTimeout(stopTimer);
  stopTimer = setTimeout(() => { moving = false; send({ type: "integrator", value: $("integrator").value }); }, 300);
}

function sendCamera() {
  noteMove();
  if (cameraQueued) return;
  cameraQueued = true;
  requestAnimationFrame(() => {
    cameraQueued = false;
    version += 1;
    sendTimes[version] = performance.now();
    T.cameraSent = version;
    send({ type: "camera", origin: cam.origin, target: cam.target, up: cam.up, version: version });
  });
}

function orbit(dx, dy) {
  const up = norm(cam.up);
  let off = sub(cam.origin, cam.target);
  off = rot(off, up, -dx * 0.008);
  const right = norm(cross(off, up));
  const tilted = rot(off, right, dy * 0.008);
  if (Math.abs(dot(norm(tilted), up)) < 0.98) off = tilted;
  cam.origin = add(cam.target, off);
  sendCamera();
}
function pan(dx, dy) {
  const off = sub(cam.origin, cam.target), dist = Math.hypot(off[0], off[1], off[2]);
  const fwd = norm(mul(off, -1)), right = norm(cross(fwd, cam.up)), up = cross(right, fwd);
  const s = dist * 2 * hello.tanHalfY / img.clientHeight;
  const d = add(mul(right, -dx * s), mul(up, dy * s));
  cam.origin = add(cam.origin, d);
  cam.target = add(cam.target, d);
  sendCamera();
}
function dolly(f) {
  cam.origin = add(cam.target, mul(sub(cam.origin, cam.target), f));
  sendCamera();
}

let drag = null;
img.addEventListener("mousedown", e => {
  drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, image: e.button === 1 };
  e.preventDefault();
});
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => {
  if (!drag || !cam) return;
  if (drag.image) {
    zoom.x += e.clientX - drag.x; zoom.y += e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    applyZoom();
    return;
  }
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) pan(dx, dy); else orbit(dx, dy);
});
img.addEventListener("contextmenu", e => e.preventDefault());
// Wheel dollies the camera; Ctrl+wheel zooms the picture about the cursor (pixels drawn as
// squares), middle-drag pans it, 0 resets it.
let zoom = { s: 1, x: 0, y: 0 };
function applyZoom() {
  img.style.transform = `translate(${zoom.x}px, ${zoom.y}px) scale(${zoom.s})`;
  img.classList.toggle("zoomed", zoom.s > 1);
}
img.addEventListener("wheel", e => {
  if (!cam) return;
  e.preventDefault();
  if (e.ctrlKey) {
    const r = $("view").getBoundingClientRect(), f = e.deltaY > 0 ? 1 / 1.25 : 1.25;
    const px = e.clientX - r.left, py = e.clientY - r.top;
    const s = Math.min(64, Math.max(1, zoom.s * f)), k = s / zoom.s;
    zoom = { s: s, x: px - (px - zoom.x) * k, y: py - (py - zoom.y) * k };
    if (s === 1) zoom = { s: 1, x: 0, y: 0 };
    applyZoom();
  } else dolly(e.deltaY > 0 ? 1.1 : 1 / 1.1);
}, { passive: false });
// The film pixel under the cursor: where the image is drawn (object-fit: contain, then zoomed).
function filmPixel(e) {
  const m = T.lastMeta;
  if (!m) return null;
  const r = img.getBoundingClientRect();
  const fit = Math.min(r.width / m.width, r.height / m.height);
  const ox = r.left + (r.width - m.width * fit) / 2, oy = r.top + (r.height - m.height * fit) / 2;
  const x = Math.floor((e.clientX - ox) / fit), y = Math.floor((e.clientY - oy) / fit);
  return x >= 0 && y >= 0 && x < m.width && y < m.height ? [x, y] : null;
}
let pixelQueued = null, pixelTimer = null;
img.addEventListener("mousemove", e => {
  pixelQueued = filmPixel(e);
  if (pixelTimer) return;
  pixelTimer = setTimeout(() => {
    pixelTimer = null;
    if (pixelQueued) send({ type: "pixel", x: pixelQueued[0], y: pixelQueued[1] });
  }, 50);
});
window.addEventListener("keydown", e => {
  // Keys typed into a control (a dropdown's arrows, a number field) are the control's alone.
  if (!cam || ["INPUT", "SELECT", "TEXTAREA", "BUTTON"].includes(e.target.tagName)) return;
  const k = { ArrowLeft: [-20, 0], ArrowRight: [20, 0], ArrowUp: [0, -20], ArrowDown: [0, 20] }[e.key];
  if (k) orbit(k[0], k[1]);
  if (e.key === "+" || e.key === "=") dolly(1 / 1.1);
  if (e.key === "-") dolly(1.1);
  if (e.key === "0") { zoom = { s: 1, x: 0, y: 0 }; applyZoom(); }
  if (e.key === " ") { e.preventDefault(); $("pause").click(); }
});

$("exposure").addEventListener("input", e => { $("exposureValue").textContent = e.target.value; send({ type: "exposure", value: parseFloat(e.target.value) }); });
$("tonemap").addEventListener("change", e => send({ type: "tonemap", value: e.target.value }));
$("integrator").addEventListener("change", e => send({ type: "integrator", value: e.target.value }));
$("strategy").addEventListener("change", e => send({ type: "strategy", value: e.target.value }));
const sendEnv = () => send({ type: "environment", rotation: parseFloat($("rotation").value), scale: parseFloat($("envScale").value) || 0 });
$("rotation").addEventListener("input", e => { $("rotationValue").textContent = e.target.value; sendEnv(); });
$("envScale").addEventListener("change", sendEnv);
$("resolution").addEventListener("change", e => send({ type: "resolution", scale: parseFloat(e.target.value) }));
$("noiseThreshold").addEventListener("change", e => {
  const v = parseFloat(e.target.value);
  if (v >= 0 && v <= 10) send({ type: "adaptive", threshold: v }); else showMessage("noise threshold: 0 to 10");
});
$("save").addEventListener("click", () => send({ type: "save" }));
let paused = false;
$("pause").addEventListener("click", () => { paused = !paused; $("pause").textContent = paused ? "Resume" : "Pause"; send({ type: "pause", value: paused }); });
function showStatus(m) {
  const el = $("status");
  el.textContent = m.message;
  T.status = m.state;
  if (m.state === "preparing") {
    const b = document.createElement("button");
    b.textContent = "Cancel";
    b.addEventListener("click", () => send({ type: "cancel" }));
    el.appendChild(b);
  }
}

function fill(select, names, current) {
  select.innerHTML = "";
  for (const n of names) { const o = document.createElement("option"); o.value = o.textContent = n; select.appendChild(o); }
  select.value = current;
}

function onText(m) {
  if (m.type === "hello") {
    hello = m;
    cam = { origin: m.camera.origin, target: m.camera.target, up: m.camera.up };
    $("title").textContent = "envgi: " + m.scene;
    fill($("integrator"), m.integrators, m.integrator);
    fill($("strategy"), m.strategies, m.strategy);
    for (const id of ["rotation", "envScale", "strategy"]) $(id).disabled = !m.hasEnvironment;
    paused = m.paused; $("pause").textContent = paused ? "Resume" : "Pause";
    $("noiseThreshold").value = m.noiseThreshold;
  } else if (m.type === "frame") {
    pendingMeta = m;
  } else if (m.type === "saved") {
    T.saved = m.path;
    showMessage("saved " + m.path);
  } else if (m.type === "error") {
    showMessage("error: " + m.message);
  } else if (m.type === "status") {
    showStatus(m);
  } else if (m.type === "pixel") {
    const f = v => v.toPrecision(4);
    $("pixel").textContent = `(${m.x}, ${m.y})  R ${f(m.rgb[0])}  G ${f(m.rgb[1])}  B ${f(m.rgb[2])}\nluminance ${f(m.luminance)}`;
  } else if (m.type === "takenOver") {
    takenOver = true;
    showMessage(m.message);
  }
}

function onFrame(buffer) {
  const m = pendingMeta;
  pendingMeta = null;
  const bytes = new Uint8Array(buffer);
  let h = 0;
  for (let i = 0; i < bytes.length; i += 7) h = (h * 31 + bytes[i]) >>> 0;
  const url = URL.createObjectURL(new Blob([buffer], { type: "image/jpeg" }));
  img.onload = () => {
    if (lastUrl) URL.revokeObjectURL(lastUrl);
    lastUrl = url;
    T.frames += 1;
    T.lastMeta = m;
    T.frameTimes.push(performance.now());
    if (m) { $("progress").max = m.targetSpp; $("progress").value = m.spp; }
    T.lastHash = h;
    if (m && sendTimes[m.cameraVersion] !== undefined) {
      T.latencyMs = performance.now() - sendTimes[m.cameraVersion];
      T.latencies.push(T.latencyMs);
      for (const v in sendTimes) if (+v <= m.cameraVersion) delete sendTimes[v];
    }
    if (m) {
      $("stats").textContent =
        `frame   ${m.frame}\nspp     ${m.spp} / ${m.targetSpp}${m.paused ? " (paused)" : ""}\n` +
        `time    ${m.seconds.toFixed(2)} s\nfps     ${m.fps > 0 ? m.fps.toFixed(1) : "-"}\n` +
        `size    ${m.width}x${m.height}\n${m.integrator} / ${m.strategy}\n` +
        (m.adaptive ? `adaptive ${m.converged ? "converged" : (100 * m.sampling).toFixed(0) + "% sampling"}\n` +
                      `mean spp ${m.meanSpp.toFixed(1)}\n` :
         m.noiseThreshold > 0 ? `adaptive n/a (${m.integrator})\n` : "") +
        `move->frame ${T.latencyMs === null ? "-" : T.latencyMs.toFixed(0) + " ms"}`;
    }
    send({ type: "next" });
  };
  img.onerror = () => { T.errors.push("a frame did not decode"); send({ type: "next" }); };
  img.src = url;
}

// The page reconnects when the server comes back (a restart), unless another page took over.
function connect() {
  ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" + location.search);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { T.connects += 1; showMessage(""); };
  ws.onmessage = e => { if (typeof e.data === "string") onText(JSON.parse(e.data)); else onFrame(e.data); };
  ws.onclose = () => {
    $("stats").textContent = takenOver ? "another page has this session" : "disconnected: reconnecting...";
    if (!takenOver) setTimeout(connect, 1000);
  };
}
T.orbit = (dx, dy) => orbit(dx, dy);
connect();
</script>
</body>
</html>
)envgipage";

}  // namespace envgi
