// The dashboard: forms that post jobs to the API, the answer as a table and a picture.
// Plain JavaScript, no dependency: everything it loads comes from this server.
"use strict";

const $ = (selector) => document.querySelector(selector);

// ---- Forms to job inputs -------------------------------------------------------------

/** A form's fields as the input object of its job: `a.b` names nest, lists split on commas,
 *  plain numbers become numbers, anything else is sent as typed (a value with its unit).
 *  A layer given as a Prony series drops the Kelvin times the series replaces. */
function inputOf(form) {
  const input = {};
  for (const field of form.querySelectorAll("input[name], select[name], textarea[name]")) {
    const text = field.value.trim();
    if (text === "") continue;
    const path = field.name.split(".");
    let value;
    if (path[0] === "vary") {
      value = text.split(",").map((t) => t.trim()).filter((t) => t !== "").map(typed);
    } else {
      value = typed(text);
    }
    if (field.name === "options.pressure_grid" && value === 0) continue;
    let node = input;
    for (const key of path.slice(0, -1)) node = node[key] ??= {};
    node[path[path.length - 1]] = value;
  }
  if (input.layer?.prony_csv !== undefined) {
    delete input.layer.relaxation_time;
    delete input.layer.retardation_time;
  }
  return input;
}

function typed(text) {
  return /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(text) ? Number(text) : text;
}

/** The request a form makes: where, and the body. Sweeps go through /v1/jobs. */
function requestOf(form) {
  const input = inputOf(form);
  const kind = form.dataset.kind;
  const body = kind === "sweep" ? { kind: "sweep", input } : input;
  return { url: form.dataset.endpoint, body, job: { kind, input } };
}

// ---- Showing answers -----------------------------------------------------------------

/** `value` (SI `unit`) in the unit a person reads: 25 nm, 1 mN, 0.208 µm² (as the pictures). */
function readable(value, unit) {
  const bases = { m: ["m", 1], N: ["N", 1], "m/s": ["m/s", 1], "m^2": ["m²", 2], "m²": ["m²", 2] };
  if (unit === "Pa") {
    for (const [size, name] of [[1e9, "GPa"], [1e6, "MPa"], [1e3, "kPa"]]) {
      if (Math.abs(value) >= size) return [value / size, name];
    }
    return [value, "Pa"];
  }
  const base = bases[unit];
  if (!base || value === 0) return [value, base ? base[0] : unit || ""];
  const [name, power] = base;
  for (const [size, prefix] of [[1, ""], [1e-3, "m"], [1e-6, "µ"], [1e-9, "n"], [1e-12, "p"]]) {
    const scale = size ** power;
    const least = power === 2 ? 1e-2 : 1;
    if (Math.abs(value) >= least * scale || prefix === "p") {
      return [value / scale, name === "m/s" ? `${prefix}m/s` : prefix + name];
    }
  }
  return [value, unit];
}

function status(text, error = false) {
  const p = $("#status");
  p.textContent = text;
  p.className = error ? "error" : "";
}

function showProblem(problem) {
  const fields = (problem.errors || []).map((e) => e.message).join("; ");
  status(`${problem.title}: ${fields || problem.detail}`, true);
}

/** Scalars of an answer (nested objects flattened, lists left out) with their units. */
function rows(answer, units, prefix = "") {
  const out = [];
  for (const [key, value] of Object.entries(answer)) {
    if (key === "meta") continue;
    const path = prefix + key;
    if (typeof value === "number") {
      const [shown, unit] = readable(value, units[path]);
      out.push([path, Number(shown.toPrecision(6)), unit]);
    } else if (value && typeof value === "object" && !Array.isArray(value)) {
      out.push(...rows(value, units, path + "."));
    }
  }
  return out;
}

/** The answer's table, emptied, with a head row of `names`. */
function freshTable(names) {
  const table = $("#table");
  table.replaceChildren();
  const head = table.insertRow();
  for (const name of names) {
    const th = document.createElement("th");
    th.textContent = name;
    head.append(th);
  }
  return table;
}

function showTable(answer) {
  const table = freshTable(["quantity", "value", "unit"]);
  const units = (answer.meta && answer.meta.units) || {};
  // A sweep's table is what its meta says of its points; its rows are in the downloads.
  const shown = answer.points ? { points: (answer.meta && answer.meta.counts) || answer.points.length } : answer;
  for (const [name, value, unit] of rows(shown, units)) {
    const row = table.insertRow();
    for (const cell of [name, value, unit]) row.insertCell().textContent = cell;
  }
}

/** The answer's warnings, in place of those shown (or after them, `after`: comparing). */
function showWarnings(answer, after = false) {
  const box = $("#warnings");
  if (!after) box.replaceChildren();
  const meta = answer.meta || {};
  const notes = (meta.warnings || []).map((w) => w.message);
  for (const a of (meta.validity && meta.validity.assumptions) || []) {
    if (a.warned !== undefined) {
      // A sweep: how many points each assumption warns on, and why on the first.
      if (a.warned > 0) notes.push(`warn on ${a.warned} points: ${a.assumption} (first, points[${a.first_warned}]: ${a.note})`);
    } else if (a.status !== "ok") {
      notes.push(`${a.status}: ${a.assumption} (${a.ratio} = ${Number(a.value).toPrecision(3)}): ${a.note || a.rule}`);
    }
  }
  const counts = meta.counts;
  if (counts && counts.refused > 0) notes.push(`${counts.refused} of ${counts.total} points refused by the model: see their reason in the CSV or JSON`);
  if (meta.complete === false) notes.push(`partial answer: ${counts.missing} of ${counts.total} points not solved (${meta.stopped})`);
  for (const text of notes) {
    const p = document.createElement("p");
    p.className = "warning";
    p.textContent = "⚠ " + text;
    box.append(p);
  }
}

/** Puts an SVG document into the page (inline, so the page's CSP allows it). */
function showPicture(svgText) {
  const doc = new DOMParser().parseFromString(svgText, "image/svg+xml");
  const svg = doc.documentElement;
  svg.setAttribute("role", "img");
  $("#picture").replaceChildren(document.importNode(svg, true));
}

/** Download buttons: each fetches the answer in its form and saves it. */
function showDownloads(fetchIn, name) {
  const box = $("#downloads");
  box.replaceChildren();
  for (const [label, accept, ext] of [["JSON", "application/json", "json"], ["CSV", "text/csv", "csv"], ["SVG", "image/svg+xml", "svg"]]) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = `Download ${label}`;
    button.addEventListener("click", async () => {
      const response = await fetchIn(accept);
      const blob = await response.blob();
      const link = document.createElement("a");
      link.href = URL.createObjectURL(blob);
      link.download = `${name}.${ext}`;
      link.click();
      URL.revokeObjectURL(link.href);
    });
    box.append(button);
  }
}

/** What a continuum answer's verification says of its accuracy, in a sentence. */
function accuracy(answer) {
  const v = answer.meta && answer.meta.verification;
  if (!v || v.method === undefined) return "";
  const percent = (x) => `${(100 * x).toPrecision(2)} %`;
  const how = v.method === "grid"
    ? `on a ${v.grid.length} × ${v.grid.width} grid, ${Math.round(v.grid.pixels_across)} pixels across the contact`
    : "by the local law, which a layer this thin follows";
  const within = v.within_tolerance ? "" : " (less exact than 1 % in A)";
  return ` Layer as a continuum, ${how}: A within ±${percent(v.contact_area_error)}, δ within ±${percent(v.penetration_error)}${within}.`;
}

// ---- Comparing the two laws of the layer ------------------------------------------------

const SVG = "http://www.w3.org/2000/svg";

function element(name, attributes, text) {
  const node = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== undefined) node.textContent = text;
  return node;
}

/** Both laws' contact regions (and their circles at rest) on one plane, to scale. */
function comparison(answers) {
  const colours = { local: "#1f77b4", continuum: "#d62728" };
  const outline = (a) => [...a.boundary.map((p) => [p.entry, p.y]), ...a.boundary.slice().reverse().map((p) => [p.exit, p.y])];
  const rest = (a) => Math.sqrt(a.static.contact_area / Math.PI);
  let reach = 0;
  for (const [, a] of answers) {
    reach = Math.max(reach, rest(a), ...outline(a).map(([x, y]) => Math.max(Math.abs(x), Math.abs(y))));
  }
  const [scale, unit] = readable(reach, "m");
  const factor = scale / reach;
  const size = 400, margin = 50, half = size / 2;
  const px = (x) => margin + half + (x / reach) * half * 0.95;
  const py = (y) => margin + half - (y / reach) * half * 0.95;
  const svg = element("svg", { xmlns: SVG, width: size + 2 * margin + 220, height: size + 2 * margin, viewBox: `0 0 ${size + 2 * margin + 220} ${size + 2 * margin}`, "font-family": "sans-serif", "font-size": 13 });
  svg.append(element("title", {}, "Contact regions under both laws of the layer"));
  svg.append(element("rect", { x: margin, y: margin, width: size, height: size, fill: "none", stroke: "#444" }));
  for (const t of [-1, -0.5, 0, 0.5, 1]) {
    const value = (t * reach * 0.95 * factor).toPrecision(2);
    svg.append(element("text", { x: px(t * reach * 0.95), y: margin + size + 18, "text-anchor": "middle" }, value));
    svg.append(element("text", { x: margin - 6, y: py(t * reach * 0.95) + 4, "text-anchor": "end" }, value));
  }
  svg.append(element("text", { x: margin + half, y: margin + size + 40, "text-anchor": "middle" }, `x (rolling direction) [${unit}]`));
  svg.append(element("text", { x: 14, y: margin + half, "text-anchor": "middle", transform: `rotate(-90 14 ${margin + half})` }, `y [${unit}]`));
  let row = 0;
  for (const [model, a] of answers) {
    const colour = colours[model];
    const points = outline(a).map(([x, y]) => `${px(x).toFixed(1)},${py(y).toFixed(1)}`).join(" ");
    svg.append(element("polygon", { class: "series", "data-name": model, points, fill: colour, "fill-opacity": 0.25, stroke: colour, "stroke-width": 2 }));
    svg.append(element("circle", { cx: px(0), cy: py(0), r: (rest(a) / reach) * half * 0.95, fill: "none", stroke: colour, "stroke-dasharray": "6 4" }));
    const [area, areaUnit] = readable(a.contact_area, "m^2");
    svg.append(element("rect", { x: size + 2 * margin, y: margin + 22 * row - 10, width: 24, height: 12, fill: colour, "fill-opacity": 0.4, stroke: colour }));
    svg.append(element("text", { class: "entry", x: size + 2 * margin + 32, y: margin + 22 * row }, `${model}: A = ${area.toPrecision(3)} ${areaUnit}`));
    row += 1;
  }
  svg.append(element("text", { x: size + 2 * margin, y: margin + 22 * row + 6 }, "dashed: the same particle at rest"));
  return svg;
}

/** Solves the rolling form under both laws: their regions drawn together, their numbers side by side. */
async function compare(form) {
  const { url, body } = requestOf(form);
  status("Solving under both laws…");
  const answers = [];
  for (const model of ["local", "continuum"]) {
    const asked = structuredClone(body);
    (asked.layer ??= {}).model = model;
    const response = await post(url, asked);
    const answer = await response.json();
    if (!response.ok) return showProblem(answer);
    answers.push([model, answer]);
  }
  $("#picture").replaceChildren(comparison(answers));
  const table = freshTable(["quantity", "local law", "layer as a continuum"]);
  // The two answers have the same quantities, in the same order.
  const [local, continuum] = answers.map(([, a]) => rows(a, a.meta.units || {}));
  continuum.forEach(([name, value, unit], i) => {
    const row = table.insertRow();
    const [, theirs, theirUnit] = local[i];
    for (const cell of [name, `${theirs} ${theirUnit}`, `${value} ${unit}`]) row.insertCell().textContent = cell;
  });
  showWarnings(answers[0][1]);
  showWarnings(answers[1][1], true);
  status(`Both laws solved.${accuracy(answers[1][1])}`);
  $("#downloads").replaceChildren();
}

async function post(url, body, accept = "application/json") {
  return fetch(url, { method: "POST", headers: { "content-type": "application/json", accept }, body: JSON.stringify(body) });
}

async function solve(form) {
  const { url, body } = requestOf(form);
  status("Solving…");
  const response = await post(url, body);
  const answer = await response.json();
  if (!response.ok) return showProblem(answer);
  status(`Solved (${response.headers.get("x-cache") || "miss"}).${accuracy(answer)}`);
  showTable(answer);
  showWarnings(answer);
  const picture = await post(url, body, "image/svg+xml");
  if (picture.ok) showPicture(await picture.text());
  showDownloads((accept) => post(url, body, accept), form.dataset.kind);
}

// ---- Jobs: progress from the event stream, cancel -------------------------------------

let following = null;

async function runJob(form) {
  const { url, body } = requestOf(form);
  status("Submitting…");
  const response = await post(url, body);
  const view = await response.json();
  if (!response.ok) return showProblem(view);
  follow(view.id);
}

function follow(id) {
  const progress = $("#progress");
  const text = $("#progress-text");
  const cancel = $("#cancel");
  cancel.disabled = false;
  cancel.onclick = () => fetch(`/v1/jobs/${id}/cancel`, { method: "POST", headers: { accept: "application/json" } });
  if (following) following.close();
  const events = new EventSource(`/v1/jobs/${id}/events`);
  following = events;
  const update = (view) => {
    const { done, total } = view.progress;
    progress.max = Math.max(total, 1);
    progress.value = done;
    text.textContent = total ? `${done} / ${total} (${Math.round((100 * done) / total)} %)` : `${done}`;
    status(`Job ${view.status}.`);
  };
  events.addEventListener("progress", (e) => update(JSON.parse(e.data)));
  events.addEventListener("completion", async (e) => {
    events.close();
    following = null;
    cancel.disabled = true;
    const view = JSON.parse(e.data);
    update(view);
    if (view.problem) showProblem(view.problem);
    // A failed or cancelled sweep may still link to the points it finished.
    if (!view.result_url) return;
    const result = view.result_url;
    const response = await fetch(result, { headers: { accept: "application/json" } });
    const answer = await response.json();
    if (!response.ok) return showProblem(answer);
    showTable(answer);
    showWarnings(answer);
    if (view.partial) {
      const why = view.problem ? `: ${view.problem.detail}` : "";
      status(`Job ${view.status}${why}. A partial answer: the points it finished.`, view.status === "failed");
    }
    const picture = await fetch(`${result}?format=svg`);
    if (picture.ok) showPicture(await picture.text());
    showDownloads((accept) => fetch(result, { headers: { accept } }), `job-${id}`);
  });
}

// ---- Copying a form as a command ----------------------------------------------------

async function copy(form, what) {
  const { url, body, job } = requestOf(form);
  const text = what === "job"
    ? JSON.stringify(job, null, 2)
    : `curl -s -X POST ${location.origin}${url} -H 'content-type: application/json' -d '${JSON.stringify(body)}'`;
  try {
    await navigator.clipboard.writeText(text);
    status(`Copied ${what === "job" ? "the job as JSON" : "the curl command"}.`);
  } catch {
    status(text);
  }
}

// ---- Figures, tabs, start-up ---------------------------------------------------------

async function figure(n) {
  status(`Figure ${n}…`);
  const response = await fetch(`/v1/figures/${n}?format=svg`);
  if (!response.ok) return showProblem(await response.json());
  showPicture(await response.text());
  const answer = await (await fetch(`/v1/figures/${n}`, { headers: { accept: "application/json" } })).json();
  showTable({ figure: answer.figure, series: answer.series.length, meta: answer.meta });
  $("#warnings").replaceChildren();
  status(`Figure ${n}: ${answer.title}`);
  showDownloads((accept) => fetch(`/v1/figures/${n}`, { headers: { accept } }), `figure-${n}`);
}

function selectTab(tab) {
  for (const other of document.querySelectorAll("[role=tab]")) {
    const selected = other === tab;
    other.setAttribute("aria-selected", String(selected));
    document.getElementById(other.getAttribute("aria-controls")).hidden = !selected;
  }
}

document.addEventListener("DOMContentLoaded", () => {
  for (const tab of document.querySelectorAll("[role=tab]")) {
    tab.addEventListener("click", () => selectTab(tab));
  }
  for (const form of document.querySelectorAll("form")) {
    form.addEventListener("submit", (event) => {
      event.preventDefault();
      (form.dataset.kind === "sweep" ? runJob(form) : solve(form)).catch((e) => status(String(e), true));
    });
    for (const button of form.querySelectorAll("[data-copy]")) {
      button.addEventListener("click", () => copy(form, button.dataset.copy));
    }
  }
  $("#compare").addEventListener("click", () => compare($("#form-rolling")).catch((e) => status(String(e), true)));
  const buttons = $("#figure-buttons");
  for (let n = 3; n <= 9; n++) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = `Figure ${n}`;
    button.addEventListener("click", () => figure(n).catch((e) => status(String(e), true)));
    buttons.append(button);
  }
});
