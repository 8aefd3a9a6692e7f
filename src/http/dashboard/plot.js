// Explorable plots of a sweep's points, drawn in the page (the downloads keep the server's
// static SVG): any quantity against any varied input, one line per value of the others in a
// sequential colour map, linear or log axes, hover to read a point with its units, drag to
// zoom, and a heat map when two inputs vary. Plain JavaScript, no dependency; it uses
// `scaleFor`, `readable`, `unitsOf`, `valueAt`, `isSolved`, `element` and `SVG` from app.js
// (loaded before it).
"use strict";

const PLOT = { width: 720, height: 420, left: 78, right: 20, top: 16, bottom: 52 };
/** Line plots drawn so far: each one's clip path has its own id. */
let linePlotsDrawn = 0;

/** viridis at 9 stops: ordered, readable in grey, safe for colour-blind readers. */
const VIRIDIS = ["#440154", "#472d7b", "#3b528b", "#2c728e", "#21918c", "#28ae80", "#5ec962", "#addc30", "#fde725"];

/** The colour at `t` ∈ [0, 1] of the sequential map. */
function sequential(t) {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1);
  const i = Math.min(Math.floor(x), VIRIDIS.length - 2);
  const [a, b] = [VIRIDIS[i], VIRIDIS[i + 1]].map((c) => [1, 3, 5].map((k) => parseInt(c.slice(k, k + 2), 16)));
  const mix = a.map((v, k) => Math.round(v + (b[k] - v) * (x - i)));
  return `rgb(${mix.join(",")})`;
}

/** Scalar paths of `object` (`a.b`), numbers only. */
function numericPaths(object, prefix = "") {
  const out = [];
  for (const [key, value] of Object.entries(object || {})) {
    if (typeof value === "number") out.push(prefix + key);
    else if (value && typeof value === "object" && !Array.isArray(value)) out.push(...numericPaths(value, `${prefix}${key}.`));
  }
  return out;
}

/** About `count` round tick values across [lo, hi], or decades on a log axis. */
function ticks(lo, hi, log, count = 6) {
  if (log) {
    const out = [];
    for (let e = Math.floor(Math.log10(lo)); e <= Math.ceil(Math.log10(hi)); e++) {
      if (10 ** e >= lo * (1 - 1e-9) && 10 ** e <= hi * (1 + 1e-9)) out.push(10 ** e);
    }
    return out.length >= 2 ? out : ticks(lo, hi, false, count);
  }
  const raw = (hi - lo) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

/** [lo, hi] of `values`, widened when they are one value (a one-point sweep still draws). */
function extent(values, log) {
  let lo = Math.min(...values);
  let hi = Math.max(...values);
  if (lo === hi) {
    const pad = log ? 2 : Math.abs(lo) * 0.1 || 1;
    return log ? [lo / pad, hi * pad] : [lo - pad, hi + pad];
  }
  if (!log) {
    const pad = (hi - lo) * 0.04;
    return [lo - pad, hi + pad];
  }
  return [lo, hi];
}

/** One number as a person reads it with its unit: 1.25 nN, 0.0947. */
function withUnit(value, unit) {
  const [shown, name] = readable(value, unit);
  return `${Number(shown.toPrecision(4))}${name ? " " + name : ""}`;
}

/** `value` in the unit `[size, name]` ([`scaleFor`]), to four digits: 0.5 nN. */
function inScale(value, [size, name]) {
  return `${Number((value / size).toPrecision(4))}${name ? " " + name : ""}`;
}

/** The labels of the plot's axes, under it and up its left side, into `g`. */
function axisLabels(g, xText, yText) {
  const { width, height, left, right, top, bottom } = PLOT;
  const middle = (top + height - bottom) / 2;
  g.append(element("text", { class: "x-label", x: (left + width - right) / 2, y: height - 12, "text-anchor": "middle" }, xText));
  g.append(element("text", { class: "y-label", x: 14, y: middle, "text-anchor": "middle", transform: `rotate(-90 14 ${middle})` }, yText));
}

/** A sweep answer's explorable plot, with its controls, in `box`. */
class SweepPlot {
  constructor(box, answer) {
    this.points = answer.points.filter((p) => p && typeof p === "object");
    this.units = unitsOf(answer, "points[].");
    const solved = this.points.find(isSolved) || this.points[0] || {};
    const varied = Object.keys((answer.meta && answer.meta.input && answer.meta.input.vary) || {});
    const paths = numericPaths(solved);
    // The varied inputs as they sit in a point (`operating.total_load` for `total_load`).
    this.inputs = varied
      .map((key) => paths.find((p) => p === key) || paths.find((p) => p.endsWith(`.${key}`)))
      .filter((p) => p !== undefined);
    this.quantities = paths.filter((p) => !this.inputs.includes(p) && !p.startsWith("validity."));
    const spread = (path) => new Set(this.points.map((p) => valueAt(p, path))).size;
    this.inputs.sort((a, b) => spread(b) - spread(a));
    this.moving = this.inputs.filter((path) => spread(path) > 1);
    this.state = {
      x: this.inputs[0],
      y: this.quantities.find((p) => p.startsWith("friction_coefficient")) || this.quantities[0],
      view: "lines",
      logX: false,
      logY: false,
      zoom: null,
    };
    this.box = box;
    box.replaceChildren(this.controls(), element("svg", { class: "plot", viewBox: `0 0 ${PLOT.width} ${PLOT.height}`, width: PLOT.width, height: PLOT.height, role: "img" }), this.legendBox = document.createElement("div"));
    this.legendBox.className = "plot-legend";
    this.svg = box.querySelector("svg.plot");
    this.draw();
  }

  /** The selects and switches above the plot. */
  controls() {
    const bar = document.createElement("div");
    bar.className = "plot-controls";
    const select = (label, name, options, value) => {
      const wrap = document.createElement("label");
      wrap.append(Object.assign(document.createElement("span"), { textContent: label }));
      const node = document.createElement("select");
      node.name = name;
      for (const [key, text] of options) node.append(new Option(text, key, false, key === value));
      node.addEventListener("change", () => this.set({ [name]: node.value, zoom: null }));
      wrap.append(node);
      return wrap;
    };
    const check = (label, name) => {
      const wrap = document.createElement("label");
      wrap.className = "check";
      const node = Object.assign(document.createElement("input"), { type: "checkbox", name });
      node.addEventListener("change", () => this.set({ [name]: node.checked, zoom: null }));
      wrap.append(node, Object.assign(document.createElement("span"), { textContent: label }));
      return wrap;
    };
    const named = (path) => [path, path];
    bar.append(select("Plot", "y", this.quantities.map(named), this.state.y));
    bar.append(select("against", "x", this.inputs.map(named), this.state.x));
    const views = [["lines", "lines"]];
    if (this.moving.length === 2) views.push(["heat", "heat map"]);
    bar.append(select("as", "view", views, this.state.view));
    bar.append(check("log x", "logX"), check("log y", "logY"));
    const reset = Object.assign(document.createElement("button"), { type: "button", textContent: "Reset zoom", className: "reset" });
    reset.addEventListener("click", () => this.set({ zoom: null }));
    bar.append(reset);
    this.note = Object.assign(document.createElement("span"), { className: "plot-note" });
    bar.append(this.note);
    return bar;
  }

  set(change) {
    Object.assign(this.state, change);
    this.draw();
  }

  draw() {
    this.svg.replaceChildren();
    this.legendBox.replaceChildren();
    this.note.textContent = "";
    this.svg.dataset.x = this.state.x;
    this.svg.dataset.y = this.state.y;
    this.svg.dataset.view = this.state.view;
    this.svg.setAttribute("aria-label", `${this.state.y} against ${this.state.x}${this.state.view === "heat" ? " (heat map)" : ""}`);
    if (this.state.view === "heat" && this.moving.length === 2) this.drawHeat();
    else this.drawLines();
  }

  /** The points that have both coordinates, positive ones only on a log axis. */
  usable(x, y) {
    const { logX, logY } = this.state;
    const kept = this.points.filter((p) => {
      const [a, b] = [valueAt(p, x), valueAt(p, y)];
      return typeof a === "number" && typeof b === "number" && Number.isFinite(a) && Number.isFinite(b)
        && (!logX || a > 0) && (!logY || b > 0);
    });
    const left = this.points.length - kept.length;
    if (left > 0) this.note.textContent = `${left} of ${this.points.length} points not drawn (refused, not solved${logX || logY ? ", or ≤ 0 on a log axis" : ""})`;
    return kept;
  }

  /** Axes over the ranges `xs` × `ys` of the quantities at `xPath` and `yPath`, in the readable
   *  units of their largest values; returns the maps from values to the plot's pixels. */
  axes(xs, ys, xPath, yPath) {
    const { logX, logY } = this.state;
    const { width, height, left, right, top, bottom } = PLOT;
    const map = (lo, hi, log, from, to) => (v) => {
      const [a, b, t] = log ? [Math.log10(lo), Math.log10(hi), Math.log10(v)] : [lo, hi, v];
      return from + ((t - a) / (b - a)) * (to - from);
    };
    const px = map(xs[0], xs[1], logX, left, width - right);
    const py = map(ys[0], ys[1], logY, height - bottom, top);
    const g = element("g", { class: "axes", "font-size": 12, "font-family": "sans-serif" });
    g.append(element("rect", { x: left, y: top, width: width - left - right, height: height - top - bottom, fill: "#fff", stroke: "#444" }));
    const [xSize, xUnit] = scaleFor(Math.max(Math.abs(xs[0]), Math.abs(xs[1])), this.units[xPath]);
    const [ySize, yUnit] = scaleFor(Math.max(Math.abs(ys[0]), Math.abs(ys[1])), this.units[yPath]);
    for (const v of ticks(xs[0], xs[1], logX)) {
      g.append(element("line", { x1: px(v), x2: px(v), y1: top, y2: height - bottom, stroke: "#eee" }));
      g.append(element("text", { x: px(v), y: height - bottom + 16, "text-anchor": "middle" }, String(Number((v / xSize).toPrecision(4)))));
    }
    for (const v of ticks(ys[0], ys[1], logY)) {
      g.append(element("line", { x1: left, x2: width - right, y1: py(v), y2: py(v), stroke: "#eee" }));
      g.append(element("text", { x: left - 6, y: py(v) + 4, "text-anchor": "end" }, String(Number((v / ySize).toPrecision(4)))));
    }
    axisLabels(g, `${xPath}${xUnit ? ` [${xUnit}]` : ""}${logX ? " (log)" : ""}`, `${yPath}${yUnit ? ` [${yUnit}]` : ""}${logY ? " (log)" : ""}`);
    this.svg.append(g);
    return { px, py };
  }

  /** One line per value of the other varied inputs, coloured in order of those values. */
  drawLines() {
    const { x, y, logX, logY, zoom } = this.state;
    const kept = this.usable(x, y);
    if (!kept.length) return;
    const xs = zoom ? zoom.x : extent(kept.map((p) => valueAt(p, x)), logX);
    const ys = zoom ? zoom.y : extent(kept.map((p) => valueAt(p, y)), logY);
    const { px, py } = this.axes(xs, ys, x, y);
    const others = this.moving.filter((path) => path !== x);
    const keyOf = (p) => others.map((path) => valueAt(p, path));
    const groups = new Map();
    for (const p of kept) {
      const key = JSON.stringify(keyOf(p));
      if (!groups.has(key)) groups.set(key, []);
      groups.get(key).push(p);
    }
    const order = [...groups.keys()].sort((a, b) => {
      const [u, v] = [JSON.parse(a), JSON.parse(b)];
      for (let i = 0; i < u.length; i++) if (u[i] !== v[i]) return u[i] - v[i];
      return 0;
    });
    // Each varied input in one unit across the legend, its largest value's: 0.5 nN beside
    // 2 nN (not 500 pN), 0 nm/s beside 4 nm/s (not 0 m/s).
    const scales = Object.fromEntries(others.map((path) => {
      const largest = kept.reduce((most, p) => Math.max(most, Math.abs(valueAt(p, path)) || 0), 0);
      return [path, scaleFor(largest, this.units[path])];
    }));
    linePlotsDrawn += 1;
    const clip = element("clipPath", { id: `plot-clip-${linePlotsDrawn}` });
    clip.append(element("rect", { x: PLOT.left, y: PLOT.top, width: PLOT.width - PLOT.left - PLOT.right, height: PLOT.height - PLOT.top - PLOT.bottom }));
    this.svg.append(clip);
    const layer = element("g", { "clip-path": `url(#plot-clip-${linePlotsDrawn})` });
    this.svg.append(layer);
    this.drawn = [];
    order.forEach((key, i) => {
      const colour = sequential(order.length === 1 ? 0.35 : i / (order.length - 1));
      const series = groups.get(key).slice().sort((a, b) => valueAt(a, x) - valueAt(b, x));
      const label = others.map((path) => `${path} = ${inScale(valueAt(series[0], path), scales[path])}`).join(", ") || y;
      if (series.length > 1) {
        const d = series.map((p, k) => `${k ? "L" : "M"}${px(valueAt(p, x)).toFixed(1)},${py(valueAt(p, y)).toFixed(1)}`).join("");
        layer.append(element("path", { class: "series", d, fill: "none", stroke: colour, "stroke-width": 2, "data-name": label }));
      }
      for (const p of series) {
        const [cx, cy] = [px(valueAt(p, x)), py(valueAt(p, y))];
        layer.append(element("circle", { class: "point", cx, cy, r: series.length > 1 ? 2.5 : 5, fill: colour }));
        this.drawn.push({ cx, cy, p, label });
      }
      this.legendEntry(colour, label);
    });
    if (order.length > 12) this.shortenLegend(order.length, others);
    this.interact(xs, ys, px, py);
  }

  legendEntry(colour, label) {
    const row = document.createElement("div");
    row.className = "entry";
    const swatch = document.createElement("span");
    swatch.className = "swatch";
    swatch.style.background = colour;
    row.append(swatch, document.createTextNode(label));
    this.legendBox.append(row);
  }

  /** Many series: the colour bar and its ends instead of an entry each. */
  shortenLegend(count, others) {
    const entries = [...this.legendBox.children];
    const [first, last] = [entries[0].textContent, entries[entries.length - 1].textContent];
    this.legendBox.replaceChildren();
    this.legendBox.append(this.colourBar(first, last, `${count} lines, by ${others.join(", ")}`));
  }

  colourBar(low, high, title) {
    const bar = document.createElement("div");
    bar.className = "colour-bar";
    const ramp = document.createElement("span");
    ramp.className = "ramp";
    ramp.style.background = `linear-gradient(to right, ${VIRIDIS.join(", ")})`;
    bar.append(Object.assign(document.createElement("div"), { textContent: title }), document.createTextNode(low), ramp, document.createTextNode(high));
    return bar;
  }

  /** Two varied inputs: a cell per point, coloured by the quantity. */
  drawHeat() {
    const { x, y } = this.state;
    const other = this.moving.find((path) => path !== x);
    const kept = this.usable(x, y).filter((p) => typeof valueAt(p, other) === "number");
    if (!kept.length) return;
    const columns = [...new Set(kept.map((p) => valueAt(p, x)))].sort((a, b) => a - b);
    const rows = [...new Set(kept.map((p) => valueAt(p, other)))].sort((a, b) => a - b);
    const values = kept.map((p) => valueAt(p, y));
    const [lo, hi] = [Math.min(...values), Math.max(...values)];
    const { width, height, left, right, top, bottom } = PLOT;
    const cw = (width - left - right) / columns.length;
    const ch = (height - top - bottom) / rows.length;
    const g = element("g", { class: "heat", "font-size": 12, "font-family": "sans-serif" });
    this.drawn = [];
    for (const p of kept) {
      const [i, j] = [columns.indexOf(valueAt(p, x)), rows.indexOf(valueAt(p, other))];
      const fill = sequential(hi > lo ? (valueAt(p, y) - lo) / (hi - lo) : 0.5);
      const cell = element("rect", { class: "cell", x: left + i * cw, y: height - bottom - (j + 1) * ch, width: cw, height: ch, fill });
      g.append(cell);
      this.drawn.push({ cx: left + (i + 0.5) * cw, cy: height - bottom - (j + 0.5) * ch, p, label: "" });
    }
    const every = (n) => Math.max(1, Math.ceil(n / 8));
    columns.forEach((v, i) => {
      if (i % every(columns.length)) return;
      g.append(element("text", { x: left + (i + 0.5) * cw, y: height - bottom + 16, "text-anchor": "middle" }, withUnit(v, this.units[x])));
    });
    rows.forEach((v, j) => {
      if (j % every(rows.length)) return;
      g.append(element("text", { x: left - 6, y: height - bottom - (j + 0.5) * ch + 4, "text-anchor": "end" }, withUnit(v, this.units[other])));
    });
    axisLabels(g, x, other);
    this.svg.append(g);
    this.legendBox.append(this.colourBar(withUnit(lo, this.units[y]), withUnit(hi, this.units[y]), y));
    this.interact(null, null, null, null);
  }

  /** Hover reads the nearest point; a drag on the lines zooms to its rectangle; a double
   *  click resets. */
  interact(xs, ys, px, py) {
    const tip = element("g", { class: "tip", visibility: "hidden", "pointer-events": "none", "font-size": 12, "font-family": "sans-serif" });
    const box = element("rect", { fill: "#fff", stroke: "#333", rx: 3, opacity: 0.95 });
    tip.append(box);
    const band = element("rect", { class: "zoom-band", fill: "rgba(31,95,168,0.15)", stroke: "#1f5fa8", visibility: "hidden" });
    this.svg.append(band, tip);
    const local = (event) => {
      const r = this.svg.getBoundingClientRect();
      return [(event.clientX - r.left) * (PLOT.width / r.width), (event.clientY - r.top) * (PLOT.height / r.height)];
    };
    const show = ([mx, my]) => {
      let best = null;
      for (const d of this.drawn) {
        const dist = Math.hypot(d.cx - mx, d.cy - my);
        if (dist < 24 && (!best || dist < best.dist)) best = { ...d, dist };
      }
      if (!best) return tip.setAttribute("visibility", "hidden");
      const lines = [...this.moving, this.state.y].map((path) => `${path} = ${withUnit(valueAt(best.p, path), this.units[path])}`);
      for (const old of tip.querySelectorAll("text")) old.remove();
      lines.forEach((line, k) => tip.append(element("text", { x: 8, y: 16 + 15 * k }, line)));
      const w = 8 + 7 * Math.max(...lines.map((l) => l.length));
      const h = 8 + 15 * lines.length;
      box.setAttribute("width", w);
      box.setAttribute("height", h);
      const tx = best.cx + w + 12 > PLOT.width ? best.cx - w - 8 : best.cx + 8;
      const ty = Math.min(Math.max(best.cy - h / 2, 0), PLOT.height - h);
      tip.setAttribute("transform", `translate(${tx},${ty})`);
      tip.setAttribute("visibility", "visible");
    };
    let drag = null;
    this.svg.onmousemove = (event) => {
      const m = local(event);
      if (drag) {
        const [x0, y0] = drag;
        band.setAttribute("x", Math.min(x0, m[0]));
        band.setAttribute("y", Math.min(y0, m[1]));
        band.setAttribute("width", Math.abs(m[0] - x0));
        band.setAttribute("height", Math.abs(m[1] - y0));
        band.setAttribute("visibility", "visible");
      }
      show(m);
    };
    this.svg.onmouseleave = () => tip.setAttribute("visibility", "hidden");
    this.svg.onmousedown = (event) => { if (px) drag = local(event); };
    this.svg.onmouseup = (event) => {
      if (!drag) return;
      const [x0, y0] = drag;
      const [x1, y1] = local(event);
      drag = null;
      band.setAttribute("visibility", "hidden");
      if (Math.abs(x1 - x0) < 6 || Math.abs(y1 - y0) < 6) return;
      const back = (lo, hi, log, from, to) => (p) => {
        const t = (p - from) / (to - from);
        return log ? 10 ** (Math.log10(lo) + t * (Math.log10(hi) - Math.log10(lo))) : lo + t * (hi - lo);
      };
      const vx = back(xs[0], xs[1], this.state.logX, PLOT.left, PLOT.width - PLOT.right);
      const vy = back(ys[0], ys[1], this.state.logY, PLOT.height - PLOT.bottom, PLOT.top);
      this.set({ zoom: { x: [vx(Math.min(x0, x1)), vx(Math.max(x0, x1))], y: [vy(Math.max(y0, y1)), vy(Math.min(y0, y1))] } });
    };
    this.svg.ondblclick = () => this.set({ zoom: null });
  }
}
