// lagsim view: draws the model from the scene description and animates it from the
// newest state at the display's frame rate (a state that arrives between two frames
// replaces the previous one: nothing queues). Strip charts of q, qd, effort (from the
// states) and energy (from the status), the status, the events, control buttons. A state
// that carries the scene's reference ("ref": r and r' of the joints that have one) has it
// drawn dashed over q and qd, in the joint's colour.
// Served by lagsim-view; uses no library.
"use strict";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
const CHART_MAX = 6000;          // samples kept per chart (latest win)
const EVENTS_MAX = 300;          // lines kept in the event list

const view = {
  scene: null, state: null, status: null, connected: false,
  dirty: true, frames: 0, statesReceived: 0, camX: null,
  charts: { q: [], qd: [], effort: [], energy: [],     // [t, values[]] per sample
            qref: [], qdref: [] },                     // the reference, in q's joint order
  hidden: new Set(),                                   // keys of the series toggled off
  history: null,                                       // what /api/history gave at load
  drawn: null,                                         // what the last frame drew
};
window.lagsimView = view;   // read by tests (DevTools) and handy in the console

const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------- stream
function connect() {
  const es = new EventSource("/events");
  es.addEventListener("open", () => { view.connected = true; showConn(); });
  es.addEventListener("error", () => { view.connected = false; showConn(); });
  es.addEventListener("bridge", (e) => { const b = JSON.parse(e.data); $("title").textContent = "lagsim view: " + b.prefix; });
  es.addEventListener("scene", (e) => { view.scene = JSON.parse(e.data); view.camX = null; view.dirty = true; kickJoints(); });
  es.addEventListener("state", (e) => onState(JSON.parse(e.data)));
  es.addEventListener("status", (e) => onStatus(JSON.parse(e.data)));
  es.addEventListener("events", (e) => onEvents(JSON.parse(e.data)));
}

// A page opened mid-run: the bridge's ring of the newest states and energies (GET
// /api/history, in pieces of at most 64 kB) is charted before the stream starts, so the
// charts show the last seconds at once; the stream's first state is newer than all of them.
async function loadHistory() {
  const got = { state: 0, energy: 0, requests: 0 };
  try {
    for (const of of ["state", "energy"]) {
      let from = 0;
      for (let k = 0; k < 64; k++) {   // bounded: the ring's 6000 fit in far fewer pieces
        const r = await fetch("/api/history?of=" + of + "&from=" + from);
        got.requests++;
        if (!r.ok) break;
        const j = await r.json();
        for (const smp of j.samples) {
          if (of === "state") {
            push(view.charts.q, smp[0], smp[1]);
            push(view.charts.qd, smp[0], smp[2]);
            push(view.charts.effort, smp[0], smp[3]);
          } else if (smp[1] !== null) push(view.charts.energy, smp[0], [smp[1]]);
        }
        got[of] += j.samples.length;
        if (!j.samples.length || j.next > j.last) break;
        from = j.next;
      }
    }
  } catch (err) {
    got.error = String(err);   // the stream still starts: live charts only
  }
  view.history = got;
  view.dirty = true;
}

function showConn() {
  const c = $("conn");
  c.textContent = view.connected ? "connected" : "disconnected (retrying)";
  c.className = view.connected ? "ok" : "bad";
}

function push(list, t, v) {
  if (list.length && t < list[list.length - 1][0]) list.length = 0;   // a reset: start over
  if (list.length && t === list[list.length - 1][0]) list[list.length - 1] = [t, v];
  else list.push([t, v]);
  if (list.length > CHART_MAX) list.splice(0, list.length - CHART_MAX);
}

function onState(s) {
  view.state = s;
  view.statesReceived++;
  if (s.sim_time !== null) {
    push(view.charts.q, s.sim_time, s.q);
    push(view.charts.qd, s.sim_time, s.qd);
    push(view.charts.effort, s.sim_time, s.effort);
    if (s.ref) {   // r and r' in the state's joint order (null: no reference for it)
      const at = s.name.map((n) => s.ref.name.indexOf(n));
      push(view.charts.qref, s.sim_time, at.map((i) => (i >= 0 ? s.ref.r[i] : null)));
      push(view.charts.qdref, s.sim_time, at.map((i) => (i >= 0 ? s.ref.rdot[i] : null)));
    }
  }
  view.dirty = true;
}

function onStatus(s) {
  view.status = s;
  if (s.sim_time !== null && s.energy !== null) push(view.charts.energy, s.sim_time, [s.energy]);
  view.dirty = true;
}

function onEvents(batch) {
  const ol = $("events");
  if (batch.missed > 0) addEvent(ol, "missed", batch.missed + " events not shown (the view fell behind)");
  for (const e of batch.events) {
    const t = e.sim_time === null ? "?" : e.sim_time.toFixed(3);
    addEvent(ol, e.kind, `t=${t}  ${e.kind}${e.joint ? " [" + e.joint + "]" : ""}  ${e.detail}`);
  }
}

function addEvent(ol, cls, text) {
  const li = document.createElement("li");
  li.className = cls.replace(/[^a-z_]/g, "");
  li.textContent = text;            // text only: event details come from the bus
  ol.insertBefore(li, ol.firstChild);
  while (ol.childNodes.length > EVENTS_MAX) ol.removeChild(ol.lastChild);
}

// ---------------------------------------------------------------- controls
async function control(request) {
  let url = "/api/control?request=" + request;
  if (request === "step") url += "&count=" + encodeURIComponent($("stepcount").value || "1");
  try {
    const r = await fetch(url, { method: "POST", headers: { "X-Lagsim": "1" } });
    const j = await r.json();
    $("ctlmsg").textContent = request + ": " + j.message;
  } catch (err) {
    $("ctlmsg").textContent = request + ": " + err;
  }
}
for (const id of ["pause", "resume", "step", "reset"]) $(id).addEventListener("click", () => control(id));

// a kick: the impulse on the chosen joint at the current sim time (lagsimctl kick); the
// daemon's kick event, or its reason, shows in the events
async function kick() {
  const j = $("kickjoint").value, imp = $("kickimpulse").value;
  const url = "/api/kick?joint=" + encodeURIComponent(j) + "&impulse=" + encodeURIComponent(imp);
  try {
    const r = await fetch(url, { method: "POST", headers: { "X-Lagsim": "1" } });
    const m = await r.json();
    $("ctlmsg").textContent = "kick " + j + " " + imp + ": " + m.message;
  } catch (err) {
    $("ctlmsg").textContent = "kick: " + err;
  }
}
$("kick").addEventListener("click", kick);
// the joints of the scene, to choose from (kept when the scene is described again)
function kickJoints() {
  const sel = $("kickjoint"), names = view.scene ? view.scene.joints : [];
  if ([...sel.options].map((o) => o.value).join() === names.join()) return;
  const keep = sel.value;
  sel.textContent = "";
  for (const n of names) {
    const o = document.createElement("option");
    o.value = o.textContent = n;
    sel.appendChild(o);
  }
  if (names.includes(keep)) sel.value = keep;
}

// ---------------------------------------------------------------- drawing helpers
function fit(canvas) {
  const r = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * r)), h = Math.max(1, Math.round(canvas.clientHeight * r));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  const g = canvas.getContext("2d");
  g.setTransform(r, 0, 0, r, 0, 0);
  return { g, w: canvas.clientWidth, h: canvas.clientHeight };
}

const P = (name) => (view.scene && view.scene.params && Number.isFinite(view.scene.params[name])) ? view.scene.params[name] : NaN;
function joint(name) {
  if (!view.scene || !view.state) return NaN;
  const i = view.state.name.indexOf(name);
  return i >= 0 && view.state.q[i] !== null ? view.state.q[i] : NaN;
}
function limitOf(name) {
  if (!view.scene) return null;
  const i = view.scene.joints.indexOf(name);
  return i >= 0 ? view.scene.limits[i] : null;
}
const hasEffect = (e) => !!view.scene && view.scene.effects.split(",").includes(e);

// A world-to-canvas map: meters, y up; scale in px per m.
function worldMap(w, h, cx, cy, scale) {
  return { scale, X: (x) => w / 2 + (x - cx) * scale, Y: (y) => h / 2 - (y - cy) * scale };
}

function line(g, m, x0, y0, x1, y1) { g.beginPath(); g.moveTo(m.X(x0), m.Y(y0)); g.lineTo(m.X(x1), m.Y(y1)); g.stroke(); }
function dot(g, m, x, y, r) { g.beginPath(); g.arc(m.X(x), m.Y(y), r, 0, 2 * Math.PI); g.fill(); }

function scaleBar(g, m, w, h) {
  const cands = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10];
  let len = cands[0];
  for (const c of cands) if (c * m.scale <= w * 0.25) len = c;
  const x0 = 14, y0 = h - 14, px = len * m.scale;
  g.strokeStyle = "#333"; g.lineWidth = 2;
  g.beginPath(); g.moveTo(x0, y0); g.lineTo(x0 + px, y0); g.moveTo(x0, y0 - 4); g.lineTo(x0, y0 + 4);
  g.moveTo(x0 + px, y0 - 4); g.lineTo(x0 + px, y0 + 4); g.stroke();
  g.fillStyle = "#333"; g.font = "12px DejaVu Sans, sans-serif";
  g.fillText(len + " m (to scale)", x0 + px + 6, y0 + 4);
}

function ground(g, m, w, y, hatched, label) {
  g.strokeStyle = "#555"; g.lineWidth = 2;
  g.beginPath(); g.moveTo(0, m.Y(y)); g.lineTo(w, m.Y(y)); g.stroke();
  if (hatched) {
    g.lineWidth = 1; g.strokeStyle = "#999";
    for (let x = -20; x < w + 20; x += 12) { g.beginPath(); g.moveTo(x, m.Y(y)); g.lineTo(x - 8, m.Y(y) + 8); g.stroke(); }
  }
  if (label) { g.fillStyle = "#777"; g.font = "11px DejaVu Sans, sans-serif"; g.fillText(label, 8, m.Y(y) + 22); }
}

// Keeps the camera on x, moving it only when x nears the edge.
function follow(x, halfWidth) {
  if (view.camX === null || !Number.isFinite(view.camX)) view.camX = 0;
  if (Math.abs(x - view.camX) > 0.6 * halfWidth) view.camX = x;
  return view.camX;
}

// ---------------------------------------------------------------- the models
// A cart on a track with a chain of rods on it: the DIPC (theta0; theta1, theta2; l1, l2;
// the pivot h0 above the track) and the cart-pole (x; theta; l1; h0 = 0). The scene says
// how many rods: every joint after the first (the cart's position) is a rod at its
// absolute angle from the upward vertical, rod i being l<i> long.
function drawCartRods(g, w, h) {
  const names = view.scene.joints, rods = names.slice(1);
  const ls = rods.map((_, i) => P("l" + (i + 1))), h0 = Number.isFinite(P("h0")) ? P("h0") : 0;
  const x = joint(names[0]), ts = rods.map(joint);
  const L = ls.reduce((a, b) => a + b, 0), span = 2 * L + 0.4;
  const scale = Math.min(h / span, w / (span * 1.6));
  const cx = follow(Number.isFinite(x) ? x : 0, w / (2 * scale));
  const m = worldMap(w, h, cx, h0, scale);
  ground(g, m, w, 0, false, "track");
  // ruler on the track every 0.1 m, numbered every 0.5 m
  g.strokeStyle = "#aaa"; g.fillStyle = "#888"; g.font = "10px DejaVu Sans, sans-serif"; g.lineWidth = 1;
  const x0 = Math.ceil((cx - w / (2 * scale)) * 10) / 10;
  for (let k = x0; k < cx + w / (2 * scale); k += 0.1) {
    const major = Math.abs(k * 2 - Math.round(k * 2)) < 1e-6;
    line(g, m, k, 0, k, major ? -0.04 : -0.02);
    if (major) g.fillText(k.toFixed(1), m.X(k) - 8, m.Y(-0.09));
  }
  const stops = [];
  const lim = limitOf(names[0]);
  if (lim) {
    g.strokeStyle = "#c62828"; g.lineWidth = 4;
    for (const s of lim) { line(g, m, s, -0.05, s, 0.12); stops.push([names[0], s]); }
  }
  if (Number.isFinite(x)) {
    for (const name of rods) {   // stops of a rod: dashed rays from the pivot
      const l = limitOf(name);
      if (!l) continue;
      g.strokeStyle = "#ef9a9a"; g.lineWidth = 1; g.setLineDash([4, 4]);
      for (const a of l) { line(g, m, x, h0, x + 0.35 * L * Math.sin(a), h0 + 0.35 * L * Math.cos(a)); stops.push([name, a]); }
      g.setLineDash([]);
    }
  }
  if (!rods.length || ![x, L, ...ts].every(Number.isFinite)) return null;
  const points = [[x, h0]];
  for (let i = 0; i < rods.length; i++) {
    const [px, py] = points[i];
    points.push([px + ls[i] * Math.sin(ts[i]), py + ls[i] * Math.cos(ts[i])]);
  }
  // the cart: its size is not a model parameter (drawn 0.3 m x 0.12 m); its centre is
  // at the cart's position, the pivot h0 above the track
  g.fillStyle = "#90a4ae"; g.strokeStyle = "#37474f"; g.lineWidth = 1.5;
  g.fillRect(m.X(x - 0.15), m.Y(h0 + 0.06), 0.3 * scale, 0.12 * scale);
  g.strokeRect(m.X(x - 0.15), m.Y(h0 + 0.06), 0.3 * scale, 0.12 * scale);
  g.lineCap = "round"; g.lineWidth = Math.max(4, 0.03 * scale);
  for (let i = 0; i < rods.length; i++) {
    g.strokeStyle = COLORS[i % COLORS.length];
    line(g, m, points[i][0], points[i][1], points[i + 1][0], points[i + 1][1]);
  }
  g.fillStyle = "#222";
  for (let i = 0; i < rods.length; i++) dot(g, m, points[i][0], points[i][1], 4);
  return { m, points, stops };
}

// Stick: centre of mass at x, angle phi from the floor, length l, lower end on the floor
// (y = 0) unless the scene publishes a height: a joint "y" (centre of mass height) or any
// other third joint (height of the lower end above the floor; with endA, the flying
// stick's, height of end A, at the centre minus l/2 along the stick).
function drawStick(g, w, h, endA) {
  const l = P("l"), x = joint("x"), phi = joint("phi");
  let yc = NaN;
  if (view.state && view.state.name.includes("y")) yc = joint("y");
  else if (view.state && view.state.name.length > 2) {
    const hh = view.state.q[2], s = Math.sin(phi);
    yc = (hh === null ? 0 : hh) + 0.5 * l * (endA ? s : Math.abs(s));
  } else yc = 0.5 * l * Math.sin(phi);
  const top = Math.max(1.15 * l, Number.isFinite(yc) ? yc + 0.65 * l : 0);
  const scale = Math.min(h / (top + 0.25 * l), w / (2.6 * l));
  const cx = follow(Number.isFinite(x) ? x : 0, w / (2 * scale));
  const m = worldMap(w, h, cx, (top - 0.25 * l) / 2, scale);
  ground(g, m, w, 0, hasEffect("floor"),
         hasEffect("floor") ? "floor (impacts on)"
           : endA ? "the floor's level: no floor (the stick passes it)"
           : "floor: the model keeps the lower end on it");
  const lim = limitOf("x");
  if (lim) { g.strokeStyle = "#c62828"; g.lineWidth = 4; for (const s of lim) line(g, m, s, 0, s, 0.3 * l); }
  if (![l, x, phi, yc].every(Number.isFinite)) return null;
  const dx = 0.5 * l * Math.cos(phi), dy = 0.5 * l * Math.sin(phi);
  const a = [x - dx, yc - dy], b = [x + dx, yc + dy];
  g.lineCap = "round"; g.strokeStyle = COLORS[0]; g.lineWidth = Math.max(5, 0.04 * scale);
  line(g, m, a[0], a[1], b[0], b[1]);
  g.fillStyle = "#222"; dot(g, m, x, yc, 4);
  return { m, points: [a, [x, yc], b] };
}

// Manipulator: arm 1 about the axis at the origin at angle q1 from the horizontal (drawn
// 2 l1 long: a uniform arm whose centre of mass is at l1), the sliding link with its
// centre of mass at q2 along it.
function drawManipulator(g, w, h) {
  const l1 = P("l1"), q1 = joint("q1"), q2 = joint("q2");
  const lim2 = limitOf("q2"), lim1 = limitOf("q1");
  let R = 2 * l1;
  if (Number.isFinite(q2)) R = Math.max(R, Math.abs(q2) + 0.3 * l1);
  if (lim2) R = Math.max(R, Math.abs(lim2[0]), Math.abs(lim2[1]));
  const scale = Math.min(w, h) / (2 * R + 0.4 * l1);
  const m = worldMap(w, h, 0, 0, scale);
  g.strokeStyle = "#ddd"; g.lineWidth = 1; line(g, m, -R, 0, R, 0);
  if (lim1) {
    g.strokeStyle = "#ef9a9a"; g.setLineDash([4, 4]);
    for (const a of lim1) line(g, m, 0, 0, 1.05 * R * Math.cos(a), 1.05 * R * Math.sin(a));
    g.setLineDash([]);
  }
  if (![l1, q1, q2].every(Number.isFinite)) return null;
  const c = Math.cos(q1), s = Math.sin(q1);
  g.lineCap = "round"; g.strokeStyle = "#78909c"; g.lineWidth = Math.max(5, 0.03 * scale);
  line(g, m, 0, 0, 2 * l1 * c, 2 * l1 * s);
  if (lim2) {
    g.fillStyle = "#c62828";
    for (const d of lim2) dot(g, m, d * c, d * s, 4);
  }
  const half = 0.25 * l1;   // the sliding link's length is not a parameter: drawn 0.5 l1
  g.strokeStyle = COLORS[1]; g.lineWidth = Math.max(9, 0.06 * scale);
  line(g, m, (q2 - half) * c, (q2 - half) * s, (q2 + half) * c, (q2 + half) * s);
  g.fillStyle = "#222"; dot(g, m, 0, 0, 5); dot(g, m, q2 * c, q2 * s, 4); dot(g, m, l1 * c, l1 * s, 3);
  return { m, points: [[0, 0], [2 * l1 * c, 2 * l1 * s], [q2 * c, q2 * s]] };
}

// The flying stick named by a scene (no floor: model stick's floor publishes model stick):
// its third joint h is end A's height.
function drawFlyingStick(g, w, h) { return drawStick(g, w, h, true); }

// A drawing per model of the core's table, by its name (scene_tables_view: every model of
// the table has one here, and nothing else is here).
const DRAW = {
  stick: drawStick, manipulator: drawManipulator, dipc: drawCartRods, cartpole: drawCartRods,
  "flying-stick": drawFlyingStick,
};

function drawModel() {
  const { g, w, h } = fit($("model"));
  g.clearRect(0, 0, w, h);
  g.fillStyle = "#666"; g.font = "13px DejaVu Sans, sans-serif";
  if (!view.scene) { g.fillText("waiting for the scene description (is lagsimd running with this prefix?)", 14, 24); return null; }
  const f = DRAW[view.scene.model];
  const st = view.state;
  let r = null;
  if (f) {
    r = f(g, w, h);
    if (r) scaleBar(g, r.m, w, h);
  } else {
    // a model this page cannot draw: its coordinates as numbers (the charts go on below)
    r = { note: "no drawing for model \"" + view.scene.model + "\": its coordinates are listed here and charted below" };
    g.fillText(r.note, 14, 24);
    g.fillStyle = "#333"; g.font = "13px DejaVu Sans Mono, monospace";
    const names = st ? st.name : view.scene.joints;
    names.forEach((n, i) => {
      const v = st && st.q[i] !== null ? st.q[i].toFixed(6) : "–";
      const vd = st && st.qd[i] !== null ? st.qd[i].toFixed(6) : "–";
      g.fillText(`${n} = ${v}   ${n}_dot = ${vd}`, 14, 50 + 18 * i);
    });
  }
  g.fillStyle = "#333"; g.font = "13px DejaVu Sans Mono, monospace";
  if (st && st.sim_time !== null) g.fillText("t = " + st.sim_time.toFixed(3) + " s", w - 130, 20);
  return r;
}

// ---------------------------------------------------------------- charts
// A chart draws a list of series. A series is a key (unique, for the toggles), a label,
// a colour, a dash pattern, a unit, the samples it reads ([t, values[]] each) and get(values)
// giving its number from one sample; a second series per joint (a reference, say) is one
// more entry in what a chart's series() returns. Units of the "m" family go on the left
// axis, those of the "rad" family on the right one, each axis with its own range.
const UNIT_FAMILY = { m: "left", "m/s": "left", N: "left", rad: "right", "rad/s": "right", "N m": "right" };
const DERIVED_UNIT = {   // a joint's unit (scene.units, from the core's table) per chart
  q: (u) => u, qd: (u) => u + "/s", effort: (u) => (u === "m" ? "N" : "N m"),
};
const MIN_SPAN = 1e-6;   // an axis spans at least MIN_SPAN x max(1, |largest value|), as lagsim-plot

// The scene's facts about a joint by name: its unit ("m", "rad", or null) and whether a
// command can move it (unknown: treated as actuated).
function jointInfo(name) {
  const sc = view.scene, i = sc ? sc.joints.indexOf(name) : -1;
  return {
    unit: i >= 0 && sc.units ? sc.units[i] : null,
    actuated: i >= 0 ? sc.actuated[i] : true,
  };
}

// One series per joint of the newest state, from samples `list`; `keep(name)` picks joints.
function jointSeries(chart, list, suffix, keep) {
  const names = view.state ? view.state.name : [];
  const out = [];
  names.forEach((name, k) => {
    const info = jointInfo(name);
    if (keep && !keep(name, info)) return;
    out.push({
      key: chart + ":" + name, label: name + suffix, color: COLORS[k % COLORS.length], dash: [],
      unit: info.unit ? DERIVED_UNIT[chart](info.unit) : null, samples: list, get: (v) => v[k],
    });
  });
  return out;
}

// The reference (r over q, r' over q dot), dashed in its joint's colour: the scene's
// `reference:` as the daemon publishes it beside each state (none: no series).
function refSeries(chart, list, suffix) {
  if (!list.length) return [];
  return jointSeries(chart, list, suffix).map((s) => Object.assign(s, { key: s.key + ":ref", dash: [6, 4] }));
}

const CHARTS = [
  { id: "chart_q", name: "q",
    series: () => jointSeries("q", view.charts.q, "").concat(refSeries("q", view.charts.qref, "_ref")) },
  { id: "chart_qd", name: "qd",
    series: () => jointSeries("qd", view.charts.qd, "_dot").concat(refSeries("qd", view.charts.qdref, "_dot_ref")) },
  // an unactuated joint's effort is zero by definition: not drawn
  { id: "chart_effort", name: "effort",
    series: () => jointSeries("effort", view.charts.effort, "_effort", (n, info) => info.actuated) },
  { id: "chart_energy", name: "energy",
    series: () => [{ key: "energy:E", label: "E = T + U", color: COLORS[0], dash: [], unit: "J",
                     samples: view.charts.energy, get: (v) => v[0] }] },
];

// lo..hi widened to the minimum span about its middle, then padded 8 % each side.
function axisRange(lo, hi) {
  const min = MIN_SPAN * Math.max(1, Math.abs(lo), Math.abs(hi));
  if (hi - lo < min) { const c = 0.5 * (lo + hi); lo = c - 0.5 * min; hi = c + 0.5 * min; }
  const pad = 0.08 * (hi - lo);
  return [lo - pad, hi + pad];
}

// The legend under a chart: one button per series, a click hides or shows it.
function legend(canvas, series) {
  let box = canvas.nextElementSibling;
  if (!box || !box.classList.contains("legend")) {
    box = document.createElement("div");
    box.className = "legend";
    canvas.after(box);
  }
  const keys = series.map((s) => s.key).join("\n");
  if (box.dataset.keys !== keys) {
    box.dataset.keys = keys;
    box.textContent = "";
    for (const s of series) {
      const b = document.createElement("button");
      b.type = "button";
      b.dataset.key = s.key;
      b.textContent = s.label + (s.unit ? " (" + s.unit + ")" : "");
      b.style.color = s.color;
      b.title = "click: hide or show this trace";
      b.addEventListener("click", () => {
        if (view.hidden.has(s.key)) view.hidden.delete(s.key); else view.hidden.add(s.key);
        view.dirty = true;
      });
      box.appendChild(b);
    }
  }
  for (const b of box.children) b.classList.toggle("off", view.hidden.has(b.dataset.key));
}

// Draws a chart's visible series over the chosen window of sim time; returns what it drew
// (axes with their unit and range, the series on each) for view.drawn.
function drawChart(canvas, series) {
  const { g, w, h } = fit(canvas);
  g.clearRect(0, 0, w, h);
  legend(canvas, series);
  g.fillStyle = "#555"; g.font = "11px DejaVu Sans, sans-serif";
  g.fillText(canvas.dataset.title, 6, 12);
  const win = Number($("window").value) || 10;
  const shown = series.filter((s) => !view.hidden.has(s.key));
  let tEnd = -Infinity;
  for (const s of shown) if (s.samples.length) tEnd = Math.max(tEnd, s.samples[s.samples.length - 1][0]);
  const drawnInfo = { axes: {}, series: [] };
  if (!Number.isFinite(tEnd)) return drawnInfo;
  let t0 = tEnd - win;
  let tFirst = Infinity;
  for (const s of shown) if (s.samples.length) tFirst = Math.min(tFirst, s.samples[0][0]);
  t0 = Math.max(t0, tFirst);
  const span = Math.max(tEnd - t0, 1e-9);
  // one axis per side: the units of a side (one family) and their range
  const axes = {};
  for (const s of shown) {
    const side = UNIT_FAMILY[s.unit] || "left";
    const ax = axes[side] || (axes[side] = { units: [], lo: Infinity, hi: -Infinity });
    if (!ax.units.includes(s.unit || "m or rad")) ax.units.push(s.unit || "m or rad");
    for (let i = s.samples.length - 1; i >= 0 && s.samples[i][0] >= t0; i--) {
      const v = s.get(s.samples[i][1]);
      if (v !== null && v !== undefined && Number.isFinite(v)) { ax.lo = Math.min(ax.lo, v); ax.hi = Math.max(ax.hi, v); }
    }
  }
  const L = 86, R = 86, T = 16, B = 14;
  const X = (t) => L + (t - t0) / span * (w - L - R);
  for (const side of Object.keys(axes)) {
    const ax = axes[side];
    if (!(ax.hi >= ax.lo)) { delete axes[side]; continue; }
    [ax.lo, ax.hi] = axisRange(ax.lo, ax.hi);
    ax.Y = (v) => T + (ax.hi - v) / (ax.hi - ax.lo) * (h - T - B);
    // enough digits to tell the bounds apart (energy drifts in its 7th digit)
    const digits = Math.min(12, Math.max(4, 2 + Math.ceil(Math.log10(Math.max(Math.abs(ax.hi), Math.abs(ax.lo)) / (ax.hi - ax.lo)))));
    const x = side === "left" ? 2 : w - R + 4;
    g.fillStyle = "#777";
    g.fillText(ax.units.join(", "), x, T + 20);
    g.fillText(ax.hi.toPrecision(digits), x, T + 8); g.fillText(ax.lo.toPrecision(digits), x, h - B);
    if (ax.lo < 0 && ax.hi > 0) {
      g.strokeStyle = "#eee"; g.lineWidth = 1;
      g.beginPath(); g.moveTo(L, ax.Y(0)); g.lineTo(w - R, ax.Y(0)); g.stroke();
    }
    drawnInfo.axes[side] = { units: ax.units, lo: ax.lo, hi: ax.hi };
  }
  g.fillStyle = "#777";
  g.fillText(t0.toFixed(1) + " s", L, h - 2); g.fillText(tEnd.toFixed(1) + " s", w - R - 40, h - 2);
  for (const s of shown) {
    const side = UNIT_FAMILY[s.unit] || "left", ax = axes[side];
    if (!ax) continue;
    g.strokeStyle = s.color; g.lineWidth = 1.5; g.setLineDash(s.dash); g.beginPath();
    let pen = false, n = 0, first = s.samples.length;
    while (first > 0 && s.samples[first - 1][0] >= t0) first--;
    for (let i = first; i < s.samples.length; i++) {
      const v = s.get(s.samples[i][1]);
      if (v === null || v === undefined) { pen = false; continue; }
      if (pen) g.lineTo(X(s.samples[i][0]), ax.Y(v)); else g.moveTo(X(s.samples[i][0]), ax.Y(v));
      pen = true; n++;
    }
    g.stroke(); g.setLineDash([]);
    drawnInfo.series.push({ key: s.key, label: s.label, unit: s.unit, axis: side, points: n,
                            t_first: first < s.samples.length ? s.samples[first][0] : null });
  }
  return drawnInfo;
}

function drawCharts() {
  const out = {};
  for (const c of CHARTS) out[c.name] = drawChart($(c.id), c.series());
  return out;
}

// ---------------------------------------------------------------- status
function fmt(x, d) { return x === null || x === undefined ? "–" : Number(x).toFixed(d); }
function drawStatus() {
  const s = view.status, sc = view.scene, rows = [];
  if (sc) rows.push(["model", `${sc.model}, ${sc.integrator}, dt ${sc.dt} s, period ${sc.control_period} s` +
                     (sc.effects ? `, effects: ${sc.effects}` : ", no effects")]);
  if (s) {
    const rej = s.rejected_unknown_joint + s.rejected_unactuated + s.rejected_nonfinite +
                s.rejected_bad_length + s.rejected_undecodable + s.rejected_stale;
    rows.push(["run state", s.run_state, s.run_state !== "running"]);
    rows.push(["mode", s.mode + (sc && s.mode === "realtime" ? ` at rate ${sc.rate}` : "")]);
    rows.push(["real-time factor", fmt(s.rtf, 3)]);
    rows.push(["overruns", `${s.overruns} (bursts ${s.overrun_bursts})`, s.overruns > 0]);
    rows.push(["step time", `mean ${fmt(s.step_time_mean_us, 1)} us, max ${fmt(s.step_time_max_us, 1)} us`]);
    rows.push(["commands", `${s.commands_accepted} accepted, ${rej} rejected` +
               (rej ? ` (unknown ${s.rejected_unknown_joint}, unactuated ${s.rejected_unactuated}, non-finite ${s.rejected_nonfinite}, length ${s.rejected_bad_length}, undecodable ${s.rejected_undecodable}, stale ${s.rejected_stale})` : ""), rej > 0]);
    rows.push(["controls rejected", String(s.controls_rejected)]);
    rows.push(["watchdog", (s.watchdog_tripped ? "TRIPPED: efforts zeroed" : "ok") + `, ${s.watchdog_trips} trips`, s.watchdog_tripped]);
    rows.push(["lockstep timeouts", String(s.lockstep_timeouts), s.lockstep_timeouts > 0]);
    rows.push(["numeric faults", String(s.numeric_faults), s.numeric_faults > 0]);
    rows.push(["energy", fmt(s.energy, 6) + " J"]);
    rows.push(["states published", String(s.states_published)]);
    if (s.error_joint)
      rows.push(["error estimate", `${Number(s.error_estimate).toPrecision(3)} per period (${s.error_joint})` +
                 (s.error_budget > 0 ? `, budget ${Number(s.error_budget).toPrecision(3)}, ${s.error_warnings} over` : ""),
                 s.error_budget > 0 && s.error_estimate > s.error_budget]);
    if (s.plant_conflicts > 0)
      rows.push(["prefix conflict", `${s.plant_conflicts} scenes of another plant on this prefix (running on; one plant per prefix)`, true]);
  } else rows.push(["status", "none yet"]);
  const tb = $("status").tBodies[0];
  tb.textContent = "";
  for (const [k, v, warn] of rows) {
    const tr = tb.insertRow(), a = tr.insertCell(), b = tr.insertCell();
    a.textContent = k; b.textContent = v;
    if (warn) b.className = "warn";
  }
}

// ---------------------------------------------------------------- frame loop
function frame() {
  if (view.dirty) {
    view.dirty = false;
    const r = drawModel();
    const charts = drawCharts();
    drawStatus();
    const st = view.state;
    if (st && st.sim_time !== null) $("simtime").textContent = "t = " + st.sim_time.toFixed(3) + " s";
    view.frames++;
    view.drawn = {
      frame: view.frames,
      model: view.scene ? view.scene.model : null,
      sim_time: st ? st.sim_time : null,
      q: st ? st.q.slice() : null,
      points: r && r.points ? r.points : null, // world coordinates (m) of what was drawn
      stops: r && r.stops ? r.stops : null,      // [joint, value] of each stop drawn
      note: r && r.note ? r.note : null,         // said instead of a drawing
      run_state: view.status ? view.status.run_state : null,
      ref: st && st.ref ? st.ref : null,         // the state's reference, as it came
      // dashed series drawn over q and over qd (with at least one point)
      ref_dashed: ["q", "qd"].map((c) => charts[c].series.filter((s) => s.key.endsWith(":ref") && s.points > 0).length),
      charts,                                    // per chart: axes {left, right} and series drawn
    };
    document.body.dataset.drawnSimTime = st && st.sim_time !== null ? String(st.sim_time) : "";
  }
  requestAnimationFrame(frame);
}

$("window").addEventListener("change", () => { view.dirty = true; });
window.addEventListener("resize", () => { view.dirty = true; });
loadHistory().finally(connect);
requestAnimationFrame(frame);
