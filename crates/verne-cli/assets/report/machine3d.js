"use strict";
// The VERNE machine in 3D on a canvas, with a hand-written orthographic projection (no
// library): the three vertical sliders on their guideways, the four rods (leg I: two rods;
// legs II and III: one line per parallelogram), the platform through its attachments, the
// spindle and the tool along the platform's z axis, and the tilting table of AIM 2007 eq. (7)
// with the part's path drawn on it. Every length comes from the machine file (the page's
// data); the module's pose comes from the forward kinematics computed by verne.
// Base frame: x, y, z down (IFToMM 2007 Fig. 4); drawn with z up.
var VerneView = (function () {
  const DEG = Math.PI / 180;
  const LEG = ["#1f77b4", "#1f77b4", "#d62728", "#2ca02c"];

  // Slider attachments A and platform attachments B of the rods of eqs. (3)-(6), base frame.
  function module(m, rho, P, alphaDeg) {
    const A = [
      [-m.dx1, m.r1, rho[0]],
      [-m.dx1, -m.r1, rho[0]],
      [-m.dx2, -m.r4, rho[1]],
      [-m.dx2, m.r4, rho[2]],
    ];
    if (!P || !isFinite(P[0]) || !isFinite(alphaDeg)) return { A: A, B: null };
    const a = alphaDeg * DEG, s = Math.sin(a), c = Math.cos(a);
    const B = [
      [P[0], P[1] + m.R1 * c, P[2] + m.R1 * s],
      [P[0], P[1] - m.R1 * c, P[2] - m.R1 * s],
      [P[0], P[1] - m.R2 * c, P[2] - m.R2 * s],
      [P[0], P[1] + m.R2 * c, P[2] + m.R2 * s],
    ];
    // The tool along the platform's z axis: bT_pl (0, 0, L) of AIM 2007 eq. (1).
    const n = [0, -s, c];
    const tip = [P[0], P[1] + m.tool_length * n[1], P[2] + m.tool_length * n[2]];
    return { A: A, B: B, u: [0, c, s], n: n, tip: tip };
  }

  // bT_t of AIM 2007 eq. (7): Trans(0,0,d_a) Rx(theta1) Trans(0,0,d_t) Rx(pi) Rz(theta2), as a
  // function from the workpiece frame to the base frame.
  function table(m, theta1Deg, theta2Deg) {
    const t1 = theta1Deg * DEG, t2 = theta2Deg * DEG;
    const c1 = Math.cos(t1), s1 = Math.sin(t1), c2 = Math.cos(t2), s2 = Math.sin(t2);
    const cf = -c1, sf = -s1; // Rx(theta1) Rx(pi) = Rx(theta1 + pi)
    const o = [0, -s1 * m.d_t, m.d_a + c1 * m.d_t];
    const R = [
      [c2, -s2, 0],
      [cf * s2, cf * c2, -sf],
      [sf * s2, sf * c2, cf],
    ];
    const apply = function (p) {
      return [
        o[0] + R[0][0] * p[0] + R[0][1] * p[1] + R[0][2] * p[2],
        o[1] + R[1][0] * p[0] + R[1][1] * p[1] + R[1][2] * p[2],
        o[2] + R[2][0] * p[0] + R[2][1] * p[1] + R[2][2] * p[2],
      ];
    };
    return { origin: o, apply: apply };
  }

  function camera() {
    return { yaw: -0.75, pitch: 0.32, zoom: 1, target: [0, 0, 600], span: 2000, follow: false, followSpan: 500 };
  }

  // One view on a canvas. options: { camera (shared between views), onCamera(cam) }.
  function create(canvas, m, options) {
    options = options || {};
    const ctx = canvas.getContext("2d");
    const cam = options.camera || camera();
    let state = null;

    function project(p) {
      const X = p[0] - cam.target[0], Y = p[1] - cam.target[1], Z = -(p[2] - cam.target[2]);
      const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
      const x1 = X * cy - Y * sy, y1 = X * sy + Y * cy;
      const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
      const up = Z * cp + y1 * sp;
      const k = (cam.zoom * Math.min(canvas.width, canvas.height)) / cam.span;
      return [canvas.width / 2 + k * x1, canvas.height / 2 - k * up];
    }

    function line(a, b, color, width, dash) {
      const p = project(a), q = project(b);
      ctx.beginPath();
      ctx.setLineDash(dash || []);
      ctx.strokeStyle = color;
      ctx.lineWidth = width;
      ctx.moveTo(p[0], p[1]);
      ctx.lineTo(q[0], q[1]);
      ctx.stroke();
      ctx.setLineDash([]);
    }

    function polygon(points, fill, stroke) {
      ctx.beginPath();
      points.forEach(function (pt, i) {
        const p = project(pt);
        if (i === 0) ctx.moveTo(p[0], p[1]);
        else ctx.lineTo(p[0], p[1]);
      });
      ctx.closePath();
      if (fill) {
        ctx.fillStyle = fill;
        ctx.fill();
      }
      if (stroke) {
        ctx.strokeStyle = stroke;
        ctx.lineWidth = 1;
        ctx.stroke();
      }
    }

    function dot(a, r, color, ring) {
      const p = project(a);
      ctx.beginPath();
      ctx.arc(p[0], p[1], r, 0, 2 * Math.PI);
      if (ring) {
        ctx.strokeStyle = color;
        ctx.lineWidth = 2;
        ctx.stroke();
      } else {
        ctx.fillStyle = color;
        ctx.fill();
      }
    }

    // A polyline of points xyz (workpiece frame) from `from` to `to`, through `map`; NaN breaks.
    function path(xyz, from, to, map, color, width) {
      ctx.beginPath();
      ctx.strokeStyle = color;
      ctx.lineWidth = width;
      let pen = false;
      for (let i = from; i < to; i++) {
        const x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        if (!(isFinite(x) && isFinite(y) && isFinite(z))) {
          pen = false;
          continue;
        }
        const p = project(map([x, y, z]));
        if (pen) ctx.lineTo(p[0], p[1]);
        else ctx.moveTo(p[0], p[1]);
        pen = true;
      }
      ctx.stroke();
    }

    function draw() {
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.clearRect(0, 0, canvas.width, canvas.height);
      ctx.fillStyle = "#fbfcfd";
      ctx.fillRect(0, 0, canvas.width, canvas.height);
      if (!state) return;
      const s = state;
      const md = module(m, s.rho, s.P, s.alpha);
      // A close-up follows the tool tip.
      if (cam.follow && md.B) {
        cam.target = md.tip.slice();
        cam.span = cam.followSpan;
      }
      // The frame: guideways over the strokes, joined at their ends.
      const guide = [
        [-m.dx1, 0, 0],
        [-m.dx2, -m.r4, 1],
        [-m.dx2, m.r4, 2],
      ];
      guide.forEach(function (g) {
        line([g[0], g[1], m.rho_min[g[2]]], [g[0], g[1], m.rho_max[g[2]]], "#8c959f", 4);
      });
      for (let i = 0; i < 3; i++) {
        const a = guide[i], b = guide[(i + 1) % 3];
        line([a[0], a[1], m.rho_min[a[2]]], [b[0], b[1], m.rho_min[b[2]]], "#d0d7de", 2);
      }
      // The table: the tilting axis, the cradle, the plate with its theta2 mark, the path.
      if (s.theta1 !== null && s.theta1 !== undefined && isFinite(s.theta1)) {
        const T = table(m, s.theta1, s.theta2);
        const w = Math.max(m.r4 * 0.9, s.reach * 1.3, 150);
        line([-w, 0, m.d_a], [w, 0, m.d_a], "#57606a", 5);
        line([0, 0, m.d_a], T.origin, "#57606a", 3);
        const R = Math.max(s.reach * 1.12, 80);
        const disc = [];
        for (let k = 0; k < 48; k++) {
          const u = (2 * Math.PI * k) / 48;
          disc.push(T.apply([R * Math.cos(u), R * Math.sin(u), 0]));
        }
        polygon(disc, "rgba(175,184,193,0.35)", "#8c959f");
        line(T.apply([0, 0, 0]), T.apply([R, 0, 0]), "#8c959f", 2);
        if (s.intended) {
          const n = s.intended.length / 3;
          path(s.intended, 0, n, T.apply, "rgba(9,105,218,0.35)", 1.5);
          path(s.intended, 0, Math.min(n, s.upTo + 1), T.apply, "#0969da", 2);
        }
        if (s.actual) {
          const n = s.actual.length / 3;
          path(s.actual, 0, Math.min(n, s.upTo + 1), T.apply, "#fb8500", 1.2);
        }
        if (s.target && isFinite(s.target[0])) dot(T.apply(s.target), 6, "#0969da", true);
      }
      // The module.
      md.A.forEach(function (a, i) {
        dot(a, 4, LEG[i]);
      });
      line(md.A[0], md.A[1], LEG[0], 6);
      if (md.B) {
        md.A.forEach(function (a, i) {
          line(a, md.B[i], LEG[i], 2.5);
        });
        const P = s.P, w = 0.3 * m.R2, e = md.u, R = Math.max(m.R1, m.R2);
        const corner = function (sx, su) {
          return [P[0] + sx * w, P[1] + su * R * e[1], P[2] + su * R * e[2]];
        };
        polygon([corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)], "rgba(36,41,47,0.55)", "#24292f");
        md.B.forEach(function (b) {
          dot(b, 3, "#24292f");
        });
        const top = [P[0], P[1] - 0.8 * m.R2 * md.n[1], P[2] - 0.8 * m.R2 * md.n[2]];
        line(top, P, "#8c959f", 9);
        line(P, md.tip, "#24292f", 3);
        dot(md.tip, 4, "#cf222e");
      } else {
        ctx.fillStyle = "#a40e26";
        ctx.font = "14px system-ui, sans-serif";
        ctx.fillText("no assembly mode of the machine's kind at this row", 12, canvas.height - 14);
      }
      if (s.label) {
        ctx.fillStyle = "#24292f";
        ctx.font = "13px system-ui, sans-serif";
        ctx.fillText(s.label, 10, 18);
      }
    }

    // Centres the camera on the machine: the guideways, the table and the state's module.
    function fit(states) {
      const pts = [];
      [[-m.dx1, 0, 0], [-m.dx2, -m.r4, 1], [-m.dx2, m.r4, 2]].forEach(function (g) {
        pts.push([g[0], g[1], m.rho_min[g[2]]], [g[0], g[1], m.rho_max[g[2]]]);
      });
      (states || [state]).forEach(function (s) {
        if (!s) return;
        if (s.theta1 !== null && s.theta1 !== undefined && isFinite(s.theta1)) {
          pts.push([0, 0, m.d_a], table(m, s.theta1, s.theta2).origin);
        }
        const md = module(m, s.rho, s.P, s.alpha);
        if (md.B) pts.push(md.tip);
      });
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      pts.forEach(function (p) {
        for (let i = 0; i < 3; i++) {
          if (isFinite(p[i])) {
            lo[i] = Math.min(lo[i], p[i]);
            hi[i] = Math.max(hi[i], p[i]);
          }
        }
      });
      cam.target = [0, 1, 2].map(function (i) {
        return (lo[i] + hi[i]) / 2;
      });
      cam.span = 1.15 * Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1);
      cam.zoom = 1;
      cam.whole = { target: cam.target.slice(), span: cam.span };
    }

    // The whole machine, or a close-up that follows the tool tip (`span` mm across).
    function closeUp(on, span) {
      cam.follow = on;
      if (span) cam.followSpan = span;
      if (!on && cam.whole) {
        cam.target = cam.whole.target.slice();
        cam.span = cam.whole.span;
      }
      cam.zoom = 1;
    }

    // Drag turns, wheel zooms, double-click resets.
    let drag = null;
    canvas.addEventListener("mousedown", function (e) {
      drag = [e.clientX, e.clientY];
      e.preventDefault();
    });
    window.addEventListener("mouseup", function () {
      drag = null;
    });
    window.addEventListener("mousemove", function (e) {
      if (!drag) return;
      cam.yaw += (e.clientX - drag[0]) * 0.008;
      cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + (e.clientY - drag[1]) * 0.008));
      drag = [e.clientX, e.clientY];
      changed();
    });
    canvas.addEventListener(
      "wheel",
      function (e) {
        cam.zoom = Math.max(0.2, Math.min(20, cam.zoom * Math.exp(-e.deltaY * 0.0015)));
        e.preventDefault();
        changed();
      },
      { passive: false }
    );
    canvas.addEventListener("dblclick", function () {
      const t = camera();
      cam.yaw = t.yaw;
      cam.pitch = t.pitch;
      cam.zoom = 1;
      changed();
    });
    let queued = false;
    function changed() {
      if (options.onCamera) options.onCamera(cam);
      if (queued) return;
      queued = true;
      requestAnimationFrame(function () {
        queued = false;
        draw();
      });
    }

    return {
      camera: cam,
      draw: draw,
      fit: fit,
      closeUp: closeUp,
      set: function (s) {
        state = s;
      },
    };
  }

  return { create: create, module: module, table: table, camera: camera };
})();
