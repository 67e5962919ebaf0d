"use strict";
// The report of `verne verify --html`: reads the page's data (written by verne), lists the
// findings, draws the plots (uPlot) and the machine at the chosen row (VerneView), and keeps
// the three on one row: a finding, a click on a plot or the slider moves them all.
(function () {
  const started = performance.now();
  const D = JSON.parse(document.getElementById("verne-data").textContent);
  const M = D.machine;
  const TH = D.thresholds;

  function bytes(s) {
    const bin = atob(s);
    const u = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    return u.buffer;
  }
  const f32 = function (s) {
    return new Float32Array(bytes(s));
  };
  const u32 = function (s) {
    return new Uint32Array(bytes(s));
  };
  function fmt(v, digits) {
    if (v === null || v === undefined || !isFinite(v)) return "";
    const a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e6)) return v.toExponential((digits || 6) - 1);
    return String(+v.toPrecision(digits || 6));
  }
  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  // The rows of the 3D view.
  const F = D.frames;
  const fRow = u32(F.row), fx = f32(F.x), fjl = u32(F.jl), fpl = u32(F.pl), ch = f32(F.ch);
  const NC = F.channels.length;
  const chan = function (i, name) {
    return ch[i * NC + F.channels.indexOf(name)];
  };
  const label = function (i) {
    return F.labels ? F.labels[i] : String(fRow[i]);
  };
  const intended = new Float32Array(3 * F.n), actual = new Float32Array(3 * F.n);
  for (let i = 0; i < F.n; i++) {
    for (let k = 0; k < 3; k++) {
      intended[3 * i + k] = ch[i * NC + 9 + k];
      actual[3 * i + k] = ch[i * NC + 12 + k];
    }
  }
  function state(i) {
    const c = function (n) {
      return chan(i, n);
    };
    return {
      rho: [c("rho1"), c("rho2"), c("rho3")],
      theta1: c("theta1"),
      theta2: c("theta2"),
      P: [c("px"), c("py"), c("pz")],
      alpha: c("alpha"),
      intended: intended,
      actual: actual,
      upTo: i,
      target: [c("tip_x"), c("tip_y"), c("tip_z")],
      reach: F.reach,
      label: "row " + label(i),
    };
  }

  // The findings at each frame.
  const findings = D.findings;
  const byFrame = {};
  findings.forEach(function (f, k) {
    if (f.frame === null) return;
    (byFrame[f.frame] = byFrame[f.frame] || []).push(k);
  });

  const canvas = document.getElementById("view3d");
  const view = VerneView.create(canvas, M);
  const scrub = document.getElementById("scrub");
  const info = document.getElementById("rowinfo");
  scrub.max = String(Math.max(0, F.n - 1));
  let cur = 0;
  const charts = [];

  function go(i) {
    if (F.n === 0) return;
    cur = Math.max(0, Math.min(F.n - 1, i));
    scrub.value = String(cur);
    view.set(state(cur));
    view.draw();
    const c = function (n) {
      return chan(cur, n);
    };
    const parts = ["<b>row " + esc(label(cur)) + "</b>", "joint program line " + fjl[cur]];
    if (fpl[cur]) parts.push("path line " + fpl[cur]);
    parts.push(D.x.label + " = " + fmt(fx[cur], 7));
    let html = parts.join(" &middot; ") + "<br>";
    html +=
      "rho = (" + [c("rho1"), c("rho2"), c("rho3")].map(function (v) { return fmt(v, 7); }).join(", ") +
      ") mm, theta1 = " + fmt(c("theta1"), 6) + " deg, theta2 = " + fmt(c("theta2"), 6) + " deg";
    if (isFinite(c("px"))) {
      html +=
        "<br>platform P = (" + [c("px"), c("py"), c("pz")].map(function (v) { return fmt(v, 6); }).join(", ") +
        ") mm, alpha = " + fmt(c("alpha"), 6) + " deg";
    } else {
      html += "<br><span class=\"f\">no assembly mode of the machine's kind</span>";
    }
    if (F.stride > 1) {
      html += "<br><span class=\"hint\">The view holds one row in " + F.stride +
        " and the row of every finding listed; the slider goes from one to the next.</span>";
    }
    (byFrame[cur] || []).forEach(function (k) {
      const f = findings[k];
      html += "<br><span class=\"f\">" + esc(f.check) + ": " + esc(f.detail) + "</span>";
    });
    info.innerHTML = html;
    document.querySelectorAll("#findings tbody tr").forEach(function (tr) {
      tr.classList.toggle("here", tr.dataset.frame === String(cur));
    });
    charts.forEach(function (c) {
      c.cursor();
    });
    document.body.dataset.row = label(cur);
    document.body.dataset.frame = String(cur);
  }
  function esc(t) {
    return String(t).replace(/[&<>"']/g, function (c) {
      return { "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" }[c];
    });
  }
  // The frame nearest x (x never decreases along the frames).
  function frameAt(x) {
    let lo = 0, hi = F.n - 1;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (fx[mid] < x) lo = mid + 1;
      else hi = mid;
    }
    if (lo > 0 && Math.abs(fx[lo - 1] - x) <= Math.abs(fx[lo] - x)) lo -= 1;
    return lo;
  }

  scrub.addEventListener("input", function () {
    go(+scrub.value);
  });
  document.getElementById("prev").addEventListener("click", function () {
    go(cur - 1);
  });
  document.getElementById("next").addEventListener("click", function () {
    go(cur + 1);
  });
  let timer = null;
  const play = document.getElementById("play");
  play.addEventListener("click", function () {
    if (timer) {
      clearInterval(timer);
      timer = null;
      play.textContent = "play";
      return;
    }
    play.textContent = "stop";
    timer = setInterval(function () {
      if (cur >= F.n - 1) {
        clearInterval(timer);
        timer = null;
        play.textContent = "play";
        return;
      }
      go(cur + Math.max(1, Math.round(F.n / 600)));
    }, 30);
  });
  document.addEventListener("keydown", function (e) {
    if (e.target && (e.target.tagName === "INPUT" || e.target.tagName === "TEXTAREA")) return;
    if (e.key === "ArrowLeft") go(cur - 1);
    else if (e.key === "ArrowRight") go(cur + 1);
  });

  // The findings table.
  const tbody = document.querySelector("#findings tbody");
  let filter = null;
  function location(file, line, text) {
    const td = el("td");
    if (!line) return td;
    const name = file.name.split("/").pop();
    if (file.href) {
      const a = el("a", { href: file.href, title: file.name }, name + ":" + line);
      a.addEventListener("click", function (e) {
        e.stopPropagation();
      });
      td.appendChild(a);
    } else {
      td.appendChild(document.createTextNode(name + ":" + line));
    }
    if (text !== null && text !== undefined) td.appendChild(el("code", {}, text));
    return td;
  }
  function fillFindings() {
    tbody.textContent = "";
    let shown = 0;
    findings.forEach(function (f) {
      if (filter && f.check !== filter) return;
      shown++;
      const tr = el("tr", { "data-frame": f.frame === null ? "" : String(f.frame), "data-check": f.check });
      tr.appendChild(el("td", { class: "num" }, f.row));
      tr.appendChild(el("td", {}, f.check));
      tr.appendChild(el("td", { class: "num" }, fmt(f.value, 6)));
      tr.appendChild(el("td", { class: "num" }, fmt(f.limit, 6)));
      tr.appendChild(el("td", {}, f.detail));
      tr.appendChild(location(D.inputs.joints, f.jl, f.jt));
      tr.appendChild(location(D.inputs.path, f.pl, f.pt));
      tr.addEventListener("click", function () {
        if (f.frame !== null) go(f.frame);
      });
      tbody.appendChild(tr);
    });
    const total = D.findings_total;
    let title = total === 0 ? "Findings: none" : "Findings: " + total;
    if (findings.length < total) {
      title += " (" + findings.length + " listed: the first in row order and the worst of each check; all in the --report CSV)";
    }
    if (filter) title += " \u2014 showing " + shown + " of check " + filter + " (click the check again to show all)";
    document.getElementById("findings-title").textContent = title;
  }
  document.querySelectorAll("table.checks tbody tr").forEach(function (tr) {
    tr.addEventListener("click", function () {
      const c = tr.dataset.check;
      filter = filter === c ? null : c;
      document.querySelectorAll("table.checks tbody tr").forEach(function (t) {
        t.classList.toggle("active", t.dataset.check === filter);
      });
      fillFindings();
      const s = D.summary.checks.find(function (k) {
        return k.code === c;
      });
      if (filter && s && s.finding !== null && findings[s.finding].frame !== null) {
        go(findings[s.finding].frame);
      }
    });
  });
  fillFindings();

  // The plots.
  const P = D.plot;
  const px = Array.from(f32(P.x));
  const marks = u32(P.marks);
  const series = {};
  for (const k in P.series) series[k] = f32(P.series[k]);
  const checkBit = function (code) {
    return 1 << D.checks.indexOf(code);
  };
  const th = function (n) {
    return TH[n].value;
  };
  const same = function (a) {
    return a.every(function (v) {
      return v === a[0];
    });
  };
  const strokeLimits = [];
  if (same(M.rho_min) && same(M.rho_max)) {
    strokeLimits.push([M.rho_min[0], "stroke", "#57606a"], [M.rho_max[0], "stroke", "#57606a"]);
  } else {
    for (let i = 0; i < 3; i++) {
      const col = ["#1f77b4", "#d62728", "#2ca02c"][i];
      strokeLimits.push([M.rho_min[i], "rho" + (i + 1), col], [M.rho_max[i], "rho" + (i + 1), col]);
    }
  }
  const C3 = ["#1f77b4", "#d62728", "#2ca02c"], C2 = ["#8250df", "#bf8700"];
  const pm = function (v, name, col) {
    return [[v, name, col], [-v, name, col]];
  };
  const defs = [
    { title: "Sliders rho1, rho2, rho3 (mm) and their strokes", keys: ["rho1", "rho2", "rho3"], colors: C3,
      limits: strokeLimits, checks: ["limits", "joint_jump", "branch", "input", "pairing", "motion"] },
    { title: "Tilting table theta1, theta2 (deg) and the theta1 range", keys: ["theta1", "theta2"], colors: C2,
      limits: [[M.theta1_min_deg, "theta1", C2[0]], [M.theta1_max_deg, "theta1", C2[0]]],
      checks: ["limits", "theta2_flip", "joint_jump", "branch"] },
    { title: "Tip error and chordal error (mm, log scale)", keys: ["tip_error", "chord_error"], colors: ["#cf222e", "#fb8500"],
      limits: [[th("tip_error_mm"), "tip_error_mm", "#cf222e"], [th("chord_error_mm"), "chord_error_mm", "#fb8500"]],
      log: true, checks: ["tip_error", "chord_error"] },
    { title: "Axis error and chordal axis error (deg, log scale)", keys: ["axis_error", "chord_axis"], colors: ["#cf222e", "#fb8500"],
      limits: [[th("axis_error_deg"), "axis_error_deg", "#cf222e"], [th("chord_axis_error_deg"), "chord_axis_error_deg", "#fb8500"]],
      log: true, checks: ["axis_error", "chord_axis"] },
    { title: "Velocity amplification factors and parallel margin", keys: ["lambda_max", "lambda_min", "parallel_margin"],
      colors: ["#cf222e", "#0969da", "#57606a"],
      limits: [[th("lambda_max"), "lambda_max", "#cf222e"], [th("lambda_min"), "lambda_min", "#0969da"],
        [th("parallel_margin_min"), "parallel_margin_min", "#57606a"]], checks: ["singularity"] },
    { title: "Largest rod tilt (deg)", keys: ["rod_tilt"], colors: ["#1f77b4"],
      limits: [[M.rod_tilt_max_deg, "rod_tilt_max", "#cf222e"]], checks: ["limits"] },
    { title: "Slider speeds (mm/s)", keys: ["v_rho1", "v_rho2", "v_rho3"], colors: C3, timed: true,
      limits: pm(th("rho_velocity_mm_s"), "rho_velocity_mm_s", "#cf222e"), checks: ["velocity"] },
    { title: "Table speeds (deg/s)", keys: ["v_theta1", "v_theta2"], colors: C2, timed: true,
      limits: pm(th("theta1_velocity_deg_s"), "theta1", C2[0]).concat(pm(th("theta2_velocity_deg_s"), "theta2", C2[1])),
      checks: ["velocity"] },
    { title: "Slider accelerations (mm/s\u00b2)", keys: ["a_rho1", "a_rho2", "a_rho3"], colors: C3, timed: true,
      limits: pm(th("rho_accel_mm_s2"), "rho_accel_mm_s2", "#cf222e"), checks: ["acceleration"] },
    { title: "Table accelerations (deg/s\u00b2)", keys: ["a_theta1", "a_theta2"], colors: C2, timed: true,
      limits: pm(th("theta1_accel_deg_s2"), "theta1", C2[0]).concat(pm(th("theta2_accel_deg_s2"), "theta2", C2[1])),
      checks: ["acceleration"] },
  ];
  const box = document.getElementById("charts");
  const note = document.getElementById("plots-note");
  note.textContent =
    "Against " + D.x.label + ". " +
    (P.width > 1
      ? "Each point pair is the smallest and largest value of " + P.width + " consecutive rows, so no peak is lost."
      : "Every row is a point.") +
    " Red ticks mark the rows with findings of the plotted checks; the blue line is the row shown in 3D. Drag to zoom, double-click to zoom out.";
  let syncing = false;
  const width = function () {
    return Math.max(400, box.clientWidth - 10);
  };
  const notTimed = D.summary.checks.find(function (c) {
    return c.code === "velocity";
  });
  let untimedShown = false;
  defs.forEach(function (def) {
    if (def.timed && !D.summary.timed) {
      if (!untimedShown) {
        box.appendChild(
          el("p", { class: "untimed" },
            "Velocity and acceleration were not checked: " + (notTimed ? notTimed.why : "no time") +
            ". Give the joint table a t or feed column (or a path with feeds) to check them.")
        );
        untimedShown = true;
      }
      return;
    }
    const data = [px];
    let lo = Infinity, hi = -Infinity;
    def.keys.forEach(function (k) {
      const s = series[k], out = new Array(s.length);
      for (let i = 0; i < s.length; i++) {
        const v = s[i];
        if (!isFinite(v) || (def.log && v <= 0)) {
          out[i] = null;
        } else {
          out[i] = v;
          if (v < lo) lo = v;
          if (v > hi) hi = v;
        }
      }
      data.push(out);
    });
    def.limits.forEach(function (l) {
      if (!isFinite(l[0]) || (def.log && l[0] <= 0)) return;
      lo = Math.min(lo, l[0]);
      hi = Math.max(hi, l[0]);
    });
    if (!isFinite(lo)) {
      lo = def.log ? 1e-6 : 0;
      hi = def.log ? 1 : 1;
    }
    let range;
    if (def.log) {
      const a = Math.pow(10, Math.floor(Math.log10(lo))), b = Math.pow(10, Math.ceil(Math.log10(hi)));
      range = [a, b > a ? b : a * 10];
    } else {
      const pad = (hi - lo) * 0.06 || Math.abs(hi) * 0.1 || 1;
      range = [lo - pad, hi + pad];
    }
    const mask = def.checks.reduce(function (m, c) {
      return m | checkBit(c);
    }, 0);
    const div = el("div", { class: "chart" });
    box.appendChild(div);
    let chart = null;
    const opts = {
      title: def.title,
      width: width(),
      height: 200,
      scales: {
        x: { time: false },
        y: def.log ? { distr: 3, log: 10, range: function () { return range; } } : { range: function () { return range; } },
      },
      cursor: { sync: { key: "verne" }, drag: { x: true, y: false } },
      series: [{ label: D.x.label, value: function (u, v) { return v === null ? "" : fmt(v, 8); } }].concat(
        def.keys.map(function (k, i) {
          return { label: k, stroke: def.colors[i], width: 1.25, points: { show: false },
            value: function (u, v) { return v === null ? "" : fmt(v, 6); } };
        })
      ),
      axes: [{ label: D.x.label }, { size: 70, values: function (u, vals) { return vals.map(function (v) { return v === null ? "" : String(+v.toPrecision(4)); }); } }],
      hooks: {
        draw: [
          function (u) {
            const c = u.ctx;
            c.save();
            // The limits.
            def.limits.forEach(function (l) {
              if (!isFinite(l[0]) || (def.log && l[0] <= 0)) return;
              const y = u.valToPos(l[0], "y", true);
              c.strokeStyle = l[2];
              c.lineWidth = 1;
              c.setLineDash([6, 4]);
              c.beginPath();
              c.moveTo(u.bbox.left, y);
              c.lineTo(u.bbox.left + u.bbox.width, y);
              c.stroke();
            });
            c.setLineDash([]);
            // The findings of this plot's checks, one tick per pixel.
            c.strokeStyle = "#cf222e";
            c.lineWidth = 2;
            let last = -1;
            const min = u.scales.x.min, max = u.scales.x.max;
            for (let i = 0; i < marks.length; i++) {
              if (!(marks[i] & mask)) continue;
              const x = px[i];
              if (x < min || x > max) continue;
              const p = Math.round(u.valToPos(x, "x", true));
              if (p === last) continue;
              last = p;
              c.beginPath();
              c.moveTo(p, u.bbox.top);
              c.lineTo(p, u.bbox.top + 10 * devicePixelRatio);
              c.moveTo(p, u.bbox.top + u.bbox.height);
              c.lineTo(p, u.bbox.top + u.bbox.height - 10 * devicePixelRatio);
              c.stroke();
            }
            c.restore();
          },
        ],
        setScale: [
          function (u, key) {
            if (key !== "x" || syncing) return;
            syncing = true;
            charts.forEach(function (o) {
              if (o.u !== u) o.u.setScale("x", { min: u.scales.x.min, max: u.scales.x.max });
            });
            syncing = false;
            charts.forEach(function (o) {
              o.cursor();
            });
          },
        ],
      },
    };
    const u = new uPlot(opts, data, div);
    const line = el("div", { class: "cursor-row" });
    u.over.appendChild(line);
    let down = null;
    u.over.addEventListener("mousedown", function (e) {
      down = [e.clientX, e.clientY];
    });
    u.over.addEventListener("mouseup", function (e) {
      if (down && Math.abs(e.clientX - down[0]) < 4 && Math.abs(e.clientY - down[1]) < 4) {
        const x = u.posToVal(e.clientX - u.over.getBoundingClientRect().left, "x");
        go(frameAt(x));
      }
      down = null;
    });
    chart = {
      u: u,
      cursor: function () {
        if (F.n === 0) return;
        const x = fx[cur];
        const inside = x >= u.scales.x.min && x <= u.scales.x.max;
        line.style.display = inside ? "block" : "none";
        if (inside) line.style.left = u.valToPos(x, "x") + "px";
      },
    };
    charts.push(chart);
  });
  window.addEventListener("resize", function () {
    charts.forEach(function (c) {
      c.u.setSize({ width: width(), height: 200 });
      c.cursor();
    });
  });

  // The first row with a finding, or the first row.
  view.fit(F.n ? [state(0)] : []);
  const close = document.getElementById("closeup");
  close.addEventListener("change", function () {
    view.closeUp(close.checked, Math.max(4 * F.reach, 300));
    view.draw();
  });
  const first = findings.find(function (f) {
    return f.frame !== null;
  });
  go(first ? first.frame : 0);
  document.body.dataset.ready = "1";
  document.body.dataset.drawMs = String(Math.round(performance.now()));
  document.body.dataset.scriptMs = String(Math.round(performance.now() - started));
  // For tests: the drawn machine's geometry at a frame (the module and the table of this page).
  window.verneReport = {
    frames: F.n,
    go: go,
    state: state,
    row: function () {
      return label(cur);
    },
    frame: function () {
      return cur;
    },
  };
})();
