// spatialmech studio in Jupyter (anywidget): draws the `figure` trait, shows the readouts of the
// `state` trait and sends one message per slider move ({type: "drive", actuators: [...]}); the
// next value goes when `answered` grows (one request in flight).  The drag pad (SMPad, static/pad.js)
// sends {type: "drag", point_len: [x, y, z]}.  The 3-D view is plotly's WebGL scene or the light
// one (SMScene2D, static/scene2d.js: the same traces on a 2-D canvas, its orange handle dragged
// like the pad's), chosen by the `view` trait ("auto": light where WebGL is rendered in software)
// and switched by two buttons.  Plotly, SMPad and SMScene2D are defined by the bundle this file
// is appended to (interfaces/studio/widget.py).


function fmt(x, d = 5) { return (x === null || x === undefined) ? "-" : Number(x).toPrecision(d); }

function actuatorEntries(st, unit) {
  return st.drivers.map(d => (d in st.actuators_deg)
    ? { name: d, value: st.actuators_deg[d], unit: "deg", range: st.slider_ranges_deg[d] }
    : { name: d, value: st.actuators_len[d], unit: unit, range: st.slider_ranges_len[d] });
}

function poseEntries(st, unit) {  // the output link's given task coordinates (pose sliders)
  const t = st.task;
  if (!t) return [];
  return t.given.map(n => (n in t.slider_ranges_len)
    ? { name: n, value: t.values_len[n], unit: unit, range: t.slider_ranges_len[n], key: "task_len" }
    : { name: n, value: t.values_deg[n], unit: "deg", range: t.slider_ranges_deg[n], key: "task_deg" });
}

function sliderRow(a, onInput) {
  const step = a.unit === "deg" ? 0.1 : (a.range[1] - a.range[0]) / 2000, div = document.createElement("div");
  div.innerHTML = `<label style="font: 12px sans-serif">${a.name} [${a.unit}] <input type="range" ` +
    `min="${a.range[0]}" max="${a.range[1]}" step="${step}" value="${a.value}" style="width: 60%"> <span></span></label>`;
  div.querySelector("input").addEventListener("input", onInput);
  return div;
}

function readoutRows(st, unit, model) {
  const p = st.pose, last = model.get("last_drive"), err = model.get("error");
  return [
    ["output point [" + unit + "]", p.position_len.map(x => fmt(x)).join(", ")],
    ["orientation " + p.euler_sequence + " [deg]", p.euler_deg.map(x => fmt(x)).join(", ")],
    ["DJ of the drivers", st.dj !== null ? fmt(st.dj) : "n/a (" + st.dj_note + ")"],
    ["sigma_min (direct)", fmt(st.sigma_min, 4) + (st.singular ? " singular" : st.near_singular ? " near a singularity" : "")],
    ["transmission (inverse)", fmt(st.transmission_min, 4) + (st.inverse_singular ? " inverse singular" : "")],
    ["last drive", err ? "error: " + err : (last.status ? last.status + ": " + last.message : "-")],
  ];
}

function render({ model, el }) {
  el.classList.add("spatialmech-studio");
  el.innerHTML = '<div class="sm-sliders"></div><div class="sm-pose"></div><div class="sm-buttons" style="font: 12px sans-serif">' +
    '<button class="sm-snap">snapshot</button> <button class="sm-undo">undo</button> <span class="sm-snaps"></span></div><table class="sm-readouts" style="font: 12px sans-serif"></table>' +
    '<div class="sm-pad" style="display: none; font: 12px sans-serif" title="drag the output point in this plane (inverse position along the branch)">' +
    '<div class="sm-pad-label"></div><svg class="sm-drag-svg" width="200" height="200" style="border: 1px solid #ccc; touch-action: none"></svg></div>' +
    '<div class="sm-viewbar" style="font: 12px sans-serif">3-D view: <button class="sm-view-full" title="plotly\'s WebGL scene">full (WebGL)</button> ' +
    '<button class="sm-view-light" title="a Canvas 2-D drawing of the same scene: drag to turn, wheel to zoom, double-click to reset">light</button> ' +
    '<span class="sm-view-why"></span></div>' +
    '<div class="sm-plot" style="width: 100%"></div><div class="sm-light" style="position: relative; width: 100%; display: none"></div>';
  const box = el.querySelector(".sm-sliders"), pbox = el.querySelector(".sm-pose"), table = el.querySelector(".sm-readouts"), plot = el.querySelector(".sm-plot");
  const pad = el.querySelector(".sm-pad"), padSvg = el.querySelector(".sm-drag-svg");
  const lightBox = el.querySelector(".sm-light"), renderer = SMScene2D.webglRenderer();
  let inFlight = false, pending = null, built = "", range = null, frame = null, view = "full", turns = 0;
  const light = new SMScene2D.View(lightBox, { handlePlane: () => (frame ? [frame.e1, frame.e2] : null),
    onHandle: p => { pending = { type: "drag", point_len: p }; send(); } });
  lightBox.smView = light;  // for tests: the camera, the frame count

  function send() {
    if (inFlight || pending === null) return;
    inFlight = true; model.send(pending); pending = null;
  }
  function build() {
    const st = model.get("state"), unit = model.get("unit");
    const entries = actuatorEntries(st, unit), key = st.mechanism + ":" + st.drivers.join(",");
    const poses = poseEntries(st, unit);
    if (key !== built) {
      built = key; box.innerHTML = ""; pbox.innerHTML = ""; range = SMPad.sceneRange(st.scene);
      entries.forEach(a => box.appendChild(sliderRow(a, () => {
        pending = { type: "drive", actuators: [...box.querySelectorAll("input")].map(x => Number(x.value)) }; send();
      })));
      poses.forEach(a => pbox.appendChild(sliderRow(a, () => {
        const msg = { type: "pose", task_len: {}, task_deg: {}, euler: st.task.euler };
        [...pbox.querySelectorAll("input")].forEach((x, k) => { msg[poses[k].key][poses[k].name] = Number(x.value); });
        pending = msg; send();
      })));
    }
    const sync = (b, list) => b.querySelectorAll("input").forEach((x, k) => {
      if (pending === null && !inFlight) x.value = list[k].value;
      x.nextElementSibling.textContent = fmt(list[k].value, 6) + " " + list[k].unit;
    });
    sync(box, entries); sync(pbox, poses);
    el.querySelector(".sm-snaps").textContent = model.get("snapshots").map(x => x.label).join(", ");
    frame = SMPad.frame(st, range);
    pad.style.display = frame ? "" : "none";
    if (frame) {
      el.querySelector(".sm-pad-label").textContent = SMPad.label(frame);
      padSvg.innerHTML = SMPad.svg(frame, st.scene);
    }
    table.innerHTML = readoutRows(st, unit, model).map(([k, v]) => `<tr><th style="text-align: left">${k}</th><td>${v}</td></tr>`).join("");
  }
  function draw() {
    const f = model.get("figure"), st = model.get("state"), n = st.scene.plane_normal;
    if (view === "full") { Plotly.react(plot, f.data, f.layout, { displaylogo: false, responsive: true, plotGlPixelRatio: SMPad.glPixelRatio }); return; }
    lightBox.style.height = (f.layout.height || 460) + "px";
    light.show(f.data, st.scene.platform_point_len, range, { camera: built + ":" + turns, unit: model.get("unit"),
      top: n ? [n, SMPad.planeBasis(n)[1]] : null, title: f.layout.title ? f.layout.title.text : st.mechanism });
  }
  function setView(v, why) {
    view = v; turns += 1;
    plot.style.display = v === "full" ? "" : "none"; lightBox.style.display = v === "light" ? "" : "none";
    el.querySelector(".sm-view-full").setAttribute("aria-pressed", String(v === "full"));
    el.querySelector(".sm-view-light").setAttribute("aria-pressed", String(v === "light"));
    el.querySelector(".sm-view-full").style.fontWeight = v === "full" ? "bold" : "";
    el.querySelector(".sm-view-light").style.fontWeight = v === "light" ? "bold" : "";
    el.querySelector(".sm-view-why").textContent = why;
    draw();
  }

  SMPad.attach(padSvg, () => frame, () => model.get("state").scene.platform_point_len,
               p => { pending = { type: "drag", point_len: p }; send(); });
  el.querySelector(".sm-snap").addEventListener("click", () => { pending = { type: "snapshot" }; send(); });
  el.querySelector(".sm-undo").addEventListener("click", () => { pending = { type: "undo" }; send(); });
  model.on("change:state", build);
  model.on("change:snapshots", build);
  model.on("change:figure", draw);
  model.on("change:answered", () => { inFlight = false; build(); send(); });
  el.querySelector(".sm-view-full").addEventListener("click", () => (renderer === null
    ? setView("light", "this browser has no WebGL: only the light 3-D view") : setView("full", "full 3-D view (WebGL): switched by hand")));
  model.on("change:view", () => { const c = SMScene2D.choose(model.get("view"), renderer); setView(c.view, c.why); });
  el.querySelector(".sm-view-light").addEventListener("click", () => setView("light", "light 3-D view: switched by hand"));
  build();
  const chosen = SMScene2D.choose(model.get("view") || "auto", renderer);
  setView(chosen.view, chosen.why);
  return () => { Plotly.purge(plot); light.destroy(); };
}

export default { render };
