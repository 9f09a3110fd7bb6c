#include "renderer/view/view_assets.h"

namespace ofl {

const char* view_style() {
  return R"CSS(
body { font: 13px/1.35 system-ui, sans-serif; margin: 0; color: #222; background: #f4f4f2; }
header { display: flex; flex-wrap: wrap; gap: 14px; align-items: center; padding: 8px 12px; background: #fff; border-bottom: 1px solid #ddd; }
header h1 { font-size: 15px; margin: 0 12px 0 0; font-weight: 600; }
main { display: flex; gap: 12px; padding: 12px; align-items: flex-start; }
#panels { display: flex; gap: 10px; flex-wrap: wrap; align-content: flex-start; flex: 0 0 auto; }
figure { margin: 0; background: #fff; border: 1px solid #ddd; padding: 6px; }
figcaption { font-size: 12px; color: #555; margin-bottom: 4px; max-width: 640px; overflow-wrap: anywhere; }
.stage { position: relative; line-height: 0; cursor: crosshair; }
.stage canvas { width: 100%; image-rendering: pixelated; }
.stage canvas.over { position: absolute; left: 0; top: 0; height: 100%; }
#side { background: #fff; border: 1px solid #ddd; padding: 8px; width: 520px; }
#plots svg { width: 500px; height: 230px; display: block; }
#plots svg text { font-size: 11px; fill: #333; }
.legend span { display: inline-block; margin-right: 10px; font-size: 12px; }
.legend i { display: inline-block; width: 14px; height: 3px; margin-right: 4px; vertical-align: middle; }
table { border-collapse: collapse; font-size: 12px; margin-top: 6px; }
td, th { padding: 1px 6px; text-align: right; border-bottom: 1px solid #eee; }
th { text-align: left; font-weight: 600; }
.notes { font-size: 12px; color: #666; margin: 4px 0 0; padding-left: 16px; }
#materials { flex-basis: 100%; }
#materials span { display: inline-block; margin-right: 10px; }
#materials i { display: inline-block; width: 10px; height: 10px; margin-right: 3px; vertical-align: middle; }
#errors { color: #b00; white-space: pre-wrap; }
.muted { color: #777; }
)CSS";
}

const char* view_body() {
  return R"HTML(<header><h1 id="title">oralfluor view</h1>
<label>show <select id="mode"><option value="srgb">sRGB preview</option><option value="fluo">fluorescence only</option><option value="band">one band</option></select></label>
<label>band <input id="band" type="range" min="0" max="0" value="0"> <span id="bandlabel"></span></label>
<label><input id="overlay" type="checkbox"> materials</label>
<label>brightness <input id="gain" type="range" min="-4" max="4" step="0.25" value="0"></label>
<label><input id="logy" type="checkbox"> log plot</label>
<span class="muted">hover: spectrum &middot; click: pin &middot; drag: region</span></header>
<main><div id="panels"></div>
<section id="side"><div id="plots"></div>
<table id="readout"></table><div id="region"></div><div id="errors"></div></section></main>
)HTML";
}

const char* view_script() {
  return R"JS(
"use strict";
const oflErrors = [];
window.oflErrors = oflErrors;
window.addEventListener("error", e => { oflErrors.push(String(e.message)); showErrors(); });
function showErrors() { document.getElementById("errors").textContent = oflErrors.join("\n"); }
const META = JSON.parse(document.getElementById("ofl-meta").textContent);
const PALETTE = ["#e6194b","#3cb44b","#4363d8","#f58231","#911eb4","#42d4f4","#f032e6","#bfef45","#fabed4","#469990","#dcbeff","#9a6324","#800000","#aaffc3","#808000","#000075"];
const COLOURS = ["#222", "#1a7f37"];

function bytesOf(id) {
  const el = document.getElementById(id);
  if (!el) return null;
  const s = atob(el.textContent), out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; ++i) out[i] = s.charCodeAt(i);
  return out;
}
const HALF = (() => {  // float16 bit pattern -> value
  const t = new Float32Array(65536);
  for (let h = 0; h < 65536; ++h) {
    const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 31, m = h & 1023;
    t[h] = e === 0 ? s * m * Math.pow(2, -24) : e === 31 ? (m ? NaN : s * Infinity) : s * (1024 + m) * Math.pow(2, e - 25);
  }
  return t;
})();
function cubeOf(id, scale) {
  const b = bytesOf(id);
  if (!b) return null;
  const n = b.length / 2, c = scale.length, out = new Float32Array(n);
  for (let i = 0; i < n; ++i) out[i] = HALF[b[2 * i] | (b[2 * i + 1] << 8)] * scale[i % c];
  return out;
}

const images = META.images.map((m, i) => ({
  m, i,
  cube: cubeOf("ofl-" + i + "-cube", m.scale),
  fluo: m.has_fluo ? cubeOf("ofl-" + i + "-fluo", m.fscale) : null,
  preview: bytesOf("ofl-" + i + "-preview"),
  fpreview: m.has_fluo ? bytesOf("ofl-" + i + "-fpreview") : null,
  material: m.has_material ? bytesOf("ofl-" + i + "-material") : null,
}));

const state = { mode: "srgb", band: 0, overlay: false, gain: 1, logy: false, hover: null, pinned: null, region: null, drag: null };
window.oflView = { state, images, spectrumAt, regionStats };

// Values of image `im` at grid pixel (x, y): {values, fluorescence} (k x k means when decimated).
function spectrumAt(im, x, y) {
  const m = im.m, c = m.channels.length;
  const cx = Math.min(m.dw - 1, Math.floor(x / m.k)), cy = Math.min(m.dh - 1, Math.floor(y / m.k));
  const o = (cy * m.dw + cx) * c;
  return { values: Array.from(im.cube.subarray(o, o + c)), fluorescence: im.fluo ? Array.from(im.fluo.subarray(o, o + c)) : null };
}
// Mean, standard deviation (over the region's cells) and chromaticity of a rectangle of grid pixels.
function regionStats(im, r) {
  const m = im.m, c = m.channels.length;
  const x0 = Math.floor(r.x0 / m.k), x1 = Math.floor((r.x1 - 1) / m.k), y0 = Math.floor(r.y0 / m.k), y1 = Math.floor((r.y1 - 1) / m.k);
  const sum = new Float64Array(c), sq = new Float64Array(c), fsum = new Float64Array(c);
  let n = 0;
  for (let y = y0; y <= y1; ++y) for (let x = x0; x <= x1; ++x) {
    const o = (y * m.dw + x) * c; ++n;
    for (let j = 0; j < c; ++j) { const v = im.cube[o + j]; sum[j] += v; sq[j] += v * v; if (im.fluo) fsum[j] += im.fluo[o + j]; }
  }
  const mean = Array.from(sum, s => s / n), std = Array.from(sq, (s, j) => Math.sqrt(Math.max(0, s / n - mean[j] * mean[j]) * (n > 1 ? n / (n - 1) : 0)));
  return { n, mean, std, fluorescence: im.fluo ? Array.from(fsum, s => s / n) : null, colour: colourOf(im, mean) };
}
function colourOf(im, v) {
  const dot = w => w.reduce((s, x, j) => s + x * v[j], 0);
  const rgb = im.m.to_rgb.map(dot), t = rgb[0] + rgb[1] + rgb[2];
  const out = { rgb, r: t > 0 ? rgb[0] / t : NaN, g: t > 0 ? rgb[1] / t : NaN };
  if (im.m.to_xyz) { const X = im.m.to_xyz.map(dot), s = X[0] + X[1] + X[2]; out.x = s > 0 ? X[0] / s : NaN; out.y = s > 0 ? X[1] / s : NaN; }
  return out;
}

// ---- drawing -------------------------------------------------------------------------------
function setupPanels() {
  const panels = document.getElementById("panels");
  const width = images.length > 1 ? 440 : 600;
  panels.style.width = images.length * (width + 24) + "px";
  for (const im of images) {
    const fig = document.createElement("figure");
    fig.innerHTML = "<figcaption></figcaption><div class=stage><canvas class=img></canvas><canvas class=over></canvas></div><ul class=notes></ul>";
    fig.querySelector("figcaption").textContent = im.m.file + " (" + im.m.kind + ", " + im.m.width + " x " + im.m.height + ")";
    for (const n of im.m.notes) { const li = document.createElement("li"); li.textContent = n; fig.querySelector(".notes").appendChild(li); }
    fig.style.width = width + "px";
    panels.appendChild(fig);
    im.canvas = fig.querySelector("canvas.img");
    im.over = fig.querySelector("canvas.over");
    im.canvas.width = im.m.pw; im.canvas.height = im.m.ph;
    im.over.width = Math.min(2048, im.m.pw * 2); im.over.height = Math.round(im.over.width * im.m.ph / im.m.pw);
    attachMouse(im);
  }
  const maxBands = Math.max(...images.map(im => im.m.channels.length));
  document.getElementById("band").max = String(maxBands - 1);
  document.getElementById("band").value = String(Math.floor(maxBands / 2));
  state.band = Math.floor(maxBands / 2);
  if (!images.some(im => im.fluo)) document.querySelector("#mode option[value=fluo]").disabled = true;
  if (!images.some(im => im.material)) document.getElementById("overlay").disabled = true;
}

function drawImage(im) {
  const m = im.m, ctx = im.canvas.getContext("2d"), img = ctx.createImageData(m.pw, m.ph), d = img.data;
  const g = state.gain, enc = v => 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
  const lin = v => { v /= 255; return v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4); };
  if (state.mode === "band") {
    const b = Math.min(state.band, m.channels.length - 1), c = m.channels.length, s = 1 / (m.scale[b] || 1);
    for (let y = 0; y < m.ph; ++y) for (let x = 0; x < m.pw; ++x) {
      const gx = Math.min(m.dw - 1, Math.floor(x * m.kp / m.k)), gy = Math.min(m.dh - 1, Math.floor(y * m.kp / m.k));
      const v = enc(Math.min(1, Math.max(0, im.cube[(gy * m.dw + gx) * c + b] * s * g))), o = (y * m.pw + x) * 4;
      d[o] = d[o + 1] = d[o + 2] = v; d[o + 3] = 255;
    }
  } else {
    const src = state.mode === "fluo" && im.fpreview ? im.fpreview : im.preview;
    const lut = new Uint8ClampedArray(256);
    for (let i = 0; i < 256; ++i) lut[i] = g === 1 ? i : enc(Math.min(1, lin(i) * g));
    for (let i = 0, n = m.pw * m.ph; i < n; ++i) {
      d[4 * i] = lut[src[3 * i]]; d[4 * i + 1] = lut[src[3 * i + 1]]; d[4 * i + 2] = lut[src[3 * i + 2]]; d[4 * i + 3] = 255;
    }
  }
  if (state.overlay && im.material) {
    for (let i = 0, n = m.pw * m.ph; i < n; ++i) {
      const id = im.material[i] - 2;
      if (id < 0) continue;
      const col = PALETTE[id % PALETTE.length], r = parseInt(col.substr(1, 2), 16), gg = parseInt(col.substr(3, 2), 16), b = parseInt(col.substr(5, 2), 16);
      d[4 * i] = 0.55 * d[4 * i] + 0.45 * r; d[4 * i + 1] = 0.55 * d[4 * i + 1] + 0.45 * gg; d[4 * i + 2] = 0.55 * d[4 * i + 2] + 0.45 * b;
    }
  }
  ctx.putImageData(img, 0, 0);
}

function drawOverlay(im) {
  const ctx = im.over.getContext("2d"), sx = im.over.width / im.m.width, sy = im.over.height / im.m.height;
  ctx.clearRect(0, 0, im.over.width, im.over.height);
  const mark = (p, col) => {
    if (!p) return;
    const x = (p.u * im.m.width + 0.5) * sx, y = (p.v * im.m.height + 0.5) * sy;
    ctx.strokeStyle = col; ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(x - 9, y); ctx.lineTo(x - 3, y); ctx.moveTo(x + 3, y); ctx.lineTo(x + 9, y);
    ctx.moveTo(x, y - 9); ctx.lineTo(x, y - 3); ctx.moveTo(x, y + 3); ctx.lineTo(x, y + 9); ctx.stroke();
  };
  mark(state.hover, "#ff0"); mark(state.pinned, "#f0f");
  const r = state.drag || state.region;
  if (r) {
    ctx.strokeStyle = "#0ff"; ctx.lineWidth = 1.5;
    ctx.strokeRect(r.u0 * im.m.width * sx, r.v0 * im.m.height * sy, (r.u1 - r.u0) * im.m.width * sx, (r.v1 - r.v0) * im.m.height * sy);
  }
}

// Grid pixel of `im` at a normalised position (u, v) in [0, 1): the shared cursor of all panels.
function gridPixel(im, p) { return { x: Math.min(im.m.width - 1, Math.floor(p.u * im.m.width)), y: Math.min(im.m.height - 1, Math.floor(p.v * im.m.height)) }; }
function rectOf(im, r) {
  const x0 = Math.floor(r.u0 * im.m.width), y0 = Math.floor(r.v0 * im.m.height);
  return { x0, y0, x1: Math.max(x0 + 1, Math.ceil(r.u1 * im.m.width)), y1: Math.max(y0 + 1, Math.ceil(r.v1 * im.m.height)) };
}

function attachMouse(im) {
  const pos = e => {
    const b = im.over.getBoundingClientRect();
    return { u: Math.min(0.999999, Math.max(0, (e.clientX - b.left) / b.width)), v: Math.min(0.999999, Math.max(0, (e.clientY - b.top) / b.height)) };
  };
  im.over.addEventListener("mousedown", e => { state.dragStart = pos(e); e.preventDefault(); });
  im.over.addEventListener("mousemove", e => {
    const p = pos(e);
    state.hover = p;
    if (state.dragStart && (Math.abs(p.u - state.dragStart.u) * im.m.width > 2 || Math.abs(p.v - state.dragStart.v) * im.m.height > 2))
      state.drag = { u0: Math.min(p.u, state.dragStart.u), v0: Math.min(p.v, state.dragStart.v), u1: Math.max(p.u, state.dragStart.u), v1: Math.max(p.v, state.dragStart.v) };
    refresh(false);
  });
  im.over.addEventListener("mouseup", e => {
    if (state.drag) { state.region = state.drag; state.drag = null; }
    else state.pinned = pos(e);
    state.dragStart = null;
    refresh(false);
  });
  im.over.addEventListener("mouseleave", () => { state.hover = null; refresh(false); });
}

// ---- plot and tables ----------------------------------------------------------------------
function fmt(v) { return !isFinite(v) ? String(v) : v === 0 ? "0" : Math.abs(v) >= 1e4 || Math.abs(v) < 1e-3 ? v.toExponential(4) : v.toPrecision(5); }

// One plot per image (their units differ): series of image i go to the i-th plot.
function plotAll(series) {
  const box = document.getElementById("plots");
  box.innerHTML = images.map(() => `<svg viewBox="0 0 500 230"></svg><div class="legend"></div>`).join("");
  const svgs = box.querySelectorAll("svg"), legends = box.querySelectorAll(".legend");
  images.forEach((im, i) => plot(svgs[i], legends[i], series.filter(s => s.image === i), im));
}

function plot(svg, legend, series, im) {
  const W = 500, H = 230, L = 62, R = 10, T = 22, B = 34, m = im.m, nm = m.wavelengths.length > 0;
  const xs = nm ? m.wavelengths : m.channels.map((_, i) => i);
  // Log plot: decades below the largest value, down to 1e-4 of it.
  const peak = Math.max(1e-30, ...series.flatMap(s => s.y.concat(s.hi || [])).filter(isFinite));
  const tr = state.logy ? v => Math.log10(Math.max(v, peak * 1e-4)) : v => v;
  series = series.map(se => Object.assign({}, se, { y: se.y.map(tr), lo: se.lo && se.lo.map(tr), hi: se.hi && se.hi.map(tr) }));
  const all = series.flatMap(s => s.y.concat(s.lo || [], s.hi || [])).filter(isFinite);
  const ymin = !all.length ? 0 : state.logy ? Math.min(...all) : Math.min(0, ...all);
  const ymax = all.length && Math.max(...all) > ymin ? Math.max(...all) : ymin + 1, x0 = xs[0];
  const x1 = xs[xs.length - 1] === x0 ? x0 + 1 : xs[xs.length - 1];
  const X = x => L + (W - L - R) * (x - x0) / (x1 - x0), Y = y => H - B - (H - T - B) * (y - ymin) / (ymax - ymin);
  let s = `<rect x="${L}" y="${T}" width="${W - L - R}" height="${H - T - B}" fill="none" stroke="#bbb"/>`;
  s += `<text x="${L}" y="${T - 7}">[${im.i + 1}] ${m.kind}, ${m.units}</text>`;
  for (let i = 0; i <= 4; ++i) { const y = ymin + (ymax - ymin) * i / 4; s += `<text x="${L - 4}" y="${Y(y) + 4}" text-anchor="end">${fmt(state.logy ? Math.pow(10, y) : y)}</text>`; }
  (nm ? niceTicks(x0, x1) : xs).forEach((t, i) => { s += `<text x="${X(t)}" y="${H - B + 14}" text-anchor="middle">${nm ? t : m.channels[i]}</text>`; });
  s += `<text x="${(L + W - R) / 2}" y="${H - 4}" text-anchor="middle">${nm ? "wavelength (nm)" : "channel"}</text>`;
  for (const se of series) {
    if (se.lo) {
      const pts = xs.map((x, i) => `${X(x)},${Y(se.hi[i])}`).concat(xs.map((x, i) => `${X(x)},${Y(se.lo[i])}`).reverse());
      s += `<polygon points="${pts.join(" ")}" fill="${se.colour}" opacity="0.15"/>`;
    }
    s += `<polyline points="${xs.map((x, i) => `${X(x)},${Y(se.y[i])}`).join(" ")}" fill="none" stroke="${se.colour}" stroke-width="1.6"/>`;
    if (!nm) s += xs.map((x, i) => `<circle cx="${X(x)}" cy="${Y(se.y[i])}" r="3" fill="${se.colour}"/>`).join("");
  }
  if (!series.length) s += `<text x="${(L + W - R) / 2}" y="${(T + H - B) / 2}" text-anchor="middle" class="muted">hover over an image</text>`;
  svg.innerHTML = s;
  legend.innerHTML = series.map(se => `<span><i style="background:${se.colour}"></i>${se.name}</span>`).join("");
}
function niceTicks(a, b) {
  const step = [10, 20, 50, 100, 200].find(s => (b - a) / s <= 8) || 500, out = [];
  for (let t = Math.ceil(a / step) * step; t <= b; t += step) out.push(t);
  return out;
}

function seriesFor(im, vals, name, colour, extra) {
  return Object.assign({ image: im.i, y: vals, name, colour }, extra || {});
}

function refresh(redraw) {
  if (redraw) images.forEach(drawImage);
  images.forEach(drawOverlay);
  const p = state.hover || state.pinned, series = [], rows = [];
  const table = document.getElementById("readout");
  if (p) {
    images.forEach((im, i) => {
      const q = gridPixel(im, p), s = spectrumAt(im, q.x, q.y);
      series.push(seriesFor(im, s.values, im.m.kind + " at " + q.x + ", " + q.y, COLOURS[0]));
      if (s.fluorescence) series.push(seriesFor(im, s.fluorescence, "fluorescence", COLOURS[1]));
      const c = colourOf(im, s.values), mat = materialAt(im, q);
      rows.push({ image: i, x: q.x, y: q.y, values: s.values, fluorescence: s.fluorescence, r: c.r, g: c.g, cx: c.x, cy: c.y, material: mat });
    });
  }
  if (state.region) {
    images.forEach((im, i) => {
      const st = regionStats(im, rectOf(im, state.region));
      series.push(seriesFor(im, st.mean, "region mean \u00b1 sd", "#1f5fbf",
                            { lo: st.mean.map((v, j) => v - st.std[j]), hi: st.mean.map((v, j) => v + st.std[j]) }));
    });
  }
  plotAll(series);
  renderReadout(table, rows);
  renderRegion();
}

function materialAt(im, q) {
  if (!im.material) return null;
  const px = Math.min(im.m.pw - 1, Math.floor(q.x / im.m.kp)), py = Math.min(im.m.ph - 1, Math.floor(q.y / im.m.kp));
  const id = im.material[py * im.m.pw + px] - 2;
  return id === -2 ? "LED" : id === -1 ? "none" : (im.m.material_names[id] || "material " + id);
}

function renderReadout(table, rows) {
  table.dataset.rows = JSON.stringify(rows);
  if (!rows.length) { table.innerHTML = "<tr><td class=muted>hover over an image</td></tr>"; return; }
  const im0 = images[rows[0].image], c = im0.m.channels.length;
  let h = "<tr><th>pixel</th>" + rows.map(r => `<th>[${r.image + 1}] ${r.x}, ${r.y}${r.material ? " " + r.material : ""}</th>`).join("") + "</tr>";
  h += "<tr><th>(r, g)</th>" + rows.map(r => `<td>${fmt(r.r)}, ${fmt(r.g)}</td>`).join("") + "</tr>";
  if (rows.some(r => r.cx !== undefined)) h += "<tr><th>CIE (x, y)</th>" + rows.map(r => `<td>${r.cx === undefined ? "-" : fmt(r.cx) + ", " + fmt(r.cy)}</td>`).join("") + "</tr>";
  const b = Math.min(state.band, c - 1);
  h += `<tr><th>${im0.m.channels[b]} (${im0.m.units})</th>` + rows.map(r => `<td>${fmt(r.values[b])}</td>`).join("") + "</tr>";
  if (rows[0].fluorescence) h += `<tr><th>fluorescence at ${im0.m.channels[b]}</th>` + rows.map(r => `<td>${r.fluorescence ? fmt(r.fluorescence[b]) : "-"}</td>`).join("") + "</tr>";
  table.innerHTML = h;
}

function renderRegion() {
  const el = document.getElementById("region");
  if (!state.region) { el.innerHTML = ""; el.dataset.stats = "[]"; return; }
  const out = images.map(im => { const r = rectOf(im, state.region), st = regionStats(im, r); return Object.assign({ rect: [r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0] }, st); });
  el.dataset.stats = JSON.stringify(out);
  el.innerHTML = "<table><tr><th>region</th><th>x, y, w, h</th><th>cells</th><th>(r, g)</th><th>CIE (x, y)</th></tr>" +
    out.map((s, i) => `<tr><td>[${i + 1}]</td><td>${s.rect.join(", ")}</td><td>${s.n}</td><td>${fmt(s.colour.r)}, ${fmt(s.colour.g)}</td><td>${s.colour.x === undefined ? "-" : fmt(s.colour.x) + ", " + fmt(s.colour.y)}</td></tr>`).join("") + "</table>";
}

function controls() {
  const band = document.getElementById("band"), label = () => {
    const im = images[0], b = Math.min(state.band, im.m.channels.length - 1);
    document.getElementById("bandlabel").textContent = im.m.channels[b];
  };
  document.getElementById("mode").addEventListener("change", e => { state.mode = e.target.value; refresh(true); });
  band.addEventListener("input", e => { state.band = +e.target.value; label(); if (state.mode === "band") refresh(true); else refresh(false); });
  document.getElementById("overlay").addEventListener("change", e => { state.overlay = e.target.checked; refresh(true); });
  document.getElementById("gain").addEventListener("input", e => { state.gain = Math.pow(2, +e.target.value); refresh(true); });
  document.getElementById("logy").addEventListener("change", e => { state.logy = e.target.checked; refresh(false); });
  label();
  const legend = images.filter(im => im.material).map(im => im.m.material_names.map((n, j) => `<span><i style="background:${PALETTE[j % PALETTE.length]}"></i>${n}</span>`).join(""));
  if (legend.length) document.getElementById("panels").insertAdjacentHTML("beforeend", `<div id="materials" class="muted">${legend[0]}</div>`);
}

document.getElementById("title").textContent = "oralfluor view: " + META.title;
setupPanels();
controls();
refresh(true);
document.body.dataset.loadMs = String(Math.round(performance.now()));
document.body.dataset.ready = "1";
)JS";
}

}  // namespace ofl
