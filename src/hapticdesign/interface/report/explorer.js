// Design explorer of an optimization study's report (hapticdesign/interface/report/optimization_page.py).
// Data: JSON in #explorer-data (hapticdesign/optimization/study_explorer.py). Plots: Plotly.js from plotly.min.js
// beside the page (written there by the report); the parallel coordinates and the device pictures are canvases
// drawn here. User strings reach the page only through textContent, canvas fillText, and Plotly text escaped by
// plotlyText (Plotly reads a few tags in its text). The state (picked design, pins, filters, axes) lives in the
// address's hash, so a link reopens the same view. window.hdExplorer is the scripting and testing hook.
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("explorer-data").textContent);
  var E = data.evaluations, N = E.generation.length, MAX_PINS = 4;
  var PIN_COLOURS = ["#8e44ad", "#16a085", "#d35400", "#2c3e50"];
  var hasPlotly = typeof window.Plotly !== "undefined";
  // the records embedded (above a limit, the front and a seeded sample: data.count evaluated in all), each by its
  // evaluation number (evaluations.csv's row): ev(k) for record k, recordOf[number] back
  var recordOf = {};
  E.evaluation.forEach(function (number, k) { recordOf[number] = k; });
  function ev(k) { return E.evaluation[k]; }
  // served by `hapticdesign explore`: the card of a design off the front is computed there on demand (cards[k])
  var served = location.protocol === "http:" || location.protocol === "https:", cards = {};
  var GL_ABOVE = 2000;  // a scatter trace of more points is drawn by WebGL (scattergl)

  // ---- quantities: variables, objectives, constraints (a "result" role: a value shown, not bounded) and the
  // evaluation number, each a column over the records
  var dims = [];
  data.variables.forEach(function (v, k) {
    dims.push({ key: "var:" + v.name, name: v.name, kind: "variable", unit: v.unit || "SI", values: E.variables[k] });
  });
  data.objectives.forEach(function (o, k) {
    dims.push({ key: "obj:" + o.name, name: o.name, kind: "objective", unit: o.unit, sense: o.sense, about: o.about,
                values: E.objectives[k] });
  });
  data.constraints.forEach(function (c, k) {
    dims.push({ key: "con:" + c.name, name: c.name, kind: "constraint", role: c.role, unit: c.unit, values: E.constraints[k] });
  });
  var numbers = [];
  for (var r = 0; r < N; r++) { numbers.push(ev(r)); }
  dims.push({ key: "evaluation", name: "evaluation", kind: "evaluation", unit: "", values: numbers });
  var byKey = {};
  dims.forEach(function (d) { byKey[d.key] = d; });
  var objectiveDims = dims.filter(function (d) { return d.kind === "objective"; });
  var variableDims = dims.filter(function (d) { return d.kind === "variable"; });
  var frontOf = {};  // record index -> front design number (1-based, as front.csv)
  data.front.forEach(function (k, i) { frontOf[k] = i + 1; });
  var selectedRecord = data.front[data.selected.position];

  function label(d) {
    var unit = d.unit === "" ? "" : d.unit === "SI" ? " [device file's SI unit]" : " [" + d.unit + "]";
    return d.name + unit + (d.sense ? " (" + d.sense + "imize)" : "");
  }

  function baselineValue(d) {
    var b = data.baseline;
    if (!b) { return null; }
    if (d.kind === "variable") { return b.variables[d.name]; }
    if (d.kind === "objective") { return b.objectives[d.name]; }
    if (d.kind === "constraint") { return b.constraints[data.constraints.map(function (c) { return c.name; }).indexOf(d.name)]; }
    return null;
  }

  function finite(v) { return v !== null && v !== undefined && isFinite(v); }
  function shown(v) { return finite(v) ? Number(v).toPrecision(6).replace(/(\.\d*?)0+(e|$)/, "$1$2").replace(/\.(e|$)/, "$1") : ""; }
  function plotlyText(s) {  // Plotly reads <br>, <b>, ... in its text: escape every user string given to it
    return String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;").replace(/"/g, "&quot;").replace(/'/g, "&#39;");
  }
  function name(k) { return frontOf[k] ? "design " + frontOf[k] : "evaluation " + ev(k); }
  function element(tag, text, cls) {
    var e = document.createElement(tag);
    if (text !== undefined && text !== null) { e.textContent = text; }
    if (cls) { e.className = cls; }
    return e;
  }

  // ---- state, kept in the address's hash
  var defaults = objectiveDims.length >= 2 ? [objectiveDims[0].key, objectiveDims[1].key]
    : [variableDims[0].key, objectiveDims[0].key];
  var state = { picked: selectedRecord, pins: [], sel: null, ranges: {}, x: defaults[0], y: defaults[1] };

  function readHash() {
    var p = new URLSearchParams(location.hash.replace(/^#/, ""));
    var record = function (text) { var n = parseInt(text, 10); return String(n) === text && recordOf.hasOwnProperty(n) ? recordOf[n] : null; };
    if (p.has("pick")) { var k = record(p.get("pick")); if (k !== null) { state.picked = k; } }
    if (p.has("pins")) {
      state.pins = p.get("pins").split(",").map(record).filter(function (k, i, all) {
        return k !== null && all.indexOf(k) === i;
      }).slice(0, MAX_PINS);
    }
    ["x", "y"].forEach(function (axis) { if (byKey[p.get(axis)]) { state[axis] = p.get(axis); } });
    try {
      var sel = p.has("sel") ? JSON.parse(p.get("sel")) : null;
      if (sel && byKey[sel.x] && byKey[sel.y] && (validBox(sel.box) || validPath(sel.lasso))) { state.sel = sel; }
      var ranges = p.has("ranges") ? JSON.parse(p.get("ranges")) : {};
      Object.keys(ranges).forEach(function (key) {
        var v = ranges[key];
        if (byKey[key] && Array.isArray(v) && v.length === 2 && v.every(finite)) { state.ranges[key] = [Math.min(v[0], v[1]), Math.max(v[0], v[1])]; }
      });
    } catch (e) {
      note("The address's filters could not be read; they are left off.");
    }
  }

  function validBox(b) { return Array.isArray(b) && b.length === 4 && b.every(finite); }
  function validPath(p) {
    return Array.isArray(p) && p.length >= 3 && p.every(function (xy) { return Array.isArray(xy) && xy.length === 2 && xy.every(finite); });
  }

  function writeHash() {
    var p = new URLSearchParams();
    if (state.picked !== null) { p.set("pick", String(ev(state.picked))); }
    if (state.pins.length) { p.set("pins", state.pins.map(ev).join(",")); }
    p.set("x", state.x);
    p.set("y", state.y);
    if (state.sel) { p.set("sel", JSON.stringify(state.sel)); }
    if (Object.keys(state.ranges).length) { p.set("ranges", JSON.stringify(state.ranges)); }
    history.replaceState(null, "", "#" + p.toString());
  }

  function note(text) { document.getElementById("explorer-note").textContent = text; }

  // ---- filters: the box or lasso of a scatter plot and the ranges brushed on the parallel axes
  function insidePolygon(x, y, path) {
    var inside = false;
    for (var i = 0, j = path.length - 1; i < path.length; j = i++) {
      var xi = path[i][0], yi = path[i][1], xj = path[j][0], yj = path[j][1];
      if ((yi > y) !== (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) { inside = !inside; }
    }
    return inside;
  }

  function passes(k) {
    if (state.sel) {
      var x = byKey[state.sel.x].values[k], y = byKey[state.sel.y].values[k];
      if (!finite(x) || !finite(y)) { return false; }
      if (state.sel.box) {
        var b = state.sel.box;
        if (x < Math.min(b[0], b[1]) || x > Math.max(b[0], b[1]) || y < Math.min(b[2], b[3]) || y > Math.max(b[2], b[3])) { return false; }
      } else if (!insidePolygon(x, y, state.sel.lasso)) { return false; }
    }
    for (var key in state.ranges) {
      var v = byKey[key].values[k], range = state.ranges[key];
      if (!finite(v) || v < range[0] || v > range[1]) { return false; }
    }
    return true;
  }

  function filtering() { return state.sel !== null || Object.keys(state.ranges).length > 0; }

  // ---- the objective space (a chosen pair) and the pair plot
  function groups() {
    var out = { infeasible: [], feasible: [], front: [] };
    for (var k = 0; k < N; k++) {
      if (frontOf[k]) { out.front.push(k); } else if (E.feasible[k]) { out.feasible.push(k); } else { out.infeasible.push(k); }
    }
    return out;
  }
  var GROUPS = groups();

  function hover(k, xd, yd) {
    var head = frontOf[k] ? "front design " + frontOf[k] + " (evaluation " + ev(k) + ")" : "evaluation " + ev(k);
    var why = E.feasible[k] ? (frontOf[k] ? "" : "<br>feasible, dominated") : "<br>not feasible: " + plotlyText(E.reason[k].slice(0, 300));
    return plotlyText(head) + why + "<br>" + plotlyText(xd.name) + " = " + shown(xd.values[k]) + "<br>" +
      plotlyText(yd.name) + " = " + shown(yd.values[k]);
  }

  function pointsOf(records, xd, yd) {
    var x = [], y = [], ids = [], text = [];
    records.forEach(function (k) {
      if (finite(xd.values[k]) && finite(yd.values[k])) {
        x.push(xd.values[k]); y.push(yd.values[k]); ids.push(k); text.push(hover(k, xd, yd));
      }
    });
    return { x: x, y: y, customdata: ids, hovertext: text };
  }

  function trace(records, xd, yd, axes, name, marker, extra) {
    var p = pointsOf(records, xd, yd);
    var t = { type: p.x.length > GL_ABOVE ? "scattergl" : "scatter", mode: "markers", name: name, x: p.x, y: p.y, customdata: p.customdata,
              hovertext: p.hovertext, hoverinfo: "text", marker: marker, xaxis: axes[0], yaxis: axes[1],
              showlegend: axes[0] === "x" };
    if (filtering()) {
      t.selectedpoints = [];
      p.customdata.forEach(function (k, i) { if (passes(k)) { t.selectedpoints.push(i); } });
      t.unselected = { marker: { opacity: 0.12 } };
    }
    Object.keys(extra || {}).forEach(function (key) { t[key] = extra[key]; });
    return t;
  }

  function traces(xd, yd, axes) {
    var polished = data.front.filter(function (k) { return E.polished[k]; });
    var out = [
      trace(GROUPS.infeasible, xd, yd, axes, "not feasible (why: hover)", { symbol: "x-thin-open", size: 6, color: "#c0392b" }),
      trace(GROUPS.feasible, xd, yd, axes, "feasible, dominated", { size: 5, color: "#b0b4ba" }),
      trace(GROUPS.front, xd, yd, axes, "front", { size: 9, color: "#2e6fd8" }),
      trace([selectedRecord], xd, yd, axes, "selected (report's rule)", { symbol: "star", size: 17, color: "#e02020" })
    ];
    if (polished.length) {
      out.push(trace(polished, xd, yd, axes, "polished", { symbol: "circle-open", size: 14, color: "#27ae60", line: { width: 2 } }));
    }
    var bx = baselineValue(xd), by = baselineValue(yd);
    if (finite(bx) && finite(by)) {
      out.push({ type: "scatter", mode: "markers", name: "device file's design" + (data.baseline.feasible ? "" : " (not feasible)"),
                 x: [bx], y: [by], hoverinfo: "text", xaxis: axes[0], yaxis: axes[1], showlegend: axes[0] === "x",
                 hovertext: [plotlyText("the device file's design (" + data.device + ")")],
                 marker: { symbol: "diamond", size: 11, color: "#111" } });
    }
    state.pins.forEach(function (k, i) {
      out.push(trace([k], xd, yd, axes, "pinned: " + name(k), { symbol: "square-open", size: 16, color: PIN_COLOURS[i], line: { width: 2.5 } }));
    });
    if (state.picked !== null) {
      out.push(trace([state.picked], xd, yd, axes, "picked: " + name(state.picked), { symbol: "circle-open", size: 20, color: "#f39c12", line: { width: 3.5 } }));
    }
    return out;
  }

  function selectionShape(xref, yref) {
    if (!state.sel) { return []; }
    if (state.sel.box) {
      var b = state.sel.box;
      return [{ type: "rect", xref: xref, yref: yref, x0: b[0], x1: b[1], y0: b[2], y1: b[3] }];
    }
    return [{ type: "path", xref: xref, yref: yref,
              path: "M" + state.sel.lasso.map(function (p) { return p[0] + "," + p[1]; }).join("L") + "Z" }];
  }

  var CONFIG = { displaylogo: false, responsive: true };

  function drawSpace() {
    var xd = byKey[state.x], yd = byKey[state.y];
    var shapes = state.sel && state.sel.x === state.x && state.sel.y === state.y ? selectionShape("x", "y") : [];
    var layout = { height: 470, margin: { l: 70, r: 20, t: 30, b: 60 }, dragmode: "select", hovermode: "closest",
                   clickmode: "event", uirevision: state.x + "|" + state.y,
                   xaxis: { title: { text: plotlyText(label(xd)) }, zeroline: false },
                   yaxis: { title: { text: plotlyText(label(yd)) }, zeroline: false },
                   legend: { orientation: "h", y: -0.2 }, selections: [], shapes: shapes.map(outline) };
    Plotly.react("objective-space", traces(xd, yd, ["x", "y"]), layout, CONFIG);
  }

  function outline(shape) {  // the filter's region, drawn (the region itself is the state: box or lasso in data units)
    shape.line = { color: "#e0a800", width: 2, dash: "dot" };
    shape.fillcolor = "rgba(255, 200, 0, 0.08)";
    shape.layer = "below";
    return shape;
  }

  function pairs() {  // pairs of the pair plot: every pair of objectives (3 or more), an objective against each variable (1)
    var out = [];
    if (objectiveDims.length >= 3) {
      for (var i = 0; i < objectiveDims.length; i++) {
        for (var j = i + 1; j < objectiveDims.length; j++) { out.push([objectiveDims[i], objectiveDims[j]]); }
      }
    } else if (objectiveDims.length === 1) {
      variableDims.forEach(function (v) { out.push([v, objectiveDims[0]]); });
    }
    return out;
  }
  var PAIRS = pairs();

  function drawPairs() {
    if (!PAIRS.length) { return; }
    var columns = Math.min(3, PAIRS.length), rows = Math.ceil(PAIRS.length / columns), gap = 0.08;
    var layout = { height: 320 * rows, margin: { l: 60, r: 20, t: 20, b: 50 }, dragmode: "select", hovermode: "closest",
                   clickmode: "event", showlegend: false, uirevision: "pairs", selections: [], shapes: [] };
    var all = [];
    PAIRS.forEach(function (pair, p) {
      var c = p % columns, r = Math.floor(p / columns), n = p === 0 ? "" : String(p + 1);
      var width = (1 - gap * (columns - 1)) / columns, height = (1 - gap * (rows - 1)) / rows;
      layout["xaxis" + n] = { domain: [c * (width + gap), c * (width + gap) + width], anchor: "y" + n, zeroline: false,
                              title: { text: plotlyText(label(pair[0])), font: { size: 11 } } };
      layout["yaxis" + n] = { domain: [1 - r * (height + gap) - height, 1 - r * (height + gap)], anchor: "x" + n, zeroline: false,
                              title: { text: plotlyText(label(pair[1])), font: { size: 11 } } };
      all = all.concat(traces(pair[0], pair[1], ["x" + n, "y" + n]));
      if (state.sel && state.sel.x === pair[0].key && state.sel.y === pair[1].key) {
        layout.shapes = layout.shapes.concat(selectionShape("x" + n, "y" + n).map(outline));
      }
    });
    Plotly.react("pairs", all, layout, CONFIG);
  }

  function onSelected(plot, dimsOf) {
    plot.on("plotly_selected", function (event) {
      if (!event) { return; }
      var region = event.range || event.lassoPoints;
      if (!region) { return; }
      var xs = Object.keys(region).filter(function (a) { return a.charAt(0) === "x"; })[0];
      var ys = Object.keys(region).filter(function (a) { return a.charAt(0) === "y"; })[0];
      var pair = dimsOf(xs);
      if (event.range) {
        state.sel = { x: pair[0].key, y: pair[1].key, box: [region[xs][0], region[xs][1], region[ys][0], region[ys][1]] };
      } else {
        state.sel = { x: pair[0].key, y: pair[1].key, lasso: region[xs].map(function (x, i) { return [x, region[ys][i]]; }) };
      }
      update(false);
    });
    plot.on("plotly_deselect", function () { state.sel = null; update(false); });
    plot.on("plotly_click", function (event) {
      var point = event && event.points && event.points[0];
      if (point && typeof point.customdata === "number") { pick(point.customdata); }
    });
  }

  // ---- parallel coordinates: a canvas of its own, so that lines can be picked and axes brushed
  var parallel = (function () {
    var canvas = document.getElementById("parallel"), ctx = canvas.getContext("2d"), tip = document.getElementById("parallel-tip");
    var axes = dims.filter(function (d) { return d.kind !== "evaluation"; });
    var drawn = [];  // the records drawn: feasible, with every quantity
    for (var k = 0; k < N; k++) {
      if (E.feasible[k] && axes.every(function (d) { return finite(d.values[k]); })) { drawn.push(k); }
    }
    drawn.sort(function (a, b) { return (frontOf[a] ? 1 : 0) - (frontOf[b] ? 1 : 0); });  // the front on top
    var M = { left: 60, right: 60, top: 78, bottom: 26 };
    var spans = axes.map(function (d) {
      var values = drawn.map(function (k) { return d.values[k]; });
      var low = Math.min.apply(null, values), high = Math.max.apply(null, values);
      if (!(high > low)) { var pad = Math.abs(low) * 0.05 || 1; low -= pad; high += pad; }
      return [low, high];
    });
    var brushing = null, press = null, hovered = null;

    function axisX(i) { return M.left + (axes.length === 1 ? 0 : i * (canvas.width - M.left - M.right) / (axes.length - 1)); }
    function toY(i, v) { return canvas.height - M.bottom - (v - spans[i][0]) / (spans[i][1] - spans[i][0]) * (canvas.height - M.top - M.bottom); }
    function toValue(i, y) { return spans[i][0] + (canvas.height - M.bottom - y) / (canvas.height - M.top - M.bottom) * (spans[i][1] - spans[i][0]); }

    var layer = document.createElement("canvas"), drawnAt = {};  // the lines, drawn once per change of the filters
    drawn.forEach(function (k, i) { drawnAt[k] = i; });

    function polyline(k, colour, width, where) {
      var c = where || ctx;
      c.strokeStyle = colour; c.lineWidth = width;
      c.beginPath();
      axes.forEach(function (d, i) { var x = axisX(i), y = toY(i, d.values[k]); if (i === 0) { c.moveTo(x, y); } else { c.lineTo(x, y); } });
      c.stroke();
    }

    function draw() {  // every line into the layer, then the rest (overlay): a brush or a hover redraws only the rest
      canvas.width = layer.width = Math.max(600, canvas.parentNode.clientWidth - 4);
      layer.height = canvas.height;
      var lines = layer.getContext("2d"), filter = filtering();
      drawn.forEach(function (k) {
        var on = !filter || passes(k);
        var colour = frontOf[k] ? (on ? "rgba(46, 111, 216, 0.75)" : "rgba(46, 111, 216, 0.12)")
          : (on ? "rgba(120, 125, 135, 0.35)" : "rgba(120, 125, 135, 0.06)");
        polyline(k, colour, frontOf[k] ? 1.4 : 1, lines);
      });
      overlay();
    }

    function overlay() {
      ctx.clearRect(0, 0, canvas.width, canvas.height);
      ctx.drawImage(layer, 0, 0);
      state.pins.forEach(function (k, i) { if (drawnAt.hasOwnProperty(k)) { polyline(k, PIN_COLOURS[i], 2.5); } });
      if (state.picked !== null && drawnAt.hasOwnProperty(state.picked)) { polyline(state.picked, "#f39c12", 3.5); }
      if (hovered !== null) { polyline(hovered, "#111", 2); }
      ctx.font = "11px sans-serif";
      axes.forEach(function (d, i) {
        var x = axisX(i), range = state.ranges[d.key] || null;
        if (brushing && brushing.axis === i && brushing.y1 !== undefined) {
          range = [toValue(i, Math.max(brushing.y0, brushing.y1)), toValue(i, Math.min(brushing.y0, brushing.y1))];
        }
        if (range) {
          ctx.fillStyle = "rgba(255, 200, 0, 0.35)";
          var y0 = toY(i, Math.min(range[1], spans[i][1])), y1 = toY(i, Math.max(range[0], spans[i][0]));
          ctx.fillRect(x - 8, y0, 16, Math.max(1, y1 - y0));
        }
        ctx.strokeStyle = "#333"; ctx.lineWidth = 1;
        ctx.beginPath(); ctx.moveTo(x, M.top); ctx.lineTo(x, canvas.height - M.bottom); ctx.stroke();
        ctx.fillStyle = "#333"; ctx.textAlign = "center";
        ctx.fillText(shown(spans[i][1]), x, M.top - 4);
        ctx.fillText(shown(spans[i][0]), x, canvas.height - M.bottom + 13);
        ctx.save(); ctx.translate(x, M.top - 16); ctx.rotate(-0.45); ctx.textAlign = "left";
        ctx.fillStyle = d.kind === "objective" ? "#1b4f9c" : d.kind === "constraint" ? "#7a4b00" : "#222";
        var text = d.name + (d.unit && d.unit !== "SI" && d.unit !== "-" ? " [" + d.unit + "]" : "");
        ctx.fillText(text.length > 28 ? text.slice(0, 27) + "\u2026" : text, 0, 0);
        ctx.restore();
      });
    }

    function nearest(mx, my) {  // the drawn line closest to (mx, my) between two axes, within 8 px
      var best = null, distance = 8;
      for (var i = 0; i + 1 < axes.length; i++) {
        var a = axisX(i), b = axisX(i + 1);
        if (mx < a || mx > b) { continue; }
        var t = (mx - a) / (b - a);
        drawn.forEach(function (k) {
          if (filtering() && !passes(k)) { return; }
          var y = (1 - t) * toY(i, axes[i].values[k]) + t * toY(i + 1, axes[i + 1].values[k]);
          if (Math.abs(y - my) <= distance) { distance = Math.abs(y - my); best = k; }
        });
      }
      return best;
    }

    function at(event) {
      var box = canvas.getBoundingClientRect();
      return [(event.clientX - box.left) * canvas.width / box.width, (event.clientY - box.top) * canvas.height / box.height];
    }

    function axisAt(mx, my) {
      for (var i = 0; i < axes.length; i++) {
        if (Math.abs(mx - axisX(i)) <= 10 && my >= M.top - 6 && my <= canvas.height - M.bottom + 6) { return i; }
      }
      return null;
    }

    canvas.addEventListener("mousedown", function (event) {
      var p = at(event), axis = axisAt(p[0], p[1]);
      if (axis !== null) { brushing = { axis: axis, y0: p[1] }; } else { press = p; }
      event.preventDefault();
    });
    window.addEventListener("mousemove", function (event) {
      var p = at(event);
      if (brushing) { brushing.y1 = p[1]; overlay(); return; }
      if (event.target !== canvas) { return; }
      var k = nearest(p[0], p[1]);
      if (k !== hovered) { hovered = k; overlay(); }
      if (k === null) { tip.hidden = true; return; }
      tip.hidden = false;
      tip.textContent = name(k) + (frontOf[k] ? "" : " (feasible, dominated)") + ": click to pick";
      tip.style.left = (event.pageX + 12) + "px";
      tip.style.top = (event.pageY + 12) + "px";
    });
    canvas.addEventListener("mouseleave", function () { tip.hidden = true; if (hovered !== null) { hovered = null; overlay(); } });
    window.addEventListener("mouseup", function (event) {
      var p = at(event);
      if (brushing) {
        var i = brushing.axis, key = axes[i].key;
        if (brushing.y1 === undefined || Math.abs(brushing.y1 - brushing.y0) < 3) {
          delete state.ranges[key];
        } else {
          state.ranges[key] = [toValue(i, Math.max(brushing.y0, brushing.y1)), toValue(i, Math.min(brushing.y0, brushing.y1))];
        }
        brushing = null;
        update(false);
        return;
      }
      if (press && Math.abs(p[0] - press[0]) < 4 && Math.abs(p[1] - press[1]) < 4) {
        var k = nearest(p[0], p[1]);
        if (k !== null) { pick(k); }
      }
      press = null;
    });
    return {
      draw: draw,
      line: function (k) {  // the line of record k as canvas pixels per axis (the hook's view of the drawing)
        return !drawnAt.hasOwnProperty(k) ? null : axes.map(function (d, i) { return [axisX(i), toY(i, d.values[k])]; });
      }
    };
  })();

  // ---- a still picture of a design (the skeleton of `show`, at one pose), turned by dragging
  function pictureExtent(picture) {  // the largest side of the box holding the picture's points [m]
    var all = Object.keys(picture.origins).map(function (n) { return picture.origins[n]; });
    picture.bars.forEach(function (b) { all.push(b[1]); });
    picture.masses.forEach(function (m) { all.push(m.p); });
    return Math.max.apply(null, [0, 1, 2].map(function (i) {
      return Math.max.apply(null, all.map(function (p) { return p[i]; })) - Math.min.apply(null, all.map(function (p) { return p[i]; }));
    }).concat([1e-3]));
  }

  function devicePicture(canvas, picture, common) {  // common: the extent [m] shared by pictures shown side by side
    var ctx = canvas.getContext("2d"), view = { az: -0.9, el: 0.45 };
    var names = Object.keys(picture.origins), all = names.map(function (n) { return picture.origins[n]; });
    picture.bars.forEach(function (b) { all.push(b[1]); });
    picture.masses.forEach(function (m) { all.push(m.p); });
    var low = [0, 1, 2].map(function (i) { return Math.min.apply(null, all.map(function (p) { return p[i]; })); });
    var high = [0, 1, 2].map(function (i) { return Math.max.apply(null, all.map(function (p) { return p[i]; })); });
    var centre = [0, 1, 2].map(function (i) { return 0.5 * (low[i] + high[i]); });
    var extent = common || pictureExtent(picture);
    function project(p) {
      var ca = Math.cos(view.az), sa = Math.sin(view.az), ce = Math.cos(view.el), se = Math.sin(view.el);
      var d = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]], s = 0.8 * Math.min(canvas.width, canvas.height) / extent;
      return [canvas.width / 2 + s * (-sa * d[0] + ca * d[1]), canvas.height / 2 - s * (-se * ca * d[0] - se * sa * d[1] + ce * d[2])];
    }
    function line(a, b, colour, width) {
      var pa = project(a), pb = project(b);
      ctx.strokeStyle = colour; ctx.lineWidth = width;
      ctx.beginPath(); ctx.moveTo(pa[0], pa[1]); ctx.lineTo(pb[0], pb[1]); ctx.stroke();
    }
    function dot(p, radius, colour) {
      var s = project(p);
      ctx.fillStyle = colour; ctx.beginPath(); ctx.arc(s[0], s[1], radius, 0, 2 * Math.PI); ctx.fill();
    }
    function draw() {
      var o = picture.origins;
      ctx.clearRect(0, 0, canvas.width, canvas.height);
      ["#c0392b", "#27ae60", "#2e6fd8"].forEach(function (colour, i) { var tip = [0, 0, 0]; tip[i] = 0.2 * extent; line([0, 0, 0], tip, colour, 1.5); });
      picture.plates.forEach(function (names) {
        ctx.fillStyle = "rgba(170, 183, 196, 0.45)"; ctx.strokeStyle = "#34495e"; ctx.lineWidth = 1;
        ctx.beginPath();
        names.forEach(function (n, i) { var s = project(o[n]); if (i === 0) { ctx.moveTo(s[0], s[1]); } else { ctx.lineTo(s[0], s[1]); } });
        ctx.closePath(); ctx.fill(); ctx.stroke();
      });
      picture.links.forEach(function (pair) { line(o[pair[0]], o[pair[1]], "#34495e", 1.5); });
      picture.bars.forEach(function (b) { line(b[0], b[1], "#2c3e50", 5); });
      var heaviest = Math.max.apply(null, picture.masses.map(function (m) { return m.m; }).concat([1e-12]));
      picture.masses.forEach(function (m) { dot(m.p, 3 + 9 * Math.sqrt(m.m / heaviest), "rgba(200, 40, 40, 0.55)"); });
      names.forEach(function (n) { dot(o[n], 2.5, "#7f8c8d"); });
      if (picture.end_effector && o[picture.end_effector]) { dot(o[picture.end_effector], 5, "#e67e22"); }
      var length = 0.8 * Math.min(canvas.width, canvas.height) / extent * picture.scale;
      ctx.strokeStyle = "#000"; ctx.lineWidth = 3;
      ctx.beginPath(); ctx.moveTo(12, canvas.height - 12); ctx.lineTo(12 + length, canvas.height - 12); ctx.stroke();
      ctx.fillStyle = "#000"; ctx.font = "11px sans-serif"; ctx.textAlign = "left";
      ctx.fillText(String(+(picture.scale * 1000).toPrecision(3)) + " mm", 12, canvas.height - 18);
    }
    var drag = null;
    canvas.addEventListener("mousedown", function (e) { drag = [e.clientX, e.clientY]; e.preventDefault(); });
    window.addEventListener("mouseup", function () { drag = null; });
    window.addEventListener("mousemove", function (e) {
      if (!drag) { return; }
      view.az -= 0.01 * (e.clientX - drag[0]);
      view.el = Math.max(-1.5, Math.min(1.5, view.el + 0.01 * (e.clientY - drag[1])));
      drag = [e.clientX, e.clientY];
      draw();
    });
    draw();
  }

  // ---- the design card
  var failures = {}, deviceUrl = null;  // why the server could not compute a card; the computed device file's address
  function detailOf(k) { return frontOf[k] ? data.designs[frontOf[k] - 1] : cards[k] || null; }

  function fetchCard(k) {  // the card of record k off the front, computed by `hapticdesign explore` (cards[k]; null: failed)
    cards[k] = undefined;
    fetch("api/card?evaluation=" + ev(k)).then(function (response) {
      return response.json().then(function (body) { return response.ok ? body : Promise.reject(body.error); });
    }).then(function (card) { cards[k] = card; }, function (why) { cards[k] = null; failures[k] = String(why); })
      .then(function () { if (state.picked === k) { drawCard(); } if (state.pins.indexOf(k) >= 0) { drawCompare(); } });
  }

  function numberCell(kind, nameText, value) {
    var td = element("td", shown(value));
    td.setAttribute("data-kind", kind);
    td.setAttribute("data-name", nameText);
    td.setAttribute("data-value", finite(value) ? String(value) : "");
    return td;
  }

  function specTable(rows) {  // the spec summary at home (hapticdesign spec's numbers), data-kind "spec"
    var wrap = element("div", null, "table-wrap"), table = element("table");
    table.id = "card-spec";
    table.appendChild(element("caption", "Its spec summary at home (hapticdesign spec; blank: the device file lacks what it needs)"));
    var head = element("tr");
    ["quantity", "spec.json", "value", "unit"].forEach(function (h) { head.appendChild(element("th", h)); });
    table.appendChild(head);
    rows.forEach(function (r) {
      var tr = element("tr");
      tr.appendChild(element("td", r.label, "text"));
      tr.appendChild(element("td", r.name, "text"));
      tr.appendChild(numberCell("spec", r.name, r.value));
      tr.appendChild(element("td", r.unit, "text"));
      table.appendChild(tr);
    });
    wrap.appendChild(table);
    return wrap;
  }

  function quantities(k) {  // [kind, name, value, unit] of record k: variables, objectives, constrained values
    return dims.filter(function (d) { return d.kind !== "evaluation"; }).map(function (d) {
      return [d.role || d.kind, d.name, d.values[k], d.unit === "SI" ? "SI" : d.unit];
    });
  }

  function mapPlot(div, map, points) {
    var varying = [0, 1, 2].filter(function (i) {
      return Math.max.apply(null, points.map(function (p) { return p[i]; })) > Math.min.apply(null, points.map(function (p) { return p[i]; }));
    });
    var unique = function (i) { return points.map(function (p) { return p[i]; }).filter(function (v, j, a) { return a.indexOf(v) === j; }).sort(function (a, b) { return a - b; }); };
    var axisName = function (i) { return "xyz".charAt(i) + " [mm]"; };
    var marks = map.reductions.filter(function (r) { return r.at !== null; });
    var tracesOut = [], layout = { height: 260, margin: { l: 55, r: 10, t: 28, b: 45 }, showlegend: false,
                                   title: { text: plotlyText(map.name + " [" + map.unit + "]"), font: { size: 12 } } };
    if (varying.length <= 1) {
      var i = varying.length ? varying[0] : 0;
      tracesOut.push({ type: "scatter", mode: "lines+markers", x: points.map(function (p) { return 1000 * p[i]; }), y: map.values });
      marks.forEach(function (r) {
        tracesOut.push({ type: "scatter", mode: "markers", x: [1000 * points[r.at][i]], y: [map.values[r.at]], hoverinfo: "text",
                         hovertext: [plotlyText(r.name + ": the " + r.how + ", " + shown(r.value))],
                         marker: { symbol: "circle-open", size: 14, color: "#e02020", line: { width: 2 } } });
      });
      layout.xaxis = { title: { text: axisName(i) } };
    } else {
      var a = varying[0], b = varying[1], slices = varying.length === 3 ? unique(varying[2]) : [null];
      var xs = unique(a), ys = unique(b), gap = 0.04, width = (1 - gap * (slices.length - 1)) / slices.length;
      slices.forEach(function (level, s) {
        var z = ys.map(function () { return xs.map(function () { return null; }); });
        points.forEach(function (p, j) {
          if (level === null || p[varying[2]] === level) { z[ys.indexOf(p[b])][xs.indexOf(p[a])] = map.values[j]; }
        });
        var n = s === 0 ? "" : String(s + 1);
        tracesOut.push({ type: "heatmap", x: xs.map(function (v) { return 1000 * v; }), y: ys.map(function (v) { return 1000 * v; }), z: z,
                         colorscale: "Viridis", xaxis: "x" + n, yaxis: "y" + n, coloraxis: "coloraxis",
                         hovertemplate: "%{x:.4g}, %{y:.4g} mm: %{z:.6g}<extra></extra>" });
        marks.forEach(function (r) {
          var p = points[r.at];
          if (level !== null && p[varying[2]] !== level) { return; }
          tracesOut.push({ type: "scatter", mode: "markers", x: [1000 * p[a]], y: [1000 * p[b]], xaxis: "x" + n, yaxis: "y" + n,
                           hoverinfo: "text", hovertext: [plotlyText(r.name + ": the " + r.how + ", " + shown(r.value))],
                           marker: { symbol: "circle-open", size: 16, color: "#e02020", line: { width: 3 } } });
        });
        layout["xaxis" + n] = { domain: [s * (width + gap), s * (width + gap) + width], anchor: "y" + n,
                                title: { text: axisName(a) + (level === null ? "" : ", " + "xyz".charAt(varying[2]) + " = " + shown(1000 * level) + " mm"), font: { size: 10 } } };
        layout["yaxis" + n] = { anchor: "x" + n, title: { text: s === 0 ? axisName(b) : "" }, scaleanchor: "x" + n };
      });
      layout.coloraxis = { colorscale: "Viridis", colorbar: { thickness: 10 } };
      layout.width = Math.min(900, 170 + 260 * slices.length);
    }
    Plotly.newPlot(div, tracesOut, layout, { displayModeBar: false, responsive: false });
  }

  function drawCard() {
    var card = document.getElementById("design-card"), k = state.picked;
    card.textContent = "";
    if (k === null) { card.appendChild(element("p", "Pick a design: click a point or a line.", "note")); return; }
    var n = frontOf[k];
    card.setAttribute("data-design", n ? String(n) : "");
    card.setAttribute("data-evaluation", String(ev(k)));
    card.appendChild(element("h3", n ? "Front design " + n + " (evaluation " + ev(k) + ", generation " + E.generation[k] + ")"
      + (k === selectedRecord ? ": the selected design" : "") : "Evaluation " + ev(k) + " (generation " + E.generation[k] + ")"));
    var status = E.feasible[k] ? (n ? (E.polished[k] ? "On the front, polished by the local search." : "On the front.")
      : "Feasible, but dominated by a front design.") : "Not feasible: " + E.reason[k];
    card.appendChild(element("p", status));
    var pin = element("button", state.pins.indexOf(k) >= 0 ? "Unpin" : "Pin for comparison");
    pin.id = "pin-button";
    pin.addEventListener("click", function () { if (state.pins.indexOf(k) >= 0) { unpin(k); } else { pinRecord(k); } });
    card.appendChild(pin);
    var row = element("div", null, "card-row");
    var table = element("table");
    table.appendChild(element("caption", n ? "Its numbers (" + (data.front_file || "front.csv") + ", row " + n + ")" : (data.evaluations_file ? "Its numbers (" + data.evaluations_file + ", row " + ev(k) + ")" : "Its numbers (design " + ev(k) + " of this page)")));
    var head = element("tr");
    ["quantity", "kind", "value", "unit"].forEach(function (h) { head.appendChild(element("th", h)); });
    table.appendChild(head);
    quantities(k).forEach(function (q) {
      var tr = element("tr");
      tr.appendChild(element("td", q[1], "text"));
      tr.appendChild(element("td", q[0], "text"));
      tr.appendChild(numberCell(q[0], q[1], q[2]));
      tr.appendChild(element("td", q[3] === "SI" ? "device file's" : q[3], "text"));
      table.appendChild(tr);
    });
    var wrap = element("div", null, "table-wrap");
    wrap.appendChild(table);
    row.appendChild(wrap);
    var detail = detailOf(k);
    if (!detail && served && !cards.hasOwnProperty(k)) { fetchCard(k); }
    if (detail && detail.picture) {
      var figure = element("figure");
      var canvas = element("canvas");
      canvas.width = 380; canvas.height = 320; canvas.id = "card-picture";
      figure.appendChild(canvas);
      figure.appendChild(element("figcaption", "The design " + detail.picture.where + " (drag to turn): links, bodies as bars, mass centres in red (area ~ mass), the end effector in orange."));
      row.appendChild(figure);
      devicePicture(canvas, detail.picture);
    }
    card.appendChild(row);
    if (detail && detail.spec) { card.appendChild(specTable(detail.spec)); }
    if (!detail) {
      card.appendChild(element("p", !served ? (data.evaluations_file ? "The maps, the picture and a device file are written for the front's designs; this one's numbers are " + data.evaluations_file + "'s (hapticdesign explore, serving this folder, computes any design's card)."
          : "The picture and the commands are shown for the front's designs; this one has its numbers only.")
        : cards[k] === undefined ? "Its maps and picture are being computed (hapticdesign explore)\u2026"
        : "hapticdesign explore could not compute its card: " + failures[k], "note"));
      return;
    }
    var names = Object.keys(detail.maps);
    if (names.length && hasPlotly) {
      card.appendChild(element("h4", "The study's indices over its " + data.workspace.coarseness + " (the reduced values circled where they are taken)"));
      var maps = element("div", null, "maps");
      card.appendChild(maps);
      names.forEach(function (m) {
        var box = element("div", null, "map"), div = element("div");
        box.setAttribute("data-map", m);
        box.appendChild(div);
        maps.appendChild(box);
        mapPlot(div, { name: m, unit: detail.maps[m].unit, values: detail.maps[m].values, reductions: detail.maps[m].reductions },
                data.workspace.points);
        detail.maps[m].reductions.forEach(function (r) {
          var where = r.at === null ? " (no one point holds it)" : " at (" + data.workspace.points[r.at].map(function (v) { return shown(1000 * v); }).join(", ") + ") mm, circled";
          box.appendChild(element("p", r.name + " = the " + r.how + " = " + shown(r.value) + " " + detail.maps[m].unit + where, "note"));
        });
      });
    }
    card.appendChild(element("h4", "To reproduce it (in the output folder)"));
    if (detail.file) {
      var link = element("p");
      link.appendChild(document.createTextNode("Its device file: "));
      var a = element("a", detail.file);
      if (detail.text === undefined) { a.href = detail.file; } else {  // computed on demand: not in the folder, saved from here
        if (deviceUrl) { URL.revokeObjectURL(deviceUrl); }
        a.href = deviceUrl = URL.createObjectURL(new Blob([detail.text], { type: "text/yaml" }));
        a.download = detail.file;
        link.appendChild(document.createTextNode("(not in the folder: save it from here) "));
      }
      link.appendChild(a);
      card.appendChild(link);
    }
    var pre = element("pre");
    pre.id = "card-commands";
    pre.textContent = detail.commands.map(function (c) { return "# " + c.what + "\n" + c.command; }).join("\n");
    card.appendChild(pre);
  }

  // ---- compare: up to four pinned designs side by side
  function drawCompare() {
    var box = document.getElementById("compare");
    box.textContent = "";
    if (!state.pins.length) { box.appendChild(element("p", "Pin up to four designs (the card's button) to compare them here.", "note")); return; }
    var table = element("table"), head = element("tr");
    table.appendChild(element("caption", "Pinned designs side by side: rows that differ shaded, the best of each objective in bold; the pictures at one scale"));
    head.appendChild(element("th", "quantity"));
    state.pins.forEach(function (k, i) { var th = element("th", name(k)); th.style.color = PIN_COLOURS[i]; head.appendChild(th); });
    table.appendChild(head);
    dims.filter(function (d) { return d.kind !== "evaluation"; }).forEach(function (d) {
      var tr = element("tr"), values = state.pins.map(function (k) { return d.values[k]; });
      tr.appendChild(element("td", d.name + (d.unit && d.unit !== "SI" ? " [" + d.unit + "]" : ""), "text"));
      var finiteValues = values.filter(finite);
      if (finiteValues.some(function (v) { return v !== finiteValues[0]; }) || finiteValues.length !== values.length) { tr.className = "differs"; }
      var best = d.sense === "min" ? Math.min.apply(null, finiteValues) : d.sense === "max" ? Math.max.apply(null, finiteValues) : null;
      values.forEach(function (v) {
        var td = numberCell(d.role || d.kind, d.name, v);
        if (best !== null && v === best && state.pins.length > 1) { td.className = "best"; }
        tr.appendChild(td);
      });
      table.appendChild(tr);
    });
    var wrap = element("div", null, "table-wrap");
    wrap.appendChild(table);
    box.appendChild(wrap);
    var row = element("div", null, "card-row"), pictures = state.pins.map(function (k) {
      return detailOf(k) && detailOf(k).picture;
    }).filter(Boolean);
    var common = pictures.length ? Math.max.apply(null, pictures.map(pictureExtent)) : null;
    state.pins.forEach(function (k, i) {
      var figure = element("figure", null, "pinned");
      if (frontOf[k]) { figure.setAttribute("data-design", String(frontOf[k])); } else { figure.setAttribute("data-evaluation", String(ev(k))); }
      var detail = detailOf(k);
      if (detail && detail.picture) {
        var canvas = element("canvas");
        canvas.width = 240; canvas.height = 210;
        figure.appendChild(canvas);
        devicePicture(canvas, detail.picture, common);
      }
      var caption = element("figcaption", name(k) + " ");
      caption.style.color = PIN_COLOURS[i];
      var button = element("button", "unpin");
      button.addEventListener("click", function () { unpin(k); });
      caption.appendChild(button);
      figure.appendChild(caption);
      row.appendChild(figure);
    });
    box.appendChild(row);
  }

  // ---- actions
  function status() {
    var passing = 0, front = 0;
    for (var k = 0; k < N; k++) { if (passes(k)) { passing++; if (frontOf[k]) { front++; } } }
    var of = N === data.count ? " evaluated designs" : " designs shown (of " + data.count + " evaluated)";
    var text = filtering() ? passing + " of " + N + of + " pass the filters (" + front + " of the front's " + data.front.length + ")"
      : "No filter: " + N + of + ", " + data.front.length + " on the front. Drag a box or lasso on a plot, or along a parallel axis, to filter.";
    document.getElementById("filter-status").textContent = text;
    document.getElementById("clear-filters").disabled = !filtering();
  }

  function update(card) {
    if (hasPlotly) { drawSpace(); drawPairs(); }
    parallel.draw();
    if (card) { drawCard(); }
    drawCompare();
    status();
    writeHash();
  }

  function pick(k) { state.picked = k; update(true); }
  function pinRecord(k) {
    if (state.pins.indexOf(k) >= 0) { return true; }
    if (state.pins.length >= MAX_PINS) { note("Four designs are pinned: unpin one first."); return false; }
    state.pins.push(k);
    update(true);
    return true;
  }
  function unpin(k) { state.pins = state.pins.filter(function (p) { return p !== k; }); update(true); }

  function frontRecord(n) {
    if (!(n >= 1 && n <= data.front.length && Math.floor(n) === n)) { throw new RangeError("the front has designs 1 to " + data.front.length + ", not " + n); }
    return data.front[n - 1];
  }

  function design(n) {
    var k = frontRecord(n), detail = data.designs[n - 1], out = { design: n, evaluation: ev(k), variables: {}, objectives: {}, constraints: {} };
    dims.forEach(function (d) {
      if (d.kind === "variable") { out.variables[d.name] = d.values[k]; }
      if (d.kind === "objective") { out.objectives[d.name] = d.values[k]; }
      if (d.kind === "constraint") { out.constraints[d.name] = d.values[k]; }
    });
    out.polished = E.polished[k];
    out.file = detail.file;
    out.commands = detail.commands;
    out.picture = detail.picture;
    out.spec = detail.spec || null;
    out.maps = {};
    Object.keys(detail.maps).forEach(function (m) {
      out.maps[m] = { points: data.workspace.points, values: detail.maps[m].values, unit: detail.maps[m].unit,
                      index: detail.maps[m].index, reductions: detail.maps[m].reductions };
    });
    return out;
  }

  function designOf(k) { return k === null ? null : frontOf[k] || null; }

  // ---- the page's controls
  function axisSelect(id, axis) {
    var select = document.getElementById(id);
    dims.forEach(function (d) {
      var option = element("option", label(d));
      option.value = d.key;
      select.appendChild(option);
    });
    select.value = state[axis];
    select.addEventListener("change", function () { state[axis] = select.value; update(false); });
  }

  readHash();
  axisSelect("x-axis", "x");
  axisSelect("y-axis", "y");
  document.getElementById("clear-filters").addEventListener("click", function () { state.sel = null; state.ranges = {}; update(false); });
  Array.prototype.forEach.call(document.querySelectorAll("#front-table tbody tr"), function (tr, i) {
    tr.title = "pick design " + (i + 1);
    tr.addEventListener("click", function () { pick(data.front[i]); });
  });
  if (hasPlotly) {
    drawSpace();
    onSelected(document.getElementById("objective-space"), function () { return [byKey[state.x], byKey[state.y]]; });
    if (PAIRS.length) {
      drawPairs();
      onSelected(document.getElementById("pairs"), function (axis) { return PAIRS[(parseInt(axis.slice(1), 10) || 1) - 1]; });
    }
  } else {
    note("plotly.min.js, written beside this page, did not load: the plots are missing (the parallel coordinates, the cards and the tables work).");
  }
  update(true);

  window.hdExplorer = {
    design: design,
    select: function (n) { pick(frontRecord(n)); },
    pin: function (n) { return pinRecord(frontRecord(n)); },
    unpin: function (n) { unpin(frontRecord(n)); },
    filter: function (key, low, high) {
      if (!byKey[key]) { throw new RangeError("no quantity " + key); }
      if (low === null || low === undefined) { delete state.ranges[key]; } else { state.ranges[key] = [Math.min(low, high), Math.max(low, high)]; }
      update(false);
    },
    state: function () {
      var passing = [];
      for (var k = 0; k < N; k++) { if (passes(k)) { passing.push(ev(k)); } }
      return { selected: designOf(state.picked), evaluation: state.picked === null ? null : ev(state.picked),
               pins: state.pins.map(designOf), pinnedEvaluations: state.pins.map(ev),
               x: state.x, y: state.y, selection: state.sel, ranges: state.ranges, passing: passing };
    },
    parallelLine: function (n) { return parallel.line(frontRecord(n)); }
  };
})();
