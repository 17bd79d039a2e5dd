// spherewarp view: the page. Raw WebGL2 (one full-screen fragment shader, see shader.js).
import { BODY, VERTEX, withExpressions } from "./shader.js";

const MAX_STAGES = 32;
const DEG = Math.PI / 180;
const $ = (id) => document.getElementById(id);
const canvas = $("view");
const marks = $("marks"); // the 2D layer over the canvas: pins, clicked corners, disks
// the footer: read out politely (role status); an error at once (role alert)
const status = (text, bad = false) => {
  $("status").textContent = text;
  $("status").className = bad ? "bad" : "";
  $("status").setAttribute("role", bad ? "alert" : "status");
  $("status").setAttribute("aria-live", bad ? "assertive" : "polite");
};

const S = {
  recipe: { spherewarp: 1, steps: [] },
  view: "flat",
  side: null, // a second panel: another view of the edit, or "original" (the image unedited)
  mode: null, // clicking out a step: {kind: "droste", points} or {kind: "schottky", disks}
  size: [1024, 512],
  look: [0, 0, 90], // yaw, pitch, fov in degrees (sphere view)
  planet: 1.0,
  pins: [
    [0, 90],
    [0, -90],
  ],
  undo: [],
  redo: [],
  stages: null,
  image: null,
  frames: 0,
  overlay: 0, // how much of the test pattern is mixed in
  ss: 2, // sub-samples per pixel along each axis (?ss=1..4)
  marks: true, // the recipe's marks (frames, disks) over the picture (?marks=0 hides them)
};

// -- WebGL ---------------------------------------------------------------------------------------
const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false });
const UNIFORMS = ["uImage", "uParams", "uCodes", "uCount", "uView", "uSize", "uLook", "uPlanet",
  "uSS", "uPattern", "uOverlay", "uLabels", "uOrigin"];
let uni = {};
let paramsTex = null;
let labelsTex = null;
let header = "";
const programs = new Map(); // the GLSL of the expression maps -> {prog, uni}
let current = null; // that GLSL, of the program in use

// a program for the recipe's expression maps (the shader with their functions), cached
function useProgram(glsl, slots) {
  const key = `${slots}\n${glsl}`;
  if (current === key) return;
  let p = programs.get(key);
  if (!p) {
    // the server's functions are fixed pieces (spherewarp/viewer/glsl.py): refuse anything else
    if (!/^[A-Za-z0-9_\s(){},;=+\-*]*$/.test(glsl)) throw new Error("unexpected expression GLSL");
    const src = `#version 300 es\nprecision highp float;\nprecision highp int;\n#define MAX_STAGES ${MAX_STAGES}\n${header}\n${withExpressions(BODY, glsl, slots)}`;
    const mk = (type, text) => {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, text);
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      return sh;
    };
    const prog = gl.createProgram();
    gl.attachShader(prog, mk(gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(prog, mk(gl.FRAGMENT_SHADER, src));
    gl.bindAttribLocation(prog, 0, "pos");
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    const u = {};
    for (const n of UNIFORMS) u[n] = gl.getUniformLocation(prog, n);
    p = { prog, uni: u };
    if (programs.size > 16) programs.clear();
    programs.set(key, p);
  }
  gl.useProgram(p.prog);
  uni = p.uni;
  current = key;
}

function compile(hdr) {
  header = hdr;
  useProgram("", 0);
  const buf = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, buf);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
}

// an image or a video's current frame into a mipmapped texture (a new one unless given)
function uploadImage(img, unit = 0, tex = null) {
  tex = tex || gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, img);
  gl.generateMipmap(gl.TEXTURE_2D);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  return tex;
}

// -- a video as the texture: each new frame uploaded and drawn as it plays ------------------------
let videoTex = null;

function videoFrame() {
  const v = S.video;
  if (v.readyState < 2) return;
  S.videoTime = v.currentTime;
  uploadImage(v, 0, videoTex);
  draw();
  if (animated()) restage(); // the recipe at the video's time (drawn again when it comes)
  $("vtime").textContent = `${v.currentTime.toFixed(2)} s`;
  if (!S.seeking && v.duration) $("vseek").value = v.currentTime / v.duration;
}

async function startVideo() {
  const v = document.createElement("video");
  v.muted = true;
  v.loop = true;
  v.playsInline = true;
  v.preload = "auto";
  const loaded = new Promise((res, rej) => {
    v.addEventListener("loadeddata", res, { once: true });
    v.addEventListener("error", () => rej(new Error(`video: ${v.error ? v.error.message || `error ${v.error.code}` : "cannot play"} (the browser may lack its codec)`)), { once: true });
  });
  v.src = "video"; // served with range requests: the browser seeks by itself
  await loaded;
  S.video = v;
  videoTex = uploadImage(v, 0);
  // a frame is uploaded when the time shown has changed (playing, or after a seek)
  const tick = () => {
    if (v.currentTime !== S.videoTime && !v.seeking) videoFrame();
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
  v.addEventListener("seeked", videoFrame);
  $("vctl").hidden = false;
  $("play").onclick = () => (v.paused ? v.play() : v.pause());
  v.addEventListener("play", () => ($("play").textContent = "Pause"));
  v.addEventListener("pause", () => ($("play").textContent = "Play"));
  $("vseek").oninput = () => {
    S.seeking = true;
    v.currentTime = +$("vseek").value * (v.duration || 0);
  };
  $("vseek").onchange = () => (S.seeking = false);
  v.play().catch(() => ($("play").textContent = "Play")); // a browser may refuse autoplay
}

// the stages this shader runs (shader.js); a stage added to the table later is named, not
// run wrongly
const SHADER_STAGES = ["mobius", "power", "exp", "rational", "droste", "schottky", "schottky_mask", "expression"];

function floatTexture(tex, unit, w, h, data) {
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.R32F, w, h, 0, gl.RED, gl.FLOAT, data);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
}

// a masked Schottky stage's labels: fetched once by their key (int16), kept as a texture
async function uploadLabels(lab) {
  if (S.labelsKey === lab.key) return;
  const r = await fetch(`api/labels/${lab.key}`);
  if (!r.ok) throw new Error(`labels: HTTP ${r.status}`);
  const ints = new Int16Array(await r.arrayBuffer());
  if (!labelsTex) labelsTex = gl.createTexture();
  floatTexture(labelsTex, 3, lab.width, lab.height, Float32Array.from(ints));
  S.labelsKey = lab.key;
}

async function uploadStages(st) {
  S.stages = { codes: null };
  if (st.codes === null) {
    status(`no live preview: ${st.missing}`, true);
    return;
  }
  const unknown = st.codes.map((c) => S.stageNames[c]).filter((n) => !SHADER_STAGES.includes(n));
  if (unknown.length) {
    status(`no live preview: the shader has no '${unknown[0]}' stage yet (render full resolution)`, true);
    return;
  }
  if (st.codes.length > MAX_STAGES) {
    status(`no live preview: ${st.codes.length} stages (the shader takes ${MAX_STAGES})`, true);
    return;
  }
  const labels = st.labels || [];
  if (labels.length > 1) {
    status("no live preview: the shader takes one masked Schottky group", true);
    return;
  }
  const slots = st.codes.filter((c) => S.stageNames[c] === "expression").length;
  try {
    useProgram(st.glsl || "", slots);
    if (labels.length) await uploadLabels(labels[0]);
  } catch (e) {
    status(`no live preview: ${e.message}`, true);
    return;
  }
  const w = Math.max(1, ...st.rows.map((r) => r.length));
  const data = new Float32Array(w * Math.max(1, st.rows.length));
  st.rows.forEach((r, s) => data.set(r, s * w));
  if (!paramsTex) paramsTex = gl.createTexture();
  floatTexture(paramsTex, 1, w, Math.max(1, st.rows.length), data);
  S.stages = st;
}

// the panels side by side, left to right: {view, edited}
function panels() {
  const main = { view: S.view, edited: true };
  if (!S.side) return [main];
  if (S.side === "original") return [main, { view: S.view, edited: false }];
  return [main, { view: S.side, edited: true }];
}

function draw() {
  const [w, h] = S.size;
  const list = panels();
  if (canvas.width !== w * list.length || canvas.height !== h) {
    canvas.width = w * list.length;
    canvas.height = h;
  }
  const codes = new Int32Array(MAX_STAGES);
  if (S.stages && S.stages.codes) codes.set(S.stages.codes);
  gl.uniform1iv(uni.uCodes, codes);
  gl.uniform1i(uni.uImage, 0);
  gl.uniform1i(uni.uParams, 1);
  gl.uniform1i(uni.uPattern, 2);
  gl.uniform1i(uni.uLabels, 3);
  gl.uniform2f(uni.uSize, w, h);
  gl.uniform3f(uni.uLook, S.look[0] * DEG, S.look[1] * DEG, S.look[2] * DEG);
  gl.uniform1f(uni.uPlanet, S.planet);
  gl.uniform1i(uni.uSS, S.ss);
  gl.uniform1f(uni.uOverlay, S.overlay);
  const count = S.stages && S.stages.codes ? S.stages.codes.length : -1;
  list.forEach((panel, i) => {
    gl.viewport(i * w, 0, w, h);
    gl.uniform2f(uni.uOrigin, i * w, 0);
    gl.uniform1i(uni.uCount, panel.edited ? count : 0); // no stages: the image itself
    gl.uniform1i(uni.uView, { flat: 0, sphere: 1, planet: 2 }[panel.view]);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  });
  S.frames += 1;
  drawMarks();
}

// -- marks over the canvas: the pins, the corners clicked so far, the Schottky disks -----------
function drawMarks() {
  const [w, h] = S.size;
  const list = panels();
  if (marks.width !== canvas.width || marks.height !== canvas.height) {
    marks.width = canvas.width;
    marks.height = canvas.height;
  }
  const c = marks.getContext("2d");
  c.clearRect(0, 0, marks.width, marks.height);
  const dot = (x, y, colour, r = 5) => {
    c.beginPath();
    c.arc(x, y, r, 0, 2 * Math.PI);
    c.lineWidth = 3;
    c.strokeStyle = "black";
    c.stroke();
    c.lineWidth = 1.5;
    c.strokeStyle = colour;
    c.stroke();
  };
  // a line through points on the sphere, broken where it leaves the panel or jumps the seam
  const line = (pts, colour, x0, view, closed) => {
    const all = closed ? [...pts, pts[0]] : pts;
    c.lineWidth = 1.5;
    c.strokeStyle = colour;
    c.beginPath();
    let prev = null;
    for (const p of all) {
      const q = lonLatToPixel(p[0], p[1], view);
      if (q && prev && Math.abs(q[0] - prev[0]) < w / 2) c.lineTo(x0 + q[0], q[1]);
      else if (q) c.moveTo(x0 + q[0], q[1]);
      prev = q;
    }
    c.stroke();
  };
  list.forEach((panel, i) => {
    const x0 = i * w;
    c.save();
    c.beginPath();
    c.rect(x0, 0, w, h);
    c.clip();
    if (i > 0) {
      c.fillStyle = "#1d1f21";
      c.fillRect(x0, 0, 1, h);
    }
    if (panel.edited) {
      for (const pin of S.marks ? S.pins : []) {
        const q = lonLatToPixel(pin[0], pin[1], panel.view);
        if (q) dot(x0 + q[0], q[1], "#ffd54a");
      }
      if (S.marks) drawRecipeMarks(c, x0, panel.view, line, dot);
      const m = S.mode;
      if (m && m.kind === "droste") {
        m.points.forEach((p) => {
          const q = lonLatToPixel(p[0], p[1], panel.view);
          if (q) dot(x0 + q[0], q[1], "#4ae3ff", 4);
        });
        if (m.points.length > 1) line(arcs(m.points, false), "#4ae3ff", x0, panel.view, false);
      }
      if (m && m.kind === "schottky") {
        const disks = m.cur ? [...m.disks, m.cur] : m.disks;
        disks.forEach((d, k) => line(circle(d), k % 2 ? "#ff7a4a" : "#7aff4a", x0, panel.view, true));
      }
    }
    c.restore();
  });
}

// -- the recipe's marks: every Droste step's frame (or its round hole), every Schottky
// step's disks D_x and D_X with an arrow between them. Handles (a frame's corners, a
// centre, a disk's centre, a disk's rim) can be dragged to edit the step. An animated
// recipe's marks are where its effect is at the page's time: its steps at that time, as
// the server evaluates them with the stages (S.at).
const isNum = (v) => typeof v === "number" && Number.isFinite(v);
const isPoint = (p) => Array.isArray(p) && p.length >= 2 && isNum(p[0]) && isNum(p[1]);
const isDisk = (d) => isPoint(d) && d.length === 3 && isNum(d[2]);
const isTrack = (v) => !!v && typeof v === "object" && Array.isArray(v.keyframes);
const marked = () => (animated() && S.at ? S.at : S.recipe);
const valueAt = (recipe, path) => path.reduce((o, key) => o[key], recipe.steps);

// the shapes of the recipe: {pts, closed, colour, arrow} polylines on the sphere, and
// handles {at, colour, path, disk} where path names the value in the recipe ([step, ...keys])
function recipeShapes(recipe = marked()) {
  const shapes = [], handles = [];
  (recipe.steps || []).forEach((step, k) => {
    if (step.droste) {
      const v = step.droste;
      if (Array.isArray(v.frame) && v.frame.length === 4 && v.frame.every(isPoint)) {
        shapes.push({ pts: arcs(v.frame, true), closed: false, colour: "#ff4ae3" });
        v.frame.forEach((p, j) => handles.push({ at: p, colour: "#ff4ae3", path: [k, "droste", "frame", j] }));
      }
      if (isPoint(v.center)) {
        if (isNum(v.inner_radius))
          shapes.push({ pts: circle([...v.center, v.inner_radius]), closed: true, colour: "#ff4ae3" });
        handles.push({ at: v.center, colour: "#ff4ae3", path: [k, "droste", "center"] });
      }
    }
    if (step.schottky && Array.isArray(step.schottky.generators)) {
      step.schottky.generators.forEach((g, j) => {
        if (!g || !isDisk(g.disk)) return;
        shapes.push({ pts: circle(g.disk), closed: true, colour: "#7aff4a" });
        handles.push({ at: g.disk, colour: "#7aff4a", path: [k, "schottky", "generators", j, "disk"], disk: true });
        if (!isDisk(g.to)) return;
        shapes.push({ pts: circle(g.to), closed: true, colour: "#ff7a4a" });
        handles.push({ at: g.to, colour: "#ff7a4a", path: [k, "schottky", "generators", j, "to"], disk: true });
        shapes.push({ pts: geodesic(g.disk, g.to), closed: false, colour: "#ffffff", arrow: true });
      });
    }
    if (step.schottky && Array.isArray(step.schottky.targets)) {
      step.schottky.targets.forEach((t, j) => {
        if (!t || !isDisk(t.to)) return;
        shapes.push({ pts: circle(t.to), closed: true, colour: "#ff7a4a" });
        handles.push({ at: t.to, colour: "#ff7a4a", path: [k, "schottky", "targets", j, "to"], disk: true });
      });
    }
  });
  return { shapes, handles };
}

function drawRecipeMarks(c, x0, view, line, dot) {
  const { shapes, handles } = recipeShapes();
  for (const s of shapes) {
    line(s.pts, s.colour, x0, view, s.closed);
    if (s.arrow) {  // the head at the end (D_X), along the last piece that is shown
      const qs = s.pts.slice(-6).map((p) => lonLatToPixel(p[0], p[1], view));
      const [a, b] = [qs[0], qs[qs.length - 1]];
      if (a && b && Math.hypot(b[0] - a[0], b[1] - a[1]) > 1 && Math.abs(b[0] - a[0]) < S.size[0] / 2) {
        const t = Math.atan2(b[1] - a[1], b[0] - a[0]);
        c.beginPath();
        for (const s2 of [-1, 1])
          c.moveTo(x0 + b[0], b[1]), c.lineTo(x0 + b[0] - 8 * Math.cos(t + s2 * 0.4), b[1] - 8 * Math.sin(t + s2 * 0.4));
        c.stroke();
      }
    }
  }
  for (const h of handles) {
    const q = lonLatToPixel(h.at[0], h.at[1], view);
    if (q) dot(x0 + q[0], q[1], h.colour, 3.5);
  }
}

// the handles' pixels in each panel (the tests): [{path, panel, x, y}] (x of the whole canvas)
function markPositions() {
  const out = [];
  if (!S.marks) return out;
  const { handles } = recipeShapes();
  panels().forEach((panel, i) => {
    if (!panel.edited) return;
    for (const h of handles) {
      const q = lonLatToPixel(h.at[0], h.at[1], panel.view);
      if (q && q[0] >= 0 && q[0] < S.size[0] && q[1] >= 0 && q[1] < S.size[1])
        out.push({ path: h.path, panel: i, x: i * S.size[0] + q[0], y: q[1] });
    }
  });
  return out;
}

// the handle within 8 pixels of (px, py) in a panel of this view, the nearest; else a
// disk whose rim passes within 5 pixels, as a handle of its radius; else null
function handleAt(px, py, view) {
  if (!S.marks) return null;
  const { handles } = recipeShapes();
  let best = null, bd = 8;
  for (const h of handles) {
    const q = lonLatToPixel(h.at[0], h.at[1], view);
    const d = q ? Math.hypot(q[0] - px, q[1] - py) : Infinity;
    if (d <= bd) (best = h), (bd = d);
  }
  if (best) return best;
  bd = 5;
  for (const h of handles.filter((h) => h.disk)) {
    const qs = circle(h.at).map((p) => lonLatToPixel(p[0], p[1], view));
    qs.forEach((a, j) => {
      const b = qs[(j + 1) % qs.length];
      if (!a || !b || Math.abs(b[0] - a[0]) >= S.size[0] / 2) return; // behind, or across the seam
      const d = segmentDistance([px, py], a, b);
      if (d <= bd) (best = { ...h, radius: true }), (bd = d);
    });
  }
  return best;
}

// the distance from p to the segment ab (pixels)
function segmentDistance(p, a, b) {
  const [dx, dy] = [b[0] - a[0], b[1] - a[1]];
  const t = Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy || 1)));
  return Math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
}

// the recipe with the handle's value moved to `to`: a point, a disk's centre (its radius
// kept) or, for a rim, a disk's radius (its centre kept). A value that is a track gets
// a keyframe at `time` (the one there changed, or one added; see keyed).
function movedRecipe(recipe, handle, to, time = 0) {
  const r = JSON.parse(JSON.stringify(recipe));
  const o = valueAt(r, handle.path.slice(0, -1));
  const last = handle.path[handle.path.length - 1];
  const old = o[last];
  if (handle.radius) o[last] = [old[0], old[1], round([angle(old, to)])[0]];
  else o[last] = keyed(old, old.length === 3 ? [...round(to), old[2]] : round(to), time);
  return r;
}

// `value` in place of `old`, at time t: where old is a track (the whole point, or one
// coordinate), its keyframe at t becomes value (a keyframe added at t if none is there),
// so that the effect is where the mark was dropped at that time and keeps its other keys
function keyed(old, value, t) {
  if (isTrack(old)) {
    const frames = old.keyframes.filter((f) => Math.abs(f[0] - t) > 1e-9);
    frames.push([t, value]);
    return { ...old, keyframes: frames.sort((a, b) => a[0] - b[0]) };
  }
  if (Array.isArray(old) && Array.isArray(value)) return value.map((v, i) => keyed(old[i], v, t));
  return value;
}

const unit = (p) => {
  const [lon, lat] = [p[0] * DEG, p[1] * DEG];
  return [Math.cos(lat) * Math.cos(lon), Math.cos(lat) * Math.sin(lon), Math.sin(lat)];
};
const lonlat = (d) => [Math.atan2(d[1], d[0]) / DEG, Math.atan2(d[2], Math.hypot(d[0], d[1])) / DEG];
const angle = (a, b) => {
  const [u, v] = [unit(a), unit(b)];
  return Math.acos(Math.max(-1, Math.min(1, u[0] * v[0] + u[1] * v[1] + u[2] * v[2]))) / DEG;
};

// great-circle arcs through the points, 16 pieces each (the edges of a frame)
function arcs(pts, closed) {
  const out = [];
  const n = closed ? pts.length : pts.length - 1;
  for (let k = 0; k < n; k++) {
    const [a, b] = [unit(pts[k]), unit(pts[(k + 1) % pts.length])];
    for (let j = 0; j <= 16; j++) {
      const t = j / 16;
      out.push(lonlat(a.map((x, i) => x * (1 - t) + b[i] * t)));
    }
  }
  return out;
}

// the great circle arc from a to b (degrees), 32 pieces (by way of a point off the
// line when they are antipodal)
function geodesic(a, b) {
  let [u, v] = [unit(a), unit(b)];
  const d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  if (d < -0.999) {
    const e = Math.abs(u[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0];
    const mid = lonlat(e.map((x, i) => x - (e[0] * u[0] + e[1] * u[1] + e[2] * u[2]) * u[i]));
    return [...geodesic(a, mid), ...geodesic(mid, b).slice(1)];
  }
  const w = Math.acos(Math.max(-1, Math.min(1, d)));
  const out = [];
  for (let j = 0; j <= 32; j++) {
    const t = j / 32;
    const [p, q] = w < 1e-9 ? [1 - t, t] : [Math.sin((1 - t) * w) / Math.sin(w), Math.sin(t * w) / Math.sin(w)];
    out.push(lonlat(u.map((x, i) => p * x + q * v[i])));
  }
  return out;
}

// the circle of a disk [lon, lat, radius] on the sphere, as 72 points
function circle(d) {
  const cv = unit(d);
  const e1 = Math.abs(cv[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0];
  const dotp = e1[0] * cv[0] + e1[1] * cv[1] + e1[2] * cv[2];
  let a = e1.map((x, i) => x - dotp * cv[i]);
  const n = Math.hypot(...a);
  a = a.map((x) => x / n);
  const b = [cv[1] * a[2] - cv[2] * a[1], cv[2] * a[0] - cv[0] * a[2], cv[0] * a[1] - cv[1] * a[0]];
  const r = d[2] * DEG;
  const pts = [];
  for (let k = 0; k < 72; k++) {
    const t = (2 * Math.PI * k) / 72;
    pts.push(lonlat(cv.map((x, i) => Math.cos(r) * x + Math.sin(r) * (Math.cos(t) * a[i] + Math.sin(t) * b[i]))));
  }
  return pts;
}

// -- the views, in JS as in the shader's outDir: canvas pixel <-> (lon, lat) degrees ----------
function pixelToLonLat(px, py, view = S.view) {
  const [w, h] = S.size;
  if (view === "flat") return [(px / w) * 360 - 180, 90 - (py / h) * 180];
  const nx = (2 * px - w) / w;
  const ny = (2 * py - h) / w;
  let d;
  if (view === "sphere") {
    const [yaw, pitch, fov] = S.look.map((a) => a * DEG);
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const k = Math.tan(fov / 2);
    d = [
      cp * cy - k * nx * sy + k * ny * sp * cy,
      cp * sy + k * nx * cy + k * ny * sp * sy,
      sp - k * ny * cp,
    ];
  } else {
    let qx = nx * S.planet, qy = ny * S.planet;
    const cy = Math.cos(S.look[0] * DEG), sy = Math.sin(S.look[0] * DEG);
    [qx, qy] = [cy * qx - sy * qy, sy * qx + cy * qy];
    const r2 = qx * qx + qy * qy;
    d = [(2 * qx) / (1 + r2), (-2 * qy) / (1 + r2), (r2 - 1) / (1 + r2)];
  }
  const lon = Math.atan2(d[1], d[0]) / DEG;
  const lat = Math.atan2(d[2], Math.hypot(d[0], d[1])) / DEG;
  return [lon, lat];
}

// the panel's pixel (px, py) of the point (lon, lat) in degrees, or null where the view
// does not show it (behind the sphere view's camera)
function lonLatToPixel(lon, lat, view = S.view) {
  const [w, h] = S.size;
  if (view === "flat") return [(((lon + 180) % 360) + 360) % 360 / 360 * w, ((90 - lat) / 180) * h];
  const d = unit([lon, lat]);
  let nx, ny;
  if (view === "sphere") {
    const [yaw, pitch, fov] = S.look.map((a) => a * DEG);
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const f = [cp * cy, cp * sy, sp], r = [-sy, cy, 0], u = [-sp * cy, -sp * sy, cp];
    const dt = (a) => a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
    const k = Math.tan(fov / 2);
    if (dt(f) <= 1e-6) return null;
    nx = dt(r) / (k * dt(f));
    ny = -dt(u) / (k * dt(f));
  } else {
    if (d[2] > 1 - 1e-9) return null; // the zenith is at infinity
    const qx = d[0] / (1 - d[2]), qy = -d[1] / (1 - d[2]);
    const cy = Math.cos(S.look[0] * DEG), sy = Math.sin(S.look[0] * DEG);
    nx = (cy * qx + sy * qy) / S.planet;
    ny = (-sy * qx + cy * qy) / S.planet;
  }
  const px = ((nx + 1) * w) / 2, py = (ny * w + h) / 2;
  return Math.abs(px) < 1e5 && Math.abs(py) < 1e5 ? [px, py] : null;
}

// the event's pixel in a panel (the one under it, or the given one) and that panel
function eventPixel(ev, panel = null) {
  const r = canvas.getBoundingClientRect();
  const x = ((ev.clientX - r.left) * canvas.width) / r.width;
  const y = ((ev.clientY - r.top) * canvas.height) / r.height;
  const i = panel ?? Math.max(0, Math.min(panels().length - 1, Math.floor(x / S.size[0])));
  return [x - i * S.size[0], y, i];
}

const round = (p) => p.map((v) => Math.round(v * 1e6) / 1e6);

// -- the recipe: stages from the server, history, URL ---------------------------------------
let pending = null;
let inflight = false;

async function post(path, recipe) {
  const r = await fetch(path, {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify(recipe),
  });
  const data = await r.json();
  if (!r.ok) throw new Error(data.error || `HTTP ${r.status}`);
  return data;
}

// the latest recipe wins; one request in flight at a time
function refresh() {
  restage();
  writeURL();
}

// the stages again: the recipe changed, or (an animated recipe over a video) the time did
function restage() {
  pending = JSON.parse(JSON.stringify(S.recipe));
  if (!inflight) pump();
}

// the recipe's time: that of the video's frame shown (as 'spherewarp video' renders each
// frame: the recipe at the frame's time), else 0
function recipeTime() {
  if (!S.video) return 0;
  const t = S.video.currentTime;
  return S.rate ? Math.floor(t * S.rate + 1e-4) / S.rate : t;
}
const animated = () => JSON.stringify(S.recipe).includes('"keyframes"');

async function pump() {
  inflight = true;
  while (pending) {
    const recipe = pending;
    pending = null;
    try {
      const { stages, at } = await post(`api/stages${S.video ? `?t=${recipeTime()}` : ""}`, recipe);
      S.at = at || null; // an animated recipe's steps at this time: where its marks go
      await uploadStages(stages);
      if (stages.codes)
        status([`${recipe.steps.length} step(s), ${stages.codes.length} stage(s)`, ...previewNotes(recipe)].join("; "));
    } catch (e) {
      status(e.message, true);
    }
    draw();
  }
  inflight = false;
  S.settled = true;
  window.dispatchEvent(new Event("sw-drawn"));
}

// what the preview does not show of a recipe that 'spherewarp render' honours: its view
// (another projection, a field of view, a size) and its interpolation
function previewNotes(recipe) {
  const notes = [];
  const v = recipe.view && typeof recipe.view === "object" ? recipe.view : {};
  const parts = [];
  if (v.projection) parts.push(`${v.projection}`);
  if (v.fov != null) parts.push(`fov ${v.fov}°`);
  if (v.look_at != null) parts.push(`look_at ${JSON.stringify(v.look_at)}`);
  if (v.roll) parts.push(`roll ${v.roll}°`);
  if (Array.isArray(v.size)) parts.push(`${v.size[0]}x${v.size[1]}`);
  if (parts.length)
    notes.push(`the preview shows the panorama; the render uses the recipe's view (${parts.join(", ")})`);
  const interp = recipe.options && recipe.options.interp;
  if (interp && interp !== "bilinear")
    notes.push(`the preview interpolates bilinearly; the render uses options.interp "${interp}"`);
  return notes;
}

function commit(recipe) {
  S.undo.push(JSON.stringify(S.recipe));
  S.redo = [];
  S.recipe = recipe;
  refresh();
  buildSliders();
}

// undo: from S.undo to S.redo; redo: the other way
function shift(from, to) {
  if (!from.length) return;
  to.push(JSON.stringify(S.recipe));
  S.recipe = JSON.parse(from.pop());
  refresh();
  buildSliders();
}
const undo = () => shift(S.undo, S.redo);
const redo = () => shift(S.redo, S.undo);

function writeURL() {
  const q = new URLSearchParams();
  q.set("view", S.view);
  q.set("size", `${S.size[0]}x${S.size[1]}`);
  if (S.ss !== 2) q.set("ss", S.ss);
  if (S.side) q.set("side", S.side);
  if (!S.marks) q.set("marks", "0");
  q.set("recipe", JSON.stringify(S.recipe));
  history.replaceState(null, "", `?${q}`);
}

// the size of one panel: at most 8192 a side (as the URL's size), and what the GPU draws
// whole (its viewport and drawing buffer, shared by the panels side by side)
const MAX_SIZE = 8192;
function sizeLimit(n = panels().length) {
  const dims = gl.getParameter(gl.MAX_VIEWPORT_DIMS);
  const buffer = gl.getParameter(gl.MAX_RENDERBUFFER_SIZE);
  return [
    Math.min(MAX_SIZE, Math.floor(Math.min(dims[0], buffer) / n)),
    Math.min(MAX_SIZE, dims[1], buffer),
  ];
}

// "WxH" as [w, h], or throws an Error saying what is wrong with it
function parseSize(text, n = panels().length) {
  const m = /^\s*(\d+)\s*[x×]\s*(\d+)\s*$/i.exec(text || "");
  if (!m) throw new Error(`size: expected WIDTHxHEIGHT, such as 1024x512, got "${text}"`);
  const [w, h] = [+m[1], +m[2]];
  const [mw, mh] = sizeLimit(n);
  if (w < 1 || h < 1 || w > mw || h > mh)
    throw new Error(`size: expected a width of 1 to ${mw} and a height of 1 to ${mh} ` +
      `(what this GPU draws${n > 1 ? `, ${n} panels side by side` : ""}), got ${w}x${h}`);
  return [w, h];
}

// the size box: a size that cannot be drawn is refused with the reason, the size kept
function setSize(text) {
  try {
    S.size = parseSize(text);
  } catch (e) {
    $("size").setAttribute("aria-invalid", "true");
    return status(e.message, true);
  }
  $("size").removeAttribute("aria-invalid");
  $("size").value = `${S.size[0]}x${S.size[1]}`;
  status(`size ${S.size[0]}x${S.size[1]}`);
  writeURL();
  draw();
}

function readURL() {
  const q = new URLSearchParams(location.search);
  if (["flat", "sphere", "planet"].includes(q.get("view"))) S.view = q.get("view");
  if (["flat", "sphere", "planet", "original"].includes(q.get("side"))) S.side = q.get("side");
  if (q.get("size")) {
    try {
      S.size = parseSize(q.get("size"));
    } catch (e) {
      status(`the URL's ${e.message}`, true);
    }
  }
  if (q.get("marks") === "0") S.marks = false;
  const ss = +q.get("ss");
  if (ss >= 1 && ss <= 4) S.ss = Math.round(ss);
  if (q.get("recipe")) {
    try {
      S.recipe = JSON.parse(q.get("recipe"));
    } catch (e) {
      status(`recipe in the URL: ${e.message}`, true);
    }
  }
}

// -- direct manipulation ---------------------------------------------------------------------
let drag = null;

// a recipe checked by the server first (a frame whose corners are out of order, disks that
// overlap: the server's line, and the recipe stays as it was)
async function commitChecked(recipe, what) {
  try {
    await post("api/stages", recipe);
  } catch (e) {
    status(`${what}: ${e.message}`, true);
    return false;
  }
  commit(recipe);
  return true;
}

function setMode(kind) {
  S.mode = kind === null || (S.mode && S.mode.kind === kind) ? null : { kind, points: [], disks: [], cur: null };
  $("m-droste").classList.toggle("on", !!S.mode && S.mode.kind === "droste");
  $("m-schottky").classList.toggle("on", !!S.mode && S.mode.kind === "schottky");
  if (S.mode && S.mode.kind === "droste") status("Droste frame: click its four corners, in order round the frame");
  if (S.mode && S.mode.kind === "schottky")
    status("Schottky disks: press at a centre and drag out the radius, for D_x and then its target D_X");
  drawMarks();
}

// the four corners clicked: a droste step with that frame (spherewarp droste --corners)
async function drosteClick(at) {
  const m = S.mode;
  m.points.push(round(at));
  drawMarks();
  if (m.points.length < 4) return status(`Droste frame: corner ${m.points.length} of 4`);
  const frame = m.points;
  setMode(null);
  if (await commitChecked({ ...S.recipe, steps: [...S.recipe.steps, { droste: { frame } }] }, "Droste frame"))
    status("Droste frame added");
}

// a disk drawn: D_x, then its target D_X; the pair is a generator of the last schottky step
// (or of a new one)
async function schottkyDisk(disk) {
  const m = S.mode;
  m.disks.push(disk);
  m.cur = null;
  drawMarks();
  if (m.disks.length < 2) return status("Schottky disks: now the target disk D_X");
  const gen = { disk: m.disks[0], to: m.disks[1] };
  setMode(null);
  const steps = [...S.recipe.steps];
  const last = steps[steps.length - 1];
  if (last && last.schottky && Array.isArray(last.schottky.generators))
    steps[steps.length - 1] = { schottky: { ...last.schottky, generators: [...last.schottky.generators, gen] } };
  else steps.push({ schottky: { generators: [gen] } });
  if (await commitChecked({ ...S.recipe, steps }, "Schottky disks")) status("Schottky generator added");
}

canvas.addEventListener("mousedown", (ev) => {
  ev.preventDefault();
  const [px, py, i] = eventPixel(ev);
  const panel = panels()[i];
  const at = pixelToLonLat(px, py, panel.view);
  const look = () => (drag = { look: true, x: ev.clientX, y: ev.clientY, start: [...S.look] });
  if (!panel.edited) {
    if (panel.view === "sphere") look();
    else status("this panel is the image unedited: edit in the other one");
    return;
  }
  if (S.mode && S.mode.kind === "droste") return void drosteClick(at);
  if (S.mode && S.mode.kind === "schottky") {
    S.mode.cur = [...round(at), 0];
    drag = { disk: true, panel: i, view: panel.view };
    return;
  }
  const h = !ev.altKey && handleAt(px, py, panel.view);
  if (h) {  // a mark of the recipe: drag it to move that corner or centre (a rim: the radius)
    const time = animated() && S.at ? S.at.time : 0; // a track gets its keyframe at the time shown
    drag = { handle: h, time, base: JSON.parse(JSON.stringify(S.recipe)), moved: false, panel: i, view: panel.view };
    return;
  }
  if (ev.altKey) {  // pin a point (the older pin goes)
    S.pins = [S.pins[1], round(at)];
    showPins();
    drawMarks();
    return;
  }
  if (panel.view === "sphere" && !ev.shiftKey) return void look();
  drag = { from: round(at), base: JSON.parse(JSON.stringify(S.recipe)), moved: false, panel: i, view: panel.view };
});

function dragStep(from, to) {
  return { mobius: { from: [from, ...S.pins], to: [round(to), ...S.pins] } };
}

const dragAt = (ev) => {
  const [px, py] = eventPixel(ev, drag.panel);
  return pixelToLonLat(px, py, drag.view);
};

window.addEventListener("mousemove", (ev) => {
  if (!drag) return;
  if (drag.look) {
    const k = S.look[2] / (canvas.getBoundingClientRect().width / panels().length);
    S.look[0] = drag.start[0] + (ev.clientX - drag.x) * k;
    S.look[1] = Math.max(-89.9, Math.min(89.9, drag.start[1] + (ev.clientY - drag.y) * k));
    draw();
    return;
  }
  if (drag.disk) {
    S.mode.cur[2] = round([angle(S.mode.cur, dragAt(ev))])[0];
    drawMarks();
    return;
  }
  drag.moved = true;
  if (drag.handle) {  // live, unchecked: the server's line shows if it is not a step
    S.recipe = movedRecipe(drag.base, drag.handle, dragAt(ev), drag.time);
    refresh();
    return;
  }
  S.recipe = { ...drag.base, steps: [...drag.base.steps, dragStep(drag.from, dragAt(ev))] };
  refresh();
});

window.addEventListener("mouseup", (ev) => {
  if (!drag) return;
  const d = drag;
  const to = d.look ? null : dragAt(ev);
  drag = null;
  if (d.disk) {
    const disk = [...S.mode.cur.slice(0, 2), round([angle(S.mode.cur, to)])[0]];
    if (!(disk[2] >= 0.5 && disk[2] < 90)) {
      S.mode.cur = null;
      drawMarks();
      return status("Schottky disks: drag out a radius (0.5 to 90 degrees) from the centre", true);
    }
    return void schottkyDisk(disk);
  }
  if (d.look || !d.moved) return;
  if (d.handle) return void dropHandle(d, to);
  S.undo.push(JSON.stringify(d.base));
  S.redo = [];
  S.recipe = { ...d.base, steps: [...d.base.steps, dragStep(d.from, to)] };
  refresh();
  buildSliders();
});

// a mark dropped: the step checked by the server as a new one; kept (undo takes it back)
// or the recipe as it was before the drag, with the server's line
async function dropHandle(d, to) {
  const recipe = movedRecipe(d.base, d.handle, to, d.time);
  S.recipe = d.base;
  try {
    await post(`api/stages?t=${d.time}`, recipe); // at the time it was moved at
  } catch (e) {
    refresh(); // the picture of the recipe as it was, then the server's line
    await window.spherewarp.settle();
    return status(`moving the mark: ${e.message}`, true);
  }
  commit(recipe);
  await window.spherewarp.settle();
  const keyframe = JSON.stringify(valueAt(d.base, d.handle.path)).includes('"keyframes"');
  status((d.handle.radius ? "disk radius changed" : "mark moved") + (keyframe ? ` (keyframe at t = ${d.time} s)` : ""));
}

canvas.addEventListener(
  "wheel",
  (ev) => {
    ev.preventDefault();
    const [px, py, i] = eventPixel(ev);
    const panel = panels()[i];
    if ((ev.ctrlKey || ev.metaKey || ev.altKey) && panel.edited) {  // a conformal (Möbius) zoom at the cursor
      const at = round(pixelToLonLat(px, py, panel.view));
      const f = Math.exp(-ev.deltaY * 0.002);
      const steps = [...S.recipe.steps];
      const last = steps[steps.length - 1];
      if (last && last.zoom && last.zoom.at[0] === at[0] && last.zoom.at[1] === at[1] && !drag)
        steps[steps.length - 1] = { zoom: { at, factor: last.zoom.factor * f } };
      else steps.push({ zoom: { at, factor: f } });
      commit({ ...S.recipe, steps });
    } else if (panel.view === "sphere") {
      S.look[2] = Math.max(10, Math.min(170, S.look[2] * Math.exp(ev.deltaY * 0.001)));
      draw();
    } else if (panel.view === "planet") {
      S.planet = Math.max(0.05, Math.min(20, S.planet * Math.exp(ev.deltaY * 0.001)));
      draw();
    }
  },
  { passive: false },
);

window.addEventListener("keydown", (ev) => {
  if (ev.key === "Escape" && S.mode) {
    setMode(null);
    return status("cancelled");
  }
  if (!(ev.ctrlKey || ev.metaKey)) return;
  // in a text box (the size, the command), Ctrl+Z is the box's own undo, not the recipe's
  const t = ev.target;
  if (t instanceof HTMLElement && (t.isContentEditable || t.tagName === "TEXTAREA" ||
      (t.tagName === "INPUT" && !["range", "checkbox", "button", "file"].includes(t.type))))
    return;
  if (ev.key === "z" && !ev.shiftKey) undo();
  else if (ev.key === "y" || (ev.key === "z" && ev.shiftKey)) redo();
  else return;
  ev.preventDefault();
});

function showPins() {
  $("pins").textContent = S.pins.map((p) => `(${p[0].toFixed(1)}, ${p[1].toFixed(1)})`).join(" ");
}

// -- sliders for every numeric parameter -------------------------------------------------------
// a slider's [min, max, step] about the value v: v +- twice its size, inside the bounds of
// its parameter's spec (a value the recipe refuses is never reached: a zoom factor > 0,
// an integer where one is expected), with v on the slider's steps
function sliderRange(v, spec) {
  const span = Math.max(1, Math.abs(v)) * 2;
  const s = spec || {};
  const step = s.integer ? Math.max(1, Math.round(span / 500)) : span / 500;
  let below = Math.round(span / step); // steps below v, and above
  let above = below;
  const upTo = (d) => Math.max(0, Math.floor(d / step - 1e-6)); // steps k with k * step <= d
  const under = (d) => Math.max(0, Math.ceil(d / step - 1e-6) - 1); // ... with k * step < d
  if (s.ge != null) below = Math.min(below, upTo(v - s.ge));
  if (s.gt != null) below = Math.min(below, under(v - s.gt));
  if (s.le != null) above = Math.min(above, upTo(s.le - v));
  if (s.lt != null) above = Math.min(above, under(s.lt - v));
  return [v - below * step, v + above * step, step];
}

function buildSliders() {
  const box = $("params");
  box.replaceChildren();
  S.recipe.steps.forEach((step, k) => {
    const [name, params] = Object.entries(step)[0];
    const fs = document.createElement("fieldset");
    const lg = document.createElement("legend");
    lg.textContent = `${k + 1}. ${name}`;
    const del = document.createElement("button");
    del.textContent = "×";
    del.title = "remove this step";
    del.onclick = () => commit({ ...S.recipe, steps: S.recipe.steps.filter((_, i) => i !== k) });
    lg.append(" ", del);
    fs.append(lg);
    const add = (label, get, set, spec) => {
      const v = get();
      const [lo, hi, step] = sliderRange(v, spec);
      const row = document.createElement("label");
      const input = document.createElement("input");
      input.type = "range";
      input.min = lo;
      input.max = hi;
      input.step = step;
      input.value = v;
      const out = document.createElement("span");
      out.textContent = (+v).toPrecision(5);
      let base = null;
      let last = v;
      input.oninput = () => {
        if (base === null) base = JSON.stringify(S.recipe);
        if (spec && spec.nonzero && +input.value === 0) input.value = last > 0 ? -step : step;
        last = +input.value;
        set(+input.value);
        out.textContent = (+input.value).toPrecision(5);
        refresh();
      };
      input.onchange = () => {
        if (base !== null) S.undo.push(base), (S.redo = []);
        base = null;
        buildSliders();
      };
      row.append(`${label} `, input, out);
      fs.append(row);
    };
    const walk = (obj, path) => {
      for (const [key, val] of Object.entries(obj)) {
        if (typeof val === "number") {
          // a top-level parameter has the bounds of its effect's spec (a point's coordinates none)
          const spec = path ? null : ((S.params || {})[name] || {})[key];
          add(`${path}${key}`, () => obj[key], (x) => (obj[key] = x), spec);
        }
        else if (Array.isArray(val) || (val && typeof val === "object" && !val.keyframes))
          walk(val, `${path}${key}.`);
      }
    };
    walk(params, "");
    box.append(fs);
  });
}

// -- load, save, copy, render ------------------------------------------------------------------
function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
}

function cliCommand() {
  const json = JSON.stringify(S.recipe, null, 1);
  const [w, h] = S.size;
  // a recipe with a view renders that view (its projection, size): the page's size is not it
  const v = S.recipe.view;
  const size = v && typeof v === "object" && Object.keys(v).length ? "" : ` --size ${w}x${h}`;
  const render = S.video // every frame, the recipe at each frame's time
    ? `spherewarp video ${S.imageName} -o out.mp4${size} recipe recipe.json`
    : `spherewarp render recipe.json ${S.imageName} -o out.png${size}`;
  return `cat > recipe.json <<'EOF'\n${json}\nEOF\n${render}`;
}

function wireButtons() {
  $("undo").onclick = undo;
  $("redo").onclick = redo;
  $("save").onclick = () =>
    download("recipe.json", new Blob([JSON.stringify(S.recipe, null, 2) + "\n"], { type: "application/json" }));
  $("load-button").onclick = () => $("load").click(); // a button: reachable by Tab
  $("load").onchange = async (ev) => {
    const file = ev.target.files[0];
    if (!file) return;
    ev.target.value = ""; // the same file again is a change too (edited since, or undone)
    try {
      const recipe = JSON.parse(await file.text());
      await post("api/stages", recipe); // validated by the server first
      commit(recipe);
    } catch (e) {
      status(`${file.name}: ${e.message}`, true);
    }
  };
  $("copy").onclick = async () => {
    const text = cliCommand();
    $("cli").value = text;
    try {
      await navigator.clipboard.writeText(text);
      status("copied the command");
    } catch {
      status("the command is in the box below (the clipboard is not available)");
    }
  };
  $("render").onclick = async () => {
    // one render at a time from the page: the button is off until it is done or failed,
    // and what ends it (a refusal such as 429 included) stays in the status
    const button = $("render");
    if (button.disabled) return;
    button.disabled = true;
    const end = (text, bad = false) => {
      button.disabled = false;
      status(text, bad);
    };
    try {
      // a video: the frame shown now
      const at = S.video ? `?t=${recipeTime()}` : "";
      const { job } = await post(`api/render${at}`, S.recipe);
      const poll = async () => {
        let st;
        try {
          const r = await fetch(`api/render/${job}`);
          st = await r.json();
          if (!r.ok) throw new Error(st.error || `HTTP ${r.status}`);
        } catch (e) {
          // the server stopped (or forgot the render): say so, not "rendering" forever
          return end(`render: no answer from the server about the render (${e.message})`, true);
        }
        if (st.error) return end(`render: ${st.error}`, true);
        if (!st.done) {
          status(st.started ? `rendering ${(100 * st.progress).toFixed(0)}%`
                            : "waiting for an earlier render");
          return setTimeout(poll, 300);
        }
        end("rendered: downloading");
        const a = document.createElement("a");
        a.href = `api/render/${job}/file`;
        a.download = "";
        a.click();
      };
      poll();
    } catch (e) {
      end(`render: ${e.message}`, true);
    }
  };
  for (const v of ["flat", "sphere", "planet"])
    $(`v-${v}`).onclick = () => {
      S.view = v;
      writeURL();
      draw();
    };
  $("side").onchange = () => {
    S.side = $("side").value || null;
    const [mw] = sizeLimit();
    if (S.size[0] > mw) {
      // side by side wider than the GPU draws: each panel narrower, the shape kept
      S.size = [mw, Math.max(1, Math.round((S.size[1] * mw) / S.size[0]))];
      $("size").value = `${S.size[0]}x${S.size[1]}`;
      status(`size ${S.size[0]}x${S.size[1]}: the panels side by side are as wide as this GPU draws`);
    }
    writeURL();
    draw();
  };
  $("show-marks").checked = S.marks;
  $("show-marks").onchange = () => {
    S.marks = $("show-marks").checked;
    writeURL();
    drawMarks();
  };
  $("m-droste").onclick = () => setMode("droste");
  $("m-schottky").onclick = () => setMode("schottky");
  $("overlay").oninput = async () => {
    if (!S.patternLoaded) {
      S.patternLoaded = true;
      const pat = new Image();
      pat.src = "testpattern";
      await pat.decode();
      uploadImage(pat, 2);
    }
    S.overlay = +$("overlay").value;
    draw();
  };
  $("size").onchange = () => setSize($("size").value);
}

// -- start -------------------------------------------------------------------------------------
async function start() {
  const state = await (await fetch("api/state")).json();
  S.imageName = state.image.name;
  S.rate = state.rate;
  S.stageNames = Object.fromEntries(state.table.stages.map((t) => [t.code, t.name]));
  S.params = state.params; // the bounds of the effects' number parameters, for the sliders
  S.recipe = state.recipe;
  const ar = state.image.width / state.image.height;
  S.size = [Math.min(state.image.width, 2048), Math.round(Math.min(state.image.width, 2048) / ar)];
  readURL();
  $("size").value = `${S.size[0]}x${S.size[1]}`;
  $("side").value = S.side || "";
  compile(state.glsl_header);
  const img = new Image();
  img.src = "image"; // a video's first frame
  await img.decode();
  uploadImage(img);
  uploadImage(img, 2); // the overlay's texture until the test pattern is asked for
  if (state.image.video) await startVideo();
  wireButtons();
  showPins();
  buildSliders();
  refresh();
}

// hooks for the browser tests and the benchmark
window.spherewarp = {
  S,
  draw,
  pixelToLonLat,
  lonLatToPixel,
  markPositions,
  setRecipe: (r) => commit(r),
  // packed stages straight from Python (maps that no recipe effect makes yet)
  setStages: async (st) => {
    await uploadStages(st);
    draw();
  },
  // the video paused at time t (seconds), its frame there shown; resolves to the time
  seek: (t) =>
    new Promise((res) => {
      const v = S.video;
      v.pause();
      // "seeked" can come before the frame is decodable (readyState < 2: videoFrame then
      // uploads nothing, and the tick uploads it a frame or more later): resolve once the
      // frame of the new time is the texture and drawn
      const shown = () => {
        if (v.seeking || S.videoTime !== v.currentTime) return requestAnimationFrame(shown);
        window.spherewarp.settle().then(() => res(v.currentTime));
      };
      v.addEventListener("seeked", () => requestAnimationFrame(shown), { once: true });
      v.currentTime = t;
    }),
  settle: () =>
    new Promise((res) => {
      if (!inflight && !pending) return res();
      window.addEventListener("sw-drawn", () => res(), { once: true });
    }),
  frameTime: (n) => {
    const px = new Uint8Array(4);
    const t0 = performance.now();
    for (let i = 0; i < n; i++) {
      draw();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px); // waits for the frame
    }
    return (performance.now() - t0) / n;
  },
};

start()
  .then(() => (window.spherewarp.ready = true))
  .catch((e) => {
    status(e.message, true);
    window.spherewarp.error = e.message;
  });
