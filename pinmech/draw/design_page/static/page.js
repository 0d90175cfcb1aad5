// pinmech design page: draws what the engine sends; computes nothing of the mechanism.
// Every length from the engine is in metres, world frame; the drawing is in millimetres
// with y up (SVG y = -1000 y).
"use strict";
(function () {
  const NS = "http://www.w3.org/2000/svg";
  const token = new URLSearchParams(location.search).get("token") || "";
  const $ = (id) => document.getElementById(id);
  const svg = $("drawing");
  const state = {
    frame: null, index: 0, view: null, pending: false, queued: null, dragging: null, phantom: null,
    error: "", centres: null, motion: null, arrowScale: null, playing: false, targets: [], answers: [],
    chosen: -1, synthRunning: false, saved: null, frames: 0,
  };
  window.pinmechPage = state;  // for tests and for the curious: what the page holds

  // ------------------------------------------------------------------ connection
  const ws = new WebSocket(`ws://${location.host}/ws?token=${encodeURIComponent(token)}`);
  ws.onopen = () => { status("connected"); ws.send(JSON.stringify({ type: "synthesis" })); };  // answers already found
  ws.onclose = (e) => status(`disconnected (${e.code})`);
  ws.onmessage = (event) => receive(JSON.parse(event.data));

  function send(message) {
    if (ws.readyState !== WebSocket.OPEN) return;
    if (message.type === "drag" || message.type === "param") {
      if (state.pending) { state.queued = message; return; }
      state.pending = true;
    }
    ws.send(JSON.stringify(message));
  }

  function receive(m) {
    if (m.type === "frame") {
      state.pending = false;
      if (m.ok) takeFrame(m); else showError(m.error);
      if (state.queued) { const next = state.queued; state.queued = null; send(next); }
    } else if (m.type === "diagnostics") { takeDiagnostics(m); }
    else if (m.type === "motion") { state.motion = m.ok ? m : null; draw(); }
    else if (m.type === "centres") { state.centres = m.ok ? m : null; draw(); }
    else if (m.type === "saved") { state.saved = m; showSaved(m); }
    else if (m.type === "synthesis") { takeSynthesis(m); }
    else if (m.type === "bounds") { if (m.error) message(m.error, "error"); else $("bounds").value = m.text; }
    if (m.type === "frame" && m.ok && state.answers.length && state.adopting) { state.adopting = false; state.chosen = -1; state.targets = []; showEntries(); draw(); }
    else if (m.type === "error") {
      state.pending = false; showError(m.error);
      if (state.queued) { const next = state.queued; state.queued = null; send(next); }
    }
  }

  function takeFrame(f) {
    const first = state.frame === null;
    state.frame = f; state.frames += 1; state.error = ""; state.phantom = null;
    state.centres = null; state.motion = null; state.arrowScale = null;
    if (first || !state.dragging || !state.view) state.view = fitView(f);
    message(f.stopped ? stoppedText(f) : "", f.stopped ? "note" : "");
    status(`solved ${f.driver.values.length} poses in ${f.ms.toFixed(0)} ms`);
    const names = f.joints.map((j) => j.name).join(" ");
    if (first || names !== state.names) { buildParams(f); buildPointChoice(f); state.names = names; }
    else showParams(f);
    $("diagnostics").classList.add("stale");
    draw(); requestDetails();
  }

  function takeDiagnostics(m) {
    if (!state.frame || m.id !== state.frame.id) return;  // of a drawing already replaced
    state.frame.diagnostics = m.diagnostics;
    state.diagnosticsMs = m.ms;
    $("diagnostics").classList.remove("stale");
    drawDiagnostics(state.frame); draw();
    status(`solved ${state.frame.driver.values.length} poses in ${state.frame.ms.toFixed(0)} ms, diagnostics in ${m.ms.toFixed(0)} ms`);
  }

  function showError(text) {
    state.error = text;
    message(`${text} - the last valid drawing is kept`, "error");
    draw();
  }

  // ------------------------------------------------------------------ helpers
  const mm = (p) => [p[0] * 1000, -p[1] * 1000];
  function el(name, attrs, parent) {
    const e = document.createElementNS(NS, name);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function status(text) { $("status").textContent = text; }
  function message(text, kind) { const m = $("message"); m.textContent = text; m.className = `message ${kind || ""}`; }
  function driverText(f, value) {
    return f.driver.angular ? `${(value * 180 / Math.PI).toFixed(2)} deg` : `${(value * 1000).toFixed(3)} mm`;
  }
  function stoppedText(f) {
    const at = driverText(f, f.driver.values[f.stopped.index]);
    return `the turn stops before ${f.driver.name} = ${at}: ${f.stopped.why}`;
  }
  // paths come flat, x0 y0 x1 y1 ..., with `solved` saying which poses closed
  function pointAt(f, name, index) {
    const p = f.paths[name];
    return p && f.solved[index] ? [p[2 * index], p[2 * index + 1]] : null;
  }
  function pathPoints(f, name) { return f.solved.map((ok, i) => pointAt(f, name, i)); }

  function fitView(f) {
    let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    const add = (p) => { if (!p) return; const q = mm(p);
      lo = [Math.min(lo[0], q[0]), Math.min(lo[1], q[1])]; hi = [Math.max(hi[0], q[0]), Math.max(hi[1], q[1])]; };
    for (const j of f.joints) add(j.at);
    for (const n in f.paths) pathPoints(f, n).forEach(add);
    const a = state.answers[state.chosen];  // a chosen answer is drawn whole too
    if (a) { Object.values(a.points).forEach(add); a.path.forEach(add); }
    const w = Math.max(hi[0] - lo[0], 1), h = Math.max(hi[1] - lo[1], 1), pad = 0.15 * Math.max(w, h);
    return [lo[0] - pad, lo[1] - pad, w + 2 * pad, h + 2 * pad];
  }

  // ------------------------------------------------------------------ drawing
  function draw() {
    const f = state.frame;
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    if (!f) return;
    const [x, y, w, h] = state.view;
    svg.setAttribute("viewBox", `${x} ${y} ${w} ${h}`);
    svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
    const unit = Math.max(w, h) / 600;  // one screen pixel, about [mm]
    defs(unit);
    const index = f.solved[state.index] ? state.index : 0;
    if ($("show-ghosts").checked && f.diagnostics) drawGhosts(f, unit);
    drawPaths(f);
    drawSlides(f, w + h);
    drawLinks(f, index);
    drawFolds(f, unit);
    drawTargets(unit);
    drawAnswer(unit);
    if ($("show-centres").checked && state.centres && state.centres.index === index) drawCentres(unit);
    if ($("show-arrows").checked && state.motion && state.motion.index === index) drawArrows(unit, w + h);
    drawJoints(f, index, unit);
    if (state.phantom) el("circle", { class: "phantom", cx: state.phantom[0], cy: state.phantom[1], r: 7 * unit }, svg);
    $("pose").max = String(f.driver.values.length - 1);
    $("pose").value = String(state.index);
    $("pose-text").textContent = `${f.driver.name} = ${driverText(f, f.driver.values[state.index])}`;
    drawMuChart(f);
  }

  function defs(unit) {
    const d = el("defs", {}, svg);
    for (const [id, cls] of [["head-v", "arrow-v"], ["head-a", "arrow-a"]]) {
      const m = el("marker", { id, viewBox: "0 0 10 10", refX: 9, refY: 5, markerWidth: 6, markerHeight: 6,
        orient: "auto-start-reverse" }, d);
      el("path", { d: "M0,0 L10,5 L0,10 z", class: cls }, m);
    }
  }

  function segments(points) {
    const out = []; let cur = [];
    for (const p of points) { if (p) cur.push(mm(p)); else if (cur.length) { out.push(cur); cur = []; } }
    if (cur.length) out.push(cur);
    return out;
  }
  function polyline(pts, cls, parent) {
    return el("polyline", { class: cls, points: pts.map((p) => `${p[0]},${p[1]}`).join(" "),
      "vector-effect": "non-scaling-stroke" }, parent || svg);
  }

  function drawPaths(f) {
    for (const j of f.joints) {
      if (j.ground) continue;
      for (const seg of segments(pathPoints(f, j.name))) polyline(seg, j.pin ? "path-pin" : "path-point");
    }
  }

  function linkShape(f, link, place) {
    const pts = link.points.map(place).filter((p) => p);
    if (pts.length < 2) return null;
    if (pts.length === 2) return polyline(pts, "link bar");
    return el("polygon", { class: "link", points: pts.map((p) => `${p[0]},${p[1]}`).join(" "),
      "vector-effect": "non-scaling-stroke" }, svg);
  }
  function drawLinks(f, index) {
    for (const link of f.links) {
      if (link.ground) continue;
      linkShape(f, link, (n) => { const p = pointAt(f, n, index); return p ? mm(p) : null; });
    }
  }
  function drawGhosts(f, unit) {
    const d = f.diagnostics || {};
    const ghosts = [];
    for (const o of d.outputs || []) for (const l of o.limits) ghosts.push([`${o.name} ${l.label}`, l.points]);
    for (const x of d.folds || []) ghosts.push([`fold at ${driverText(f, x.driver)}`, x.points]);
    const placed = [];
    ghosts.forEach((g) => {
      for (const link of f.links) {
        if (link.ground) continue;
        const pts = link.points.map((n) => g[1][n]).filter((p) => p).map(mm);
        if (pts.length >= 2) polyline(pts.length > 2 ? pts.concat([pts[0]]) : pts, "ghost");
      }
      const away = farthest(f, g[1]);  // labelled where the ghost is farthest from the linkage shown
      if (!away) return;
      const p = mm(away), at = [p[0] + 6 * unit, p[1] - 6 * unit];
      while (placed.some((q) => Math.abs(q[0] - at[0]) < 70 * unit && Math.abs(q[1] - at[1]) < 12 * unit)) at[1] -= 13 * unit;
      placed.push(at);  // a label on another's place goes a line up
      el("text", { class: "ghost-label", x: at[0], y: at[1], "font-size": 11 * unit }, svg).textContent = g[0];
    });
  }
  function farthest(f, ghost) {  // the ghost's point farthest from the same point of the linkage shown
    let best = null, gap = -1;
    for (const n in ghost) {
      const now = pointAt(f, n, f.solved[state.index] ? state.index : 0);
      const d = now ? Math.hypot(ghost[n][0] - now[0], ghost[n][1] - now[1]) : 0;
      if (d > gap) { gap = d; best = ghost[n]; }
    }
    return best;
  }
  function drawSlides(f, size) {
    for (const s of f.slides) {
      const a = mm(s.at), u = [s.along[0], -s.along[1]];
      el("line", { class: "slide", x1: a[0] - u[0] * size, y1: a[1] - u[1] * size, x2: a[0] + u[0] * size,
        y2: a[1] + u[1] * size, "vector-effect": "non-scaling-stroke" }, svg);
    }
  }
  function drawFolds(f, unit) {
    if (!f.stopped) return;
    const last = f.stopped.index - 1;
    for (const j of f.joints) {
      if (j.ground || last < 0) continue;
      const p = pointAt(f, j.name, last); if (!p) continue;
      const q = mm(p), r = 5 * unit;
      el("path", { class: "fold", d: `M${q[0] - r},${q[1] - r}L${q[0] + r},${q[1] + r}M${q[0] - r},${q[1] + r}L${q[0] + r},${q[1] - r}`,
        "vector-effect": "non-scaling-stroke" }, svg);
    }
  }
  function drawJoints(f, index, unit) {
    for (const j of f.joints) {
      const p = j.ground ? j.at : pointAt(f, j.name, index);
      if (!p) continue;
      const q = mm(p);
      const c = el("circle", { class: `joint${j.ground ? " ground" : ""}${j.pin ? "" : " point"}`, cx: q[0], cy: q[1],
        r: 5 * unit, "data-joint": j.name, "vector-effect": "non-scaling-stroke" }, svg);
      c.addEventListener("mousedown", (e) => startDrag(e, j.name));
      el("text", { class: "joint-label", x: q[0] + 7 * unit, y: q[1] - 7 * unit, "font-size": 12 * unit }, svg)
        .textContent = j.name;
    }
  }
  function drawCentres(unit) {
    const placed = [];
    for (const c of state.centres.centres) {
      if (!c.position) continue;
      const p = mm(c.position), text = `I(${c.links[0]},${c.links[1]})`, at = [p[0] + 4 * unit, p[1] + 10 * unit];
      while (placed.some((q) => Math.abs(q[1] - at[1]) < 11 * unit && at[0] < q[0] + q[2] && q[0] < at[0] + 6 * unit * text.length))
        at[1] += 11 * unit;  // a label on another's place goes a line down
      placed.push([at[0], at[1], 6 * unit * text.length]);
      el("circle", { class: "centre", cx: p[0], cy: p[1], r: 3 * unit }, svg);
      el("text", { class: "centre-label", x: at[0], y: at[1], "font-size": 10 * unit }, svg).textContent = text;
    }
  }
  function drawArrows(unit, size) {
    const m = state.motion, p = mm(m.position);
    const norm = (v) => Math.hypot(v[0], v[1]);
    if (!state.arrowScale) state.arrowScale = {
      v: 0.15 * size / Math.max(norm(m.velocity), 1e-12), a: 0.15 * size / Math.max(norm(m.acceleration), 1e-12) };
    for (const [v, s, cls, head] of [[m.velocity, state.arrowScale.v, "arrow-v", "head-v"],
      [m.acceleration, state.arrowScale.a, "arrow-a", "head-a"]]) {
      el("line", { class: cls, x1: p[0], y1: p[1], x2: p[0] + v[0] * s, y2: p[1] - v[1] * s,
        "marker-end": `url(#${head})`, "vector-effect": "non-scaling-stroke" }, svg);
    }
    $("arrow-text").textContent = `|v| = ${norm(m.velocity).toPrecision(4)} m/s (green), ` +
      `|a| = ${norm(m.acceleration).toPrecision(4)} m/s^2 (red)`;
  }
  function drawTargets(unit) {  // a pose's angle: a tick from its place along the coupler's direction
    if ($("synth-task").value === "function") return;
    state.targets.forEach((t, i) => {
      const p = mm(t);
      el("circle", { class: "target", cx: p[0], cy: p[1], r: 6 * unit, "vector-effect": "non-scaling-stroke" }, svg);
      if (t.length > 2) el("line", { class: "target-angle", x1: p[0], y1: p[1], x2: p[0] + 24 * unit * Math.cos(t[2]),
        y2: p[1] - 24 * unit * Math.sin(t[2]), "vector-effect": "non-scaling-stroke" }, svg);
      const label = el("text", { class: "target-label", x: p[0] + 7 * unit, y: p[1] + 12 * unit, "font-size": 11 * unit }, svg);
      label.textContent = String(i + 1);
    });
  }
  function drawAnswer(unit) {
    const a = state.answers[state.chosen];
    if (!a) return;
    for (const seg of segments(a.path)) polyline(seg, "answer-path");
    for (const n in a.points) { const p = mm(a.points[n]); el("circle", { class: "target", cx: p[0], cy: p[1], r: 3 * unit }, svg); }
    for (const link of a.links) {
      const pts = link.map((n) => a.points[n]).filter((p) => p).map(mm);
      if (pts.length >= 2) polyline(pts, "ghost");
    }
  }

  // ------------------------------------------------------------------ diagnostics
  function drawDiagnostics(f) {
    const d = f.diagnostics, box = $("diagnostics");
    if (!d) return;
    box.innerHTML = "";
    const row = (html) => { const r = document.createElement("div"); r.className = "diag-row"; r.innerHTML = html; box.appendChild(r); };
    const deg = (x) => (x * 180 / Math.PI).toFixed(2);
    if (!d.applicable) { row(`planar diagnostics: not applicable (${d.reason})`); return; }
    for (const l of d.loops) {
      row(`<b>${l.kind}</b> ${l.links.join("-")}: <b>${l.class}</b>${l.barker ? `, Barker <b>${l.barker}</b>` : ""}` +
        `<br><span class="small">${l.condition}</span>`);
    }
    for (const y of d.dyads) {
      const at = y.least_at === null ? "" : ` at ${f.driver.name} = ${driverText(f, y.least_at)}`;
      row(`${y.name}: transmission angle least <b>${y.least === null ? "-" : y.least.toFixed(2)} deg</b>${at}`);
    }
    for (const o of d.outputs) {
      const what = o.travel === null ? "" : o.kind === "pin" ? `swing <b>${deg(o.travel)} deg</b>` : `stroke <b>${(o.travel * 1000).toFixed(3)} mm</b>`;
      const q = o.ratio === null ? "" : `, Q = <b>${o.ratio.toFixed(4)}</b>`;
      if (what || q) row(`${o.name}: ${what}${q}`);
      for (const l of o.limits) row(`<span class="small">${o.name}: ${l.kind} (${l.label}) at ${f.driver.name} = ${driverText(f, l.driver)}${l.toggle ? `, ${l.toggle}` : ""}</span>`);
    }
    for (const x of d.folds) row(`<span class="small">fold of the driver at ${f.driver.name} = ${driverText(f, x.driver)}</span>`);
  }
  function drawMuChart(f) {
    const chart = $("mu-chart");
    while (chart.firstChild) chart.removeChild(chart.firstChild);
    const d = f.diagnostics;
    if (!d) return;
    if (!d || !d.applicable || !d.dyads.length) return;
    const n = f.driver.values.length, X = (i) => 25 + 270 * i / (n - 1), Y = (mu) => 110 - mu;  // mu in [0, 90] deg
    el("text", { x: 2, y: 14 }, chart).textContent = "90";
    el("text", { x: 2, y: 110 }, chart).textContent = "0";
    el("text", { x: 30, y: 10 }, chart).textContent = "transmission angle [deg] over the turn";
    for (const y of d.dyads) {
      let path = "", pen = "M";
      y.mu.forEach((mu, i) => { if (mu === null) { pen = "M"; return; } path += `${pen}${X(i).toFixed(1)},${Y(mu).toFixed(1)}`; pen = "L"; });
      el("path", { class: "mu", d: path }, chart);
      if (y.least !== null) el("line", { class: "least", x1: 25, x2: 295, y1: Y(y.least), y2: Y(y.least) }, chart);
    }
    el("line", { class: "now", x1: X(state.index), x2: X(state.index), y1: 20, y2: 110 }, chart);
  }

  // ------------------------------------------------------------------ interaction
  function toWorld(event) {
    const pt = svg.createSVGPoint(); pt.x = event.clientX; pt.y = event.clientY;
    const p = pt.matrixTransform(svg.getScreenCTM().inverse());
    return [p.x, p.y];
  }
  function startDrag(event, name) {
    if ($("targets-on").checked) return;  // placing targets: a click on a joint is a target too
    event.preventDefault();
    state.dragging = name; stopPlay();  // dragged at the pose shown: under the mouse at this crank angle
  }
  window.addEventListener("mousemove", (event) => {  // the window's: a drag may leave the drawing
    if (!state.dragging) return;
    const p = toWorld(event);
    state.phantom = state.error ? p : null;
    const shown = state.frame.solved[state.index] ? state.index : 0;  // an unsolved pose is drawn at the drawn one
    send({ type: "drag", joint: state.dragging, x: p[0] / 1000, y: -p[1] / 1000, index: shown });
    if (state.error) draw();
  });
  window.addEventListener("mouseup", () => {
    if (!state.dragging) return;
    state.dragging = null; state.phantom = null;
    if (state.frame) { state.view = fitView(state.frame); draw(); }
  });
  svg.addEventListener("click", (event) => {  // a path's target
    if (!$("targets-on").checked || state.dragging || $("synth-task").value !== "path") return;
    const p = toWorld(event);
    state.targets.push([p[0] / 1000, -p[1] / 1000]); showEntries(); draw();
  });
  svg.addEventListener("mousedown", (event) => {  // a pose: its place, then its angle dragged
    if (!$("targets-on").checked || $("synth-task").value !== "motion") return;
    event.preventDefault();
    const p = toWorld(event);
    state.targets.push([p[0] / 1000, -p[1] / 1000, 0]); state.posing = state.targets.length - 1;
    showEntries(); draw();
  });
  window.addEventListener("mousemove", (event) => {
    if (state.posing === undefined || state.posing === null) return;
    const t = state.targets[state.posing], p = toWorld(event);
    const dx = p[0] / 1000 - t[0], dy = -p[1] / 1000 - t[1];
    if (Math.hypot(dx, dy) > 1e-9) t[2] = Math.atan2(dy, dx);
    showEntries(); draw();
  });
  window.addEventListener("mouseup", () => { state.posing = null; });
  $("pose").addEventListener("input", () => { state.index = Number($("pose").value); draw(); requestDetails(); });
  for (const id of ["show-ghosts", "show-centres", "show-arrows", "arrow-point"])
    $(id).addEventListener("change", () => { state.arrowScale = null; draw(); requestDetails(); });
  function requestDetails() {
    if (!state.frame) return;
    if ($("show-centres").checked) send({ type: "centres", index: state.index });
    if ($("show-arrows").checked && $("arrow-point").value) send({ type: "motion", index: state.index, point: $("arrow-point").value });
  }
  function stopPlay() { state.playing = false; $("playing").innerHTML = "&#9654;"; }
  $("playing").addEventListener("click", () => {
    state.playing = !state.playing;
    $("playing").innerHTML = state.playing ? "&#10074;&#10074;" : "&#9654;";
    if (state.playing) requestAnimationFrame(step);
  });
  function step() {
    if (!state.playing || !state.frame) return;
    const n = state.frame.driver.values.length;
    state.index = (state.index + 1) % n;
    if (!state.frame.solved[state.index]) state.index = 0;
    draw(); requestDetails();
    requestAnimationFrame(step);
  }
  function buildParams(f) {
    const box = $("params"); box.innerHTML = "";
    const names = Object.keys(f.params);
    $("params-box").open = names.length > 0;
    if (!names.length) { box.textContent = "the file has no [params]"; return; }
    for (const name of names) {
      const v = f.params[name] * 1000;
      const label = document.createElement("label");
      label.dataset.name = name;
      label.innerHTML = `${name} <input type="range" min="${(v * 0.2).toFixed(3)}" max="${(v * 2).toFixed(3)}" step="${(v / 200).toPrecision(3)}" value="${v}"> <span>${v.toFixed(3)} mm</span>`;
      const input = label.querySelector("input"), text = label.querySelector("span");
      input.addEventListener("input", () => { text.textContent = `${Number(input.value).toFixed(3)} mm`;
        send({ type: "param", name, value: Number(input.value) / 1000 }); });
      box.appendChild(label);
    }
  }
  function showParams(f) {  // the values a drag gave the parameters (the slider being moved left alone)
    for (const label of $("params").querySelectorAll("label")) {
      const input = label.querySelector("input"), name = label.dataset.name;
      if (!input || document.activeElement === input || !(name in f.params)) continue;
      input.value = f.params[name] * 1000;
      label.querySelector("span").textContent = `${(f.params[name] * 1000).toFixed(3)} mm`;
    }
  }
  function buildPointChoice(f) {
    const select = $("arrow-point"); select.innerHTML = "";
    const moving = f.joints.filter((j) => !j.ground);
    moving.sort((a, b) => a.pin - b.pin);
    for (const j of moving) { const o = document.createElement("option"); o.value = o.textContent = j.name; select.appendChild(o); }
  }

  // ------------------------------------------------------------------ save
  function figureSvg() {
    const copy = svg.cloneNode(true);
    copy.setAttribute("width", svg.clientWidth); copy.setAttribute("height", svg.clientHeight);
    const style = document.createElementNS(NS, "style");
    style.textContent = [...document.styleSheets[0].cssRules].map((r) => r.cssText).filter((t) => /^\.(link|ghost|path|slide|joint|fold|phantom|centre|arrow|target|answer)/.test(t)).join("\n");
    copy.insertBefore(style, copy.firstChild);
    return new XMLSerializer().serializeToString(copy);
  }
  function figurePng(text, done) {
    const image = new Image();
    image.onload = () => {
      const canvas = document.createElement("canvas");
      canvas.width = svg.clientWidth * 2; canvas.height = svg.clientHeight * 2;
      const g = canvas.getContext("2d"); g.fillStyle = "#fff"; g.fillRect(0, 0, canvas.width, canvas.height);
      g.drawImage(image, 0, 0, canvas.width, canvas.height);
      done(canvas.toDataURL("image/png"));
    };
    image.onerror = () => done(null);
    image.src = "data:image/svg+xml;charset=utf-8," + encodeURIComponent(text);
  }
  $("save").addEventListener("click", () => {
    const text = figureSvg();
    figurePng(text, (png) => ws.send(JSON.stringify({ type: "save", svg: text, png })));
  });
  function showSaved(m) {
    $("saved").textContent = m.ok ? `written: ${m.files.join(", ")}` : m.error;
    if (!m.ok) message(m.error, "error");
  }

  // ------------------------------------------------------------------ synthesis
  const HELP = {
    path: "Tick <b>place on the drawing</b> and click the coupler point's targets, in order (or type x, y in mm).",
    motion: "Tick <b>place on the drawing</b>, press at a pose's place and drag towards its angle (or type x, y in mm, angle in deg).",
    function: "Type the pairs: the crank's turn (deg) and the output's turn (deg; a slider's travel in mm), from the first pair.",
  };
  function showHelp() {
    const task = $("synth-task").value;
    $("synth-help").innerHTML = HELP[task];
    $("ground-box").style.display = task === "function" && $("synth-kind").value !== "slider-crank" ? "" : "none";
  }
  function showEntries() {  // the targets, poses or pairs in the page's units: mm, deg
    const d = (r) => (r * 180 / Math.PI).toFixed(3), m = (x) => (x * 1000).toFixed(3);
    $("entries").value = state.targets.map((t) => $("synth-task").value === "function" ? t.join(", ")
      : t.length > 2 ? `${m(t[0])}, ${m(t[1])}, ${d(t[2])}` : `${m(t[0])}, ${m(t[1])}`).join("\n");
  }
  function readEntries() {  // the text typed: one entry a line, numbers split by commas or spaces
    const rows = $("entries").value.split("\n").map((l) => l.trim()).filter((l) => l)
      .map((l) => l.split(/[\s,;]+/).map(Number));
    const task = $("synth-task").value;
    state.targets = task === "function" ? rows.map((r) => [r[0], r[1]])
      : rows.map((r) => task === "motion" ? [r[0] / 1000, r[1] / 1000, (r[2] || 0) * Math.PI / 180] : [r[0] / 1000, r[1] / 1000]);
    draw();
  }
  $("entries").addEventListener("change", readEntries);
  for (const id of ["synth-task", "synth-kind"]) $(id).addEventListener("change", () => {
    if (id === "synth-task") {  // another task: its own targets, and no answers of the last
      state.targets = []; state.answers = []; state.chosen = -1; $("answers").innerHTML = "";
      $("synth-progress").textContent = ""; showEntries(); state.view = fitView(state.frame); draw();
    }
    showHelp();
  });
  showHelp();
  function request(type) {  // the synthesis asked for: SI (m, rad) in the message
    const task = $("synth-task").value, rad = Math.PI / 180;
    const m = { type, kind: $("synth-kind").value, task, max_crank: Number($("synth-max").value) / 1000,
      ground: Number($("synth-ground").value) / 1000, bounds: $("bounds").value,
      generations: Number($("synth-generations").value) };
    if (task === "function") m.pairs = state.targets.map(([a, b]) =>
      [a * rad, $("synth-kind").value === "slider-crank" ? b / 1000 : b * rad]);
    else if (task === "motion") m.poses = state.targets; else m.targets = state.targets;
    return m;
  }
  $("bounds-propose").addEventListener("click", () => ws.send(JSON.stringify(request("bounds"))));
  $("targets-clear").addEventListener("click", () => { state.targets = []; showEntries(); draw(); });
  $("synth-run").addEventListener("click", () => {
    state.answers = []; state.chosen = -1; $("answers").innerHTML = "";
    ws.send(JSON.stringify(request("synthesise")));
  });
  $("synth-cancel").addEventListener("click", () => ws.send(JSON.stringify({ type: "cancel" })));
  function takeSynthesis(m) {
    $("synth-progress").textContent = m.progress || m.error || "";
    if (m.error) message(m.error, "error");
    state.synthRunning = !!m.running;
    if (m.running) setTimeout(() => ws.send(JSON.stringify({ type: "synthesis" })), 500);
    if (!m.answers) return;
    state.answers = m.answers;
    const list = $("answers"); list.innerHTML = "";
    m.answers.forEach((a, i) => {
      const li = document.createElement("li"); li.textContent = a.summary;
      li.addEventListener("click", () => { state.chosen = i; [...list.children].forEach((c, k) => c.className = k === i ? "chosen" : "");
        state.view = fitView(state.frame); draw(); });
      const adopt = document.createElement("button"); adopt.textContent = "adopt"; adopt.type = "button";
      adopt.addEventListener("click", (e) => { e.stopPropagation(); state.adopting = true; state.view = null;
        ws.send(JSON.stringify({ type: "adopt", answer: i })); });
      li.appendChild(adopt); list.appendChild(li);
    });
  }
})();
