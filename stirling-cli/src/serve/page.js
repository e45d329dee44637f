// The page of `stirling serve`: every number comes from the Rust endpoints; this script only
// draws. The model is a family member (`cv2`) or an engine compiled from the editor
// (`@ID`); the sliders start at the model's defaults.
"use strict";
// slider ranges (widened to hold the model's default)
const SLIDERS = [
  ["Th", 350, 1000], ["Tk", 250, 400], ["Pmean", 5e4, 1e6],
  ["kd", 100, 3000], ["kp", 0, 1000], ["md", 0.02, 0.5], ["mp", 0.1, 2],
];
const GONE = "no engine compiled under this id";
const $ = (id) => document.getElementById(id);
const NS = "http://www.w3.org/2000/svg";
// the model the panels show, and the declaration it was compiled from (null: a member)
const state = { model: "cv2", hasArray: false, source: null, defaults: {} };
let anim = null;

function el(svg, name, attrs, text) {
  const e = document.createElementNS(NS, name);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  svg.appendChild(e);
  return e;
}

function buildSliders() {
  for (const [name, lo, hi] of SLIDERS) {
    const l = document.createElement("label");
    l.id = `l_${name}`;
    l.innerHTML = `${name} <input id="s_${name}" type="range" min="${lo}" max="${hi}" step="any"> <span id="v_${name}"></span>`;
    $("sliders").appendChild(l);
  }
  document.querySelectorAll("#controls input").forEach((i) => {
    i.addEventListener("change", update);
    i.addEventListener("input", () => {
      $(i.id.replace(/^s_/, "v_").replace(/^n$/, "n_v")).textContent = i.value;
    });
  });
  $("model").addEventListener("change", () => pickMember($("model").value).then(update));
  $("compile").addEventListener("click", () => compile().then((ok) => ok && update()));
  $("revert").addEventListener("click", () => pickMember($("model").value).then(update));
  $("source").addEventListener("keydown", (e) => {
    if (e.key === "Enter" && e.ctrlKey) { e.preventDefault(); $("compile").click(); }
  });
  $("source").addEventListener("input", () => { $("status").textContent = "edited, not compiled"; });
}

function setSlider(name, v) {
  const s = $("s_" + name);
  if (!s) return;
  s.min = Math.min(+s.min, v);
  s.max = Math.max(+s.max, v);
  s.value = v;
  $("v_" + name).textContent = v;
}

// the parameters and equations of the model shown; sliders to its defaults
async function loadModel() {
  const d = await (await get("/api/equations?" + modelQuery())).json();
  state.defaults = {};
  for (const p of d.params) state.defaults[p.name] = p.default;
  for (const [name] of SLIDERS) {
    const has = name in state.defaults;
    $("l_" + name).style.display = has ? "" : "none";
    if (has) setSlider(name, state.defaults[name]);
  }
  $("nlabel").style.display = state.hasArray ? "" : "none";
  $("equations").textContent = d.equations;
  return d;
}

// a family member: its declaration in the editor, its macro-built model in the panels
async function pickMember(name) {
  const d = await (await get("/api/source?model=" + name)).json();
  $("source").value = d.source;
  $("bases").textContent = Object.values(d.bases).join("\n");
  $("diagnostics").textContent = "";
  Object.assign(state, { model: name, hasArray: name === "nsection", source: null });
  const m = await loadModel();
  $("status").textContent = `the member \`${name}\` (${m.states.length} states)`;
}

// compile the editor's text; on an error the panels keep the last good model
async function compile() {
  const text = $("source").value;
  $("diagnostics").textContent = "";
  $("status").textContent = "compiling...";
  const r = await fetch(`/api/compile?n=${$("n").value}`, { method: "POST", body: text });
  let d;
  try { d = await r.json(); } catch (e) { d = { error: `${r.status} ${r.statusText}` }; }
  if (!r.ok) {
    $("status").textContent = `not compiled: the panels keep \`${state.model}\``;
    showDiagnostics(d);
    return false;
  }
  Object.assign(state, { model: "@" + d.id, hasArray: d.has_array, source: text });
  const m = await loadModel();
  $("status").textContent = `compiled \`${d.name}\`: ${m.states.length} states, ${m.params.length} parameters`;
  return true;
}

function showDiagnostics(d) {
  const box = $("diagnostics");
  const list = d.diagnostics && d.diagnostics.length ? d.diagnostics : [{ line: 0, column: 0, message: d.error, snippet: "" }];
  for (const g of list) {
    const div = document.createElement("div");
    div.className = "diagnostic";
    const at = g.line > 0 ? `${g.line}:${g.column}: ` : "";
    div.textContent = `${at}${g.message}${g.snippet ? "\n" + g.snippet : ""}`;
    if (g.line > 0) div.addEventListener("click", () => goTo(g.line, g.column));
    box.appendChild(div);
  }
  if (list[0].line > 0) goTo(list[0].line, list[0].column);
}

// put the editor's cursor at line:column (1-based)
function goTo(line, column) {
  const t = $("source"), lines = t.value.split("\n");
  let at = 0;
  for (let i = 0; i < line - 1 && i < lines.length; i++) at += lines[i].length + 1;
  at += Math.max(column - 1, 0);
  t.focus();
  t.setSelectionRange(at, at + 1);
}

function modelQuery() {
  let q = `model=${state.model}`;
  if (state.hasArray) q += `&n=${$("n").value}`;
  return q;
}

function query() {
  let q = modelQuery();
  for (const [name] of SLIDERS) {
    if (name in state.defaults) q += `&${name}=${$("s_" + name).value}`;
  }
  return q;
}

async function get(path) {
  const r = await fetch(path);
  if (!r.ok) {
    let msg = `${r.status}`;
    try { msg += ": " + (await r.json()).error; } catch (e) { /* not JSON */ }
    throw new Error(`${path.split("?")[0]}: ${msg}`);
  }
  return r;
}

async function update(retried) {
  $("error").textContent = "";
  const q = query();
  const errors = [];
  await Promise.all([
    get("/api/graph?" + q).then((r) => r.text()).then((t) => { $("graph").innerHTML = t; }),
    get("/api/linear?" + q).then((r) => r.json()).then(drawLinear),
    get("/api/cycle?" + q).then((r) => r.json()).then(drawCycle, (e) => { stopCycle(); throw e; }),
  ].map((p) => p.catch((e) => errors.push(e.message))));
  // the server forgot the engine (restarted, or it keeps only the last few): compile again
  if (!retried && state.source !== null && errors.some((e) => e.includes(GONE))) {
    $("source").value = state.source;
    if (await compile()) return update(true);
  }
  $("error").textContent = errors.join("\n");
  $("poles").dataset.ready = "1";
}

function scale(lo, hi, a, b) { const d = hi - lo || 1; return (v) => a + (v - lo) / d * (b - a); }

function axes(svg, w, h, label) {
  el(svg, "rect", { x: 50, y: 10, width: w - 60, height: h - 50, fill: "none", stroke: "#888" });
  el(svg, "text", { x: w / 2, y: h - 5, "text-anchor": "middle", "font-size": 12 }, label);
}

// symmetric log: linear within 1 of 0, logarithmic beyond (poles span 1 to 1e5 1/s)
const symlog = (v) => Math.sign(v) * Math.log10(1 + Math.abs(v));
function ticks(limit) { // 0, +-1, +-10, ... up to the decade holding `limit`
  const t = [0];
  for (let d = 1; d <= 10 * limit; d *= 10) { t.push(d, -d); if (d >= limit) break; }
  return t.sort((a, b) => a - b);
}
const tickLabel = (v) => (Math.abs(v) >= 1e4 ? `${v < 0 ? "-" : ""}1e${Math.round(Math.log10(Math.abs(v)))}` : `${v}`);

function drawLinear(d) {
  const r = d.report, svg = $("poles");
  svg.innerHTML = "";
  const W = 440, H = 360, x0 = 50, x1 = W - 10, y0 = 10, y1 = H - 40;
  const all = r.poles.concat(r.loop.open_loop_poles);
  const xr = Math.max(...all.map((p) => Math.abs(p.re)), 1), yr = Math.max(...all.map((p) => Math.abs(p.im)), 1);
  const xt = ticks(xr), yt = ticks(yr);
  const sxl = scale(symlog(xt[0]), symlog(xt[xt.length - 1]), x0, x1);
  const syl = scale(symlog(yt[0]), symlog(yt[yt.length - 1]), y1, y0);
  const sx = (v) => sxl(symlog(v)), sy = (v) => syl(symlog(v));
  // the right half plane: unstable
  el(svg, "rect", { x: sx(0), y: y0, width: x1 - sx(0), height: y1 - y0, fill: "#fbe3e3" });
  el(svg, "text", { x: x1 - 4, y: y0 + 14, "text-anchor": "end", "font-size": 11, fill: "#b00" }, "unstable");
  for (const t of xt) {
    el(svg, "line", { x1: sx(t), x2: sx(t), y1: y0, y2: y1, stroke: t === 0 ? "#888" : "#e4e4e4" });
    if (t === 0 || Math.abs(sx(t) - sx(0)) >= 16) el(svg, "text", { x: sx(t), y: y1 + 13, "text-anchor": "middle", "font-size": 10 }, tickLabel(t));
  }
  for (const t of yt) {
    el(svg, "line", { x1: x0, x2: x1, y1: sy(t), y2: sy(t), stroke: t === 0 ? "#888" : "#e4e4e4" });
    if (t === 0 || Math.abs(sy(t) - sy(0)) >= 11) el(svg, "text", { x: x0 - 3, y: sy(t) + 3, "text-anchor": "end", "font-size": 10 }, tickLabel(t));
  }
  axes(svg, W, H, "Re (1/s), symmetric log; Im (rad/s)   x closed loop, o loop broken");
  for (const p of r.loop.open_loop_poles) el(svg, "circle", { cx: sx(p.re), cy: sy(p.im), r: 5, fill: "none", stroke: "#06c", "stroke-width": 1.5 });
  for (const p of r.poles) {
    const x = sx(p.re), y = sy(p.im), c = p.re > 0 ? "#c00" : "#000";
    el(svg, "path", { d: `M${x - 4},${y - 4}L${x + 4},${y + 4}M${x - 4},${y + 4}L${x + 4},${y - 4}`, stroke: c, "stroke-width": 2 });
  }
  $("poletext").textContent = `closed-loop poles (${r.rhp_count} in the right half plane):\n` + r.poles.map(fmtPole).join("\n");
  drawBode(d.bode, r.margins);
}

function fmtPole(p) {
  const neg = p.im < 0 || Object.is(p.im, -0);
  return `${p.re.toFixed(6).padStart(14)} ${(neg ? "-" : "+") + Math.abs(p.im).toFixed(6)}j`;
}

function drawBode(b, m) {
  const svg = $("bode");
  svg.innerHTML = "";
  const W = 440, H = 360;
  axes(svg, W, H, "w (rad/s, log)   black |L| dB (left), red phase deg (right)");
  const lw = b.w.map(Math.log10);
  const sx = scale(Math.min(...lw), Math.max(...lw), 50, W - 10);
  for (let k = Math.ceil(Math.min(...lw)); k <= Math.max(...lw); k++) {
    el(svg, "line", { x1: sx(k), x2: sx(k), y1: 10, y2: H - 40, stroke: "#e4e4e4" });
    el(svg, "text", { x: sx(k), y: H - 27, "text-anchor": "middle", "font-size": 10 }, `1e${k}`);
  }
  const line = (ys, color, side) => {
    const lo = Math.min(...ys), hi = Math.max(...ys), sy = scale(lo, hi, H - 40, 10);
    el(svg, "polyline", { points: ys.map((y, i) => `${sx(lw[i])},${sy(y)}`).join(" "), fill: "none", stroke: color });
    const x = side ? W - 12 : 52, anchor = side ? "end" : "start";
    el(svg, "text", { x, y: 22, "text-anchor": anchor, "font-size": 10, fill: color }, hi.toFixed(0));
    el(svg, "text", { x, y: H - 44, "text-anchor": anchor, "font-size": 10, fill: color }, lo.toFixed(0));
  };
  line(b.mag_db, "#000", false);
  line(b.phase_deg, "#c00", true);
  const f = (v, p) => (v === null || v === undefined ? "none" : v.toFixed(p));
  $("margins").textContent = `Gm = ${f(m.gain_db, 3)} dB at ${f(m.phase_crossover_rad_s, 2)} rad/s\nPm = ${f(m.phase_deg, 2)} deg at ${f(m.gain_crossover_rad_s, 2)} rad/s`;
}

function stopCycle() {
  if (anim) cancelAnimationFrame(anim);
  anim = null;
  $("engine").innerHTML = "";
  $("pv").innerHTML = "";
  $("cycletext").textContent = "no limit cycle";
}

function drawCycle(c) {
  stopCycle();
  $("cycletext").textContent = `f = ${c.frequency_hz.toFixed(3)} Hz, work ${c.work_j.toExponential(4)} J/cycle\n` +
    `power ${c.power_w.toFixed(4)} W, displacer ahead by ${c.phase_deg.toFixed(1)} deg`;
  const eng = $("engine"), pv = $("pv");
  // the loop of the vessel doing the most work (a gas space; the bounce space does little)
  const work = c.vessel_work_j || [];
  const k = work.reduce((b, w, i) => (Math.abs(w) > Math.abs(work[b]) ? i : b), 0);
  const loop = c.pv[k] || [];
  const vs = loop.map((q) => q[0] * 1e6), ps = loop.map((q) => q[1] / 1e3);
  const W = 360, H = 360;
  const sx = scale(Math.min(...vs), Math.max(...vs), 60, W - 20), sy = scale(Math.min(...ps), Math.max(...ps), H - 50, 20);
  axes(pv, W, H, `p (kPa) against V (cm^3) of ${c.vessels[k] || "the gas"}`);
  for (const [v, y] of [[Math.min(...ps), H - 50], [Math.max(...ps), 20]]) el(pv, "text", { x: 47, y: y + 3, "text-anchor": "end", "font-size": 10 }, v.toFixed(1));
  for (const [v, x] of [[Math.min(...vs), 60], [Math.max(...vs), W - 20]]) el(pv, "text", { x, y: H - 27, "text-anchor": "middle", "font-size": 10 }, v.toFixed(1));
  // the whole loop faint, the part run so far bold
  el(pv, "polyline", { points: vs.map((v, i) => `${sx(v)},${sy(ps[i])}`).join(" "), fill: "none", stroke: "#cde" });
  const trace = el(pv, "polyline", { fill: "none", stroke: "#06c", "stroke-width": 2 });
  const dot = el(pv, "circle", { r: 4, fill: "#c00" });
  const amp = Math.max(c.x_amp, c.y_amp, 1e-9);
  el(eng, "rect", { x: 60, y: 10, width: 80, height: 300, fill: "none", stroke: "#888" });
  const disp = el(eng, "rect", { x: 65, width: 70, height: 40, fill: "#e8a33c" });
  const pist = el(eng, "rect", { x: 65, width: 70, height: 30, fill: "#777" });
  el(eng, "text", { x: 100, y: 330, "text-anchor": "middle", "font-size": 11 }, "displacer (orange)");
  el(eng, "text", { x: 100, y: 345, "text-anchor": "middle", "font-size": 11 }, "piston (grey)");
  const N = loop.length, t0 = performance.now(), per = 2000; // one cycle shown over 2 s
  const draw = (i) => {
    disp.setAttribute("y", 80 - (c.x[i] || 0) / amp * 40);
    pist.setAttribute("y", 220 - (c.y[i] || 0) / amp * 40);
    trace.setAttribute("points", vs.slice(0, i + 1).map((v, k) => `${sx(v)},${sy(ps[k])}`).join(" "));
    if (loop[i]) { dot.setAttribute("cx", sx(vs[i])); dot.setAttribute("cy", sy(ps[i])); }
  };
  draw(N - 1);
  const step = (t) => {
    draw(Math.floor(((t - t0) % per) / per * N) % N);
    anim = requestAnimationFrame(step);
  };
  anim = requestAnimationFrame(step);
}

// a URL fragment sets the page up before the first update:
// `#model=cv2&n=3&Th=700` picks and moves; `&insert=TEXT` (percent-encoded) inserts TEXT
// before the declaration's last `}` in the editor and compiles it, as the button does.
function fragment() {
  const f = {};
  for (const pair of location.hash.slice(1).split("&")) {
    const at = pair.indexOf("=");
    if (at > 0) f[pair.slice(0, at)] = decodeURIComponent(pair.slice(at + 1));
  }
  return f;
}

async function start() {
  buildSliders();
  const f = fragment();
  if (f.model) $("model").value = f.model;
  if (f.n) { $("n").value = f.n; $("n_v").textContent = f.n; }
  await pickMember($("model").value);
  if (f.insert) {
    const t = $("source").value, end = t.lastIndexOf("}");
    $("source").value = t.slice(0, end) + f.insert + "\n" + t.slice(end);
    await compile(); // what the Compile button does (then the update below)
  }
  for (const [name] of SLIDERS) if (f[name] !== undefined) setSlider(name, +f[name]);
  await update();
}

start().catch((e) => { $("error").textContent = e.message; });
