// cadmorph report viewer: a small hand-written WebGL 1 viewer, inlined into every report.
// It draws the faces (before/after), the control nets, the FFD lattice (original and
// moved) and the seam edges coloured by gap or G1 angle on a log scale; drag to turn,
// shift-drag or right-drag to pan, wheel to zoom; hover or click a seam edge for its
// numbers. No network: everything it needs is in the page.
(function () {
  "use strict";
  var data = JSON.parse(document.getElementById("cadmorph-data").textContent);
  var canvas = document.getElementById("view");
  var info = document.getElementById("edge-info");
  var gl = canvas.getContext("webgl", { antialias: false, preserveDrawingBuffer: true });
  if (!gl) {
    document.documentElement.classList.add("no-webgl");
    return;
  }
  document.documentElement.classList.add("webgl");

  function b64(s, Type) {
    var bin = atob(s), n = bin.length, bytes = new Uint8Array(n);
    for (var i = 0; i < n; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }

  // Colour scale, as crates/report/src/colour.rs.
  var GOOD = [20, 170, 60], MID = [240, 200, 20], BAD = [230, 20, 20];
  function position(scale, v) {
    if (v !== v || v === null) return 1;
    if (v <= scale.good) return 0;
    var lo = Math.log10(scale.good), hi = Math.log10(scale.bad);
    return Math.min(1, Math.max(0, (Math.log10(v) - lo) / (hi - lo)));
  }
  function ramp(t) {
    var a = t < 0.5 ? GOOD : MID, b = t < 0.5 ? MID : BAD, s = t < 0.5 ? t * 2 : t * 2 - 1;
    return [0, 1, 2].map(function (i) { return Math.round(a[i] + (b[i] - a[i]) * s); });
  }

  function compile(vs, fs) {
    function sh(type, src) {
      var s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    }
    var p = gl.createProgram();
    gl.attachShader(p, sh(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, sh(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  var faceProg = compile(
    "attribute vec3 p; attribute vec3 n; uniform mat4 m; uniform vec3 eye; varying float l;" +
      "void main(){ gl_Position = m * vec4(p, 1.0); l = 0.3 + 0.7 * abs(dot(normalize(n + vec3(1e-9)), eye)); }",
    "precision mediump float; uniform vec3 c; varying float l; void main(){ gl_FragColor = vec4(c * l, 1.0); }"
  );
  var lineProg = compile(
    "attribute vec3 p; attribute vec3 c; uniform mat4 m; uniform vec2 off; varying vec3 vc;" +
      "void main(){ vec4 q = m * vec4(p, 1.0); q.xy += off * q.w; q.z -= 0.004 * q.w; gl_Position = q; vc = c; }",
    "precision mediump float; varying vec3 vc; void main(){ gl_FragColor = vec4(vc, 1.0); }"
  );
  var uintOk = !!gl.getExtension("OES_element_index_uint");

  var centre = data.centre; // face positions in the data are relative to it
  var radius = Math.max(data.size / 2, 1e-30);
  function buffer(arr, target) {
    var b = gl.createBuffer();
    gl.bindBuffer(target || gl.ARRAY_BUFFER, b);
    gl.bufferData(target || gl.ARRAY_BUFFER, arr, gl.STATIC_DRAW);
    return b;
  }
  function lineObject(pos, col) {
    return { pos: buffer(pos), col: buffer(col), count: pos.length / 3 };
  }
  function segments(points, pairs, colour) {
    var pos = new Float32Array(pairs.length * 6), col = new Float32Array(pairs.length * 6);
    pairs.forEach(function (pr, i) {
      for (var e = 0; e < 2; e++)
        for (var k = 0; k < 3; k++) {
          pos[i * 6 + e * 3 + k] = points[pr[e] * 3 + k] - centre[k];
          col[i * 6 + e * 3 + k] = colour[k] / 255;
        }
    });
    return lineObject(pos, col);
  }

  var FACE_COLOURS = data.faceColours;
  var states = data.states.map(function (st) {
    var faces = st.faces.map(function (f, fi) {
      var pos = b64(f.pos, Float32Array), nrm = b64(f.nrm, Float32Array), idx = b64(f.idx, Uint32Array);
      var small = !uintOk;
      return {
        name: f.name,
        pos: buffer(pos),
        nrm: buffer(nrm),
        idx: buffer(small ? new Uint16Array(idx) : idx, gl.ELEMENT_ARRAY_BUFFER),
        count: idx.length,
        small: small,
        colour: FACE_COLOURS[fi % FACE_COLOURS.length],
      };
    });
    var netPairs = [], netPts = [];
    st.faces.forEach(function (f) {
      var base = netPts.length / 3, nu = f.net.nu, nv = f.net.nv;
      Array.prototype.push.apply(netPts, f.net.pts);
      for (var i = 0; i < nu; i++)
        for (var j = 0; j < nv; j++) {
          if (j + 1 < nv) netPairs.push([base + i * nv + j, base + i * nv + j + 1]);
          if (i + 1 < nu) netPairs.push([base + i * nv + j, base + (i + 1) * nv + j]);
        }
    });
    return {
      name: st.name,
      faces: faces,
      net: segments(netPts, netPairs, data.netColour),
      seams: st.seams,
      seamObj: null,
    };
  });
  var lattice = null;
  if (data.lattice) {
    var L = data.lattice, pairs = [];
    for (var i = 0; i < L.lines.length; i += 2) pairs.push([L.lines[i], L.lines[i + 1]]);
    lattice = {
      original: segments(L.original, pairs, data.latticeColours[0]),
      moved: segments(L.moved, pairs, data.latticeColours[1]),
    };
  }

  function seamObject(st, by) {
    var pos = [], col = [];
    st.seams.forEach(function (s) {
      var vals = by === "angle" ? s.angle : s.gap, scale = by === "angle" ? data.angleScale : data.gapScale;
      for (var i = 0; i + 1 < s.pts.length / 3; i++) {
        var c = ramp(position(scale, vals[i]));
        for (var e = 0; e < 2; e++) {
          for (var k = 0; k < 3; k++) {
            pos.push(s.pts[(i + e) * 3 + k] - centre[k]);
            col.push(c[k] / 255);
          }
        }
      }
    });
    return lineObject(new Float32Array(pos), new Float32Array(col));
  }

  // Camera: orthographic, turned about the model's centre.
  var cam = { az: data.camera.az, el: data.camera.el, zoom: 1, pan: [0, 0] };
  function basis() {
    var ca = Math.cos(cam.az), sa = Math.sin(cam.az), ce = Math.cos(cam.el), se = Math.sin(cam.el);
    var back = [ca * ce, sa * ce, se];
    var right = [-sa, ca, 0];
    var up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0]];
    return { back: back, right: right, up: up };
  }
  function matrix() {
    var b = basis(), w = canvas.width, h = canvas.height, aspect = w / h;
    var s = 1 / (radius * 1.05 / cam.zoom), sx = s / Math.max(aspect, 1), sy = s * Math.min(aspect, 1);
    var sz = 1 / (radius * 4);
    // Column-major 4x4: clip = M * (p - centre).
    return new Float32Array([
      b.right[0] * sx, b.up[0] * sy, -b.back[0] * sz, 0,
      b.right[1] * sx, b.up[1] * sy, -b.back[1] * sz, 0,
      b.right[2] * sx, b.up[2] * sy, -b.back[2] * sz, 0,
      cam.pan[0], cam.pan[1], 0, 1,
    ]);
  }
  function project(p, m) {
    m = m || matrix();
    var q = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
    var x = m[0] * q[0] + m[4] * q[1] + m[8] * q[2] + m[12];
    var y = m[1] * q[0] + m[5] * q[1] + m[9] * q[2] + m[13];
    var r = canvas.getBoundingClientRect();
    return [(x + 1) / 2 * r.width, (1 - y) / 2 * r.height];
  }

  var layers = {};
  function checked(id) {
    var el = document.getElementById(id);
    return !!(el && el.checked);
  }
  function colourBy() {
    return checked("colour-angle") ? "angle" : "gap";
  }

  function drawLines(o, m, thick) {
    if (!o || o.count === 0) return;
    gl.useProgram(lineProg);
    gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, "m"), false, m);
    var pl = gl.getAttribLocation(lineProg, "p"), cl = gl.getAttribLocation(lineProg, "c");
    gl.bindBuffer(gl.ARRAY_BUFFER, o.pos);
    gl.enableVertexAttribArray(pl);
    gl.vertexAttribPointer(pl, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, o.col);
    gl.enableVertexAttribArray(cl);
    gl.vertexAttribPointer(cl, 3, gl.FLOAT, false, 0, 0);
    var off = gl.getUniformLocation(lineProg, "off"), r = thick ? 1 : 0;
    for (var dx = -r; dx <= r; dx++)
      for (var dy = -r; dy <= r; dy++) {
        gl.uniform2f(off, (2 * dx) / canvas.width, (2 * dy) / canvas.height);
        gl.drawArrays(gl.LINES, 0, o.count);
      }
    gl.disableVertexAttribArray(cl);
  }

  function draw() {
    var m = matrix(), b = basis();
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    states.forEach(function (st) {
      if (!checked("layer-" + st.name)) return;
      gl.useProgram(faceProg);
      gl.uniformMatrix4fv(gl.getUniformLocation(faceProg, "m"), false, m);
      gl.uniform3fv(gl.getUniformLocation(faceProg, "eye"), b.back);
      var pl = gl.getAttribLocation(faceProg, "p"), nl = gl.getAttribLocation(faceProg, "n");
      st.faces.forEach(function (f) {
        gl.uniform3fv(gl.getUniformLocation(faceProg, "c"), f.colour.map(function (v) { return v / 255; }));
        gl.bindBuffer(gl.ARRAY_BUFFER, f.pos);
        gl.enableVertexAttribArray(pl);
        gl.vertexAttribPointer(pl, 3, gl.FLOAT, false, 0, 0);
        gl.bindBuffer(gl.ARRAY_BUFFER, f.nrm);
        gl.enableVertexAttribArray(nl);
        gl.vertexAttribPointer(nl, 3, gl.FLOAT, false, 0, 0);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, f.idx);
        gl.drawElements(gl.TRIANGLES, f.count, f.small ? gl.UNSIGNED_SHORT : gl.UNSIGNED_INT, 0);
      });
      gl.disableVertexAttribArray(nl);
      if (checked("layer-net")) drawLines(st.net, m, false);
    });
    if (lattice && checked("layer-lattice")) drawLines(lattice.original, m, false);
    if (lattice && checked("layer-lattice-moved")) drawLines(lattice.moved, m, false);
    if (checked("layer-seams")) {
      var st = shownState();
      if (!st.seamObj || st.seamBy !== colourBy()) {
        st.seamObj = seamObject(st, colourBy());
        st.seamBy = colourBy();
      }
      drawLines(st.seamObj, m, true);
    }
    drawLegend();
  }

  function shownState() {
    var after = states.filter(function (s) { return s.name === "after"; })[0];
    return after && checked("layer-after") ? after : states[0];
  }

  function fmt(v) {
    return v === null || v === undefined ? "–" : Number(v).toExponential(3);
  }
  function drawLegend() {
    var c = document.getElementById("legend");
    if (!c) return;
    var x = c.getContext("2d"), w = c.width, h = c.height, by = colourBy();
    var scale = by === "angle" ? data.angleScale : data.gapScale;
    x.clearRect(0, 0, w, h);
    for (var i = 0; i < w; i++) {
      var col = ramp(i / (w - 1));
      x.fillStyle = "rgb(" + col.join(",") + ")";
      x.fillRect(i, 0, 1, h / 2);
    }
    x.fillStyle = "#000";
    x.font = "11px sans-serif";
    var unit = by === "angle" ? "°" : " " + data.unit;
    x.textAlign = "left";
    x.fillText("≤ " + fmt(scale.good) + unit, 2, h - 4);
    x.textAlign = "center";
    x.fillText(fmt(Math.sqrt(scale.good * scale.bad)) + " (tol)", w / 2, h - 4);
    x.textAlign = "right";
    x.fillText("≥ " + fmt(scale.bad) + unit, w - 2, h - 4);
    document.getElementById("legend-title").textContent =
      (by === "angle" ? "G1 angle" : "C0 gap") + ", log scale";
  }

  function nearestSeam(mx, my) {
    var st = shownState(), m = matrix(), best = null;
    st.seams.forEach(function (s, si) {
      var n = s.pts.length / 3, prev = null;
      for (var i = 0; i < n; i++) {
        var q = project([s.pts[i * 3], s.pts[i * 3 + 1], s.pts[i * 3 + 2]], m);
        if (prev) {
          var dx = q[0] - prev[0], dy = q[1] - prev[1], len2 = dx * dx + dy * dy;
          var t = len2 > 0 ? Math.max(0, Math.min(1, ((mx - prev[0]) * dx + (my - prev[1]) * dy) / len2)) : 0;
          var ex = prev[0] + t * dx - mx, ey = prev[1] + t * dy - my, d = Math.sqrt(ex * ex + ey * ey);
          if (!best || d < best.d) best = { d: d, seam: s, index: si, vertex: t < 0.5 ? i - 1 : i };
        }
        prev = q;
      }
    });
    return best && best.d <= 8 ? best : null;
  }
  var pinned = null;
  function showEdge(hit) {
    if (!hit) {
      info.textContent = "Hover or click a seam edge for its numbers.";
      return;
    }
    var s = hit.seam, r = s.report, u = data.unit;
    info.innerHTML = "";
    var rows = [
      ["edge", "#" + hit.index + (s.edge.length ? " (" + s.edge.join(", ") + ")" : "")],
      ["joins", s.faces[0] + " and " + s.faces[1]],
      ["length", fmt(r.length) + " " + u],
      ["gap (closest), max / mean", fmt(r.gap_closest.max) + " / " + fmt(r.gap_closest.mean) + " " + u],
      ["gap max at", r.gap_closest.at.map(function (v) { return v.toFixed(4); }).join(", ")],
      ["gap (matched), max", fmt(r.gap_matched.max) + " " + u],
      ["G1 angle, max / mean", fmt(r.g1_angle_deg.max) + " / " + fmt(r.g1_angle_deg.mean) + " °"],
      ["here: gap / angle", fmt(s.gap[hit.vertex]) + " " + u + " / " + fmt(s.angle[hit.vertex]) + " °"],
      ["sharp (crease)", r.sharp ? "yes" : "no"],
    ];
    var t = document.createElement("table");
    rows.forEach(function (row) {
      var tr = document.createElement("tr");
      row.forEach(function (c, i) {
        var td = document.createElement(i ? "td" : "th");
        td.textContent = c;
        tr.appendChild(td);
      });
      t.appendChild(tr);
    });
    info.appendChild(t);
  }

  var drag = null;
  canvas.addEventListener("mousedown", function (e) {
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2, moved: false };
  });
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  window.addEventListener("mouseup", function (e) {
    if (drag && !drag.moved) {
      var r = canvas.getBoundingClientRect();
      pinned = nearestSeam(e.clientX - r.left, e.clientY - r.top);
      showEdge(pinned);
    }
    drag = null;
  });
  window.addEventListener("mousemove", function (e) {
    var r = canvas.getBoundingClientRect();
    if (drag) {
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
      if (drag.pan) {
        cam.pan[0] += (2 * dx) / r.width;
        cam.pan[1] -= (2 * dy) / r.height;
      } else {
        cam.az -= dx * 0.01;
        cam.el = Math.max(-1.55, Math.min(1.55, cam.el + dy * 0.01));
      }
      drag.x = e.clientX;
      drag.y = e.clientY;
      draw();
    } else if (!pinned && e.target === canvas) {
      showEdge(nearestSeam(e.clientX - r.left, e.clientY - r.top));
    }
  });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    cam.zoom *= Math.exp(-e.deltaY * 0.001);
    draw();
  }, { passive: false });
  Array.prototype.forEach.call(document.querySelectorAll(".layers input"), function (el) {
    el.addEventListener("change", function () {
      draw();
    });
  });
  document.getElementById("reset-view").addEventListener("click", function () {
    cam = { az: data.camera.az, el: data.camera.el, zoom: 1, pan: [0, 0] };
    draw();
  });

  showEdge(null);
  draw();
  window.cadmorph = {
    /** CSS pixel position inside the canvas of model point p. */
    project: function (p) { return project(p); },
    redraw: draw,
    ready: true,
  };
})();
