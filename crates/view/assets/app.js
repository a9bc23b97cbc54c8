// volray view: the page. It keeps the whole view state, sends it over the
// WebSocket on every change ("draft" while the user drags, "full" once the
// interaction stops), and shows the frames that come back.
//
// Hooks for automation: the frame is #frame; document.body.dataset.frames
// counts the frames shown; document.body.dataset.state is "still" once the
// full-quality frame of the current state is shown ("moving" before,
// "error" when the current state was refused); for a multiscale volume
// document.body.dataset.level is the level the frame shown renders (0 the
// finest) and dataset.pieces the pieces it was rendered in. A scene of
// several volumes (volray view --channels, --overlay) lists them under
// #volumes: state.layers[i - 1] is volume i's look (volume 0's is the
// state's own window, opacity and colormap), volrayView.select(i) edits
// it; a time axis (--frames) sets state.time from #time.
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
let selected = 0;      // the volume whose transfer function is edited
// A draft's size over the full frame's, per side: adapted from the last
// drafts' render times to take about DRAFT_MS (the time goes with the
// pixels, the square of the scale), so that a drag holds its frame rate
// at any window size.
let draftScale = 0.5;
const DRAFT_MS = 30;

// ---------------------------------------------------------------- socket

function connect() {
  // Relative to the page, so that the viewer works behind a proxy that
  // serves it under a path (JupyterHub's, jupyter-server-proxy's).
  // In a notebook (embed.js) the socket is the parent window's and takes
  // no URL: the page is an iframe's srcdoc, with no address of its own.
  let url = "";
  if (!window.volrayEmbedded) {
    url = new URL(`ws?token=${encodeURIComponent(token)}`, location.href);
    url.protocol = location.protocol === "https:" ? "wss:" : "ws:";
  }
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
  const message = { type: "view", seq, quality, state };
  if (quality === "draft") message.draft_scale = round(draftScale, 4);
  socket.send(JSON.stringify(message));
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
  if (message.type === "probe") {
    showProbe(message);
  } else if (message.type === "hello") {
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
    if (header.quality === "draft") adaptDraftScale(header);
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

function adaptDraftScale(header) {
  const shown = header.width / state.width;
  if (!(shown > 0) || !(header.render_ms >= 0)) return;
  const wanted = clamp(shown * Math.sqrt(DRAFT_MS / Math.max(1, header.render_ms)), 1 / 16, 1);
  // Halfway (in the logarithm) to the new scale: steady under noise.
  draftScale = clamp(Math.sqrt(draftScale * wanted), 1 / 16, 1);
}
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
  // A scene's other volumes' files, each under its name.
  const more = $("layer-tf-files");
  more.replaceChildren();
  for (const [name, json] of header.layer_tf_files || []) {
    const title = document.createElement("div");
    title.className = "row small muted";
    title.append("with ");
    const code = document.createElement("code");
    code.textContent = name;
    title.append(code, ":");
    const pre = document.createElement("pre");
    pre.className = "code layer-tf";
    pre.dataset.name = name;
    pre.textContent = json;
    more.append(title, pre);
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

// ---------------------------------------------------------- the window
//
// Started without --size (hello.fit), the frame is the viewport's size in
// device pixels (at most 4096 a side) and follows it; a draft, smaller,
// is shown at the same size on the screen.

function dpr() {
  return window.devicePixelRatio || 1;
}

function fitSize() {
  const r = viewport.getBoundingClientRect();
  let w = Math.max(1, Math.round(r.width * dpr()));
  let h = Math.max(1, Math.round(r.height * dpr()));
  const over = Math.max(w, h) / 4096;
  if (over > 1) {
    w = Math.max(1, Math.floor(w / over));
    h = Math.max(1, Math.floor(h / over));
  }
  return [w, h];
}

// Sizes the state to the window; whether it changed.
function fitToWindow() {
  if (!hello || !hello.fit || !state) return false;
  const [w, h] = fitSize();
  if (w === state.width && h === state.height) return false;
  state.width = w;
  state.height = h;
  $("save-width").value = w;
  $("save-height").value = h;
  return true;
}

// The frame's size on the screen: the state's, in CSS pixels.
function sizeFrame() {
  const k = hello && hello.fit ? dpr() : 1;
  frame.style.width = `${state.width / k}px`;
  frame.style.height = `${state.height / k}px`;
}

// Full-size pixels per CSS pixel of the frame as shown.
function frameScale() {
  const r = frame.getBoundingClientRect();
  const shown = Math.min(r.width, r.height * (state.width / state.height));
  return state.width / Math.max(1, shown);
}

let resizeTimer = 0;
new ResizeObserver(() => {
  clearTimeout(resizeTimer);
  resizeTimer = setTimeout(() => {
    if (fitToWindow()) {
      sizeFrame();
      sendFull();
    }
  }, 120);
}).observe(document.getElementById("viewport"));

// ------------------------------------------------------------ the start

function start(message) {
  hello = message;
  state = structuredClone(message.start);
  // What the server leaves out when empty.
  state.clip = state.clip ?? [];
  state.crop = state.crop ?? null;
  state.lighting = state.lighting ?? null;
  state.shadows = state.shadows ?? false;
  state.ambient_occlusion = state.ambient_occlusion ?? null;
  state.layers = state.layers ?? [];
  state.figure = state.figure ?? {};
  const [nx, ny, nz] = message.dims;
  const [lo, hi] = message.range;
  const levels = message.levels ? ` · ${message.levels.length} levels` : "";
  $("volume").textContent =
    `${message.name} · ${nx}×${ny}×${nz}${levels} · values ${fmt(lo)} to ${fmt(hi)}` +
    (message.log ? " (log10)" : "");
  fitToWindow();
  sizeFrame();
  showVolumes();
  const time = message.time;
  $("time-box").hidden = !time;
  if (time) {
    $("time").min = time[0];
    $("time").max = time[1] - 1;
  }
  $("save-width").value = state.width;
  $("save-height").value = state.height;
  showControls();
  drawTf();
  sendFull();
}

// The volume being edited: its look (window, opacity, colormap) in the
// state, and what the server said of it (range, histogram, start).
function look(i = selected) {
  return i === 0 ? state : state.layers[i - 1];
}

function info(i = selected) {
  if (i === 0) return hello;
  const v = hello.volumes[i - 1];
  const shared = hello.colormaps.filter(([name]) => name !== "start");
  return {
    ...v,
    colormaps: v.start_colours ? [["start", v.start_colours], ...shared] : shared,
  };
}

function volumeCount() {
  return 1 + (hello.volumes ? hello.volumes.length : 0);
}

// One colour for the colour bar and the swatch: "#rrggbb" or a choice's.
function coloursOf(i = selected) {
  const name = look(i).colormap;
  if (name.startsWith("#")) return [fromHex(name), fromHex(name)];
  const maps = info(i).colormaps;
  return (maps.find(([n]) => n === name) || maps[0])[1];
}

function showVolumes() {
  const n = volumeCount();
  $("volumes-box").hidden = n < 2;
  const list = $("volumes");
  list.replaceChildren();
  for (let i = 0; i < n && n > 1; i++) {
    const row = document.createElement("div");
    row.className = "volume" + (i === selected ? " selected" : "");
    row.dataset.index = String(i);
    const shown = document.createElement("input");
    shown.type = "checkbox";
    shown.checked = i === 0 || state.layers[i - 1].visible;
    shown.disabled = i === 0;
    shown.title = i === 0 ? "the first volume frames the scene: lower its opacity to see through it" : "show or hide";
    shown.addEventListener("change", () => {
      state.layers[i - 1].visible = shown.checked;
      sendFull();
    });
    const swatch = document.createElement("span");
    swatch.className = "swatch";
    const colours = coloursOf(i);
    swatch.style.background = toCss(colours[colours.length - 1]);
    const name = document.createElement("span");
    name.className = "name";
    name.textContent = (i === 0 ? hello.name : hello.volumes[i - 1].name);
    name.addEventListener("click", () => selectVolume(i));
    row.append(shown, swatch, name);
    list.append(row);
  }
  const select = $("colormap");
  select.replaceChildren(...info().colormaps.map(([name]) => {
    const option = document.createElement("option");
    option.value = name;
    option.textContent = name === "start" ? "as started" : name;
    return option;
  }), new Option("one colour", "solid"));
  $("tf-of").textContent = n > 1 ? `· ${selected === 0 ? hello.name : hello.volumes[selected - 1].name}` : "";
  const labels = selected > 0 && hello.volumes[selected - 1].labels;
  $("tf-box").classList.toggle("labels", labels);
  $("tf-labels").hidden = !labels;
  $("colormap").disabled = labels;
  $("solid").disabled = labels;
}

function selectVolume(i) {
  if (!state || i < 0 || i >= volumeCount()) return;
  selected = i;
  showVolumes();
  showControls();
  drawTf();
}

function isLabels() {
  return selected > 0 && hello.volumes[selected - 1].labels;
}

function showControls() {
  const colours = look().colormap;
  $("colormap").value = colours.startsWith("#") ? "solid" : colours;
  if (colours.startsWith("#")) $("solid").value = colours;
  if (state.time !== undefined && state.time !== null) {
    $("time").value = state.time;
    $("time-value").textContent = String(state.time);
  }
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
  showCuts();
  showFigure();
  const [wlo, whi] = windowOf();
  $("window-lo").value = round(wlo, 6);
  $("window-hi").value = round(whi, 6);
}

// The crop box, a clip plane and the lighting: sliders over the box the
// view frames (hello.bounds), in fractions of it.

const AXES = ["x", "y", "z"];

function boxAt(axis, t) {
  const [lo, hi] = hello.bounds;
  return sig(lo[axis] + t * (hi[axis] - lo[axis]), 6);
}

function fractionOf(axis, v) {
  const [lo, hi] = hello.bounds;
  return hi[axis] > lo[axis] ? clamp((v - lo[axis]) / (hi[axis] - lo[axis]), 0, 1) : 0;
}

function showCuts() {
  $("crop-on").checked = !!state.crop;
  AXES.forEach((name, axis) => {
    for (const end of [0, 1]) {
      const el = $(`crop-${name}${end}`);
      el.disabled = !state.crop;
      if (state.crop) el.value = fractionOf(axis, state.crop[end][axis]);
    }
  });
  const plane = state.clip[0];
  const axis = plane ? plane[1].findIndex((c) => c !== 0) : -1;
  const aligned = plane && plane[1].filter((c) => c !== 0).length === 1;
  $("clip-axis").value = aligned ? AXES[axis] : "";
  $("clip-flip").checked = !!aligned && plane[1][axis] < 0;
  $("clip-at").disabled = !aligned;
  if (aligned) $("clip-at").value = fractionOf(axis, plane[0][axis]);
  const l = state.lighting ?? hello.lighting;
  for (const key of ["ambient", "diffuse", "specular", "shininess"]) $(`l-${key}`).value = l[key];
  $("headlight").checked = !l.light;
  if (l.light) {
    const [x, y, z] = l.light;
    const n = Math.hypot(x, y, z);
    $("l-azimuth").value = Math.atan2(y, x) * 180 / Math.PI;
    $("l-elevation").value = Math.asin(clamp(z / n, -1, 1)) * 180 / Math.PI;
  }
  $("l-azimuth").disabled = $("l-elevation").disabled = !l.light;
  // Depth cues: shadows where lit, ambient occlusion where composited;
  // one volume's (a scene refuses them).
  const scene = state.layers.length > 0;
  $("shadows").checked = state.shadows;
  $("shadows").disabled = scene || isProjection() || !state.shading;
  $("ao").checked = state.ambient_occlusion !== null;
  $("ao").disabled = scene || isProjection();
  if (state.ambient_occlusion !== null) $("ao-radius").value = state.ambient_occlusion;
  $("ao-radius").disabled = $("ao").disabled || state.ambient_occlusion === null;
}

// The figure: what volray-annotate draws into the frame.
function showFigure() {
  const f = state.figure;
  $("f-colorbar").checked = !!f.colorbar;
  $("f-side").value = f.colorbar || "right";
  $("f-side").disabled = !f.colorbar;
  $("f-scale").checked = !!f.scale_bar;
  $("f-axes").checked = !!f.axes;
  $("f-outline").checked = !!f.outline;
  if (document.activeElement !== $("f-title")) $("f-title").value = f.title ?? "";
  if (document.activeElement !== $("f-label")) $("f-label").value = f.label ?? "";
  for (const el of $("figure-box").querySelectorAll("input, select")) {
    if (hello.levels) el.disabled = true;
  }
}

function readFigure() {
  const text = (id) => $(id).value.trim() || null;
  return {
    ...state.figure,
    colorbar: $("f-colorbar").checked ? $("f-side").value : null,
    scale_bar: $("f-scale").checked,
    axes: $("f-axes").checked,
    outline: $("f-outline").checked,
    title: text("f-title"),
    label: text("f-label"),
  };
}

function readCrop() {
  if (!$("crop-on").checked) return null;
  const lo = [], hi = [];
  AXES.forEach((name, axis) => {
    let a = Number($(`crop-${name}0`).value);
    let b = Number($(`crop-${name}1`).value);
    if (b - a < 0.01) b = Math.min(1, a + 0.01), a = b - 0.01;
    lo.push(boxAt(axis, a));
    hi.push(boxAt(axis, b));
  });
  return [lo, hi];
}

function readClip() {
  const name = $("clip-axis").value;
  const rest = state.clip.slice(1);
  if (!name) return rest;
  const axis = AXES.indexOf(name);
  const [lo, hi] = hello.bounds;
  const point = [0, 1, 2].map((i) => sig((lo[i] + hi[i]) / 2, 6));
  point[axis] = boxAt(axis, Number($("clip-at").value));
  const normal = [0, 0, 0];
  normal[axis] = $("clip-flip").checked ? -1 : 1;
  return [[point, normal], ...rest];
}

function readLighting() {
  const v = (id) => Number($(id).value);
  let light = null;
  if (!$("headlight").checked) {
    const az = v("l-azimuth") * Math.PI / 180;
    const el = v("l-elevation") * Math.PI / 180;
    light = [Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el)].map((c) => round(c, 4));
    if (light.every((c) => c === 0)) light = [1, 0, 0];
  }
  return {
    ambient: v("l-ambient"), diffuse: v("l-diffuse"), specular: v("l-specular"),
    shininess: v("l-shininess"), light,
  };
}

function isProjection() {
  return ["mip", "minip", "average"].includes(state.blend);
}

// --------------------------------------------------------------- camera

const viewport = $("viewport");
let drag = null;

viewport.addEventListener("pointerdown", (e) => {
  if (!state || e.button !== 0 || e.target.closest("#toolbar")) return;
  viewport.setPointerCapture(e.pointerId);
  drag = {
    x: e.clientX, y: e.clientY, pan: e.shiftKey,
    azimuth: state.azimuth, elevation: state.elevation,
    lookAt: state.look_at ?? (basis ? basis.reference : null),
    viewPoint: state.view_point,
  };
});

viewport.addEventListener("pointermove", (e) => {
  if (!drag) {
    probeAt(e);
    return;
  }
  const dx = e.clientX - drag.x;
  const dy = e.clientY - drag.y;
  if (drag.pan) {
    if (!basis || !drag.lookAt) return;
    // Full-size pixels per screen pixel, then world units.
    const scale = frameScale() / basis.pixels_per_unit;
    const move = [0, 1, 2].map((i) => (-dx * basis.right[i] + dy * basis.up[i]) * scale);
    state.look_at = drag.lookAt.map((v, i) => sig(v + move[i], 6));
    if (drag.viewPoint) state.view_point = drag.viewPoint.map((v, i) => sig(v + move[i], 6));
  } else {
    state.azimuth = round(wrap(drag.azimuth - dx * 0.4), 2);
    state.elevation = round(clamp(drag.elevation + dy * 0.4, -90, 90), 2);
  }
  sendDraft();
});

// The probe: what the pixel under the pointer shows, asked at most every
// PROBE_MS while the pointer moves over the frame (not while dragging).
const PROBE_MS = 80;
let probeTime = 0;
let probeTimer = 0;

function probeAt(e) {
  if (!state || !socket || socket.readyState !== WebSocket.OPEN) return;
  const r = frame.getBoundingClientRect();
  const aspect = state.width / state.height;
  const shownW = Math.min(r.width, r.height * aspect);
  const shownH = shownW / aspect;
  const left = r.left + (r.width - shownW) / 2;
  const top = r.top + (r.height - shownH) / 2;
  const x = ((e.clientX - left) / shownW) * state.width;
  const y = ((e.clientY - top) / shownH) * state.height;
  if (!(x >= 0 && y >= 0 && x < state.width && y < state.height)) {
    $("probe").textContent = "";
    return;
  }
  clearTimeout(probeTimer);
  const wait = probeTime + PROBE_MS - performance.now();
  if (wait > 0) {
    probeTimer = setTimeout(() => probeAt(e), wait);
    return;
  }
  probeTime = performance.now();
  seq += 1;
  socket.send(JSON.stringify({ type: "probe", seq, x, y, state }));
}

function showProbe(message) {
  const box = $("probe");
  if (!message.position) {
    box.textContent = "nothing under the pointer";
    return;
  }
  const [x, y, z] = message.position.map((v) => fmt(v));
  const [i, j, k] = message.index.map((v) => round(v, 1));
  box.textContent = `(${x}, ${y}, ${z}) · voxel (${i}, ${j}, ${k}) · value ${fmt(message.value)}`;
}

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

viewport.addEventListener("dblclick", (e) => {
  if (e.target.closest("#toolbar")) return;
  setView("reset");
});

// The views from each side, isometric, and the start: the eye orbits the
// up vector from the +x side (azimuth 90: from +y), then rises.
const VIEWS = {
  "+x": [0, 0], "-x": [180, 0], "+y": [90, 0], "-y": [-90, 0],
  "+z": [0, 90], "-z": [0, -90], "iso": [45, 35.26],
};

function setView(name) {
  if (!state) return;
  const keys = name === "reset"
    ? ["azimuth", "elevation", "zoom", "look_at", "view_point"]
    : ["look_at", "view_point"];
  for (const key of keys) state[key] = structuredClone(hello.start[key]);
  if (name !== "reset") [state.azimuth, state.elevation] = VIEWS[name];
  sendFull();
}

for (const button of document.querySelectorAll("#toolbar [data-view]")) {
  button.addEventListener("click", () => setView(button.dataset.view));
}
$("fullscreen").addEventListener("click", toggleFullscreen);
$("panel-toggle").addEventListener("click", togglePanel);

function toggleFullscreen() {
  const done = document.fullscreenElement
    ? document.exitFullscreen()
    : document.documentElement.requestFullscreen();
  done?.catch?.(() => {});
}

function togglePanel() {
  const hidden = body.classList.toggle("panel-hidden");
  $("panel-toggle").setAttribute("aria-expanded", String(!hidden));
}

const KEYS = { "1": "+x", "2": "-x", "3": "+y", "4": "-y", "5": "+z", "6": "-z", "0": "iso", "r": "reset" };
document.addEventListener("keydown", (e) => {
  if (!state || e.ctrlKey || e.metaKey || e.altKey) return;
  if (e.target.closest && e.target.closest("input, select, textarea, button")) return;
  if (KEYS[e.key]) setView(KEYS[e.key]);
  else if (e.key === "f") toggleFullscreen();
  else if (e.key === "p") togglePanel();
  else return;
  e.preventDefault();
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

onControl("colormap", "change", (el) => {
  look().colormap = el.value === "solid" ? $("solid").value : el.value;
  showVolumes();
});
onControl("solid", "change", (el) => { look().colormap = el.value; showVolumes(); });
onControl("time", "input", (el) => { state.time = Number(el.value); }, "draft");
onControl("time", "change", (el) => { state.time = Number(el.value); });
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
onControl("window-reset", "click", () => { look().window = null; });
onControl("opacity-reset", "click", () => { look().opacity = null; });

for (const id of ["f-colorbar", "f-side", "f-scale", "f-axes", "f-outline", "f-title", "f-label"]) {
  onControl(id, "change", () => { state.figure = readFigure(); });
}
for (const id of ["crop-on", "crop-x0", "crop-x1", "crop-y0", "crop-y1", "crop-z0", "crop-z1"]) {
  onControl(id, "input", () => { state.crop = readCrop(); }, "draft");
  onControl(id, "change", () => { state.crop = readCrop(); });
}
for (const id of ["clip-axis", "clip-flip", "clip-at"]) {
  onControl(id, "input", () => { state.clip = readClip(); }, "draft");
  onControl(id, "change", () => { state.clip = readClip(); });
}
onControl("shadows", "change", (el) => { state.shadows = el.checked; });
onControl("ao", "change", (el) => {
  state.ambient_occlusion = el.checked ? clamp(Math.round(Number($("ao-radius").value)) || 8, 1, 32) : null;
});
onControl("ao-radius", "change", (el) => {
  if (state.ambient_occlusion !== null) state.ambient_occlusion = clamp(Math.round(Number(el.value)) || 8, 1, 32);
});
for (const id of ["l-ambient", "l-diffuse", "l-specular", "l-shininess", "headlight", "l-azimuth", "l-elevation"]) {
  onControl(id, "input", () => { state.lighting = readLighting(); }, "draft");
  onControl(id, "change", () => { state.lighting = readLighting(); });
}

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
  for (const pre of document.querySelectorAll("pre.layer-tf")) {
    text = `cat > ${pre.dataset.name} <<'EOF'\n${pre.textContent}\nEOF\n${text}`;
  }
  navigator.clipboard?.writeText(text);
});

function setWindow(lo, hi) {
  if (Number.isFinite(lo) && Number.isFinite(hi) && lo < hi) look().window = [sig(lo, 6), sig(hi, 6)];
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
  return look().window ?? info().start_window;
}

function opacityOf() {
  const v = info();
  if (look().opacity) return look().opacity;
  if (v.start_opacity) return v.start_opacity;
  return [[0, v.opacity_ramp[0]], [1, v.opacity_ramp[1]]];
}

function axis() {
  const [lo, hi] = info().range;
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
  const counts = info().histogram;
  const top = Math.log1p(Math.max(1, ...counts));
  ctx.fillStyle = "#cfcfcb";
  const bw = (width - 2 * PAD) / counts.length;
  counts.forEach((c, i) => {
    const bh = (Math.log1p(c) / top) * ax.h;
    ctx.fillRect(PAD + i * bw, PAD + ax.h - bh, Math.max(1, bw - 0.5), bh);
  });
  // The window and its colours.
  const [lo, hi] = windowOf();
  const colours = coloursOf();
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
  if (!state || e.button !== 0 || isLabels()) return;
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
    look().opacity = points;
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
    look().opacity = points;
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
  if (!state || isProjection() || isLabels()) return;
  const [x, y] = canvasXY(e);
  const index = nearestPoint(axis(), x, y);
  const points = opacityOf().map((p) => p.slice());
  if (index < 0 || points.length <= 1) return;
  points.splice(index, 1);
  look().opacity = points;
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
  select: (i) => selectVolume(i),
  view: (name) => setView(name),
  probe: (x, y) => {
    seq += 1;
    socket.send(JSON.stringify({ type: "probe", seq, x, y, state }));
  },
  draftScale: () => draftScale,
  saved: () => lastSave,
  setState: (patch, quality = "full") => {
    Object.assign(state, patch);
    sizeFrame();
    showVolumes();
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
