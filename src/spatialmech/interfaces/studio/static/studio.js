// spatialmech studio page: draws what the server computes (the solver runs in the server).
// Sliders post the actuator values to /api/drive, the pose sliders the output link's task
// coordinates to /api/pose; the newest request is sent when the previous answer has arrived
// (no websockets).  window.studio exposes the last state for tests.
"use strict";

const EVENT_LOG_MAX = 100;  // services/studio/monitors.EVENT_LOG_MAX
const S = { state: null, circuit: null, unit: "", inFlight: false, pending: null, range: null, drawn: 0, errors: [],
  topView: false, viewRev: 0, nEvents: 0, view: "full", viewWhy: "", light: null, renderer: null };
window.studio = S;

async function api(path, body) {
  const opts = body === undefined ? {} : { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) };
  const r = await fetch(S.view === "light" ? path + "?solids=0" : path, opts);  // the light view draws no joint solids
  const doc = await r.json();
  if (!r.ok) throw new Error(doc.error || ("HTTP " + r.status));
  return doc;
}

// round-off (|x| < 1e-13, and -0) prints as 0, as present/numbers.py does for the text outputs
function fmt(x, d = 4) { return (x === null || x === undefined) ? "-" : (Math.abs(Number(x)) < 1e-13 ? "0" : Number(x).toPrecision(d)); }

// ------------------------------------------------------------------ shapes
function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
function mul(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }

// The joint solids and the platform body come from the server (spatialmech.present.shapes, the
// same code as the static viewer's): a mesh is {vertices_len: [[x, y, z]...], triangles: [[i, j, k]...]}.
function plotlyMesh(m) {
  return { x: m.vertices_len.map(p => p[0]), y: m.vertices_len.map(p => p[1]), z: m.vertices_len.map(p => p[2]),
    i: m.triangles.map(t => t[0]), j: m.triangles.map(t => t[1]), k: m.triangles.map(t => t[2]) };
}

function xyz(pts) { return { x: pts.map(p => p[0]), y: pts.map(p => p[1]), z: pts.map(p => p[2]) }; }

function fan(pts) {  // a closed outline (last = first) as a translucent polygon (the base)
  const P = pts.slice(0, -1);
  if (P.length < 3) return null;
  return plotlyMesh({ vertices_len: P, triangles: P.slice(2).map((_, q) => [0, q + 1, q + 2]) });
}

function traces(sc) {
  const s = sc.scale_len, out = [];
  const base = fan(sc.base_len);
  if (base) out.push({ type: "mesh3d", ...base, color: "#999999", opacity: 0.35, name: "base (ground)", hoverinfo: "skip", showlegend: true });
  out.push({ type: "scatter3d", mode: "lines", ...xyz(sc.base_len), line: { color: "#555555", width: 5 }, name: "base outline", showlegend: false });
  if (sc.platform_mesh) out.push({ type: "mesh3d", ...plotlyMesh(sc.platform_mesh), color: "#ff7f0e", opacity: 0.4, name: "platform",
    hoverinfo: "skip", showlegend: true });
  out.push({ type: "scatter3d", mode: "lines", ...xyz(sc.platform_len), line: { color: "#ff7f0e", width: 6 }, name: "platform outline", showlegend: false });
  sc.limbs_len.forEach((pl, li) => out.push({ type: "scatter3d", mode: "lines", ...xyz(pl), line: { color: sc.limb_colours[li], width: 9 },
    name: /^limb/i.test(sc.limb_names[li]) ? sc.limb_names[li] : "limb " + sc.limb_names[li] }));  // not "limb limb1"
  if (sc.bodies_len.length) {
    const pts = []; sc.bodies_len.forEach(sg => { pts.push(sg[0], sg[1], [null, null, null]); });
    out.push({ type: "scatter3d", mode: "lines", ...xyz(pts), line: { color: "#7f7f7f", width: 9 }, name: "internal bodies" });
  }
  sc.joint_meshes.forEach((m, li) => { if (m.triangles.length) out.push({ type: "mesh3d", ...plotlyMesh(m), color: sc.limb_colours[li],
    opacity: 1.0, flatshading: true, name: "joints of " + sc.limb_names[li], hoverinfo: "skip", showlegend: false }); });
  const names = sc.joints.map(j => j.name + " (" + j.type + ")");
  out.push({ type: "scatter3d", mode: "markers", ...xyz(sc.joints.map(j => j.centre_len)), marker: { size: 2, color: "#222" },
    text: names, hovertemplate: "%{text}<extra></extra>", name: "joint centres", showlegend: false });
  const cols = ["#d62728", "#2ca02c", "#1f77b4"], p = sc.platform_point_len;
  [0, 1, 2].forEach(a => {
    const e = add(p, mul([sc.platform_frame[0][a], sc.platform_frame[1][a], sc.platform_frame[2][a]], 0.3 * s));
    out.push({ type: "scatter3d", mode: "lines", ...xyz([p, e]), line: { color: cols[a], width: 6 }, name: "platform frame", showlegend: a === 0 });
  });
  if (S.circuit && S.circuit.circuit_len.length > 1) {
    out.push({ type: "scatter3d", mode: "lines", ...xyz(S.circuit.circuit_len), line: { color: "#888888", width: 2 },
      name: "traced circuit", hoverinfo: "skip" });
    if (S.circuit.dj_zeros_len.length) out.push({ type: "scatter3d", mode: "markers", ...xyz(S.circuit.dj_zeros_len),
      marker: { size: 6, color: "#d62728", symbol: "cross" }, name: "DJ zeros of " + S.state.drivers[0] });
  }
  if (sc.trail_len.length > 1) out.push({ type: "scatter3d", mode: "lines", ...xyz(sc.trail_len), line: { color: "#ff7f0e", width: 2, dash: "dot" }, name: "platform point path" });
  if (sc.task_positions_len.length) out.push({ type: "scatter3d", mode: "markers+text", ...xyz(sc.task_positions_len),
    text: sc.task_positions_len.map((_, k) => "P" + (k + 1)), marker: { size: 4, color: "#000", symbol: "diamond" }, name: "task positions" });
  return out;
}

// ------------------------------------------------------------------ the 3-D view: plotly's gl3d ("full", drawn at once)
// or the light one (static/scene2d.js, drawn on the next animation frame: several answers in one frame are drawn once)
function draw() {
  if (!S.range) S.range = SMPad.sceneRange(S.state.scene);
  if (S.view === "light") drawLight(); else drawPlot();
}

function drawNow() {  // at once (the benchmark's breakdown)
  if (!S.range) S.range = SMPad.sceneRange(S.state.scene);
  if (S.view === "light") { drawLight(); S.light.render(); } else drawPlot();
}

// the light view draws the plot's traces, the joint solids as markers in their limb's colour
function lightTraces(sc) {
  const out = traces(sc).filter(t => !(t.type === "mesh3d" && t.name.startsWith("joints of ")));
  const at = out.findIndex(t => t.name === "joint centres");
  const marks = sc.limb_names.map((n, li) => ({ type: "scatter3d", mode: "markers", name: "joints of " + n, showlegend: false,
    ...xyz(sc.joints.filter(j => j.limb_index === li).map(j => j.centre_len)), marker: { size: 9, color: sc.limb_colours[li] } }));
  out.splice(at < 0 ? out.length : at, 0, ...marks.filter(t => t.x.length));
  return out;
}

function drawLight() {
  const sc = S.state.scene, n = sc.plane_normal;
  S.light.show(lightTraces(sc), sc.platform_point_len, S.range, { camera: S.viewRev, unit: S.unit,
    top: S.topView && n ? [n, SMPad.planeBasis(n)[1]] : null,
    title: S.state.mechanism + (S.topView && n ? " (top view: along the plane's normal)" : "") });
}

// the 3-D view shown ("full" or "light") and why; the page's buttons switch it by hand
function setView(view, why) {
  S.view = view; S.viewWhy = why; S.traceKey = "";
  document.getElementById("plot").style.display = view === "light" ? "none" : "";
  document.getElementById("light").style.display = view === "light" ? "" : "none";
  ["full", "light"].forEach(v => document.getElementById("view3d-" + v).setAttribute("aria-pressed", String(v === view)));
  document.getElementById("view3d-why").textContent = why;
  document.getElementById("view3d-why").title = "WebGL renderer: " + (S.renderer === null ? "none" : S.renderer);
  if (!S.state) return;
  if (view === "full" && document.getElementById("plot").data) Plotly.Plots.resize("plot");
  draw();
  if (view === "full" && !S.inFlight) api("/api/state").then(d => { if (!S.inFlight) { S.state = d.state; draw(); } })  // with the joint solids
    .catch(e => setStatus("error", String(e)));
}

function initView() {
  const asked = new URLSearchParams(location.search).get("view") || document.body.dataset.view || "auto";
  S.renderer = SMScene2D.webglRenderer();
  S.light = new SMScene2D.View(document.getElementById("light"), {
    onFrame: () => { S.drawn += 1; },
    handlePlane: () => (S.pad ? [S.pad.e1, S.pad.e2] : null),
    onHandle: p => { S.lastDragPoint = p; S.pending = { path: "/api/drag", body: { point_len: p } }; pump(); } });
  S.setView = setView;
  const c = SMScene2D.choose(asked, S.renderer);
  setView(c.view, c.why);
  document.getElementById("view3d-full").addEventListener("click", () => (S.renderer === null
    ? setStatus("error", "this browser has no WebGL: only the light 3-D view") : setView("full", "full 3-D view (WebGL): switched by hand")));
  document.getElementById("view3d-light").addEventListener("click", () => setView("light", "light 3-D view: switched by hand"));
}

function drawPlot() {
  const sc = S.state.scene;
  const ax = (r, n) => ({ range: r, autorange: false, title: { text: n + " [" + S.unit + "]" } });  // the bundled plotly needs title.text
  const layout = { uirevision: "studio-" + S.viewRev, margin: { l: 0, r: 0, t: 30, b: 0 },
    title: { text: S.state.mechanism + (S.topView ? " (top view: along the plane's normal)" : "") },
    scene: { aspectmode: "cube", xaxis: ax(S.range[0], "x"), yaxis: ax(S.range[1], "y"), zaxis: ax(S.range[2], "z") },
    legend: { itemsizing: "constant" } };
  const n = sc.plane_normal;
  if (S.topView && n) {  // look along the plane's normal, orthographic, an in-plane "up"
    const [, e2] = SMPad.planeBasis(n);
    layout.scene.camera = { eye: { x: 2 * n[0], y: 2 * n[1], z: 2 * n[2] }, up: { x: e2[0], y: e2[1], z: e2[2] },
      center: { x: 0, y: 0, z: 0 }, projection: { type: "orthographic" } };
  }
  Plotly.react("plot", traces(sc), layout, { displaylogo: false, responsive: true, plotGlPixelRatio: SMPad.glPixelRatio });
  S.drawn += 1;
}

// ------------------------------------------------------------------ top view and drag handle
function showViewToggle() {
  const b = document.getElementById("view-toggle"), planar = !!S.state.scene.plane_normal;
  b.style.display = planar ? "" : "none";
  b.textContent = S.topView ? "oblique view" : "top view";
}

function toggleView() { S.topView = !S.topView; S.viewRev += 1; S.traceKey = ""; showViewToggle(); draw(); }

// The drag handle (static/pad.js): dragging the output point on the pad posts /api/drag with the
// point under the mouse, which moves the given translational task coordinates there by the pose
// drag's continuation (Session.drag_output).
function drawPad() {
  const pad = document.getElementById("drag-pad");
  const f = SMPad.frame(S.state, S.range);
  S.pad = f;
  if (!f) { pad.style.display = "none"; return; }
  pad.style.display = "";
  document.getElementById("drag-pad-label").textContent = SMPad.label(f);
  document.getElementById("drag-svg").innerHTML = SMPad.svg(f, S.state.scene, "drag-handle");
}

function initPad() {
  SMPad.attach(document.getElementById("drag-svg"), () => S.pad, () => S.state.scene.platform_point_len, p => {
    S.lastDragPoint = p;
    S.pending = { path: "/api/drag", body: { point_len: p } }; pump();
  });
  document.getElementById("view-toggle").addEventListener("click", toggleView);
}

// ------------------------------------------------------------------ controls and readouts
function actuatorEntries(st) {
  return st.drivers.map(d => (d in st.actuators_deg)
    ? { name: d, value: st.actuators_deg[d], unit: "deg", range: st.slider_ranges_deg[d] }
    : { name: d, value: st.actuators_len[d], unit: S.unit, range: st.slider_ranges_len[d] });
}

function buildSliders() {
  const box = document.getElementById("sliders");
  box.innerHTML = "";
  actuatorEntries(S.state).forEach((a, k) => addSlider(box, "slider", a, k, onSlide));
  syncSliders();
}

// one labelled range input (ids PREFIX-k and PREFIX-val-k) for an entry {name, value, unit, range}
function addSlider(box, prefix, a, k, onInput) {
  const div = document.createElement("div");
  div.className = "slider";
  const step = a.unit === "deg" ? 0.1 : (a.range[1] - a.range[0]) / 2000;
  div.innerHTML = `<label for="${prefix}-${k}">${a.name} [${a.unit}]: <span id="${prefix}-val-${k}"></span></label>` +
    `<input type="range" id="${prefix}-${k}" data-index="${k}" min="${a.range[0]}" max="${a.range[1]}" step="${step}" value="${a.value}">`;
  box.appendChild(div);
  div.querySelector("input").addEventListener("input", onInput);
}

function syncSliders() {
  const sync = (prefix) => (a, k) => {
    const el = document.getElementById(prefix + "-" + k);
    if (!el) return;
    el.value = a.value;
    document.getElementById(prefix + "-val-" + k).textContent = fmt(a.value, 6) + " " + a.unit;
  };
  actuatorEntries(S.state).forEach(sync("slider"));
  poseEntries(S.state).forEach(sync("pose"));
}

function sliderValues() { return actuatorEntries(S.state).map((_, k) => Number(document.getElementById("slider-" + k).value)); }

function onSlide() { S.pending = { path: "/api/drive", body: { actuators: sliderValues() } }; pump(); }

// ------------------------------------------------------------------ pose sliders (inverse position)
function poseEntries(st) {
  const t = st.task;
  if (!t) return [];
  return t.given.map(n => (n in t.slider_ranges_len)
    ? { name: n, value: t.values_len[n], unit: S.unit, range: t.slider_ranges_len[n], key: "task_len" }
    : { name: n, value: t.values_deg[n], unit: "deg", range: t.slider_ranges_deg[n], key: "task_deg" });
}

function buildPoseSliders() {
  const box = document.getElementById("pose-sliders");
  box.innerHTML = "";
  const t = S.state.task;
  document.getElementById("pose-help").textContent = !t ? "the output link cannot move" :
    "drag the output: " + t.given.join(", ") + " (Euler " + t.euler + ")" + (t.solved.length ? "; solved: " + t.solved.join(", ") : "");
  poseEntries(S.state).forEach((a, k) => addSlider(box, "pose", a, k, onPoseSlide));
  syncSliders();
}

function onPoseSlide() {
  const body = { task_len: {}, task_deg: {}, euler: S.state.task.euler };
  poseEntries(S.state).forEach((a, k) => { body[a.key][a.name] = Number(document.getElementById("pose-" + k).value); });
  S.pending = { path: "/api/pose", body: body }; pump();
}

async function pump() {
  if (S.inFlight || S.pending === null) return;
  const req = S.pending; S.pending = null; S.inFlight = true;
  try {
    const doc = await api(req.path, req.body);
    setStatus(doc.status === "reached" || doc.status === "unchanged" ? "" : "stopped", doc.status + ": " + doc.message);
    doc.events.forEach(e => logEvent(e));
    update(doc.state);
    if (doc.status !== "reached" && doc.status !== "unchanged") { S.pending = null; syncSliders(); }
  } catch (e) { setStatus("error", String(e)); }
  S.inFlight = false;
  if (S.pending !== null) pump(); else syncSliders();
}

function setStatus(cls, text) { const el = document.getElementById("status"); el.className = "status " + cls; el.textContent = text; }

function logEvent(e) {
  const li = document.createElement("li");
  const vals = Object.entries(e.actuators_deg).map(([k, v]) => k + " = " + fmt(v, 6) + " deg")
    .concat(Object.entries(e.actuators_len).map(([k, v]) => k + " = " + fmt(v, 6) + " " + S.unit));
  li.textContent = e.name + " (" + e.kind + ") at " + vals.join(", ") + ": " + e.meaning;
  const ol = document.getElementById("events"); ol.insertBefore(li, ol.firstChild);
  while (ol.children.length > EVENT_LOG_MAX) ol.removeChild(ol.lastChild);  // a bounded list, newest first
  S.nEvents += 1;
  document.getElementById("event-count").textContent = "(" + S.nEvents + ")";
}

function update(st) {
  S.state = st;
  const sig = st.sigma_min, cls = st.singular ? "sing" : (st.near_singular ? "near" : "ok");
  const icls = st.transmission_min === null ? "" : st.inverse_singular ? "sing" : (st.near_inverse_singular ? "near" : "ok");
  const p = st.pose, keys = [
    ["DJ of the drivers", st.dj !== null ? fmt(st.dj, 5)
      : `<span id="dj-note" title="${st.dj_note}">n/a</span>` + (st.dj_rate !== null ? "; driver rate " + fmt(st.dj_rate, 4) : "")
        + `<div class="small">${st.dj_note}</div>`],
    ["sigma_min (complete J, direct)", `<span id="sigma" class="${cls}">${fmt(sig, 4)}</span>` +
      (st.singular ? " singular" : st.near_singular ? " near a singularity (< " + st.near_singular_below + ")" : "")],
    ["transmission (inverse)", `<span id="transmission" class="${icls}">${fmt(st.transmission_min, 4)}</span>` +
      (st.transmission_min_actuator ? " " + st.transmission_min_actuator : "") +
      (st.inverse_singular ? " inverse singular (< " + st.inverse_singular_below + ")"
        : st.near_inverse_singular ? " near an inverse singularity (< " + st.near_inverse_singular_below + ")" : "")],
  ], rows = [
    ["output point [" + S.unit + "]", p.position_len.map(x => fmt(x, 5)).join(", ")],
    ["orientation " + p.euler_sequence + " [deg]", p.euler_deg.map(x => fmt(x, 5)).join(", ")],
    ["closure residual", fmt(st.residual, 3)],
    ["outside joint limits", st.outside_limits.length ? st.outside_limits.join(", ") : "none"],
  ];
  rows.unshift(...actuatorEntries(st).map(a => [a.name + " [" + a.unit + "]", fmt(a.value, 7)]));
  const table = rs => rs.map(r => `<tr><td>${r[0]}</td><td>${r[1]}</td></tr>`).join("");
  document.getElementById("readouts").innerHTML = table(keys);  // the key readouts, above the sliders
  document.getElementById("readouts-more").innerHTML = table(rows);
  const j = Object.entries(st.joints_deg).map(([k, v]) => [k, fmt(v, 6) + " deg"])
    .concat(Object.entries(st.joints_len).map(([k, v]) => [k, fmt(v, 6) + " " + S.unit]));
  document.getElementById("joints").innerHTML = j.map(r => `<tr><td>${r[0]}</td><td>${r[1]}</td></tr>`).join("");
  document.getElementById("note").textContent = st.note;
  syncSliders();
  draw();
  drawPad();
}

function fillDrivers(st) {
  const sel = document.getElementById("driver-select");
  const opts = st.candidate_drivers.length ? st.candidate_drivers : [st.drivers.join(",")];
  sel.innerHTML = opts.map(o => `<option value="${o}"${st.drivers.join(",") === o ? " selected" : ""}>${o}</option>`).join("");
  document.getElementById("driver-apply").disabled = st.candidate_drivers.length === 0;
}

async function loadDoc(doc) {
  // a model whose source states no length unit has "unit" (present/numbers.UNSTATED_UNIT): say so
  S.unit = doc.length_unit === "unit" ? "length unit not stated" : (doc.length_unit || "");
  S.range = null;
  document.getElementById("description").textContent = doc.model_info.description;
  const sel = document.getElementById("model-select");
  sel.innerHTML = doc.model_info.ready_made.map(n => `<option${n === doc.model ? " selected" : ""}>${n}</option>`).join("");
  if (!doc.model_info.ready_made.includes(doc.model)) sel.insertAdjacentHTML("afterbegin", `<option selected>${doc.model}</option>`);
  document.getElementById("events").innerHTML = "";
  S.nEvents = 0; document.getElementById("event-count").textContent = "(0)";

  document.getElementById("modes").innerHTML = "";
  S.state = doc.state;
  S.topView = !!doc.state.scene.plane_normal; S.viewRev += 1;  // a planar linkage opens in its top view
  showViewToggle();
  fillDrivers(doc.state);
  buildSliders();
  buildPoseSliders();
  update(doc.state);
  setStatus("", "ready: drag a slider");
  loadCircuit();
}

async function loadCircuit() {  // one-degree-of-freedom models: the traced circuit, drawn when it arrives
  S.circuit = null;
  if (S.state.drivers.length !== 1) return;
  try { S.circuit = await api("/api/circuit"); draw(); } catch (e) { S.circuit = null; }
}

async function main() {
  window.addEventListener("error", e => S.errors.push(String(e.message)));
  initPad();
  initView();
  loadDoc(await api("/api/model"));
  document.getElementById("model-select").addEventListener("change", async ev => {
    setStatus("", "loading " + ev.target.value + " ...");
    try { loadDoc(await api("/api/load", { model: ev.target.value })); } catch (e) { setStatus("error", String(e)); }
  });
  document.getElementById("driver-apply").addEventListener("click", async () => {
    try {
      const doc = await api("/api/drivers", { drivers: document.getElementById("driver-select").value.split(",") });
      S.state = doc.state; buildSliders(); update(doc.state); setStatus("", "driving with " + doc.state.drivers.join(", ")); loadCircuit();
    } catch (e) { setStatus("error", String(e)); }
  });
  document.getElementById("fk-all").addEventListener("click", async () => {
    setStatus("", "searching assembly modes ...");
    try {
      const doc = await api("/api/fk_all", {});
      const box = document.getElementById("modes");
      box.innerHTML = doc.solutions.map(s => `<button data-mode="${s.mode_number}" title="sigma_min ${fmt(s.sigma_min, 3)}">` +
        `mode ${s.mode_number}: (${s.pose.position_len.map(x => fmt(x, 3)).join(", ")})${s.singular ? " singular" : ""}</button>`).join("");
      box.querySelectorAll("button").forEach(b => b.addEventListener("click", async () => {
        const d = await api("/api/mode", { mode_number: Number(b.dataset.mode) });
        update(d.state); setStatus("", "moved to assembly mode " + b.dataset.mode + " (a branch change you asked for)"); loadCircuit();
      }));
      setStatus("", doc.n_solutions + " assembly mode(s) found; mode 1 is the current one");
    } catch (e) { setStatus("error", String(e)); }
  });
}

main().catch(e => { S.errors.push(String(e)); setStatus("error", String(e)); });
