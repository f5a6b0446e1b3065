// spatialmech studio in Jupyter (anywidget): draws the `figure` trait, shows the readouts of the
// `state` trait and sends one message per slider move ({type: "drive", actuators: [...]}); the
// next value goes when `answered` grows (one request in flight).  Plotly is defined by the
// bundle this file is appended to (interfaces/studio/widget.py).

function fmt(x, d = 5) { return (x === null || x === undefined) ? "-" : Number(x).toPrecision(d); }

function actuatorEntries(st, unit) {
  return st.drivers.map(d => (d in st.actuators_deg)
    ? { name: d, value: st.actuators_deg[d], unit: "deg", range: st.slider_ranges_deg[d] }
    : { name: d, value: st.actuators_len[d], unit: unit, range: st.slider_ranges_len[d] });
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
  el.innerHTML = '<div class="sm-sliders"></div><table class="sm-readouts" style="font: 12px sans-serif"></table>' +
    '<div class="sm-plot" style="width: 100%"></div>';
  const box = el.querySelector(".sm-sliders"), table = el.querySelector(".sm-readouts"), plot = el.querySelector(".sm-plot");
  let inFlight = false, pending = null, built = "";

  function send() {
    if (inFlight || pending === null) return;
    inFlight = true; model.send(pending); pending = null;
  }
  function build() {
    const st = model.get("state"), unit = model.get("unit");
    const entries = actuatorEntries(st, unit), key = st.mechanism + ":" + st.drivers.join(",");
    if (key !== built) {
      built = key; box.innerHTML = "";
      entries.forEach((a, k) => {
        const step = a.unit === "deg" ? 0.1 : (a.range[1] - a.range[0]) / 2000, div = document.createElement("div");
        div.innerHTML = `<label style="font: 12px sans-serif">${a.name} [${a.unit}] <input type="range" data-index="${k}" ` +
          `min="${a.range[0]}" max="${a.range[1]}" step="${step}" value="${a.value}" style="width: 60%"> <span></span></label>`;
        div.querySelector("input").addEventListener("input", () => {
          pending = { type: "drive", actuators: [...box.querySelectorAll("input")].map(x => Number(x.value)) }; send();
        });
        box.appendChild(div);
      });
    }
    box.querySelectorAll("input").forEach((x, k) => {
      if (pending === null && !inFlight) x.value = entries[k].value;
      x.nextElementSibling.textContent = fmt(entries[k].value, 6) + " " + entries[k].unit;
    });
    table.innerHTML = readoutRows(st, unit, model).map(([k, v]) => `<tr><th style="text-align: left">${k}</th><td>${v}</td></tr>`).join("");
  }
  function draw() { const f = model.get("figure"); Plotly.react(plot, f.data, f.layout, { displaylogo: false, responsive: true }); }

  model.on("change:state", build);
  model.on("change:figure", draw);
  model.on("change:answered", () => { inFlight = false; build(); send(); });
  build(); draw();
  return () => Plotly.purge(plot);
}

export default { render };
