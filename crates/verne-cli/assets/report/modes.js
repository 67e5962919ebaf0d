"use strict";
// `verne modes --plot FILE.html`: one 3D view per branch of the query, sharing one camera.
(function () {
  const D = JSON.parse(document.getElementById("verne-data").textContent);
  const M = D.machine;
  const box = document.getElementById("branches");
  const cam = VerneView.camera();
  const views = [];
  const states = D.branches.map(function (b) {
    return {
      rho: b.rho,
      P: b.P,
      alpha: b.alpha,
      theta1: b.theta1,
      theta2: b.theta2,
      intended: null,
      actual: null,
      upTo: 0,
      target: b.tip,
      reach: b.tip ? Math.hypot(b.tip[0], b.tip[1]) : 0,
      label: "",
    };
  });
  const size = D.branches.length > 2 ? 380 : 520;
  D.branches.forEach(function (b, i) {
    const div = document.createElement("div");
    div.className = "branch" + (b.working ? " working" : "");
    const label = document.createElement("div");
    label.className = "label";
    label.textContent = b.label;
    const detail = document.createElement("div");
    detail.className = "detail";
    detail.textContent = b.detail;
    const canvas = document.createElement("canvas");
    canvas.width = size;
    canvas.height = Math.round(size * 1.15);
    div.appendChild(label);
    div.appendChild(detail);
    div.appendChild(canvas);
    box.appendChild(div);
    const v = VerneView.create(canvas, M, {
      camera: cam,
      onCamera: function () {
        views.forEach(function (o) {
          if (o !== v) o.draw();
        });
      },
    });
    v.set(states[i]);
    views.push(v);
  });
  if (views.length) views[0].fit(states);
  views.forEach(function (v) {
    v.draw();
  });
  if (!views.length) {
    const p = document.createElement("p");
    p.textContent = "No real branch: nothing to draw.";
    box.appendChild(p);
  }
  document.body.dataset.ready = "1";
  document.body.dataset.drawMs = String(Math.round(performance.now()));
})();
