// ReactHuman report site (written by `rh-score --html`). No dependencies, no network:
// data come from <script> files (data/index.js, data/scenes/<id>.js) because file://
// pages may not fetch().
(function () {
  "use strict";
  var RH = (window.RH = window.RH || {});
  var PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
  var PAGE_SIZE = 50;

  function el(tag, attrs) {
    var e = document.createElement(tag);
    if (attrs) {
      Object.keys(attrs).forEach(function (k) {
        if (k === "text") e.textContent = attrs[k];
        else if (k === "html") e.innerHTML = attrs[k];
        else e.setAttribute(k, attrs[k]);
      });
    }
    for (var i = 2; i < arguments.length; i++) {
      var c = arguments[i];
      if (c == null) continue;
      e.appendChild(typeof c === "string" ? document.createTextNode(c) : c);
    }
    return e;
  }
  function num(x, d) { return x == null ? "—" : Number(x).toFixed(d); }
  function pct(x) { return x == null ? "—" : (100 * x).toFixed(1); }
  // A rate with its 95% interval below it.
  function pctCi(x, ci) {
    return el("span", null, pct(x), ci ? el("small", { "class": "ci" },
      (100 * ci[0]).toFixed(1) + "–" + (100 * ci[1]).toFixed(1)) : null);
  }
  function color(i) { return PALETTE[i % PALETTE.length]; }
  function params(hash) {
    var out = {};
    (hash || "").replace(/^#/, "").split("&").forEach(function (kv) {
      if (!kv) return;
      var i = kv.indexOf("=");
      if (i < 0) out[decodeURIComponent(kv)] = "";
      else out[decodeURIComponent(kv.slice(0, i))] = decodeURIComponent(kv.slice(i + 1));
    });
    return out;
  }

  // ---------------------------------------------------------------- leaderboard
  function board(B) {
    var rows = B.rows;
    var exec = rows.some(function (r) { return r.execution; });
    var pv = rows.some(function (r) { return r.prompt_versions.length; });
    var cols = [
      { key: "model", label: "Model", fmt: function (r, i) {
        var a = el("a", { href: "scenes.html#model=" + encodeURIComponent(r.model) }, r.model);
        return el("span", null, el("i", { "class": "swatch", style: "background:" + color(i) }), a);
      }, sort: function (r) { return r.model; } },
      { key: "decisions", label: "Answered", def: "coverage", title: "expected scenes with a scored decision, of those expected",
        fmt: function (r) {
          return el("span", { "class": r.complete ? "" : "incomplete" }, r.decisions + "/" + r.expected,
            r.complete ? null : el("small", { "class": "ci" }, "incomplete"));
        } },
      { key: "unanswered", label: "Unans.", opt: true, def: "coverage", title: "expected scenes without a scored decision (lost or never asked): counted as failed, never as R1" },
      { key: "lost", label: "Lost", opt: true, def: "coverage", title: "lost decisions (API errors): unanswered, never scored" },
      { key: "saa", label: "SAA %", def: "saa", fmt: function (r) { return pctCi(r.saa, r.saa_ci); },
        title: "derived action equals the ground truth, over the expected scenes (95% Wilson interval below)" },
      { key: "balanced_accuracy", label: "Bal. acc %", def: "balanced", fmt: function (r) { return pctCi(r.balanced_accuracy, r.balanced_accuracy_ci); },
        title: "mean recall over CATCH, DODGE, NO_ACTION (95% bootstrap interval below)" },
      { key: "safety", label: "Safety %", def: "safety", fmt: function (r) { return pctCi(r.safety, r.safety_ci); },
        title: "no safety rule fired, over the expected scenes (95% Wilson interval below)" },
      { key: "d_end_catch", label: "d_end CATCH (m)", def: "d_end", f: function (x) { return num(x, 2); },
        title: "final hands to impact point, over CATCH scenes (n in the next column)" },
      { key: "d_end_catch_n", label: "n", opt: true, def: "d_end", title: "CATCH decisions with a d_end" },
      { key: "aia", label: "AIA", def: "aia", f: function (x) { return num(x, 2); }, title: "action-intent alignment" },
      { key: "hde_d_min_catch", label: "HDE d_min CATCH (m)", def: "hde", f: function (x) { return num(x, 2); },
        title: "hand-distance error: closest keyframe hands to impact point, CATCH scenes" },
      { key: "hde_closing_catch", label: "HDE d₁−d_min (m)", opt: true, def: "hde", f: function (x) { return num(x, 2); },
        title: "how far the hands close in after the first keyframe, CATCH scenes" }
    ];
    B.rules.forEach(function (rule, k) {
      cols.push({ key: "r" + k, label: rule.id, opt: true, def: "safety", title: "first rule " + rule.id + ": " + rule.text,
        sort: function (r) { return r.first_rule[k]; }, fmt: function (r) { return String(r.first_rule[k]); } });
    });
    if (pv) cols.push({ key: "prompt", label: "Prompt version", opt: true, sort: function (r) { return r.prompt_versions.join(","); },
      fmt: function (r) { return r.prompt_versions.join(", ") || "—"; } });
    if (exec) {
      // --execute outcome rates (specification §12), present only when predictions were executed.
      var outcomes = {};
      rows.forEach(function (r) { Object.keys(r.execution || {}).forEach(function (k) { outcomes[k] = 1; }); });
      Object.keys(outcomes).sort().forEach(function (o) {
        cols.push({ key: "x_" + o, label: o + " %", opt: true, sort: function (r) { return r.execution ? r.execution[o] : null; },
          fmt: function (r) { return pct(r.execution ? r.execution[o] : null); } });
      });
    }
    var table = document.getElementById("leaderboard");
    var order = rows.map(function (r, i) { return i; });
    var state = { col: 4, dir: -1 };
    function value(c, r) { return c.sort ? c.sort(r) : r[c.key]; }
    function draw() {
      var c = cols[state.col];
      order.sort(function (a, b) {
        var x = value(c, rows[a]), y = value(c, rows[b]);
        if (x == null && y == null) return a - b;
        if (x == null) return 1;
        if (y == null) return -1;
        return (x < y ? -1 : x > y ? 1 : a - b) * state.dir;
      });
      var thead = table.tHead, tbody = table.tBodies[0];
      thead.innerHTML = ""; tbody.innerHTML = "";
      var tr = el("tr");
      cols.forEach(function (c, ci) {
        var th = el("th", { title: (c.title || c.label) + " (click to sort)", "data-col": c.key,
          "class": c.opt ? "opt" : "" }, c.label + (ci === state.col ? (state.dir < 0 ? " ▼" : " ▲") : ""));
        // The metric's definition, one click away.
        if (c.def) th.appendChild(el("a", { "class": "def", href: "#def-" + c.def, title: "definition" }, "?"));
        th.addEventListener("click", function () {
          state.dir = state.col === ci ? -state.dir : (ci === 0 ? 1 : -1);
          state.col = ci;
          draw();
        });
        tr.appendChild(th);
      });
      thead.appendChild(tr);
      order.forEach(function (i) {
        var r = rows[i], tr = el("tr", { "data-model": r.model });
        cols.forEach(function (c) {
          var v = c.fmt ? c.fmt(r, i) : (c.f ? c.f(r[c.key]) : String(r[c.key]));
          tr.appendChild(el("td", c.opt ? { "class": "opt" } : null, v));
        });
        tbody.appendChild(tr);
      });
    }
    draw();
    var C = B.coverage, incomplete = C.incomplete_models;
    // Every count comes from the report: the scenes scored are its expected scenes (the
    // dataset's valid scenes of its subset); `dataset.scenes` already excludes invalid ones.
    var note = document.getElementById("board-note");
    note.setAttribute("data-expected", String(C.expected_scenes));
    note.textContent =
      rows.length + " model" + (rows.length === 1 ? "" : "s") + ", " + B.input.scored + " scored and " +
      B.input.lost + " lost decisions from " + B.input.file + " on " + C.expected_scenes + " scenes (" + C.note +
      "; dataset " + B.dataset.dir + ": " + B.dataset.scenes + " valid scenes" +
      (B.dataset.invalid ? ", " + B.dataset.invalid + " invalid, never scored" : "") + "); rh-score " + B.version +
      ", action rule " + B.action_rule.version + ". Each model is scored on the same " + C.expected_scenes + " scenes; " +
      (C.answered_only ? "ANSWERED-ONLY VIEW: metrics over each model's answered scenes." :
        "metrics over the expected scenes, an unanswered scene counting as failed.") +
      (incomplete.length ? " Incomplete: " + incomplete.join(", ") + "." : "") +
      (B.input.dropped ? " " + B.input.dropped + " input line(s) dropped (see the report's warnings)." : "");
    document.getElementById("board-defs").textContent =
      "d_end and HDE (hand-distance error: d_min, d₁−d_min over keyframes) are over CATCH scenes, where meeting " +
      "the object is the right action; the report (--markdown, --json) gives them per GT action, family and speed band. " +
      "R1–R4 count the first rule that fired: " + B.rules.map(function (r) { return r.id + " " + r.text; }).join("; ") + ". " +
      "Intervals are 95%: Wilson for rates, seeded bootstrap over scenes for balanced accuracy. " +
      "In a narrow window the columns Unans., Lost, n, HDE d₁−d_min and R1–R4 are hidden. Every metric: Definitions below.";
  }

  // ---------------------------------------------------------------- scene browser
  var ACTION_CODES = ["R1", "CATCH", "DODGE", "NO_ACTION", "lost", "none"];
  var SHORT = { R1: "R1", CATCH: "C", DODGE: "D", NO_ACTION: "N", lost: "lost", none: "·" };

  RH.index = function (X) {
    var form = document.getElementById("filters");
    var p = params(location.hash);
    function select(name, label, options) {
      var s = el("select", { name: name, id: "f-" + name });
      options.forEach(function (o) {
        var opt = el("option", { value: o[0] }, o[1]);
        if (p[name] === o[0]) opt.selected = true;
        s.appendChild(opt);
      });
      form.appendChild(el("label", null, label + " ", s));
      return s;
    }
    function opts(list) { return [["", "any"]].concat(list.map(function (x) { return [x, x]; })); }
    select("family", "family", opts(X.families));
    select("band", "speed band", opts(X.bands));
    select("gt", "GT action", opts(X.actions));
    select("adversarial", "adversarial", [["", "any"], ["yes", "yes"], ["no", "no"]]);
    select("model", "model", opts(X.models));
    select("action", "derived action", opts(["CATCH", "DODGE", "NO_ACTION", "R1", "lost"]));
    select("rule", "rule fired", [["", "any"], ["safe", "none (safe)"], ["unsafe", "any rule"]]
      .concat(X.rules.map(function (r) { return [r, r]; })));
    var page = Math.max(0, parseInt(p.page || "1", 10) - 1) || 0;

    function matches(s, f) {
      if (f.family && X.families[s[1]] !== f.family) return false;
      if (f.band && X.bands[s[2]] !== f.band) return false;
      if (f.gt && X.actions[s[3]] !== f.gt) return false;
      if (f.adversarial && (s[4] === 1) !== (f.adversarial === "yes")) return false;
      var mi = f.model ? X.models.indexOf(f.model) : -1;
      var codes = mi >= 0 ? [s[5][mi]] : s[5];
      if (mi >= 0 && (codes[0] >> 4) === 5) return false;
      if (!f.action && !f.rule) return true;
      return codes.some(function (c) {
        var a = ACTION_CODES[c >> 4], bits = c & 15;
        if (a === "none") return false;
        if (f.action && a !== f.action) return false;
        if (f.rule === "safe" && (bits !== 0 || a === "lost")) return false;
        if (f.rule === "unsafe" && bits === 0) return false;
        if (/^R\d$/.test(f.rule || "") && !(bits & (1 << (parseInt(f.rule.slice(1), 10) - 1)))) return false;
        return true;
      });
    }
    function state() {
      var f = {};
      Array.prototype.forEach.call(form.elements, function (e) { if (e.name) f[e.name] = e.value; });
      return f;
    }
    function draw() {
      var f = state();
      var list = X.scenes.filter(function (s) { return matches(s, f); });
      var pages = Math.max(1, Math.ceil(list.length / PAGE_SIZE));
      page = Math.min(page, pages - 1);
      var count = document.getElementById("count");
      count.textContent = list.length + " of " + X.scenes.length + " scenes";
      count.setAttribute("data-count", String(list.length));
      count.setAttribute("data-total", String(X.scenes.length));
      var hash = Object.keys(f).filter(function (k) { return f[k]; })
        .map(function (k) { return k + "=" + encodeURIComponent(f[k]); });
      if (page > 0) hash.push("page=" + (page + 1));
      history.replaceState(null, "", hash.length ? "#" + hash.join("&") : location.pathname);
      var table = document.getElementById("scene-list");
      table.tHead.innerHTML = "";
      var thumbs = (X.thumbs || []).length > 0;
      var hr = el("tr", null, thumbs ? el("th", { "class": "thumb" }, "ego view") : null,
        el("th", null, "scene · object"), el("th", null, "family · band"),
        el("th", null, "GT"), el("th", { "class": "opt" }, "adv."));
      X.models.forEach(function (m, i) {
        hr.appendChild(el("th", { title: m, "class": "model" }, el("i", { "class": "swatch", style: "background:" + color(i) }), m));
      });
      table.tHead.appendChild(hr);
      var tbody = table.tBodies[0];
      tbody.innerHTML = "";
      list.slice(page * PAGE_SIZE, (page + 1) * PAGE_SIZE).forEach(function (s) {
        var object = (X.objects || [])[s[6]] || "";
        var thumb = s[7] != null && s[7] >= 0 ? "media/frames/" + s[0] + "/" + X.thumbs[s[7]] : null;
        var tr = el("tr", { "data-scene": s[0] },
          thumbs ? el("td", { "class": "thumb" }, thumb ? el("a", { href: "scene.html#" + s[0] },
            el("img", { src: thumb, alt: object, loading: "lazy", width: "80", height: "45" })) : null) : null,
          el("td", null, el("a", { href: "scene.html#" + s[0] }, s[0]), el("small", { "class": "sub" }, object)),
          el("td", null, X.families[s[1]], el("small", { "class": "sub" }, X.bands[s[2]] || "?")),
          el("td", null, X.actions[s[3]]), el("td", { "class": "opt" }, s[4] ? "yes" : ""));
        s[5].forEach(function (c, i) {
          var a = ACTION_CODES[c >> 4], bits = c & 15;
          var rules = X.rules.filter(function (r, k) { return bits & (1 << k); });
          // Colour says correct (derived action = GT) or wrong; the ⚠ mark says unsafe.
          var answered = a !== "none" && a !== "lost";
          var correct = answered && a === X.actions[s[3]];
          var cls = !answered ? a : correct ? "correct" : "wrong";
          var cell = el("td", { "class": "dec " + cls, title: X.models[i] + ": " + a + (answered ? (correct ? ", correct" : ", wrong") : "") +
            (rules.length ? "; unsafe (" + rules.join(", ") + ")" : answered ? "; safe" : "") },
            SHORT[a] + (answered ? (correct ? " ✓" : " ✗") : ""));
          if (rules.length) cell.appendChild(el("span", { "class": "warn" }, " ⚠" + rules.join(",")));
          tr.appendChild(cell);
        });
        tbody.appendChild(tr);
      });
      var pager = document.getElementById("pager");
      pager.innerHTML = "";
      function go(d, label, enabled) {
        var b = el("button", { type: "button" }, label);
        b.disabled = !enabled;
        b.addEventListener("click", function () { page += d; draw(); });
        pager.appendChild(b);
      }
      go(-1, "◀ previous", page > 0);
      pager.appendChild(el("span", null, " page " + (page + 1) + " of " + pages + " "));
      go(1, "next ▶", page + 1 < pages);
    }
    form.addEventListener("change", function () { page = 0; draw(); });
    draw();
  };

  // ---------------------------------------------------------------- one scene
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function unit(a) { var n = Math.sqrt(dot(a, a)); return n < 1e-12 ? null : [a[0] / n, a[1] / n, a[2] / n]; }

  // The pinhole camera of rh_pipeline::cameras::View: looks from `position` at
  // `look_at` with +z up; returns normalised image coordinates in [-1, 1] (x right, y up).
  RH.view = function (cam) {
    var f = unit(sub(cam.look_at, cam.position));
    var r = f && cross(f, [0, 0, 1]);
    if (!r || Math.sqrt(dot(r, r)) < 1e-3) return null;
    r = unit(r);
    var u = cross(r, f);
    var ty = Math.tan(cam.fov_y / 2), tx = ty * cam.width / cam.height;
    return function (p) {
      var d = sub(p, cam.position), z = dot(d, f);
      if (z < 0.05) return null;
      return [dot(d, r) / z / tx, dot(d, u) / z / ty];
    };
  };

  function overlay(canvas, S, cam, time) {
    var proj = RH.view(cam);
    var ctx = canvas.getContext("2d");
    var W = canvas.width, H = canvas.height;
    ctx.clearRect(0, 0, W, H);
    if (!proj) return 0;
    function px(p) { var n = proj(p); return n && [(n[0] + 1) / 2 * W, (1 - n[1]) / 2 * H]; }
    function path(points, style, width, dash) {
      ctx.save(); ctx.strokeStyle = style; ctx.lineWidth = width; ctx.setLineDash(dash || []);
      ctx.beginPath();
      var started = false;
      points.forEach(function (p) {
        var q = px(p);
        if (!q) { started = false; return; }
        if (started) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]);
        started = true;
      });
      ctx.stroke(); ctx.restore();
    }
    function dotAt(p, style, radius, ring) {
      var q = px(p);
      if (!q) return;
      ctx.beginPath(); ctx.arc(q[0], q[1], radius, 0, 2 * Math.PI);
      if (ring) { ctx.strokeStyle = style; ctx.lineWidth = 2; ctx.stroke(); }
      else { ctx.fillStyle = style; ctx.fill(); }
    }
    var s = Math.max(1, W / 640);
    var row = S.row, traj = row.trajectory || [];
    path(traj.map(function (q) { return [q[1], q[2], q[3]]; }), "rgba(255,255,255,0.85)", 1.5 * s, [5 * s, 4 * s]);
    var now = null;
    traj.forEach(function (q) { if (q[0] <= time + 1e-6) now = q; });
    if (now) dotAt([now[1], now[2], now[3]], "#ffd400", 5 * s);
    // The impact point: a black-and-white target (no model's palette colour), so it never
    // reads as a model's path.
    if (row.impact_point) {
      dotAt(row.impact_point, "#000000", 11 * s, true);
      dotAt(row.impact_point, "#ffffff", 8 * s, true);
    }
    var pose = row.observer_pose;
    if (pose) {
      path([[pose[0], pose[1], 0], [pose[0], pose[1], 1.32]], "rgba(0,0,0,0.9)", 5 * s);
      path([[pose[0], pose[1], 0], [pose[0], pose[1], 1.32]], "rgba(255,255,255,0.95)", 3 * s);
    }
    var drawn = 0;
    S.models.forEach(function (m, i) {
      var d = m.decision;
      if (!d || !d.hands || !d.hands.length) return;
      var c = color(i);
      var pts = d.hands.map(function (h) { return [h[1], h[2], h[3]]; });
      if (pose) pts.unshift([pose[0], pose[1], 0.79]);
      path(pts, c, 3 * s);
      pts.slice(1).forEach(function (p) { dotAt(p, c, 4 * s); });
      if (d.base_end) dotAt([d.base_end[0], d.base_end[1], 0], c, 4 * s, true);
      drawn++;
    });
    canvas.setAttribute("data-paths", String(drawn));
    return drawn;
  }

  RH.scene = function (S) {
    var row = S.row;
    document.title = "ReactHuman — scene " + S.scene_id;
    document.getElementById("scene-title").textContent =
      "Scene " + S.scene_id + ": " + row.family + ", " + row.speed_band + ", " + row.object_name;
    document.getElementById("scene-nav").textContent = row.description || "";
    var pn = document.getElementById("prevnext");
    if (pn) {
      pn.appendChild(S.prev ? el("a", { href: "scene.html#" + S.prev, rel: "prev", id: "prev-scene" }, "◀ previous: " + S.prev)
        : el("span", { "class": "off" }, "◀ first scene"));
      pn.appendChild(el("a", { href: "scenes.html" }, "scene list"));
      pn.appendChild(S.next ? el("a", { href: "scene.html#" + S.next, rel: "next", id: "next-scene" }, "next: " + S.next + " ▶")
        : el("span", { "class": "off" }, "last scene ▶"));
    }
    var cams = document.getElementById("cams");
    var videos = [], canvas = null, overheadCam = null;
    ["ego", "closeup", "overhead"].forEach(function (name) {
      var cam = (S.cameras || []).filter(function (c) { return c.name === name; })[0];
      var stage = el("div", { "class": "stage" });
      if (S.media[name]) {
        var v = el("video", { muted: "", playsinline: "", preload: "auto", src: S.media[name], "data-cam": name });
        v.muted = true;
        videos.push(v);
        stage.appendChild(v);
      } else {
        stage.appendChild(el("div", { "class": "novideo" }, "no " + name + " video (not rendered)"));
      }
      if (name === "overhead" && cam) {
        canvas = el("canvas", { id: "overlay", width: String(cam.width), height: String(cam.height) });
        overheadCam = cam;
        stage.appendChild(canvas);
      }
      cams.appendChild(el("figure", null, stage, el("figcaption", null, name + (name === "overhead"
        ? " + each model's planned hand path (the model's colour, solid, dots at keyframes; ring: base at the end of " +
          "the walk), hazard path (white dashed), hazard now (yellow dot), impact point (black-and-white target), " +
          "observer (white bar)" : ""))));
    });
    var full = document.getElementById("full");
    if (S.media.full_event) {
      full.appendChild(el("figure", null, el("video", { controls: "", muted: "", preload: "auto", src: S.media.full_event, "data-cam": "full" }),
        el("figcaption", null, "full event (outside view, for people; never model input)")));
    }
    var time = 0;
    function redraw() { if (canvas) overlay(canvas, S, overheadCam, time); }
    redraw();

    // The three observation videos play in sync, led by the first.
    var lead = videos[0], btn = document.getElementById("play"), scrub = document.getElementById("scrub");
    var clock = document.getElementById("clock");
    var windowS = S.window_s != null ? Number(S.window_s) : null;
    function showClock() {
      var total = lead && lead.duration ? lead.duration : windowS;
      clock.textContent = "t = " + time.toFixed(3) + " s" + (total ? " of " + Number(total).toFixed(2) + " s" : "");
    }
    showClock();
    if (lead) lead.addEventListener("loadedmetadata", showClock);
    function tick() {
      if (!lead) return;
      time = lead.currentTime;
      videos.slice(1).forEach(function (v) { if (Math.abs(v.currentTime - time) > 0.03) v.currentTime = time; });
      if (lead.duration) scrub.value = String(Math.round(1000 * time / lead.duration));
      showClock();
      redraw();
      if (!lead.paused) requestAnimationFrame(tick);
    }
    if (lead) {
      btn.addEventListener("click", function () {
        if (lead.paused) {
          if (lead.ended) videos.forEach(function (v) { v.currentTime = 0; });
          videos.forEach(function (v) { var p = v.play(); if (p) p.catch(function () {}); });
          btn.textContent = "Pause";
          requestAnimationFrame(tick);
        } else {
          videos.forEach(function (v) { v.pause(); });
          btn.textContent = "Play";
        }
      });
      lead.addEventListener("ended", function () { videos.forEach(function (v) { v.pause(); }); btn.textContent = "Play"; });
      lead.addEventListener("timeupdate", tick);
      scrub.addEventListener("input", function () {
        if (!lead.duration) return;
        var t = lead.duration * scrub.value / 1000;
        videos.forEach(function (v) { v.currentTime = t; });
        tick();
      });
    } else {
      btn.disabled = true;
      scrub.disabled = true;
    }

    // Labels and physics.
    var labels = document.getElementById("labels");
    function v3(p) { return p ? "(" + p.map(function (x) { return Number(x).toFixed(2); }).join(", ") + ")" : "—"; }
    function s(x, unit, d) { return x == null ? "—" : Number(x).toFixed(d == null ? 3 : d) + (unit ? " " + unit : ""); }
    var facts = [
      ["ground truth", row.gt_action],
      ["dangerous", String(row.dangerous)],
      ["danger present", String(row.danger_present)],
      ["danger reasons", (row.danger_reasons || []).join(", ") || "—"],
      ["impact point", v3(row.impact_point) + (row.impact_kind ? " (" + row.impact_kind + ")" : "")],
      ["time to impact", s(row.time_to_impact, "s")],
      ["time to floor", s(row.time_to_floor, "s")],
      ["impact speed", s(row.impact_speed, "m/s", 2)],
      ["closest approach", s(row.closest_approach, "m", 2)],
      ["object", row.object_name + " (" + row.object_id + ", " + row.object_category + ", " + s(row.object_mass_kg, "kg", 2) + ")"],
      ["looks like", row.looks_like ? row.looks_like + " (adversarial)" : "—"],
      ["hazard flags", (row.hazards || []).join(", ") || "—"],
      ["family / band", row.family + " / " + row.speed_band + " (" + row.speed_parameter + " = " + s(row.speed_value, "", 3) + ")"],
      ["room", row.room],
      ["observer (x, y, yaw)", v3(row.observer_pose)],
      ["label rule", row.label_rule],
      ["group", row.group_id]
    ];
    facts.forEach(function (f) { labels.appendChild(el("tr", null, el("th", null, f[0]), el("td", null, f[1]))); });
    document.getElementById("raw").textContent = JSON.stringify(row, null, 1);

    // Decisions.
    var exec = S.models.some(function (m) { return m.execution; });
    var t = document.getElementById("decisions");
    var pv = S.models.some(function (m) { return m.decision && m.decision.prompt_version; });
    var head = ["model", "action", "SAA", "rule fired", "intent", "d_end (m)", "d_min (m)", "d₁−d_min (m)", "AIA"];
    if (pv) head.push("prompt version");
    if (exec) head.push("execution");
    t.tHead.appendChild(el("tr", null));
    head.forEach(function (h) { t.tHead.rows[0].appendChild(el("th", null, h)); });
    S.models.forEach(function (m, i) {
      var d = m.decision;
      var tr = el("tr", { "data-model": m.model },
        el("td", null, el("i", { "class": "swatch", style: "background:" + color(i) }), m.model));
      var cells;
      if (!d) cells = ["no prediction", "", "", "", "", "", "", "", ""];
      else if (d.status === "lost") cells = ["lost (API error)", "", "", "", "", "", "", "", d.prompt_version || ""];
      else cells = [d.action || "R1 (no plan)", d.saa ? "✓" : "✗", d.rules.length ? "⚠ " + d.rules.join(", ") : "safe",
        d.intent || "", num(d.d_end, 2), num(d.d_min, 2), num(d.closing, 2), num(d.aia, 1), d.prompt_version || ""];
      if (!pv) cells = cells.slice(0, 8);
      var answered = d && d.status !== "lost";
      cells.forEach(function (c, k) {
        var cls = k === 2 && d && d.rules && d.rules.length ? "unsafe"
          : (k === 0 || k === 1) && answered ? (d.saa ? "correct" : "wrong") : "";
        tr.appendChild(el("td", { "class": cls }, c));
      });
      if (exec) tr.appendChild(el("td", { "class": m.execution && m.execution.outcome === "struck" ? "unsafe" : "" },
        m.execution ? m.execution.outcome + (m.execution.struck_part ? " (" + m.execution.struck_part + ", " +
          num(m.execution.impulse, 2) + " N·s)" : "") + (m.execution.first_contact_t != null ? ", first contact +" +
          num(m.execution.first_contact_t, 2) + " s" : "") : ""));
      t.tBodies[0].appendChild(tr);
    });
  };

  function loadScene() {
    var id = decodeURIComponent(location.hash.replace(/^#/, ""));
    if (!/^[0-9A-Za-z_-]+$/.test(id)) {
      document.getElementById("scene-title").textContent = "Pick a scene in the scene list";
      return;
    }
    var s = document.createElement("script");
    s.src = "data/scenes/" + id + ".js";
    s.onerror = function () {
      document.getElementById("scene-title").textContent = "Scene " + id + " is not in this report";
    };
    document.body.appendChild(s);
  }

  if (document.body.id === "page-board" && window.RH_BOARD) board(window.RH_BOARD);
  if (document.body.id === "page-scene") {
    loadScene();
    window.addEventListener("hashchange", function () { location.reload(); });
  }
})();
