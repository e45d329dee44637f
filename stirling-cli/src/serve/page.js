// The page of `stirling serve`: every number comes from the Rust endpoints; this script only
// draws. Sliders: value = default * factor, over the range below.
"use strict";
const SLIDERS = [
  ["Th", 600, 350, 1000], ["Tk", 300, 250, 400], ["Pmean", 101325, 5e4, 1e6],
  ["kd", 650.74, 100, 3000], ["kp", 61.482, 0, 1000], ["md", 0.08228, 0.02, 0.5], ["mp", 0.33363, 0.1, 2],
];
const $ = (id) => document.getElementById(id);
const NS = "http://www.w3.org/2000/svg";
let anim = null;

function el(svg, name, attrs, text) {
  const e = document.createElementNS(NS, name);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  svg.appendChild(e);
  return e;
}

function buildSliders() {
  for (const [name, def, lo, hi] of SLIDERS) {
    const l = document.createElement("label");
    l.innerHTML = `${name} <input id="s_${name}" type="range" min="${lo}" max="${hi}" step="any" value="${def}"> <span id="v_${name}">${def}</span>`;
    $("sliders").appendChild(l);
  }
  document.querySelectorAll("input,select").forEach((i) => i.addEventListener("change", update));
  document.querySelectorAll("input").forEach((i) => i.addEventListener("input", () => {
    $(i.id.replace(/^s_/, "v_").replace(/^n$/, "n_v")).textContent = i.value;
  }));
}

function query() {
  const m = $("model").value;
  let q = `model=${m}`;
  if (m === "nsection") q += `&n=${$("n").value}`;
  for (const [name] of SLIDERS) {
    q += `&${name}=${$("s_" + name).value}`;
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

async function update() {
  $("nlabel").style.display = $("model").value === "nsection" ? "" : "none";
  $("error").textContent = "";
  const q = query();
  const errors = [];
  await Promise.all([
    get("/api/graph?" + q).then((r) => r.text()).then((t) => { $("graph").innerHTML = t; }),
    get("/api/linear?" + q).then((r) => r.json()).then(drawLinear),
    get("/api/cycle?" + q).then((r) => r.json()).then(drawCycle, (e) => { stopCycle(); throw e; }),
  ].map((p) => p.catch((e) => errors.push(e.message))));
  $("error").textContent = errors.join("\n");
}

function scale(lo, hi, a, b) { const d = hi - lo || 1; return (v) => a + (v - lo) / d * (b - a); }

function axes(svg, w, h, label) {
  el(svg, "rect", { x: 40, y: 10, width: w - 50, height: h - 40, fill: "none", stroke: "#888" });
  el(svg, "text", { x: w / 2, y: h - 5, "text-anchor": "middle", "font-size": 12 }, label);
}

function fmtPole(p) {
  const neg = p.im < 0 || Object.is(p.im, -0);
  return `${p.re.toFixed(6).padStart(14)} ${(neg ? "-" : "+") + Math.abs(p.im).toFixed(6)}j`;
}

function drawLinear(d) {
  const r = d.report, svg = $("poles");
  svg.innerHTML = "";
  axes(svg, 420, 320, "Re (1/s)  [x closed loop, o open loop]");
  const all = r.poles.concat(r.loop.open_loop_poles);
  const re = all.map((p) => p.re), im = all.map((p) => p.im);
  const xr = Math.max(...re.map(Math.abs), 1), yr = Math.max(...im.map(Math.abs), 1);
  const sx = scale(-xr, xr, 45, 405), sy = scale(-yr, yr, 275, 15);
  el(svg, "line", { x1: sx(0), x2: sx(0), y1: 10, y2: 280, stroke: "#bbb" });
  el(svg, "line", { x1: 40, x2: 410, y1: sy(0), y2: sy(0), stroke: "#bbb" });
  for (const p of r.loop.open_loop_poles) el(svg, "circle", { cx: sx(p.re), cy: sy(p.im), r: 4, fill: "none", stroke: "#06c" });
  for (const p of r.poles) {
    const x = sx(p.re), y = sy(p.im), c = p.re > 0 ? "#c00" : "#000";
    el(svg, "path", { d: `M${x - 4},${y - 4}L${x + 4},${y + 4}M${x - 4},${y + 4}L${x + 4},${y - 4}`, stroke: c, "stroke-width": 2 });
  }
  $("poletext").textContent = `closed-loop poles (${r.rhp_count} in the right half plane):\n` + r.poles.map(fmtPole).join("\n");
  drawBode(d.bode, r.margins);
}

function drawBode(b, m) {
  const svg = $("bode");
  svg.innerHTML = "";
  axes(svg, 420, 320, "w (rad/s, log)  [black |L| dB, red phase deg]");
  const lw = b.w.map(Math.log10);
  const sx = scale(Math.min(...lw), Math.max(...lw), 45, 405);
  const line = (ys, color) => {
    const sy = scale(Math.min(...ys), Math.max(...ys), 275, 15);
    el(svg, "polyline", { points: ys.map((y, i) => `${sx(lw[i])},${sy(y)}`).join(" "), fill: "none", stroke: color });
  };
  line(b.mag_db, "#000");
  line(b.phase_deg, "#c00");
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
  const loop = c.pv[c.pv.length - 1] || [];
  const vs = loop.map((q) => q[0]), ps = loop.map((q) => q[1]);
  const sx = scale(Math.min(...vs), Math.max(...vs), 45, 305), sy = scale(Math.min(...ps), Math.max(...ps), 275, 15);
  axes(pv, 320, 320, `p-V loop of ${c.vessels[c.vessels.length - 1] || "the gas"}`);
  const trace = el(pv, "polyline", { fill: "none", stroke: "#06c", "stroke-width": 2 });
  const dot = el(pv, "circle", { r: 4, fill: "#c00" });
  const amp = Math.max(c.x_amp, c.y_amp, 1e-9);
  el(eng, "rect", { x: 60, y: 10, width: 80, height: 300, fill: "none", stroke: "#888" });
  const disp = el(eng, "rect", { x: 65, width: 70, height: 40, fill: "#e8a33c" });
  const pist = el(eng, "rect", { x: 65, width: 70, height: 30, fill: "#777" });
  el(eng, "text", { x: 100, y: 325, "text-anchor": "middle", "font-size": 11 }, "displacer (orange), piston");
  const N = loop.length, t0 = performance.now(), per = 2000; // one cycle shown over 2 s
  const step = (t) => {
    const i = Math.floor(((t - t0) % per) / per * N) % N;
    const x = c.x[i] || 0, y = c.y[i] || 0;
    disp.setAttribute("y", 80 - x / amp * 40);
    pist.setAttribute("y", 220 - y / amp * 40);
    trace.setAttribute("points", loop.slice(0, i + 1).map((q) => `${sx(q[0])},${sy(q[1])}`).join(" "));
    if (loop[i]) { dot.setAttribute("cx", sx(loop[i][0])); dot.setAttribute("cy", sy(loop[i][1])); }
    anim = requestAnimationFrame(step);
  };
  anim = requestAnimationFrame(step);
}

// a URL fragment `#model=cv2&Th=700` sets the controls before the first update
function fromFragment() {
  for (const pair of location.hash.slice(1).split("&")) {
    const [k, v] = pair.split("=");
    if (k === "model") $("model").value = v;
    else if (k === "n") $("n").value = v;
    else if ($("s_" + k)) { $("s_" + k).value = v; $("v_" + k).textContent = v; }
  }
}

buildSliders();
fromFragment();
update();
