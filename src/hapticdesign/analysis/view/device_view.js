// Device view: forward kinematics of the exported node table, orthographic projection on a canvas.
// Data: JSON in #device-data (see hapticdesign/analysis/view/skeleton.py). No network, no innerHTML.
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("device-data").textContent);
  var q = data.full.slice();  // every tree coordinate; sliders set the actuated ones, loops solve the passive ones
  var IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  var canvas = document.getElementById("canvas");
  var ctx = canvas.getContext("2d");
  var view = { az: -0.9, el: 0.45, zoom: 1.0 };
  var showLabels = false;

  function elementary(axis, v) {  // axis 0-2: rotation about x, y, z; 3-5: translation along x, y, z
    var t = IDENTITY.slice(), i = axis % 3;
    if (axis < 3) {
      var j = (i + 1) % 3, k = (i + 2) % 3, c = Math.cos(v), s = Math.sin(v);
      t[4 * j + j] = c; t[4 * j + k] = -s; t[4 * k + j] = s; t[4 * k + k] = c;
    } else {
      t[4 * i + 3] = v;
    }
    return t;
  }

  function multiply(a, b) {
    var out = new Array(16), r, c, k, sum;
    for (r = 0; r < 4; r++) {
      for (c = 0; c < 4; c++) {
        sum = 0;
        for (k = 0; k < 4; k++) { sum += a[4 * r + k] * b[4 * k + c]; }
        out[4 * r + c] = sum;
      }
    }
    return out;
  }

  function framePoses() {
    var nodes = [], n, k, node, value;
    for (n = 0; n < data.nodes.length; n++) {
      node = data.nodes[n];
      value = node[2];
      for (k = 0; k < q.length; k++) { value += node[3][k] * q[k]; }
      nodes.push(multiply(node[0] < 0 ? IDENTITY : nodes[node[0]], elementary(node[1], value)));
    }
    var poses = {};
    data.frames.forEach(function (f) { poses[f.name] = f.node < 0 ? IDENTITY : nodes[f.node]; });
    return poses;
  }

  function apply(t, r) {
    return [0, 1, 2].map(function (i) { return t[4 * i] * r[0] + t[4 * i + 1] * r[1] + t[4 * i + 2] * r[2] + t[4 * i + 3]; });
  }

  function origins(poses) {
    var out = {};
    Object.keys(poses).forEach(function (name) { out[name] = apply(poses[name], [0, 0, 0]); });
    return out;
  }

  // Loop closure (hapticdesign/analysis/loops): origin differences (x, y, z) and the skew part of
  // R_A R_B^T (rx, ry, rz) of each closure's frames, driven to zero over the passive coordinates.
  function residual(coordinates) {
    var saved = q, poses, out = [];
    q = coordinates;
    poses = framePoses();
    q = saved;
    data.closures.forEach(function (c) {
      var a = poses[c[0]], b = poses[c[1]];
      c[2].forEach(function (k) {
        if (k < 3) { out.push(a[4 * k + 3] - b[4 * k + 3]); return; }
        var i = k - 3, j = (i + 1) % 3, l = (i + 2) % 3, m = function (r, s) {
          var sum = 0; for (var t = 0; t < 3; t++) { sum += a[4 * r + t] * b[4 * s + t]; } return sum;
        };
        out.push(0.5 * (m(l, j) - m(j, l)));
      });
    });
    return out;
  }

  function solveLinear(a, b) {  // Gaussian elimination with partial pivoting; null when singular
    var n = b.length, i, j, k, p, f, x = new Array(n);
    a = a.map(function (row) { return row.slice(); }); b = b.slice();
    for (k = 0; k < n; k++) {
      p = k;
      for (i = k + 1; i < n; i++) { if (Math.abs(a[i][k]) > Math.abs(a[p][k])) { p = i; } }
      if (Math.abs(a[p][k]) < 1e-12) { return null; }
      f = a[k]; a[k] = a[p]; a[p] = f; f = b[k]; b[k] = b[p]; b[p] = f;
      for (i = k + 1; i < n; i++) {
        f = a[i][k] / a[k][k];
        for (j = k; j < n; j++) { a[i][j] -= f * a[k][j]; }
        b[i] -= f * b[k];
      }
    }
    for (i = n - 1; i >= 0; i--) {
      f = b[i];
      for (j = i + 1; j < n; j++) { f -= a[i][j] * x[j]; }
      x[i] = f / a[i][i];
    }
    return x;
  }

  function close(coordinates) {  // Newton on the passive coordinates; true when the loops close
    var iteration, r, jac, step, h = 1e-7;
    for (iteration = 0; iteration < 50; iteration++) {
      r = residual(coordinates);
      if (Math.max.apply(null, r.map(Math.abs).concat([0])) < 1e-13) { return true; }
      jac = r.map(function () { return []; });
      data.passive.forEach(function (k, column) {
        var plus = coordinates.slice(), minus = coordinates.slice(), rp, rm;
        plus[k] += h; minus[k] -= h;
        rp = residual(plus); rm = residual(minus);
        rp.forEach(function (v, row) { jac[row][column] = (v - rm[row]) / (2 * h); });
      });
      step = solveLinear(jac, r);
      if (step === null) { return false; }
      data.passive.forEach(function (k, column) { coordinates[k] -= step[column]; });
    }
    return false;
  }

  function moveTo(target) {  // continuation from the current pose in small steps keeps the assembly branch
    if (!data.passive.length) { target.forEach(function (v, k) { q[data.sliders[k].coordinate] = v; }); return true; }
    var start = data.sliders.map(function (s) { return q[s.coordinate]; });
    var span = Math.max.apply(null, target.map(function (v, k) { return Math.abs(v - start[k]); }));
    var steps = Math.max(1, Math.ceil(span / 0.02)), trial = q.slice(), n;
    for (n = 1; n <= steps; n++) {
      data.sliders.forEach(function (s, k) { trial[s.coordinate] = start[k] + (target[k] - start[k]) * n / steps; });
      if (!close(trial)) { return false; }
    }
    q = trial;
    return true;
  }

  function massCentres(poses) {
    return data.bodies.map(function (b) { return { name: b.name, m: b.m, p: apply(poses[b.frame], b.r) }; });
  }

  var centre = (function () {
    var o = origins(framePoses()), names = Object.keys(o), sum = [0, 0, 0];
    names.forEach(function (n) { for (var i = 0; i < 3; i++) { sum[i] += o[n][i] / names.length; } });
    return sum;
  })();

  function project(p) {
    var ca = Math.cos(view.az), sa = Math.sin(view.az), ce = Math.cos(view.el), se = Math.sin(view.el);
    var d = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
    var right = -sa * d[0] + ca * d[1];
    var up = -se * ca * d[0] - se * sa * d[1] + ce * d[2];
    var scale = pixelsPerMetre();
    return [canvas.width / 2 + scale * right, canvas.height / 2 - scale * up];
  }

  function pixelsPerMetre() {
    return 0.42 * Math.min(canvas.width, canvas.height) / data.extent * view.zoom;
  }

  function plate(points) {  // a rigid plate: its outline's frame origins, filled
    ctx.fillStyle = "rgba(170, 183, 196, 0.45)"; ctx.strokeStyle = "#34495e"; ctx.lineWidth = 1;
    ctx.beginPath();
    points.forEach(function (p, i) { var s = project(p); if (i === 0) { ctx.moveTo(s[0], s[1]); } else { ctx.lineTo(s[0], s[1]); } });
    ctx.closePath(); ctx.fill(); ctx.stroke();
  }

  function scaleBar() {  // a round length (data.scale, m) at the current zoom, bottom left
    var length = pixelsPerMetre() * data.scale, x = 16, y = canvas.height - 16;
    ctx.strokeStyle = "#000"; ctx.lineWidth = 3;
    ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x + length, y); ctx.stroke();
    ctx.fillStyle = "#000"; ctx.font = "12px sans-serif";
    ctx.fillText((data.scale * 1000).toPrecision(3).replace(/\.?0+$/, "") + " mm", x, y - 6);
  }

  function line(a, b, colour, width) {
    var pa = project(a), pb = project(b);
    ctx.strokeStyle = colour; ctx.lineWidth = width;
    ctx.beginPath(); ctx.moveTo(pa[0], pa[1]); ctx.lineTo(pb[0], pb[1]); ctx.stroke();
  }

  function dot(p, radius, colour) {
    var s = project(p);
    ctx.fillStyle = colour;
    ctx.beginPath(); ctx.arc(s[0], s[1], radius, 0, 2 * Math.PI); ctx.fill();
  }

  function draw() {
    var poses = framePoses(), o = origins(poses), axisLength = 0.25 * data.extent;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ["#c0392b", "#27ae60", "#2e6fd8"].forEach(function (colour, i) {
      var tip = [0, 0, 0]; tip[i] = axisLength;
      line([0, 0, 0], tip, colour, 1.5);
    });
    data.plates.forEach(function (outline) { plate(outline.map(function (name) { return o[name]; })); });
    data.links.forEach(function (pair) { line(o[pair[0]], o[pair[1]], "#34495e", 1.5); });
    data.bars.forEach(function (b) { line(o[b.frame], apply(poses[b.frame], b.end), "#2c3e50", 5); });
    data.closures.forEach(function (c) {  // loop closures: a ring where the two frames meet
      var s = project(o[c[0]]);
      ctx.strokeStyle = "#8e44ad"; ctx.lineWidth = 1.5;
      ctx.beginPath(); ctx.arc(s[0], s[1], 7, 0, 2 * Math.PI); ctx.stroke();
      line(o[c[0]], o[c[1]], "#8e44ad", 1.5);
    });
    var heaviest = Math.max.apply(null, data.bodies.map(function (b) { return b.m; }).concat([1e-12]));
    massCentres(poses).forEach(function (b) { dot(b.p, 3 + 9 * Math.sqrt(b.m / heaviest), "rgba(200, 40, 40, 0.55)"); });
    Object.keys(o).forEach(function (name) { dot(o[name], 2.5, "#7f8c8d"); });
    if (data.end_effector) { dot(o[data.end_effector], 5, "#e67e22"); }
    scaleBar();
    if (showLabels) {
      ctx.fillStyle = "#222"; ctx.font = "11px sans-serif";
      Object.keys(o).forEach(function (name) { var s = project(o[name]); ctx.fillText(name, s[0] + 4, s[1] - 4); });
    }
  }

  var controls = document.getElementById("controls");
  var status = document.createElement("p");
  status.className = "note";
  var inputs = data.sliders.map(function (s) {
    var label = document.createElement("label");
    var input = document.createElement("input");
    var output = document.createElement("output");
    label.appendChild(document.createTextNode(s.name + " [" + s.unit + "]"));
    label.appendChild(document.createElement("br"));
    input.type = "range"; input.min = s.low; input.max = s.high; input.step = "any";
    input.value = s.value; input.setAttribute("data-joint", s.index);
    output.textContent = s.value.toFixed(3);
    input.addEventListener("input", function () {
      var target = data.sliders.map(function (t) { return q[t.coordinate]; });
      target[s.index] = parseFloat(input.value);
      if (moveTo(target)) {
        status.textContent = "";
      } else {
        input.value = q[s.coordinate];
        status.textContent = "The loops cannot close there on this assembly branch; the pose stays.";
      }
      output.textContent = q[s.coordinate].toFixed(3);
      draw();
    });
    label.appendChild(input); label.appendChild(output); controls.appendChild(label);
    return input;
  });
  controls.appendChild(status);

  document.getElementById("labels").addEventListener("change", function (e) { showLabels = e.target.checked; draw(); });
  var drag = null;
  canvas.addEventListener("mousedown", function (e) { drag = [e.clientX, e.clientY]; });
  window.addEventListener("mouseup", function () { drag = null; });
  window.addEventListener("mousemove", function (e) {
    if (!drag) { return; }
    view.az -= 0.01 * (e.clientX - drag[0]);
    view.el = Math.max(-1.5, Math.min(1.5, view.el + 0.01 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY];
    draw();
  });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    view.zoom *= Math.exp(-0.001 * e.deltaY);
    draw();
  }, { passive: false });

  // A small read-only interface for tests and for the curious (browser console).
  window.deviceView = {
    pose: function () { return data.sliders.map(function (s) { return q[s.coordinate]; }); },
    fullPose: function () { return q.slice(); },
    setJoint: function (k, value) { inputs[k].value = value; inputs[k].dispatchEvent(new Event("input")); },
    frameOrigins: function () { return origins(framePoses()); },
    massCentres: function () { return massCentres(framePoses()); }
  };
  draw();
})();
