// volray view: the page. It keeps the whole view state, sends it over the
// WebSocket on every change ("draft" while the user drags, "full" once the
// interaction stops), and shows the frames that come back.
//
// Hooks for automation: the frame is #frame; document.body.dataset.frames
// counts the frames shown; document.body.dataset.state is "still" once the
// full-quality frame of the current state is shown ("moving" before,
// "error" when the current state was refused); for a multiscale volume
// document.body.dataset.level is the level the frame shown renders (0 the
// finest) and dataset.pieces the pieces it was rendered in.
"use strict";

const token = new URLSearchParams(location.search).get("token") || "";
const $ = (id) => document.getElementById(id);
const frame = $("frame");
const body = document.body;

let hello = null;      // the server's first message
let state = null;      // the current ViewState
let socket = null;
let seq = 0;           // the last request's sequence number
let lastViewSeq = 0;   // the last view request's
let framesShown = 0;
let shownTimes = [];   // when recent frames were shown, for the rate
let stillTimer = 0;

// ---------------------------------------------------------------- socket

function connect() {
  const url = `ws://${location.host}/ws?token=${encodeURIComponent(token)}`;
  socket = new WebSocket(url);
  socket.binaryType = "arraybuffer";
  socket.onmessage = (event) => {
    if (typeof event.data === "string") onText(JSON.parse(event.data));
    else onFrame(event.data);
  };
  socket.onclose = () => {
    body.dataset.state = "closed";
    showError("The server closed the connection (stopped, or too many tabs). Reload to reconnect.");
  };
}

function send(quality) {
  if (!socket || socket.readyState !== WebSocket.OPEN || !state) return;
  seq += 1;
  lastViewSeq = seq;
  body.dataset.state = "moving";
  socket.send(JSON.stringify({ type: "view", seq, quality, state }));
}

// While dragging: at most one draft per animation frame.
let draftFrame = 0;
function sendDraft() {
  body.dataset.state = "moving";
  if (draftFrame) return;
  draftFrame = requestAnimationFrame(() => {
    draftFrame = 0;
    send("draft");
  });
}

// The full frame supersedes a draft still waiting for its animation frame.
function sendFull() {
  clearTimeout(stillTimer);
  if (draftFrame) {
    cancelAnimationFrame(draftFrame);
    draftFrame = 0;
  }
  send("full");
}

// A full frame once nothing has changed for `ms` (the wheel has no "up").
function fullSoon(ms) {
  clearTimeout(stillTimer);
  stillTimer = setTimeout(sendFull, ms);
}

function onText(message) {
  if (message.type === "hello") {
    start(message);
  } else if (message.type === "error") {
    showError(message.message);
    if (message.seq === null || message.seq === lastViewSeq) body.dataset.state = "error";
  }
}

function onFrame(buffer) {
  const view = new DataView(buffer);
  const n = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n)));
  const blob = new Blob([new Uint8Array(buffer, 4 + n)], { type: header.mime });
  if (header.quality === "save") {
    lastSave = { width: header.width, height: header.height, command: header.command };
    download(blob);
    return;
  }
  if (header.seq < lastShownSeq) return; // older than what is shown
  const url = URL.createObjectURL(blob);
  const image = new Image();
  image.src = url;
  image.decode().then(() => {
    if (header.seq < lastShownSeq) { URL.revokeObjectURL(url); return; }
    lastShownSeq = header.seq;
    const old = frame.src;
    frame.src = url;
    if (old.startsWith("blob:")) URL.revokeObjectURL(old);
    basis = header.basis;
    lastHeader = header;
    framesShown += 1;
    body.dataset.frames = String(framesShown);
    showCommand(header);
    showRate(header);
    if (header.seq === lastViewSeq) {
      hideError();
      if (header.quality === "full") body.dataset.state = "still";
    }
  }).catch(() => URL.revokeObjectURL(url));
}
let lastShownSeq = 0;
let basis = null;
let lastHeader = null;
let lastSave = null;

function download(blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = "volray-view.png";
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

// --------------------------------------------------------------- display

function showError(text) {
  const box = $("error");
  box.textContent = text;
  box.hidden = false;
}

function hideError() {
  $("error").hidden = true;
}

// The command, each flag kept on one line with its value.
function showCommand(header) {
  const box = $("command");
  const words = header.command.split(" ");
  const groups = [];
  const isFlag = (w) => /^--?[a-z]/i.test(w);
  for (const word of words) {
    const last = groups[groups.length - 1];
    if (last && !isFlag(word) && isFlag(last) && !last.includes(" ")) {
      groups[groups.length - 1] += " " + word;
    } else {
      groups.push(word);
    }
  }
  box.replaceChildren();
  groups.forEach((group, i) => {
    if (i) box.append(" ");
    const span = document.createElement("span");
    span.textContent = group;
    box.append(span);
  });
  const tf = header.tf_file;
  $("tf-file").hidden = !tf;
  if (tf) {
    $("tf-name").textContent = tf[0];
    $("tf-json").textContent = tf[1];
  }
}

function showRate(header) {
  const now = performance.now();
  shownTimes.push(now);
  while (shownTimes.length && now - shownTimes[0] > 1000) shownTimes.shift();
  const kind = header.quality === "draft" ? "draft" : "full";
  $("status").textContent =
    `${header.width}×${header.height} ${kind} · render ${header.render_ms.toFixed(1)} ms` +
    ` · ${shownTimes.length} frames/s` + levelText(header.level);
  if (header.level) {
    body.dataset.level = String(header.level.index);
    body.dataset.pieces = String(header.level.pieces);
  }
}

// "level 2 of 5 (256³)", and the pieces of a level rendered piece by piece.
function levelText(level) {
  if (!level) return "";
  const [x, y, z] = level.dims;
  const dims = x === y && y === z ? `${x}³` : `${x}×${y}×${z}`;
  const pieces = level.pieces > 1 ? `, ${level.pieces} pieces` : "";
  return ` · level ${level.index} of ${level.count} (${dims}${pieces})`;
}

// ------------------------------------------------------------ the start

function start(message) {
  hello = message;
  state = structuredClone(message.start);
  const [nx, ny, nz] = message.dims;
  const [lo, hi] = message.range;
  const levels = message.levels ? ` · ${message.levels.length} levels` : "";
  $("volume").textContent =
    `${message.name} · ${nx}×${ny}×${nz}${levels} · values ${fmt(lo)} to ${fmt(hi)}` +
    (message.log ? " (log10)" : "");
  frame.width = state.width;
  frame.height = state.height;
  $("left").style.width = `${Math.max(360, state.width + 2)}px`;
  const select = $("colormap");
  select.replaceChildren(...message.colormaps.map(([name]) => {
    const option = document.createElement("option");
    option.value = name;
    option.textContent = name === "start" ? "as started" : name;
    return option;
  }));
  $("save-width").value = state.width;
  $("save-height").value = state.height;
  showControls();
  drawTf();
  sendFull();
}

function showControls() {
  $("colormap").value = state.colormap;
  $("blend").value = state.blend;
  $("iso").value = state.iso ?? "";
  $("iso").disabled = state.blend !== "iso";
  $("step").value = state.step;
  $("step-range").value = state.step;
  $("shading").checked = state.shading;
  $("shading").disabled = isProjection();
  $("perspective").checked = state.perspective !== null;
  $("fov").value = state.perspective ?? 30;
  $("fov").disabled = state.perspective === null;
  $("background").value = toHex(state.background);
  const [wlo, whi] = windowOf();
  $("window-lo").value = round(wlo, 6);
  $("window-hi").value = round(whi, 6);
}

function isProjection() {
  return ["mip", "minip", "average"].includes(state.blend);
}

// --------------------------------------------------------------- camera

const viewport = $("viewport");
let drag = null;

viewport.addEventListener("pointerdown", (e) => {
  if (!state || e.button !== 0) return;
  viewport.setPointerCapture(e.pointerId);
  drag = {
    x: e.clientX, y: e.clientY, pan: e.shiftKey,
    azimuth: state.azimuth, elevation: state.elevation,
    lookAt: state.look_at ?? (basis ? basis.reference : null),
    viewPoint: state.view_point,
  };
});

viewport.addEventListener("pointermove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x;
  const dy = e.clientY - drag.y;
  if (drag.pan) {
    if (!basis || !drag.lookAt) return;
    // Full-size pixels per screen pixel, then world units.
    const scale = state.width / frame.clientWidth / basis.pixels_per_unit;
    const move = [0, 1, 2].map((i) => (-dx * basis.right[i] + dy * basis.up[i]) * scale);
    state.look_at = drag.lookAt.map((v, i) => sig(v + move[i], 6));
    if (drag.viewPoint) state.view_point = drag.viewPoint.map((v, i) => sig(v + move[i], 6));
  } else {
    state.azimuth = round(wrap(drag.azimuth - dx * 0.4), 2);
    state.elevation = round(clamp(drag.elevation + dy * 0.4, -90, 90), 2);
  }
  sendDraft();
});

function endDrag(e) {
  if (!drag) return;
  const moved = e.clientX !== drag.x || e.clientY !== drag.y;
  drag = null;
  if (moved) sendFull();
}
viewport.addEventListener("pointerup", endDrag);
viewport.addEventListener("pointercancel", endDrag);

viewport.addEventListener("wheel", (e) => {
  if (!state) return;
  e.preventDefault();
  state.zoom = sig(clamp(state.zoom * Math.exp(-e.deltaY * 0.0015), 0.01, 100), 4);
  sendDraft();
  fullSoon(200);
}, { passive: false });

viewport.addEventListener("dblclick", () => {
  if (!state) return;
  for (const key of ["azimuth", "elevation", "zoom", "look_at", "view_point"]) {
    state[key] = structuredClone(hello.start[key]);
  }
  sendFull();
});

// ------------------------------------------------------------- controls

function onControl(id, event, apply, quality = "full") {
  $(id).addEventListener(event, () => {
    if (!state) return;
    apply($(id));
    showControls();
    drawTf();
    if (quality === "draft") sendDraft(); else sendFull();
  });
}

onControl("colormap", "change", (el) => { state.colormap = el.value; });
onControl("blend", "change", (el) => {
  state.blend = el.value;
  if (state.blend === "iso" && state.iso === null) {
    const [lo, hi] = windowOf();
    state.iso = sig((lo + hi) / 2, 6);
  }
});
onControl("iso", "change", (el) => { if (el.value !== "") state.iso = Number(el.value); });
onControl("step", "change", (el) => { state.step = Number(el.value); });
onControl("step-range", "input", (el) => { state.step = Number(el.value); }, "draft");
onControl("step-range", "change", (el) => { state.step = Number(el.value); });
onControl("shading", "change", (el) => { state.shading = el.checked; });
onControl("perspective", "change", (el) => {
  state.perspective = el.checked ? Number($("fov").value) || 30 : null;
});
onControl("fov", "change", (el) => { if (state.perspective !== null) state.perspective = Number(el.value); });
onControl("background", "input", (el) => { state.background = fromHex(el.value); }, "draft");
onControl("background", "change", (el) => { state.background = fromHex(el.value); });
onControl("window-lo", "change", (el) => { setWindow(Number(el.value), windowOf()[1]); });
onControl("window-hi", "change", (el) => { setWindow(windowOf()[0], Number(el.value)); });
onControl("window-reset", "click", () => { state.window = null; });
onControl("opacity-reset", "click", () => { state.opacity = null; });

$("save").addEventListener("click", () => {
  if (!socket || !state) return;
  seq += 1;
  const saved = { ...state, width: Number($("save-width").value), height: Number($("save-height").value) };
  socket.send(JSON.stringify({ type: "save", seq, state: saved }));
});

$("copy").addEventListener("click", () => {
  let text = $("command").textContent;
  if (!$("tf-file").hidden) {
    text = `cat > ${$("tf-name").textContent} <<'EOF'\n${$("tf-json").textContent}\nEOF\n${text}`;
  }
  navigator.clipboard?.writeText(text);
});

function setWindow(lo, hi) {
  if (Number.isFinite(lo) && Number.isFinite(hi) && lo < hi) state.window = [sig(lo, 6), sig(hi, 6)];
}

// ---------------------------------------------- transfer-function editor
//
// x: the value, over the volume's range; y: opacity 0 to 1. The grey bars
// are the histogram (log counts); the points are the opacity function over
// the window [lo, hi]; the bar at the bottom is the colours over the
// window, whose ends drag the window.

const tf = $("tf");
const ctx = tf.getContext("2d");
const BAR = 14;      // the colour bar's height
const PAD = 6;       // room for the points at the edges

function windowOf() {
  return state.window ?? hello.start_window;
}

function opacityOf() {
  if (state.opacity) return state.opacity;
  if (hello.start_opacity) return hello.start_opacity;
  return [[0, hello.opacity_ramp[0]], [1, hello.opacity_ramp[1]]];
}

function axis() {
  const [lo, hi] = hello.range;
  const span = hi > lo ? hi - lo : 1;
  const w = tf.width - 2 * PAD;
  const h = tf.height - BAR - 2 * PAD;
  return {
    x: (v) => PAD + ((v - lo) / span) * w,
    v: (x) => lo + ((x - PAD) / w) * span,
    y: (a) => PAD + (1 - a) * h,
    a: (y) => 1 - (y - PAD) / h,
    h,
  };
}

function pointXY(ax, [t, a]) {
  const [lo, hi] = windowOf();
  return [ax.x(lo + t * (hi - lo)), ax.y(a)];
}

function drawTf() {
  if (!hello) return;
  const ax = axis();
  const { width, height } = tf;
  ctx.clearRect(0, 0, width, height);
  // Histogram, log counts.
  const counts = hello.histogram;
  const top = Math.log1p(Math.max(1, ...counts));
  ctx.fillStyle = "#cfcfcb";
  const bw = (width - 2 * PAD) / counts.length;
  counts.forEach((c, i) => {
    const bh = (Math.log1p(c) / top) * ax.h;
    ctx.fillRect(PAD + i * bw, PAD + ax.h - bh, Math.max(1, bw - 0.5), bh);
  });
  // The window and its colours.
  const [lo, hi] = windowOf();
  const colours = (hello.colormaps.find(([n]) => n === state.colormap) || hello.colormaps[0])[1];
  const x0 = ax.x(lo);
  const x1 = ax.x(hi);
  const gradient = ctx.createLinearGradient(x0, 0, x1, 0);
  colours.forEach((c, i) => gradient.addColorStop(i / (colours.length - 1), toCss(c)));
  ctx.fillStyle = gradient;
  ctx.fillRect(x0, height - BAR, x1 - x0, BAR);
  ctx.fillStyle = toCss(colours[0]);
  ctx.fillRect(0, height - BAR, Math.max(0, x0), BAR);
  ctx.fillStyle = toCss(colours[colours.length - 1]);
  ctx.fillRect(x1, height - BAR, width - x1, BAR);
  ctx.strokeStyle = "#555";
  for (const x of [x0, x1]) {
    ctx.beginPath();
    ctx.moveTo(x, PAD);
    ctx.lineTo(x, height);
    ctx.setLineDash([3, 3]);
    ctx.stroke();
  }
  ctx.setLineDash([]);
  // Opacity.
  if (isProjection()) {
    ctx.fillStyle = "#6b6b70";
    ctx.fillText("projections ignore opacity", PAD + 4, PAD + 10);
    return;
  }
  const points = opacityOf().map((p) => pointXY(ax, p));
  ctx.strokeStyle = "#2a62b8";
  ctx.lineWidth = 1.5;
  ctx.beginPath();
  ctx.moveTo(0, points[0][1]);
  points.forEach(([x, y]) => ctx.lineTo(x, y));
  ctx.lineTo(width, points[points.length - 1][1]);
  ctx.stroke();
  ctx.fillStyle = "#fff";
  points.forEach(([x, y]) => {
    ctx.beginPath();
    ctx.arc(x, y, 4, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
  });
  ctx.lineWidth = 1;
}

let tfDrag = null;

function canvasXY(e) {
  const r = tf.getBoundingClientRect();
  return [(e.clientX - r.left) * (tf.width / r.width), (e.clientY - r.top) * (tf.height / r.height)];
}

function nearestPoint(ax, x, y) {
  const points = opacityOf();
  let best = -1;
  let bestD = 8;
  points.forEach((p, i) => {
    const [px, py] = pointXY(ax, p);
    const d = Math.hypot(px - x, py - y);
    if (d <= bestD) { best = i; bestD = d; }
  });
  return best;
}

tf.addEventListener("pointerdown", (e) => {
  if (!state || e.button !== 0) return;
  const ax = axis();
  const [x, y] = canvasXY(e);
  tf.setPointerCapture(e.pointerId);
  const [lo, hi] = windowOf();
  if (y > tf.height - BAR - 2) {
    // The colour bar: an end moves the window's end, the middle shifts it.
    const x0 = ax.x(lo);
    const x1 = ax.x(hi);
    const end = Math.abs(x - x0) < 6 ? "lo" : Math.abs(x - x1) < 6 ? "hi" : "both";
    tfDrag = { kind: "window", end, v: ax.v(x), lo, hi };
    return;
  }
  if (isProjection()) return;
  let index = nearestPoint(ax, x, y);
  if (index < 0) {
    const points = opacityOf().map((p) => p.slice());
    const t = clamp((ax.v(x) - lo) / (hi - lo), 0, 1);
    const a = clamp(ax.a(y), 0, 1);
    index = points.findIndex(([pt]) => pt > t);
    if (index < 0) index = points.length;
    points.splice(index, 0, [round(t, 4), round(a, 4)]);
    state.opacity = points;
    drawTf();
    sendDraft();
  }
  tfDrag = { kind: "point", index };
});

tf.addEventListener("pointermove", (e) => {
  if (!tfDrag) return;
  const ax = axis();
  const [x, y] = canvasXY(e);
  if (tfDrag.kind === "window") {
    const dv = ax.v(x) - tfDrag.v;
    let { lo, hi } = tfDrag;
    if (tfDrag.end !== "hi") lo += dv;
    if (tfDrag.end !== "lo") hi += dv;
    if (lo < hi) setWindow(lo, hi);
  } else {
    const points = opacityOf().map((p) => p.slice());
    const i = tfDrag.index;
    const [lo, hi] = windowOf();
    const tMin = i > 0 ? points[i - 1][0] : 0;
    const tMax = i < points.length - 1 ? points[i + 1][0] : 1;
    points[i] = [round(clamp((ax.v(x) - lo) / (hi - lo), tMin, tMax), 4), round(clamp(ax.a(y), 0, 1), 4)];
    state.opacity = points;
  }
  showControls();
  drawTf();
  sendDraft();
});

function endTfDrag() {
  if (!tfDrag) return;
  tfDrag = null;
  sendFull();
}
tf.addEventListener("pointerup", endTfDrag);
tf.addEventListener("pointercancel", endTfDrag);

function removePoint(e) {
  e.preventDefault();
  if (!state || isProjection()) return;
  const [x, y] = canvasXY(e);
  const index = nearestPoint(axis(), x, y);
  const points = opacityOf().map((p) => p.slice());
  if (index < 0 || points.length <= 1) return;
  points.splice(index, 1);
  state.opacity = points;
  drawTf();
  sendFull();
}
tf.addEventListener("dblclick", removePoint);
tf.addEventListener("contextmenu", removePoint);

// ---------------------------------------------------------------- utils

function clamp(v, lo, hi) { return Math.min(hi, Math.max(lo, v)); }
function round(v, digits) { const f = 10 ** digits; return Math.round(v * f) / f; }
function sig(v, digits) { return v === 0 ? 0 : Number(v.toPrecision(digits)); }
function wrap(a) { return ((((a + 180) % 360) + 360) % 360) - 180; }
function fmt(v) { return Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toExponential(3) : String(sig(v, 5)); }
function toCss([r, g, b]) { return `rgb(${r * 255}, ${g * 255}, ${b * 255})`; }
function toHex(rgb) { return "#" + rgb.map((c) => Math.round(c * 255).toString(16).padStart(2, "0")).join(""); }
function fromHex(hex) { return [1, 3, 5].map((i) => round(parseInt(hex.slice(i, i + 2), 16) / 255, 4)); }

// For automation: send raw text over the page's socket; read the state;
// change it as the controls do (setState) or only send it (sendState).
window.volrayView = {
  send: (text) => socket.send(text),
  state: () => structuredClone(state),
  header: () => lastHeader,
  saved: () => lastSave,
  setState: (patch, quality = "full") => {
    Object.assign(state, patch);
    showControls();
    drawTf();
    if (quality === "full") sendFull(); else send(quality);
  },
  sendState: (patch, quality = "full") => {
    Object.assign(state, patch);
    if (quality === "full") sendFull(); else send(quality);
  },
};

connect();
