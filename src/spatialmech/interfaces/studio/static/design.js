// spatialmech studio, the design tools (issue 30): snapshots with undo, the coupler curve of a
// picked point, joint values and transmission against the input, the driven path as CSV, and a
// smaller redraw during a drag.  Loaded after studio.js and uses its globals (S, api, fmt,
// setStatus, update, traces, draw, drawPlot); the two hooks below wrap studio.js's `traces` (adds
// the coupler curve; the light view draws them too) and `drawPlot` (the full view: Plotly.restyle
// of the coordinates when the traces are the same as in the last full draw, instead of
// Plotly.react of the whole figure).
"use strict";

S.coupler = null; S.traceKey = ""; S.fastRedraw = true; S.drawTimes = [];

const studioTraces = traces;
traces = function (sc) {  // eslint-disable-line no-func-assign
  const out = studioTraces(sc);
  if (S.coupler && S.coupler.curve_len.length > 1) out.push({ type: "scatter3d", mode: "lines", ...xyz(S.coupler.curve_len),
    line: { color: "#9467bd", width: 4 }, name: "coupler curve (" + S.coupler.over + ")", hoverinfo: "skip" });
  return out;
};

const studioDraw = drawPlot;
drawPlot = function () {  // eslint-disable-line no-func-assign
  const t0 = performance.now(), el = document.getElementById("plot"), tr = traces(S.state.scene);
  const key = tr.map(t => t.type + ":" + t.name + ":" + t.x.length + ":" + (t.i ? t.i.length : 0)).join("|");
  if (S.fastRedraw && el.data && key === S.traceKey) {  // only the traces that moved
    const same = (a, b) => a.length === b.length && a.every((v, q) => v === b[q]);
    const moved = tr.map((t, q) => q).filter(q => !(same(tr[q].x, el.data[q].x) && same(tr[q].y, el.data[q].y) && same(tr[q].z, el.data[q].z)));
    if (moved.length) Plotly.restyle(el, { x: moved.map(q => tr[q].x), y: moved.map(q => tr[q].y), z: moved.map(q => tr[q].z) }, moved);
    S.drawn += 1;
  } else {
    studioDraw();
    S.traceKey = key;
  }
  S.drawTimes.push(performance.now() - t0);
  if (S.drawTimes.length > 1000) S.drawTimes.shift();
};

const studioLoadDoc = loadDoc;
loadDoc = function (doc) {  // eslint-disable-line no-func-assign
  S.coupler = null; S.traceKey = "";
  document.getElementById("snapshots").innerHTML = "";
  document.getElementById("sweep-plot").style.display = "none";
  return studioLoadDoc(doc);
};

function designDoc(doc) { if (doc.state) update(doc.state); if (doc.snapshots) listSnapshots(doc.snapshots); }

function listSnapshots(list) {
  const box = document.getElementById("snapshots");
  box.innerHTML = list.map(s => `<button data-number="${s.number}" title="go back to it">${s.label}</button>`).join("");
  box.querySelectorAll("button").forEach(b => b.addEventListener("click", () => designCall("/api/restore",
    { number: Number(b.dataset.number) }, "back at " + b.textContent)));
}

async function designCall(path, body, done) {
  try { const doc = await api(path, body); designDoc(doc); setStatus("", typeof done === "function" ? done(doc) : done); return doc; }
  catch (e) { setStatus("error", String(e)); return null; }
}

async function couplerCurve() {
  const txt = document.getElementById("coupler-point").value.trim();
  const body = txt ? { point_len: txt.split(/[ ,]+/).map(Number) } : {};
  setStatus("", "tracing the coupler curve ...");
  const doc = await designCall("/api/coupler", body, d => "coupler curve over the " + d.over + " (" + d.curve_len.length + " points)");
  if (doc) { S.coupler = doc; draw(); }
}

async function sweepPlots() {
  setStatus("", "sweeping " + S.state.drivers[0] + " ...");
  const d = await designCall("/api/sweep", { samples: 61 }, doc => "swept " + doc.driver + (doc.stops.length ? "; " + doc.stops.join("; ") : ""));
  if (!d) return;
  const joint = (vals, name, unit) => ({ type: "scatter", mode: "lines", x: d.input, y: vals, name: name + " [" + unit + "]" });
  const data = Object.entries(d.joints_deg || {}).map(([k, v]) => joint(v, k, "deg"))
    .concat(Object.entries(d.joints_len || {}).map(([k, v]) => joint(v, k, S.unit)));
  data.push({ type: "scatter", mode: "lines", x: d.input, y: d.transmission_min, name: "transmission (min)", yaxis: "y2",
    line: { color: "#000", width: 3, dash: "dot" } });
  const box = document.getElementById("sweep-plot");
  box.style.display = "block";
  Plotly.newPlot(box, data, { height: 420, margin: { l: 50, r: 50, t: 10, b: 40 }, showlegend: true,
    legend: { orientation: "h", x: 0, y: -0.25, font: { size: 9 } },
    xaxis: { title: { text: d.driver + " [" + d.input_unit + "]" } }, yaxis: { title: { text: "joint values" } },
    yaxis2: { title: { text: "transmission" }, overlaying: "y", side: "right", range: [0, 1], autorange: false, tickmode: "auto" } },
    { displaylogo: false });
}

function designPanel() {
  const box = document.getElementById("design");
  box.innerHTML = '<div class="row"><button id="snap">snapshot</button><button id="undo">undo</button>' +
    '<a id="export-path" href="/api/path.csv" download>export path (CSV)</a></div><div id="snapshots" class="row"></div>' +
    '<div class="row"><label for="coupler-point" class="small">coupler point [output link frame]</label>' +
    '<input id="coupler-point" size="12" placeholder="x, y, z"><button id="coupler">draw</button></div>' +
    '<div class="row"><button id="sweep">joints and transmission against the input</button></div>';
  document.getElementById("snap").addEventListener("click", () => designCall("/api/snapshot", {}, d => "kept " + d.snapshots.at(-1).label));
  document.getElementById("undo").addEventListener("click", () => designCall("/api/undo", {}, d => "back at " + d.restored));
  document.getElementById("coupler").addEventListener("click", couplerCurve);
  document.getElementById("sweep").addEventListener("click", sweepPlots);
}

designPanel();
