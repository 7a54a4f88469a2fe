"""The design page the service serves at ``/``: choose a model (or upload one), move its actuators (or its task
coordinates: the inverse kinematics then moves the actuators) with sliders, and see the mechanism follow in the 3-D
view, with its task coordinates and its distances to the singularities.

A registered mechanism's numeric design parameters can be changed and built (``POST /models/{name}/variants``: a
new model, listed with the others). Two buttons start jobs (:mod:`pkm.serve.jobs`) at the current actuator values: every assembly mode (each listed with
its task values; a click shows it) and a workspace map of two task coordinates around the current pose (drawn as the
condition index, blue to red). The page is static HTML and JavaScript, no build step, no third-party code besides what the service already ships:
the 3-D view is the model's own preview page (``/models/{model}/preview``: meshcat's viewer with the scene, in an
``iframe`` of the same origin), whose bodies the page moves with ``set_transform`` commands from the service's
``scene`` query. Each slider move asks ``fk`` (warm-started from the last configuration, so the mechanism stays on
its assembly mode), then ``scene`` and ``diagnose``; moves made while a request is in flight are coalesced into the
next one. A token, when the service asks one, is given in the page's address: ``/?token=...``.

``window.pkmState`` exposes the page's state to tests (a real browser drives it in ``tests/serve/test_page.py``):
the model, the configuration shown, the number of updates, and the errors met.
"""

PAGE = r"""<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>pkm: design</title>
<link rel="icon" href="data:,">
<style>
body { margin: 0; font: 13px sans-serif; color: #222; display: flex; height: 100vh; }
#side { width: 300px; padding: 10px 12px; overflow-y: auto; background: #f4f4f4; border-right: 1px solid #ccc; }
#side h1 { font-size: 16px; margin: 0 0 8px; }
#side label { display: block; margin: 6px 0 2px; }
#side input[type=range] { width: 100%; }
#side table { border-collapse: collapse; margin-top: 6px; }
#side td { padding: 1px 6px 1px 0; }
#status { margin-top: 8px; color: #555; min-height: 1.2em; }
#status.error { color: #b00; }
#view { flex: 1; border: 0; height: 100vh; }
#tools { margin-top: 10px; }
#tools button { margin: 4px 0; }
#modes a { display: block; cursor: pointer; color: #0645ad; }
#map { display: block; margin-top: 4px; border: 1px solid #ccc; }
</style>
</head>
<body>
<div id="side">
  <h1>pkm: design</h1>
  <label>model <select id="model"></select></label>
  <form id="upload"><label>upload (spec + model file, Gepetto pair, MJCF, SDF)</label>
    <input type="file" id="files" multiple> <button type="submit">upload</button></form>
  <div id="sliders"></div>
  <div id="task-sliders"></div>
  <details id="design"><summary>design parameters</summary><div id="params"></div>
    <button type="button" id="params-button">build this design</button></details>
  <table id="readout"></table>
  <div id="tools">
    <button type="button" id="modes-button">every assembly mode here</button>
    <div id="modes"></div>
    <button type="button" id="map-button">workspace map around here</button>
    <canvas id="map" width="240" height="180"></canvas>
  </div>
  <div id="status"></div>
</div>
<iframe id="view" title="3-D view"></iframe>
<script>
"use strict";
const token = new URLSearchParams(location.search).get("token");
const auth = token ? {"authorization": "Bearer " + token} : {};
const state = window.pkmState = {model: null, about: null, q: null, updates: 0, errors: [], busy: false,
                                 pending: false, paths: null};

function say(text, error) {
  const s = document.getElementById("status");
  s.textContent = text;
  s.className = error ? "error" : "";
  if (error) state.errors.push(text);
}

async function api(method, path, body) {
  const options = {method: method, headers: Object.assign({}, auth)};
  if (body !== undefined) {
    options.headers["content-type"] = "application/json";
    options.body = JSON.stringify(body);
  }
  const r = await fetch(path, options);
  const answer = await r.json();
  if (!r.ok) {
    const e = new Error(answer.message || r.statusText);
    // one sample the library could not solve (unreachable, singular, not converged): said, not an error of the page
    // (by name, the failures a sample can meet: any other 4xx, a bad input of any kind, is an error of the page)
    e.sample = r.status === 422 && ["UnreachableError", "SingularityError", "ConvergenceError", "AssemblyError",
                                    "NonFiniteError"].indexOf(answer.error) >= 0;
    throw e;
  }
  return answer;
}

function fmt(x) { return typeof x === "number" ? x.toPrecision(5) : String(x); }

async function loadModels(select) {
  const list = (await api("GET", "/models")).models;
  const box = document.getElementById("model");
  box.innerHTML = "";
  for (const m of list) {
    const o = document.createElement("option");
    o.value = m.id;
    o.textContent = m.kind === "uploaded" ? m.name + " (" + m.id.slice(0, 8) + ")" : m.id;
    box.appendChild(o);
  }
  box.value = select || list[0].id;
  await selectModel(box.value);
}

async function selectModel(id) {
  const about = await api("GET", "/models/" + id);
  state.model = id; state.about = about; state.q = about.q_reference; state.paths = null;
  await showParameters(id);
  const sliders = document.getElementById("sliders");
  sliders.innerHTML = "";
  about.actuated.forEach(function (name, k) {
    const value = qaOf(about, about.q_reference)[k];
    const unit = about.actuated_units[k];
    const limits = about.limits[name];
    const span = unit === "rad" ? 1.0 : 0.1;
    const lo = limits ? Math.max(limits[0], value - span) : value - span;
    const hi = limits ? Math.min(limits[1], value + span) : value + span;
    const label = document.createElement("label");
    label.textContent = name + " [" + unit + "]";
    const input = document.createElement("input");
    Object.assign(input, {type: "range", min: lo, max: hi, step: "any", value: value, id: "qa-" + k});
    input.addEventListener("input", schedule);
    sliders.appendChild(label);
    sliders.appendChild(input);
  });
  const tasks = document.getElementById("task-sliders");
  tasks.innerHTML = "";
  const y0 = (await api("POST", "/models/" + id + "/fk", {qa: qaOf(about, about.q_reference)})).y[0];
  about.task_value_names.forEach(function (name, k) {
    if (!(name in about.task_units)) return;  // (a pose's quaternion entries: no slider)
    const unit = about.task_units[name], span = unit === "m" ? 0.05 : 0.3;
    const label = document.createElement("label");
    label.textContent = "task " + name + " [" + unit + "]";
    const input = document.createElement("input");
    Object.assign(input, {type: "range", min: y0[k] - span, max: y0[k] + span, step: "any", value: y0[k],
                          id: "y-" + k});
    input.addEventListener("input", function () { scheduleTask(k); });
    tasks.appendChild(label);
    tasks.appendChild(input);
  });
  state.y = y0;
  const view = document.getElementById("view");
  const loaded = new Promise(function (resolve) { view.onload = resolve; });
  view.src = "/models/" + id + "/preview" + (token ? "?token=" + encodeURIComponent(token) : "");
  await loaded;
  await update();
}

function qaOf(about, q) {
  return about.actuated_q.map(function (i) { return q[i]; });
}

async function scheduleTask(k) {
  // a task slider: the inverse kinematics from the pose shown, then the actuator sliders follow
  if (state.busy) { return; }
  state.busy = true;
  try {
    const y = state.y.slice();
    y[k] = parseFloat(document.getElementById("y-" + k).value);
    const ik = await api("POST", "/models/" + state.model + "/ik", {y: y, seed: state.q});
    state.y = y;
    ik.qa[0].forEach(function (v, i) { document.getElementById("qa-" + i).value = v; });
  } catch (e) {
    say(e.message, !e.sample);
  } finally {
    state.busy = false;
  }
  update();
}

function schedule() {
  if (state.busy) { state.pending = true; return; }
  update();
}

async function update() {
  state.busy = true;
  try {
    const about = state.about;
    const qa = about.actuated.map(function (_, k) { return parseFloat(document.getElementById("qa-" + k).value); });
    const fk = await api("POST", "/models/" + state.model + "/fk", {qa: qa, seed: state.q});
    state.q = fk.q[0];
    state.y = fk.y[0];
    fk.y[0].forEach(function (v, k) { const el = document.getElementById("y-" + k); if (el) el.value = v; });
    const scene = await api("POST", "/models/" + state.model + "/scene", {q: state.q});
    const viewer = document.getElementById("view").contentWindow.viewer;
    scene.paths.forEach(function (path, b) {
      viewer.handle_command({type: "set_transform", path: path, matrix: scene.matrices[0][b]});
    });
    const diag = await api("POST", "/models/" + state.model + "/diagnose", {q: state.q});
    const rows = about.task.map(function (name, k) {
      return "<tr><td>" + name + "</td><td>" + fmt(fk.y[0][k]) + " " + about.task_units[name] + "</td></tr>";
    });
    rows.push("<tr><td>direct singularity</td><td>" + fmt(diag.direct_distance[0]) + "</td></tr>");
    rows.push("<tr><td>inverse singularity</td><td>" + fmt(diag.inverse_distance[0]) + "</td></tr>");
    rows.push("<tr><td>closure residual</td><td>" + fmt(fk.residual[0]) + " m or rad</td></tr>");
    const outside = fk.outside_limits[0].map(function (o) { return o.joint + " = " + fmt(o.value); });
    rows.push("<tr><td>outside the limits</td><td>" + (outside.length ? outside.join(", ") : "none") + "</td></tr>");
    document.getElementById("readout").innerHTML = rows.join("");
    state.updates += 1;
    say("fk " + (fk.compute_s * 1e3).toFixed(2) + " ms", false);
  } catch (e) {
    say(e.message, !e.sample);
  } finally {
    state.busy = false;
    if (state.pending) { state.pending = false; update(); }
  }
}

async function showParameters(id) {
  const info = await api("GET", "/models/" + id + "/parameters");
  const box = document.getElementById("params");
  box.innerHTML = "";
  document.getElementById("design").style.display = info.registered ? "" : "none";
  state.parameters = info.parameters.filter(function (p) { return typeof p.default === "number"; });
  state.parameters.forEach(function (p) {
    const label = document.createElement("label");
    label.textContent = p.name + (p.units.length ? " [" + p.units[0] + "]" : "");
    label.title = p.description;
    const input = document.createElement("input");
    Object.assign(input, {type: "number", value: p.default, step: "any", id: "param-" + p.name});
    box.appendChild(label);
    box.appendChild(input);
  });
}

async function buildDesign() {
  const params = {};
  state.parameters.forEach(function (p) {
    const v = parseFloat(document.getElementById("param-" + p.name).value);
    if (v !== p.default) params[p.name] = v;
  });
  const base = state.model.split("@")[0];
  const entry = await api("POST", "/models/" + base + "/variants", {params: params});
  await loadModels(entry.id);
}

async function job(kind, body) {
  const started = await api("POST", "/models/" + state.model + "/jobs/" + kind, body);
  for (;;) {
    const s = await api("GET", "/jobs/" + started.id);
    if (s.state === "done") return (await api("GET", "/jobs/" + started.id + "/result")).result;
    if (s.state === "failed" || s.state === "cancelled") throw new Error(s.error ? s.error.message : s.state);
    await new Promise(function (r) { setTimeout(r, 100); });
  }
}

async function showModes() {
  const about = state.about;
  const qa = about.actuated.map(function (_, k) { return parseFloat(document.getElementById("qa-" + k).value); });
  say("solving every assembly mode...", false);
  const r = await job("assembly_modes", {qa: qa});
  const box = document.getElementById("modes");
  box.innerHTML = "";
  state.modes = r.q;
  r.q.forEach(function (q, k) {
    const a = document.createElement("a");
    a.textContent = "mode " + k + ": " + about.task.map(function (n, i) { return n + " " + fmt(r.y[k][i]); }).join(", ");
    a.addEventListener("click", function () { state.q = q; update(); });
    box.appendChild(a);
  });
  say(r.count + " assembly modes (" + (r.complete ? "complete" : "incomplete") + ")", false);
}

async function showMap() {
  const about = state.about;
  const names = about.task.filter(function (n) { return about.task_units[n] === "m"; }).slice(0, 2);
  const axes = names.length === 2 ? names : about.task.slice(0, 2);
  const y = (await api("POST", "/models/" + state.model + "/fk", {qa: qaOf(about, state.q), seed: state.q})).y[0];
  const body = {axes: {}, fixed: {}};
  axes.forEach(function (n) {
    const i = about.task.indexOf(n), span = about.task_units[n] === "m" ? 0.1 : 0.5;
    body.axes[n] = [y[i] - span, y[i] + span, 41];
  });
  about.task.forEach(function (n, i) { if (axes.indexOf(n) < 0) body.fixed[n] = y[i]; });
  if (axes.length < 2) throw new Error("a map needs two task coordinates");
  say("mapping...", false);
  const r = await job("map", body);
  const ci = r.condition_index, canvas = document.getElementById("map"), g = canvas.getContext("2d");
  const rows = ci.length, cols = ci[0].length, w = canvas.width / cols, h = canvas.height / rows;
  g.clearRect(0, 0, canvas.width, canvas.height);
  for (let j = 0; j < rows; j++) for (let i = 0; i < cols; i++) {
    const v = ci[j][i];
    if (typeof v !== "number") continue;
    g.fillStyle = "hsl(" + Math.round(240 * (1 - v)) + ", 80%, 50%)";
    g.fillRect(i * w, (rows - 1 - j) * h, w + 1, h + 1);
  }
  state.map = r;
  say("workspace: " + r.nodes + " reachable nodes of " + rows * cols + "; colour: the condition index", false);
}

document.getElementById("params-button").addEventListener("click", function () {
  buildDesign().catch(function (e) { say(e.message, true); });
});
document.getElementById("modes-button").addEventListener("click", function () {
  showModes().catch(function (e) { say(e.message, true); });
});
document.getElementById("map-button").addEventListener("click", function () {
  showMap().catch(function (e) { say(e.message, true); });
});
document.getElementById("model").addEventListener("change", function (e) {
  selectModel(e.target.value).catch(function (err) { say(err.message, true); });
});
document.getElementById("upload").addEventListener("submit", async function (e) {
  e.preventDefault();
  const form = new FormData();
  for (const f of document.getElementById("files").files) form.append("files", f);
  try {
    const r = await fetch("/models", {method: "POST", headers: auth, body: form});
    const answer = await r.json();
    if (!r.ok) throw new Error(answer.message);
    await loadModels(answer.id);
  } catch (err) { say(err.message, true); }
});
loadModels(new URLSearchParams(location.search).get("model")).catch(function (e) { say(e.message, true); });
</script>
</body>
</html>
"""

__all__ = ["PAGE"]
