// spatialmech studio: the light 3-D view, a Canvas 2-D renderer of the traces the plotly scene
// shows, for browsers whose WebGL is rendered in software (remote desktops, VMs, CI, headless
// browsers), where plotly's gl3d scene takes 80-120 ms a frame.  Shared by the page
// (static/studio.js) and the notebook widget (static/widget.js, bundled after it).
//
// It draws plotly-style trace objects ({type: "scatter3d" | "mesh3d", x, y, z, ...}): lines as
// polylines (null breaks them), markers as dots, meshes as filled triangles with the trace's
// opacity, back to front; names and colours are the traces' own, so the legend is the plot's.
// Camera: orthographic (equal scaling on every axis), an orthonormal basis (right, up, fwd):
// a point p is drawn at  (W/2 + zoom (p - c).right,  H/2 - zoom (p - c).up)  in CSS pixels, with
// depth (p - c).fwd (larger: farther).  Drag to turn about the world axis `spin` (z, or a planar
// linkage's normal) and the screen's horizontal, wheel to zoom, double-click to reset.
// Two stacked canvases: the traces that did not move since the last frame, the triad and the
// legend are kept on the back one; a frame repaints only the front one (what moved), on
// requestAnimationFrame, so several answers in one frame are drawn once.
"use strict";

const SMScene2D = (() => {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = a => { const n = Math.hypot(a[0], a[1], a[2]); return [a[0] / n, a[1] / n, a[2] / n]; };
  const turn = (v, k, t) => {  // v turned by angle t about the unit axis k (Rodrigues)
    const c = Math.cos(t), s = Math.sin(t), kv = cross(k, v), d = dot(k, v) * (1 - c);
    return [0, 1, 2].map(i => v[i] * c + kv[i] * s + k[i] * d);
  };
  const SOFTWARE = /swiftshader|llvmpipe|softpipe|software/i;

  // the WebGL renderer's name (WEBGL_debug_renderer_info where the browser gives it), or null
  // when the browser has no WebGL
  function webglRenderer() {
    let gl = null;
    try { const c = document.createElement("canvas"); gl = c.getContext("webgl") || c.getContext("experimental-webgl"); } catch (e) { gl = null; }
    if (!gl) return null;
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
    return name;
  }

  // which view to show for the asked one ("auto", "light", "full") and the renderer's name:
  // {view: "light" | "full", why: the sentence the page shows}
  function choose(asked, renderer) {
    if (renderer === null) return { view: "light", why: "light 3-D view: this browser has no WebGL" };
    if (asked === "light") return { view: "light", why: "light 3-D view: asked for (view = light)" };
    if (asked === "full") return { view: "full", why: "full 3-D view (WebGL): asked for (view = full)" };
    const soft = renderer.match(SOFTWARE);
    return soft ? { view: "light", why: "light 3-D view: this browser renders WebGL in software (" + soft[0] + ")" }
      : { view: "full", why: "full 3-D view: this browser renders WebGL in hardware" };
  }

  function points(t) { return t.x.map((x, q) => (x === null || x === undefined) ? null : [x, t.y[q], t.z[q]]); }

  // a round length near `x` (1, 2 or 5 times a power of ten), for the scale bar
  function roundLength(x) {
    const p = Math.pow(10, Math.floor(Math.log10(x))), m = x / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
  }

  class View {
    // `box`: an element to fill (position: relative); `opts.onHandle(point_len)`: a drag of the
    // handle, with `opts.handlePlane()` -> [e1, e2] the plane it moves in (or null: no drag)
    constructor(box, opts = {}) {
      this.box = box; this.opts = opts; this.frames = 0; this.backFrames = 0; this.drawMs = [];
      this.back = document.createElement("canvas"); this.front = document.createElement("canvas");
      [this.back, this.front].forEach(c => { c.style.cssText = "position: absolute; left: 0; top: 0; width: 100%; height: 100%"; box.appendChild(c); });
      this.front.style.cursor = "grab"; this.front.style.touchAction = "none";
      this.traces = []; this.last = []; this.handle = null; this.title = ""; this.unit = ""; this.requested = false; this.dirtyBack = true;
      this.screen = {};  // trace name -> the drawn markers' [u, v, depth] (CSS pixels)
      this.attach();
    }

    // the scene: `traces` (plotly-style), `handle` (the drag handle's point or null), `range`
    // ([[lo, hi] x 3], the scene's cube), `top` (a planar linkage's normal and in-plane up, or null)
    show(traces, handle, range, meta) {
      const fresh = !this.range || meta.camera !== this.cameraKey;
      Object.assign(this, { traces, handle, range, title: meta.title || "", unit: meta.unit || "" });
      if (fresh) { this.cameraKey = meta.camera; this.top = meta.top || null; this.reset(false); }
      this.request();
    }

    reset(draw = true) {  // the initial camera: the plane's normal if planar, else plotly's default eye (1.25, 1.25, 1.25)
      const r = this.range, half = (r[0][1] - r[0][0]) / 2;
      this.c = r.map(a => (a[0] + a[1]) / 2);
      if (this.top) { const [n, up] = this.top; this.cam = { fwd: n.map(v => -v), up: unit(up) }; this.spin = n; }
      else { this.cam = { fwd: unit([-1, -1, -1]), up: unit([-1, -1, 2]) }; this.spin = [0, 0, 1]; }
      this.cam.right = cross(this.cam.fwd, this.cam.up);
      this.fit = 1 / (1.1 * half); this.zoomBy = 1;
      this.dirtyBack = true;
      if (draw) this.request();
    }

    size() {
      const w = this.box.clientWidth || 300, h = this.box.clientHeight || 300, dpr = Math.max(1, window.devicePixelRatio || 1);
      if (this.W !== w || this.H !== h || this.dpr !== dpr) {
        Object.assign(this, { W: w, H: h, dpr });
        [this.back, this.front].forEach(c => { c.width = Math.round(w * dpr); c.height = Math.round(h * dpr); });
        this.dirtyBack = true;
      }
    }

    // the camera as plain numbers (the tests project the session's joints with it)
    camera() {
      return { centre: this.c, right: this.cam.right, up: this.cam.up, fwd: this.cam.fwd, zoom: this.zoom(), width: this.W, height: this.H };
    }

    zoom() { return 0.5 * Math.min(this.W, this.H) * this.fit * this.zoomBy; }

    project(p) {
      const d = sub(p, this.c), z = this.zoom();
      return [this.W / 2 + z * dot(d, this.cam.right), this.H / 2 - z * dot(d, this.cam.up), dot(d, this.cam.fwd)];
    }

    request() {
      if (this.requested) return;
      this.requested = true;
      requestAnimationFrame(() => { this.requested = false; this.render(); });
    }

    // draw now: the back canvas again if the camera, the size or a kept trace changed, then the
    // traces that moved since the last frame on the front one
    render() {
      if (!this.range) return;
      const t0 = performance.now();
      this.size();
      const same = (a, b) => a && b && a.type === b.type && a.name === b.name && ["x", "y", "z"].every(k => a[k].length === b[k].length
        && a[k].every((v, q) => v === b[k][q]));
      const moved = this.traces.map((t, q) => !same(t, this.last[q]));
      const kept = moved.map(m => !m).join();
      if (this.dirtyBack || kept !== this.keptKey || this.traces.length !== this.last.length) {
        this.keptKey = kept; this.dirtyBack = false; this.backFrames += 1;
        this.paint(this.back, this.traces.filter((_, q) => !moved[q]), true);
      }
      this.paint(this.front, this.traces.filter((_, q) => moved[q]), false);
      this.last = this.traces;
      this.frames += 1;
      this.drawMs.push(performance.now() - t0);
      if (this.drawMs.length > 1000) this.drawMs.shift();
      if (this.opts.onFrame) this.opts.onFrame(this);
    }

    paint(canvas, traces, isBack) {
      const g = canvas.getContext("2d");
      g.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
      g.clearRect(0, 0, this.W, this.H);
      if (isBack) { g.fillStyle = "#ffffff"; g.fillRect(0, 0, this.W, this.H); this.triad(g); this.legend(g); }
      this.faces(g, traces.filter(t => t.type === "mesh3d"));
      traces.filter(t => t.type === "scatter3d" && (t.mode || "").includes("lines")).forEach(t => this.lines(g, t));
      traces.filter(t => t.type === "scatter3d" && (t.mode || "").includes("markers")).forEach(t => this.markers(g, t));
      if (!isBack && this.handle) {
        const [u, v] = this.project(this.handle);
        g.beginPath(); g.arc(u, v, 6, 0, 2 * Math.PI); g.fillStyle = "#ff7f0e"; g.fill(); g.strokeStyle = "#000"; g.lineWidth = 1; g.stroke();
        this.handleAt = [u, v];
      }
    }

    faces(g, meshes) {  // every triangle of every mesh, farthest first
      const tri = [];
      meshes.forEach(m => {
        const P = points(m).map(p => this.project(p)), col = m.color || "#888", a = m.opacity === undefined ? 1 : m.opacity;
        m.i.forEach((i, q) => { const f = [P[i], P[m.j[q]], P[m.k[q]]]; tri.push({ f, col, a, d: f[0][2] + f[1][2] + f[2][2] }); });
      });
      tri.sort((s, t) => t.d - s.d);
      tri.forEach(t => {
        g.globalAlpha = t.a; g.fillStyle = t.col; g.beginPath();
        g.moveTo(t.f[0][0], t.f[0][1]); g.lineTo(t.f[1][0], t.f[1][1]); g.lineTo(t.f[2][0], t.f[2][1]); g.closePath(); g.fill();
      });
      g.globalAlpha = 1;
    }

    lines(g, t) {
      const ln = t.line || {};
      g.strokeStyle = ln.color || "#444"; g.lineWidth = Math.max(1, 0.5 * (ln.width || 2)); g.lineJoin = "round"; g.lineCap = "round";
      g.setLineDash(ln.dash === "dot" ? [2, 4] : ln.dash === "dash" ? [8, 4] : []);
      g.beginPath();
      let up = true;
      points(t).forEach(p => {
        if (p === null) { up = true; return; }
        const [u, v] = this.project(p);
        if (up) g.moveTo(u, v); else g.lineTo(u, v);
        up = false;
      });
      g.stroke(); g.setLineDash([]);
    }

    markers(g, t) {
      const mk = t.marker || {}, r = Math.max(2, 0.6 * (mk.size || 4)), names = (t.mode || "").includes("text") ? t.text : null;
      const P = this.screen[t.name] = points(t).map(p => (p === null ? null : this.project(p)));  // where each is drawn (tests)
      g.fillStyle = mk.color || "#222"; g.strokeStyle = mk.color || "#222"; g.lineWidth = 2; g.font = "11px sans-serif";
      P.forEach((p, q) => {
        if (p === null) return;
        const [u, v] = p;
        g.beginPath();
        if (mk.symbol === "cross") { g.moveTo(u - r, v - r); g.lineTo(u + r, v + r); g.moveTo(u - r, v + r); g.lineTo(u + r, v - r); g.stroke(); }
        else if (mk.symbol === "diamond") { g.moveTo(u, v - r); g.lineTo(u + r, v); g.lineTo(u, v + r); g.lineTo(u - r, v); g.fill(); }
        else { g.arc(u, v, r, 0, 2 * Math.PI); g.fill(); }
        if (names) g.fillText(names[q], u + r + 2, v - r);
      });
    }

    // the title, the axis triad (x, y, z with the length unit) and a scale bar, bottom right
    triad(g) {
      g.fillStyle = "#222"; g.font = "15px sans-serif"; g.textAlign = "center";
      g.fillText(this.title, this.W / 2, 20);
      g.font = "12px sans-serif"; g.textAlign = "left";
      // the triad: the world axes as the camera sees them; the unit as the plot's axis titles give it
      const o = [this.W - 70, this.H - 95], cols = ["#d62728", "#2ca02c", "#1f77b4"];
      [[1, 0, 0], [0, 1, 0], [0, 0, 1]].forEach((e, a) => {
        const u = o[0] + 35 * dot(e, this.cam.right), v = o[1] - 35 * dot(e, this.cam.up), end = Math.hypot(u - o[0], v - o[1]) > 8;
        g.strokeStyle = cols[a]; g.fillStyle = cols[a]; g.lineWidth = 2; g.beginPath();
        if (end) { g.moveTo(o[0], o[1]); g.lineTo(u, v); g.stroke(); } else { g.arc(o[0], o[1], 4, 0, 2 * Math.PI); g.stroke(); }
        g.textAlign = end ? "left" : "right";
        g.fillText("xyz"[a] + (end ? "" : dot(e, this.cam.fwd) < 0 ? " (toward you)" : " (away)"), end ? u + 3 : o[0] - 8, end ? v + 4 : o[1] + 4);
      });
      g.fillStyle = "#222"; g.textAlign = "right";
      g.fillText(["x", "y", "z"].map(n => n + (this.unit ? " [" + this.unit + "]" : "")).join(", "), this.W - 10, this.H - 38);
      const L = roundLength(100 / this.zoom()), px = L * this.zoom(), y = this.H - 16, x0 = this.W - 20 - px;
      g.strokeStyle = "#222"; g.fillStyle = "#222"; g.lineWidth = 2;
      g.beginPath(); g.moveTo(x0, y - 4); g.lineTo(x0, y); g.lineTo(x0 + px, y); g.lineTo(x0 + px, y - 4); g.stroke();
      g.textAlign = "right"; g.fillText(Number(L.toPrecision(3)) + (this.unit ? " " + this.unit : ""), x0 - 6, y + 1); g.textAlign = "left";
    }

    legend(g) {  // the traces plotly lists (showlegend not false), top right
      const items = []; this.traces.forEach(t => { if (t.showlegend !== false && !items.some(s => s.name === t.name)) items.push(t); });
      g.font = "12px sans-serif"; g.textAlign = "left";
      const w = Math.max(0, ...items.map(t => g.measureText(t.name).width)) + 34;
      items.forEach((t, q) => {
        const x = this.W - w - 8, y = 40 + 17 * q, col = t.type === "mesh3d" ? t.color : (t.line || t.marker || {}).color;
        g.globalAlpha = t.type === "mesh3d" ? Math.max(0.35, t.opacity || 1) : 1;
        g.fillStyle = col || "#444"; g.fillRect(x, y - 4, 22, t.type === "mesh3d" ? 8 : 3);
        g.globalAlpha = 1; g.fillStyle = "#222"; g.fillText(t.name, x + 28, y + 1);
      });
    }

    // the 3-D point under (u, v) in the plane (e1, e2) through the handle, or null when the plane is seen edge-on
    handlePoint(u, v, plane) {
      const [e1, e2] = plane, z = this.zoom(), [hu, hv] = this.project(this.handle);
      const a11 = dot(e1, this.cam.right), a12 = dot(e2, this.cam.right), a21 = dot(e1, this.cam.up), a22 = dot(e2, this.cam.up);
      const det = a11 * a22 - a12 * a21, bu = (u - hu) / z, bv = -(v - hv) / z;
      if (Math.abs(det) < 0.05) return null;
      const s = (bu * a22 - a12 * bv) / det, t = (a11 * bv - a21 * bu) / det;
      return [0, 1, 2].map(i => this.handle[i] + s * e1[i] + t * e2[i]);
    }

    attach() {
      const el = this.front;
      let mode = null, last = null;
      const at = ev => { const r = el.getBoundingClientRect(); return [ev.clientX - r.left, ev.clientY - r.top]; };
      el.addEventListener("pointerdown", ev => {
        const [u, v] = at(ev), h = this.handleAt, plane = this.opts.handlePlane ? this.opts.handlePlane() : null;
        mode = (h && plane && Math.hypot(u - h[0], v - h[1]) < 10) ? "handle" : "turn";
        last = [u, v]; el.setPointerCapture(ev.pointerId); el.style.cursor = "grabbing";
      });
      el.addEventListener("pointermove", ev => {
        if (!mode) return;
        const [u, v] = at(ev);
        if (mode === "handle") {
          const q = this.handlePoint(u, v, this.opts.handlePlane());
          if (q) this.opts.onHandle(q);
        } else {
          const k = 0.008, c = this.cam;
          ["fwd", "up", "right"].forEach(n => { c[n] = turn(c[n], this.spin, -k * (u - last[0])); });
          ["fwd", "up"].forEach(n => { c[n] = turn(c[n], c.right, -k * (v - last[1])); });
          this.dirtyBack = true; this.request();
        }
        last = [u, v];
      });
      const up = () => { mode = null; el.style.cursor = "grab"; };
      el.addEventListener("pointerup", up); el.addEventListener("pointercancel", up);
      el.addEventListener("wheel", ev => { ev.preventDefault(); this.zoomBy *= Math.exp(-0.001 * ev.deltaY); this.dirtyBack = true; this.request(); },
        { passive: false });
      el.addEventListener("dblclick", () => this.reset());
      this.onResize = () => this.request();
      window.addEventListener("resize", this.onResize);
    }

    destroy() { window.removeEventListener("resize", this.onResize); this.box.replaceChildren(); }
  }

  return { webglRenderer, choose, View, SOFTWARE };
})();
