// spatialmech studio: the drag pad's geometry, shared by the page (static/studio.js, loaded before
// it) and the notebook widget (static/widget.js, bundled after it by interfaces/studio/widget.py).
// The pad shows the linkage projected on a plane (a planar linkage's own plane, else the plane of
// the first two of x, y, z that the mechanism controls) in a 200 x 200 SVG; a point dragged on it
// becomes a 3-D point (the output point's coordinate along the plane's normal kept) that the
// session reaches by the pose drag's continuation (Session.drag_output).  Being the one file both
// frontends load, it also holds what they share of the 3-D view: `glPixelRatio`.
"use strict";

const SMPad = (() => {
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = a => mul(a, 1 / Math.hypot(a[0], a[1], a[2]));

  // in-plane axes (e1, e2) of the plane with normal n: e2 the world axis least along n (y first),
  // made perpendicular to n; e1 = e2 x n (right-handed seen from the normal's side)
  function planeBasis(n) {
    const cand = [[0, 1, 0], [1, 0, 0], [0, 0, 1]].sort((a, b) => Math.abs(dot(a, n)) - Math.abs(dot(b, n)))[0];
    const e2 = unit(add(cand, mul(n, -dot(cand, n))));
    return [cross(e2, n), e2];
  }

  // a cube around everything the scene draws, with a margin (the 3-D view's fixed axis ranges)
  function sceneRange(sc) {
    const pts = [].concat(sc.base_len, sc.platform_len, sc.task_positions_len, ...sc.limbs_len, sc.joints.map(j => j.centre_len));
    const lo = [0, 1, 2].map(a => Math.min(...pts.map(p => p[a]))), hi = [0, 1, 2].map(a => Math.max(...pts.map(p => p[a])));
    const half = Math.max(...[0, 1, 2].map(a => hi[a] - lo[a])) / 2 + 0.8 * sc.scale_len;
    return [0, 1, 2].map(a => [(lo[a] + hi[a]) / 2 - half, (lo[a] + hi[a]) / 2 + half]);
  }

  // the pad's frame for a session state and the scene's range, or null when the mechanism does not
  // control the output point's position
  function frame(st, range) {
    const sc = st.scene, given = st.task ? st.task.given.filter(g => "xyz".includes(g)) : [];
    if (!given.length || !range) return null;
    const axes = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
    let e1, e2, label;
    if (sc.plane_normal) { [e1, e2] = planeBasis(sc.plane_normal); label = "the linkage's plane"; }
    else {
      const names = given.concat(["x", "y", "z"].filter(g => !given.includes(g))).slice(0, 2);
      [e1, e2] = [axes[names[0]], axes[names[1]]]; label = names[0] + "-" + names[1] + " plane";
    }
    const c = range.map(r => (r[0] + r[1]) / 2), half = (range[0][1] - range[0][0]) / 2;
    return { e1, e2, c, half, label, given };
  }

  function xy(f, p) { const d = add(p, mul(f.c, -1)); return [100 + 100 * dot(d, f.e1) / f.half, 100 - 100 * dot(d, f.e2) / f.half]; }

  function label(f) { return "drag the output point (" + f.given.join(", ") + "), " + f.label; }

  // the SVG content: base, limbs, platform and the handle (class drag-handle, and `handleId` if
  // given) on the output point
  function svg(f, sc, handleId) {
    const line = (pts, col, w) => `<polyline fill="none" stroke="${col}" stroke-width="${w}" points="` +
      pts.map(p => xy(f, p).map(v => v.toFixed(1)).join(",")).join(" ") + `"/>`;
    const [u, v] = xy(f, sc.platform_point_len);
    return line(sc.base_len, "#999", 1) + sc.limbs_len.map((pl, li) => line(pl, sc.limb_colours[li], 2)).join("") +
      line(sc.platform_len, "#ff7f0e", 2) +
      `<circle ${handleId ? `id="${handleId}" ` : ""}class="drag-handle" cx="${u.toFixed(1)}" cy="${v.toFixed(1)}" r="6" fill="#ff7f0e" stroke="#000"/>`;
  }

  // the 3-D point under the mouse (clientX, clientY) on the pad's element box `rect`, the output
  // point `p`'s coordinate along the normal kept
  function point(f, rect, clientX, clientY, p) {
    const u = (clientX - rect.left - 100) / 100 * f.half, v = -(clientY - rect.top - 100) / 100 * f.half;
    const d = add(p, mul(f.c, -1));
    return add(p, add(mul(f.e1, u - dot(d, f.e1)), mul(f.e2, v - dot(d, f.e2))));
  }

  // pointer handling on the SVG element: `send(point_len)` on press and while dragging
  function attach(el, getFrame, getPoint, send) {
    let down = false;
    const to = ev => { const f = getFrame(); if (f) send(point(f, el.getBoundingClientRect(), ev.clientX, ev.clientY, getPoint())); };
    el.addEventListener("pointerdown", ev => { down = true; el.setPointerCapture(ev.pointerId); to(ev); });
    el.addEventListener("pointermove", ev => { if (down) to(ev); });
    const up = () => { down = false; };
    el.addEventListener("pointerup", up); el.addEventListener("pointercancel", up);
  }

  // plotly.js draws a 3-D scene's WebGL canvas at `plotGlPixelRatio` times the page's pixels (its
  // default is 2: four times the pixels to paint on a display of ratio 1).  Draw at the display's
  // own ratio: as sharp as the screen shows, and a quarter of the fill on an ordinary display.
  const glPixelRatio = Math.max(1, window.devicePixelRatio || 1);

  return { planeBasis, sceneRange, frame, xy, label, svg, point, attach, glPixelRatio };
})();
