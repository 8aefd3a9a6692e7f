// The dashboard: forms that post jobs to the API, the answer as a table and a picture.
// Plain JavaScript, no dependency: everything it loads comes from this server.
"use strict";

const $ = (selector) => document.querySelector(selector);

// ---- Forms to job inputs -------------------------------------------------------------

/** A form's fields as the input object of its job: `a.b` names nest, lists split on commas,
 *  plain numbers become numbers, anything else is sent as typed (a value with its unit); an
 *  empty or disabled field is left out (the server's default). A layer given as a Prony
 *  series drops the Kelvin times the series replaces; a fit's CSV becomes its series, and a
 *  parameter without a start is not fitted. */
function inputOf(form) {
  const input = {};
  for (const field of form.querySelectorAll("input[name], select[name], textarea[name]")) {
    const text = field.value.trim();
    if (text === "" || field.disabled) continue;
    const path = field.name.split(".");
    let value;
    if (path[0] === "vary") {
      value = text.split(",").map((t) => t.trim()).filter((t) => t !== "").map(typed);
    } else if (field.dataset.csv !== undefined) {
      value = pointsOf(text);
    } else {
      value = typed(text);
    }
    if (field.name === "options.pressure_grid" && value === 0) continue;
    let node = input;
    for (const key of path.slice(0, -1)) node = node[key] ??= {};
    node[path[path.length - 1]] = value;
  }
  dropKelvinTimes(input);
  if (form.dataset.kind === "fit") {
    // `on` chooses what was measured; a system of the defaults alone is `{}`, still a system.
    const { quantity, csv, on, system } = input.series || {};
    input.series = seriesOf(quantity, csv || [], on === "system" ? system || {} : undefined);
    for (const [name, bounds] of Object.entries(input.parameters || {})) {
      if (bounds.start === undefined) delete input.parameters[name];
    }
  }
  return input;
}

/** Every layer in `node` given as a Prony series loses the Kelvin times it replaces. */
function dropKelvinTimes(node) {
  if (!node || typeof node !== "object") return;
  if (node.prony_csv !== undefined) {
    delete node.relaxation_time;
    delete node.retardation_time;
  }
  Object.values(node).forEach(dropKelvinTimes);
}

/** Measured points from CSV text: a header row naming the columns (radius, load, velocity,
 *  value, uncertainty), then a point per row, values as typed. */
function pointsOf(text) {
  const lines = text.split(/\r?\n/).map((l) => l.trim()).filter((l) => l !== "" && !l.startsWith("#"));
  const header = (lines.shift() || "").split(",").map((h) => h.trim().toLowerCase());
  return lines.map((line, row) => {
    const cells = line.split(",").map((c) => c.trim());
    if (cells.length !== header.length) {
      throw new InputError("series.csv", `row ${row + 1} has ${cells.length} values, the header ${header.length}`);
    }
    return Object.fromEntries(header.map((name, k) => [name, typed(cells[k])]));
  });
}

/** Measured points as the fit's series: the condition (radius, load, velocity, or a system's
 *  total_load) that takes the most values is what each series runs along; the others, fixed
 *  within a series, tell the series apart, so a curve is drawn through one condition's
 *  points. Measured on a three-body `system`, every series is of that system. */
function seriesOf(quantity, points, system) {
  const conditions = ["radius", "load", "velocity", "total_load"].filter((c) => points.some((p) => p[c] !== undefined));
  const spread = (c) => new Set(points.map((p) => p[c])).size;
  const along = conditions.slice().sort((a, b) => spread(b) - spread(a))[0];
  const fixed = conditions.filter((c) => c !== along);
  const series = new Map();
  for (const point of points) {
    const key = JSON.stringify(fixed.map((c) => point[c]));
    if (!series.has(key)) series.set(key, { quantity, system, ...Object.fromEntries(fixed.map((c) => [c, point[c]])), points: [] });
    const own = { ...point };
    for (const c of fixed) delete own[c];
    series.get(key).points.push(own);
  }
  return series.size ? [...series.values()] : [{ quantity, system, points: [] }];
}

/** A form's field that cannot be read, said before anything is sent. */
class InputError extends Error {
  constructor(field, message) {
    super(message);
    this.problem = { title: "The input is not valid", errors: [{ field, message: `${field}: ${message}` }] };
  }
}

function typed(text) {
  return /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(text) ? Number(text) : text;
}

/** The request a form makes: where, and the body. Sweeps and fits go through /v1/jobs, so
 *  that they are kept in the history. */
function requestOf(form) {
  const input = inputOf(form);
  const kind = form.dataset.kind;
  const job = { kind, input };
  return { url: form.dataset.endpoint, body: isJob(form) ? job : input, job };
}

/** Whether `form` submits a job (rather than asking for the answer at once). */
function isJob(form) {
  return form.dataset.endpoint === "/v1/jobs";
}

/** Fills each `fieldset[data-fields=name]` from the template `#fields-name`: its fields named
 *  under the fieldset's `data-prefix`, without those its `data-without` lists. One list of a
 *  layer's fields serves every form that takes a layer. */
function buildFieldsets() {
  for (const set of document.querySelectorAll("fieldset[data-fields]")) {
    const without = (set.dataset.without || "").split(" ").filter(Boolean);
    set.append($(`#fields-${set.dataset.fields}`).content.cloneNode(true));
    for (const label of set.querySelectorAll("label[data-field]")) {
      if (without.includes(label.dataset.field)) label.remove();
    }
    for (const field of set.querySelectorAll("[name]")) field.name = set.dataset.prefix + field.name;
  }
}

/** Fills each `[data-bounds=name]` row with the start, least and most of the fitted
 *  parameter `name`, prefilled from its `data-start`, `data-min` and `data-max` (none: the
 *  parameter is not fitted until a start is given). */
function buildBounds() {
  for (const row of document.querySelectorAll("[data-bounds]")) {
    const label = row.textContent.trim();
    row.setAttribute("role", "group");
    row.setAttribute("aria-label", label);
    for (const [key, word] of [["start", "start"], ["min", "least"], ["max", "most"]]) {
      const input = document.createElement("input");
      input.name = `parameters.${row.dataset.bounds}.${key}`;
      input.setAttribute("aria-label", `${label}: ${word}`);
      if (row.dataset[key] !== undefined) input.value = row.dataset[key];
      else input.placeholder = key === "start" ? "not fitted" : word;
      row.append(input);
    }
  }
}

/** A form's `select[data-switch]` shows, and sends, only the parts marked `data-for` its value. */
function switchParts(form) {
  const select = form.querySelector("select[data-switch]");
  if (!select) return;
  const apply = () => {
    for (const part of form.querySelectorAll("[data-for]")) {
      const on = part.dataset.for === select.value;
      part.hidden = !on;
      for (const field of part.matches("[name]") ? [part] : part.querySelectorAll("[name]")) field.disabled = !on;
    }
  };
  select.addEventListener("change", apply);
  apply();
}

// ---- Showing answers -----------------------------------------------------------------

/** `value` (SI `unit`) in the unit a person reads: 25 nm, 1 mN, 0.208 µm² (as the pictures). */
function readable(value, unit) {
  const [size, name] = scaleFor(value, unit);
  return [value / size, name];
}

/** The unit a person reads `value` (SI `unit`) in, as [its size in SI, its name]. */
function scaleFor(value, unit) {
  const bases = { m: ["m", 1], N: ["N", 1], "m/s": ["m/s", 1], "m^2": ["m²", 2], "m²": ["m²", 2] };
  if (unit === "Pa") {
    for (const [size, name] of [[1e9, "GPa"], [1e6, "MPa"], [1e3, "kPa"]]) {
      if (Math.abs(value) >= size) return [size, name];
    }
    return [1, "Pa"];
  }
  const base = bases[unit];
  if (!base || value === 0) return [1, base ? base[0] : unit || ""];
  const [name, power] = base;
  for (const [size, prefix] of [[1, ""], [1e-3, "m"], [1e-6, "µ"], [1e-9, "n"], [1e-12, "p"]]) {
    const scale = size ** power;
    // A hair below a round value (0.999999… mN, a sum's rounding) is read at that value.
    const least = (power === 2 ? 1e-2 : 1) * (1 - 1e-9);
    if (Math.abs(value) >= least * scale || prefix === "p") {
      return [scale, name === "m/s" ? `${prefix}m/s` : prefix + name];
    }
  }
  return [1, unit];
}

// ---- Answer areas ------------------------------------------------------------------

/** One tab's answer: its status line, warnings, picture, table and downloads. Each tab owns
 *  one, so that switching tabs never shows another tab's answer; each request writes only to
 *  the area that made it, and only while it is the last one asked there, so a slow earlier
 *  answer never lands over a later one. */
class Area {
  constructor(root) {
    this.root = root;
    this.asked = 0;
  }

  part(name) {
    return this.root.querySelector(`.${name}`);
  }

  /** A new request: says `text` and returns the token that keeps its writes current. */
  begin(text) {
    this.asked += 1;
    this.markFields([]);
    this.root.setAttribute("aria-busy", "true");
    this.status(text, "busy");
    return this.asked;
  }

  /** Whether the request of `token` is still the last one asked here. */
  current(token) {
    return token === this.asked;
  }

  /** The status line; `kind` "error" for what went wrong. */
  status(text, kind = "") {
    const line = this.part("status");
    line.textContent = text;
    line.className = `status ${kind}`.trim();
    if (kind !== "busy") this.root.removeAttribute("aria-busy");
  }

  /** Everything but the status line emptied. */
  clear() {
    for (const name of ["warnings", "picture", "table", "downloads"]) this.part(name).replaceChildren();
    for (const inputs of this.root.querySelectorAll(".inputs")) inputs.remove();
  }

  /** An error in place of the answer it replaces: an old table never stands under it. */
  problem(problem) {
    this.clear();
    this.status(problemText(problem), "error");
    this.markFields(problem.errors || []);
  }

  /** Each field an error names (`vary.load[2]` is the field `vary.load`) marked invalid, with
   *  what it allows beside it; the marks of earlier errors removed. */
  markFields(errors) {
    const form = this.root.closest("[role=tabpanel]").querySelector("form");
    if (!form) return;
    for (const note of form.querySelectorAll(".field-error")) note.remove();
    for (const field of form.querySelectorAll("[aria-invalid]")) {
      field.removeAttribute("aria-invalid");
      field.removeAttribute("aria-describedby");
    }
    errors.forEach((error, i) => {
      const name = String(error.field).replace(/\[\d+\]/g, "");
      // A fit's points come from its CSV: their errors are the CSV's.
      const named = (n) => [...form.querySelectorAll("[name]")].find((f) => f.name === n && !f.disabled);
      const field = named(name) || (name.startsWith("series.points") ? named("series.csv") : undefined);
      if (!field) return;
      const note = document.createElement("span");
      note.className = "field-error";
      note.id = `${form.id}-error-${i}`;
      note.textContent = error.value === undefined ? error.message : `${JSON.stringify(error.value)}: expected ${error.allowed}`;
      field.setAttribute("aria-invalid", "true");
      // A field with several errors is described by each.
      field.setAttribute("aria-describedby", `${field.getAttribute("aria-describedby") || ""} ${note.id}`.trim());
      (field.closest("label") || field.parentElement).append(note);
    });
  }
}

/** The area of the tab panel holding `node`. */
function areaOf(node) {
  return node.closest("[role=tabpanel]").area;
}

/** A problem in one line: its title, then what each field did wrong or its detail. */
function problemText(problem) {
  const fields = (problem.errors || []).map((e) => e.message).join("; ");
  return `${problem.title}: ${fields || problem.detail}`;
}

/** A response's JSON body (`ok` true), or the problem it carries (`ok` false). A reply that is
 *  not JSON (a proxy's page, an empty 502) or a success without a body reads as a problem
 *  named by its status, never as an answer. */
async function readJson(response) {
  let body = null;
  if ((response.headers.get("content-type") || "").includes("json")) {
    body = await response.json().catch(() => null);
  }
  if (response.ok && body) return { ok: true, body };
  if (response.status === 401 && body && body.title) {
    const where = apiKey() ? "Change the API key (top of the page)." : "Enter an API key with “API key” at the top of the page.";
    return { ok: false, body: { ...body, detail: `${body.detail}. ${where}` } };
  }
  if (!response.ok && body && body.title) return { ok: false, body };
  const title = response.ok ? "Unreadable answer" : `${response.status} ${response.statusText || "Error"}`;
  const detail = response.ok ? "the server's answer is not JSON" : "the server gave no description of the problem";
  return { ok: false, body: { title, status: response.status, detail } };
}

/** The units of an answer's fields (its `meta.units`), by path; with `prefix`, those under it
 *  by their path below it (`points[].` gives each point's). */
function unitsOf(answer, prefix = "") {
  const units = {};
  for (const [path, unit] of Object.entries((answer.meta && answer.meta.units) || {})) {
    if (path.startsWith(prefix)) units[path.slice(prefix.length)] = unit;
  }
  return units;
}

/** Scalars of an answer with their units: nested objects flattened, a pair of numbers shown
 *  as the range it is, other lists left out. */
function rows(answer, units, prefix = "") {
  const out = [];
  // A zero has no magnitude of its own: it is shown in the unit of its siblings of the same
  // unit (areas.surface_surface 0 µm² beside the other areas, not 0 m²).
  const largest = {};
  for (const [key, value] of Object.entries(answer)) {
    const unit = units[prefix + key];
    if (typeof value === "number") largest[unit] = Math.max(largest[unit] || 0, Math.abs(value));
  }
  for (const [key, value] of Object.entries(answer)) {
    if (key === "meta") continue;
    const path = prefix + key;
    if (typeof value === "number") {
      const [size, unit] = scaleFor(value || largest[units[path]], units[path]);
      out.push([path, Number((value / size).toPrecision(6)), unit]);
    } else if (typeof value === "string" && path.endsWith(".mode")) {
      // A word the answer gives among its numbers: how the particle moves.
      out.push([path, value, ""]);
    } else if (Array.isArray(value) && value.length === 2 && value.every((v) => typeof v === "number")) {
      // A range (a fit's 95 % interval, its bounds): both ends in the unit of the larger.
      // A list's unit is named by its path with `[]`.
      const [size, unit] = scaleFor(Math.max(...value.map(Math.abs)), units[`${path}[]`]);
      out.push([path, value.map((v) => Number((v / size).toPrecision(4))).join(" to "), unit]);
    } else if (value && typeof value === "object" && !Array.isArray(value)) {
      out.push(...rows(value, units, path + "."));
    }
  }
  return out;
}

/** The area's table, emptied, with a head row of `names`. */
function freshTable(area, names) {
  const table = area.part("table");
  table.replaceChildren();
  const head = table.createTHead().insertRow();
  for (const name of names) {
    const th = document.createElement("th");
    th.scope = "col";
    th.textContent = name;
    head.append(th);
  }
  return table;
}

/** An answer's scalars, or a sweep's points. */
function showTable(area, answer) {
  if (Array.isArray(answer.points)) return showPoints(area, answer);
  const table = freshTable(area, ["quantity", "value", "unit"]);
  const body = table.createTBody();
  for (const [name, value, unit] of rows(answer, unitsOf(answer))) {
    const row = body.insertRow();
    for (const cell of [name, value, unit]) row.insertCell().textContent = cell;
  }
}

/** Rows of a sweep's table at most: the CSV and JSON downloads hold every point. */
const SHOWN_POINTS = 500;

/** A sweep's points as a table, a column per scalar of its first point (units in the head),
 *  sorted by a column when its head is clicked (again: the other way). */
function showPoints(area, answer) {
  const units = unitsOf(answer, "points[].");
  // Columns from a solved point: a refused or missing one has its inputs only.
  const first = answer.points.find(isSolved) || answer.points[0] || {};
  const columns = rows(first, units).map(([path]) => path).filter((path) => !path.startsWith("validity."));
  const statusColumn = typeof first.status === "string";
  // A column is shown in the unit of its largest value.
  const scales = Object.fromEntries(columns.map((c) => {
    const largest = answer.points.reduce((most, p) => Math.max(most, Math.abs(valueAt(p, c)) || 0), 0);
    return [c, scaleFor(largest, units[c])];
  }));
  const names = [...(statusColumn ? ["status"] : []), ...columns.map((c) => scales[c][1] ? `${c} [${scales[c][1]}]` : c)];
  const table = freshTable(area, names);
  const body = table.createTBody();
  const draw = (order) => {
    body.replaceChildren();
    for (const point of order.slice(0, SHOWN_POINTS)) {
      const row = body.insertRow();
      if (statusColumn) row.insertCell().textContent = point.status + (point.reason ? `: ${point.reason}` : "");
      for (const c of columns) {
        const value = valueAt(point, c);
        const cell = typeof value === "number" ? Number((value / scales[c][0]).toPrecision(6)) : value;
        row.insertCell().textContent = cell ?? "";
      }
    }
    if (order.length > SHOWN_POINTS) {
      const row = body.insertRow();
      const cell = row.insertCell();
      cell.colSpan = names.length;
      cell.textContent = `first ${SHOWN_POINTS} of ${order.length} points: every point is in the CSV and JSON downloads`;
    }
  };
  let sorted = { by: null, sign: 1 };
  [...table.tHead.rows[0].cells].forEach((th, i) => {
    const column = statusColumn ? (i === 0 ? "status" : columns[i - 1]) : columns[i];
    // The head's text in a button: a sortable column is reached and sorted by keyboard too.
    const button = Object.assign(document.createElement("button"), { type: "button", className: "sort", textContent: th.textContent });
    th.replaceChildren(button);
    button.addEventListener("click", () => {
      sorted = { by: column, sign: sorted.by === column ? -sorted.sign : 1 };
      const order = answer.points.slice().sort((a, b) => sorted.sign * compareValues(valueAt(a, column), valueAt(b, column)));
      for (const other of table.tHead.rows[0].cells) other.removeAttribute("aria-sort");
      th.setAttribute("aria-sort", sorted.sign > 0 ? "ascending" : "descending");
      draw(order);
    });
  });
  draw(answer.points);
}

/** Whether a sweep's point was solved: a refused or missing one has its inputs only. */
function isSolved(point) {
  return Boolean(point) && typeof point === "object" && point.status !== "refused" && point.status !== "missing";
}

/** The value at a dotted `path` of `object`. */
function valueAt(object, path) {
  return path.split(".").reduce((node, key) => (node == null ? undefined : node[key]), object);
}

/** Numbers before text, text in order, missing values last. */
function compareValues(a, b) {
  if (a === undefined || a === null) return b === undefined || b === null ? 0 : 1;
  if (b === undefined || b === null) return -1;
  if (typeof a === "number" && typeof b === "number") return a - b;
  return String(a).localeCompare(String(b));
}

/** The answer's warnings, in place of those shown (or after them, `after`: comparing). */
function showWarnings(area, answer, after = false) {
  const box = area.part("warnings");
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

/** Puts an SVG document into the area (inline, so the page's CSP allows it). */
function showPicture(area, svgText) {
  const doc = new DOMParser().parseFromString(svgText, "image/svg+xml");
  const svg = doc.documentElement;
  svg.setAttribute("role", "img");
  uniqueIds(svg);
  area.part("picture").replaceChildren(document.importNode(svg, true));
}

/** Pictures inlined so far: each one's ids get its number. */
let picturesShown = 0;

/** The ids of an SVG made its own, with the `url(#…)` that name them: every tab keeps a
 *  picture in one page, and a clip path's id found first in another would clip this one. */
function uniqueIds(svg) {
  picturesShown += 1;
  const renamed = new Map();
  for (const node of svg.querySelectorAll("[id]")) {
    renamed.set(node.id, `${node.id}-${picturesShown}`);
    node.id = renamed.get(node.id);
  }
  for (const node of svg.querySelectorAll("*")) {
    for (const attribute of ["clip-path", "fill", "stroke", "mask", "filter"]) {
      const value = node.getAttribute(attribute);
      const named = value && value.match(/^url\(#(.+)\)$/);
      if (named && renamed.has(named[1])) node.setAttribute(attribute, `url(#${renamed.get(named[1])})`);
    }
  }
}

/** Download buttons: each fetches the answer in its form and saves it. */
function showDownloads(area, fetchIn, name) {
  const box = area.part("downloads");
  box.replaceChildren();
  for (const [label, accept, ext] of [["JSON", "application/json", "json"], ["CSV", "text/csv", "csv"], ["SVG", "image/svg+xml", "svg"]]) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = `Download ${label}`;
    button.addEventListener("click", () => {
      fetchIn(accept).then(async (response) => {
        if (!response.ok) return area.status(`Download ${label}: ${problemText((await readJson(response)).body)}`, "error");
        const link = document.createElement("a");
        link.href = URL.createObjectURL(await response.blob());
        link.download = `${name}.${ext}`;
        link.click();
        // Revoked once the download has begun: at once may abort it.
        setTimeout(() => URL.revokeObjectURL(link.href), 10000);
      }).catch((e) => area.status(`Download ${label}: ${e.message || e}`, "error"));
    });
    box.append(button);
  }
}

/** An answer in its area: table, warnings, picture and downloads. A sweep's picture is drawn
 *  here to be explored ([`SweepPlot`]); any other's is the server's, which `picture` fetches. */
async function showAnswer(area, token, answer, picture, downloads, name) {
  area.clear();
  showTable(area, answer);
  showWarnings(area, answer);
  if (Array.isArray(answer.points) && answer.points.length) {
    new SweepPlot(area.part("picture"), answer);
  } else {
    const svg = await picture();
    const text = svg.ok ? await svg.text() : problemText((await readJson(svg)).body);
    if (!area.current(token)) return;
    if (svg.ok) {
      showPicture(area, text);
    } else {
      // The answer stands without its picture: why there is none is said in its place.
      const note = Object.assign(document.createElement("p"), { className: "warning", textContent: `⚠ No picture: ${text}` });
      area.part("picture").replaceChildren(note);
    }
  }
  showDownloads(area, downloads, name);
  if (area === $("#panel-history").area) showInputs(area, answer);
}

/** The inputs that made an answer opened from the history or a link (its canonical input,
 *  every default filled in, in SI units), under its table: the form that asked is elsewhere. */
function showInputs(area, answer) {
  const input = answer.meta && answer.meta.input;
  if (!input || typeof input !== "object") return;
  const box = Object.assign(document.createElement("details"), { className: "inputs", open: true });
  box.append(Object.assign(document.createElement("summary"), { textContent: "Inputs of this answer (SI units, every default filled in)" }));
  const table = box.appendChild(document.createElement("table"));
  const body = table.createTBody();
  const flat = (value, path) => {
    if (value && typeof value === "object" && !Array.isArray(value)) {
      for (const [key, inner] of Object.entries(value)) flat(inner, path ? `${path}.${key}` : key);
    } else {
      const row = body.insertRow();
      row.insertCell().textContent = path;
      const listed = Array.isArray(value) && value.some((v) => v && typeof v === "object");
      row.insertCell().textContent = listed ? `${value.length} items (in the JSON download)` : Array.isArray(value) ? value.join(", ") : String(value);
    }
  };
  flat(input, "");
  area.part("downloads").after(box);
}

/** What a continuum answer's verification says of its accuracy, in a sentence. */
function accuracy(answer) {
  const v = answer.meta && answer.meta.verification;
  if (!v || v.method === undefined) return "";
  const percent = (x) => `${(100 * x).toPrecision(2)} %`;
  const how = v.method === "grid"
    ? `on a ${v.grid.length} × ${v.grid.width} grid, ${Math.round(v.grid.pixels_across)} pixels across the contact`
    : "by the local law, which a layer this thin follows";
  const within = v.within_tolerance ? "" : " (bounds beyond §8's tolerance of 1 % in A, 0.5 % in δ)";
  return ` Layer as a continuum, ${how}: A within ±${percent(v.contact_area_error)}, δ within ±${percent(v.penetration_error)}${within}.`;
}

// ---- Comparing the two laws of the layer ------------------------------------------------

const SVG = "http://www.w3.org/2000/svg";

/** An SVG element with its attributes and text (the plots of plot.js draw with it too). */
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
  const area = areaOf(form);
  const { url, body } = requestOf(form);
  const token = area.begin("Solving under both laws…");
  const answers = [];
  for (const model of ["local", "continuum"]) {
    const asked = structuredClone(body);
    (asked.layer ??= {}).model = model;
    const read = await readJson(await post(url, asked));
    if (!area.current(token)) return;
    if (!read.ok) return area.problem(read.body);
    answers.push([model, read.body]);
  }
  area.clear();
  area.part("picture").replaceChildren(comparison(answers));
  const table = freshTable(area, ["quantity", "local law", "layer as a continuum"]);
  const rowsOf = table.createTBody();
  // Paired by name: a quantity one law has and the other lacks shows a dash.
  const [local, continuum] = answers.map(([, a]) => new Map(rows(a, unitsOf(a)).map(([name, value, unit]) => [name, `${value} ${unit}`.trim()])));
  for (const name of new Set([...local.keys(), ...continuum.keys()])) {
    const row = rowsOf.insertRow();
    for (const cell of [name, local.get(name) ?? "—", continuum.get(name) ?? "—"]) row.insertCell().textContent = cell;
  }
  showWarnings(area, answers[0][1]);
  showWarnings(area, answers[1][1], true);
  area.status(`Both laws solved.${accuracy(answers[1][1])}`);
}

/** `fetch` of the service, with the API key this browser was given, if any (a service may
 *  ask for one: `--anonymous`), in `x-api-key`. */
function api(url, init = {}) {
  const key = apiKey();
  if (!key) return fetch(url, init);
  const headers = new Headers(init.headers || {});
  headers.set("x-api-key", key);
  return fetch(url, { ...init, headers });
}

/** The API key entered in this browser (kept in its storage), or "". */
function apiKey() {
  return localStorage.getItem("thirdbody-api-key") || "";
}

/** The header's key control: a key entered is checked (a listing of its jobs), kept, and
 *  sent with every call from then on; forgotten, calls go without. */
function setUpApiKey() {
  const button = $("#api-key-button");
  const form = $("#api-key-form");
  const said = $("#api-key-status");
  const shown = () => {
    button.textContent = apiKey() ? "API key (in use)" : "API key";
  };
  shown();
  button.addEventListener("click", () => {
    form.hidden = !form.hidden;
    button.setAttribute("aria-expanded", String(!form.hidden));
    if (!form.hidden) $("#api-key").focus();
  });
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    const key = $("#api-key").value.trim();
    if (!key) return;
    localStorage.setItem("thirdbody-api-key", key);
    $("#api-key").value = "";
    shown();
    const response = await api("/v1/jobs?limit=1", { headers: { accept: "application/json" } });
    // A key refused is not kept: every call would be refused with it.
    if (response.status === 401) localStorage.removeItem("thirdbody-api-key");
    shown();
    const read = await readJson(response);
    said.textContent = read.ok
      ? `Key accepted: ${read.body.total} job${read.body.total === 1 ? "" : "s"} of its tenant in the history.`
      : `This key may not read jobs here: ${read.body.detail}`;
  });
  $("#api-key-forget").addEventListener("click", () => {
    localStorage.removeItem("thirdbody-api-key");
    shown();
    said.textContent = "The key is forgotten: calls go without one.";
  });
}

async function post(url, body, accept = "application/json") {
  const headers = { "content-type": "application/json", accept };
  return api(url, { method: "POST", headers: url === "/v1/jobs" ? owned(headers) : headers, body: JSON.stringify(body) });
}

/** `headers` with this browser's token as the owner: its jobs are listed to it, and only it
 *  cancels or deletes them. */
function owned(headers = {}) {
  return { ...headers, "thirdbody-owner": ownerToken() };
}

/** This browser's token as the owner of its jobs (the service lists a token's jobs to its
 *  holder only): made once, kept in local storage. 128 random bits, in hexadecimal. */
function ownerToken() {
  let token = localStorage.getItem("thirdbody-owner");
  if (!token) {
    const bytes = crypto.getRandomValues(new Uint8Array(16));
    token = [...bytes].map((b) => b.toString(16).padStart(2, "0")).join("");
    localStorage.setItem("thirdbody-owner", token);
  }
  return token;
}

async function solve(form) {
  const area = areaOf(form);
  const { url, body } = requestOf(form);
  const token = area.begin("Solving…");
  const response = await post(url, body);
  const read = await readJson(response);
  if (!area.current(token)) return;
  if (!read.ok) return area.problem(read.body);
  area.status(`Solved (${response.headers.get("x-cache") || "miss"}).${accuracy(read.body)}`);
  await showAnswer(area, token, read.body, () => post(url, body, "image/svg+xml"), (accept) => post(url, body, accept), form.dataset.kind);
}

// ---- Jobs: progress from the event stream, cancel -------------------------------------

/** The form of the tab panel of `area` (none for a panel without one, the history's). */
function formOf(area) {
  return area.root.closest("[role=tabpanel]").querySelector("form");
}

async function runJob(form) {
  const area = areaOf(form);
  const { url, body } = requestOf(form);
  const token = area.begin("Submitting…");
  // The job this tab followed, if any, is no longer followed: its stream closed.
  if (form.stopFollowing) form.stopFollowing();
  showProgress(area, { status: "queued", progress: { done: 0, total: 0 } });
  let read;
  try {
    read = await readJson(await post(url, body));
  } catch (e) {
    if (area.current(token)) showProgress(area, null);
    throw e;
  }
  if (!area.current(token)) {
    // Asked again meanwhile: this job has no one to show it to.
    if (read.ok) api(`/v1/jobs/${read.body.id}/cancel`, { method: "POST", headers: owned() }).catch(() => {});
    return;
  }
  if (!read.ok) {
    showProgress(area, null);
    return area.problem(read.body);
  }
  area.clear();
  follow(area, token, read.body.id);
}

/** The progress bar and its text in `area`'s form for a job's `view`: how far, and how it
 *  ended when it did not succeed (a failed or cancelled job's bar says so, in its colour).
 *  `null` empties it. A panel without a bar shows the progress in its status only. */
function showProgress(area, view) {
  const form = formOf(area);
  const bar = form && form.querySelector("progress");
  if (!bar) return;
  const text = form.querySelector(".progress-text");
  if (!view) {
    bar.value = 0;
    bar.className = "";
    text.textContent = "";
    return;
  }
  const { done, total } = view.progress;
  const running = ["queued", "running"].includes(view.status);
  bar.max = Math.max(total, 1);
  // A job that cannot tell its work in advance (a fit) runs with an indeterminate bar.
  if (total || !running) bar.value = total ? done : bar.max;
  else bar.removeAttribute("value");
  const count = total ? `${done} / ${total} (${Math.round((100 * done) / total)} %)` : `${done} points evaluated`;
  const ended = view.status === "failed" || view.status === "cancelled";
  bar.className = ended ? view.status : "";
  text.textContent = ended ? `${view.status} at ${count}` : count;
}

/** A request that threw (the server unreachable, a reply cut short) as a problem. */
function failure(e) {
  return { title: "The request failed", detail: e.message || String(e) };
}

/** Runs the handler `work` of a request's event; what it throws reads as an error while the
 *  request is the last one asked in `area`. */
function handled(area, token, work) {
  return (...args) => {
    Promise.resolve()
      .then(() => work(...args))
      .catch((e) => {
        if (area.current(token)) area.problem(failure(e));
      });
  };
}

/** An event stream read with this browser's API key, which an EventSource cannot send: the
 *  stream read through `fetch`, its events dispatched as an EventSource's are. It does not
 *  reconnect: a stream that ends or fails before it is closed says so with an `error` event,
 *  closed, as an EventSource that gave up does (the job is then followed from its record). */
class KeyedEventSource extends EventTarget {
  constructor(url) {
    super();
    this.readyState = EventSource.CONNECTING;
    this.aborter = new AbortController();
    this.read(url)
      .catch(() => {})
      .finally(() => {
        if (this.readyState === EventSource.CLOSED) return;
        this.readyState = EventSource.CLOSED;
        this.dispatchEvent(new Event("error"));
      });
  }

  async read(url) {
    const response = await api(url, { headers: { accept: "text/event-stream" }, signal: this.aborter.signal });
    if (!response.ok || !response.body) return;
    this.readyState = EventSource.OPEN;
    const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
    let buffer = "";
    for (;;) {
      const { value, done } = await reader.read();
      if (done) return;
      buffer += value.replace(/\r\n?/g, "\n");
      for (let end = buffer.indexOf("\n\n"); end >= 0; end = buffer.indexOf("\n\n")) {
        const block = buffer.slice(0, end);
        buffer = buffer.slice(end + 2);
        let name = "message";
        const data = [];
        for (const line of block.split("\n")) {
          if (line.startsWith("event:")) name = line.slice(6).trim();
          else if (line.startsWith("data:")) data.push(line.slice(5).replace(/^ /, ""));
        }
        if (data.length && this.readyState !== EventSource.CLOSED) this.dispatchEvent(new MessageEvent(name, { data: data.join("\n") }));
      }
    }
  }

  close() {
    this.readyState = EventSource.CLOSED;
    this.aborter.abort();
  }
}

/** Follows job `id` from its event stream; when the stream ends for good before the job does
 *  (the job unknown, too many streams, a restart), from its record. */
function follow(area, token, id) {
  const form = formOf(area);
  const cancel = (form && form.querySelector(".cancel")) || document.createElement("button");
  cancel.disabled = false;
  cancel.onclick = handled(area, token, async () => {
    cancel.disabled = true;
    const read = await readJson(await api(`/v1/jobs/${id}/cancel`, { method: "POST", headers: owned({ accept: "application/json" }) }));
    if (!read.ok && area.current(token)) area.status(`Cancel: ${problemText(read.body)}`, "error");
  });
  const url = `/v1/jobs/${id}/events`;
  const events = apiKey() ? new KeyedEventSource(url) : new EventSource(url);
  const stop = () => {
    events.close();
    cancel.disabled = true;
  };
  if (form) form.stopFollowing = stop;
  events.addEventListener("progress", handled(area, token, (e) => {
    if (!area.current(token)) return stop();
    const view = JSON.parse(e.data);
    showProgress(area, view);
    area.status(`Job ${view.status}…`, "busy");
  }));
  events.addEventListener("error", handled(area, token, async () => {
    if (events.readyState !== EventSource.CLOSED) {
      if (area.current(token)) area.status("The connection to the server was lost: reconnecting…", "busy");
      return;
    }
    // Followed from its record from now on: Cancel stays until it ends.
    events.close();
    await poll(area, token, id);
  }));
  events.addEventListener("completion", handled(area, token, async (e) => {
    stop();
    if (area.current(token)) await finished(area, token, JSON.parse(e.data));
  }));
}

/** Reads job `id`'s record every second until it ends (or another request is asked). */
async function poll(area, token, id) {
  while (area.current(token)) {
    const read = await readJson(await api(`/v1/jobs/${id}`, { headers: { accept: "application/json" } }));
    if (!area.current(token)) return;
    if (!read.ok) return area.problem(read.body);
    if (!["queued", "running"].includes(read.body.status)) return finished(area, token, read.body);
    showProgress(area, read.body);
    area.status(`Job ${read.body.status}…`, "busy");
    await new Promise((resolve) => setTimeout(resolve, 1000));
  }
}

/** A job's end: its answer, or what went wrong and the points it finished anyway. */
async function finished(area, token, view) {
  const form = formOf(area);
  if (form && form.querySelector(".cancel")) form.querySelector(".cancel").disabled = true;
  showProgress(area, view);
  const { done, total } = view.progress;
  const ending = {
    succeeded: ["Job succeeded.", ""],
    failed: [`Job failed: ${view.problem ? problemText(view.problem) : "no reason given"}.`, "error"],
    cancelled: [total ? `Job cancelled after ${done} of ${total} points.` : "Job cancelled.", "ended"],
  }[view.status] || [`Job ${view.status}.`, "ended"];
  if (!view.result_url) {
    area.clear();
    return area.status(`${ending[0]} No point was finished.`, ending[1]);
  }
  area.status(`${ending[0]} Reading its answer…`, "busy");
  const result = view.result_url;
  const read = await readJson(await api(result, { headers: { accept: "application/json" } }));
  if (!area.current(token)) return;
  if (!read.ok) return area.problem({ ...read.body, title: `${ending[0]} Its answer cannot be read (${read.body.title})` });
  const partial = view.partial ? " The answer below is partial: the points it finished." : "";
  area.status(ending[0] + partial + accuracy(read.body), ending[1]);
  await showAnswer(area, token, read.body, () => api(`${result}?format=svg`), (accept) => api(result, { headers: { accept } }), `job-${view.id}`);
}

// ---- Copying a form as a command ----------------------------------------------------

/** A form as a command: curl, the job as JSON (for `thirdbody solve`), or Python. */
async function copy(form, what) {
  const area = areaOf(form);
  const { url, body, job } = requestOf(form);
  const texts = {
    job: ["the job as JSON", JSON.stringify(job, null, 2)],
    curl: ["the curl command", `curl -s -X POST ${location.origin}${url} -H 'content-type: application/json'${apiKey() ? ` -H "x-api-key: $THIRDBODY_API_KEY"` : url === "/v1/jobs" ? ` -H "thirdbody-owner: $THIRDBODY_OWNER"` : ""} -d '${JSON.stringify(body)}'`],
    python: ["the Python script", python(url, body)],
  };
  const [name, text] = texts[what];
  try {
    await navigator.clipboard.writeText(text);
    area.status(`Copied ${name}.`);
  } catch {
    area.status(text);
  }
}

/** A Python script (requests) that posts `body` to `url` and prints the answer; a job is
 *  polled until it ends. The body is embedded as JSON, which Python reads as it is. */
function python(url, body) {
  const lines = [
    "import json, os, time, requests",
    "",
    `base = "${location.origin}"`,
    `body = json.loads(r"""${JSON.stringify(body, null, 2)}""")`,
    "# THIRDBODY_API_KEY: a key, for a service that asks for one.",
    'key = {"x-api-key": os.environ["THIRDBODY_API_KEY"]} if "THIRDBODY_API_KEY" in os.environ else {}',
  ];
  if (url === "/v1/jobs") {
    lines.push(
      "# Without a key, THIRDBODY_OWNER set to this browser's token (History: copy it) puts the job in its history.",
      'owner = {"thirdbody-owner": os.environ["THIRDBODY_OWNER"]} if "THIRDBODY_OWNER" in os.environ else {}',
      `job = requests.post(base + "${url}", json=body, headers={**key, **owner}).json()`,
      'while job["status"] in ("queued", "running"):',
      "    time.sleep(0.5)",
      '    job = requests.get(f"{base}/v1/jobs/{job[\'id\']}", headers=key).json()',
      'print(job["status"])',
      'answer = requests.get(base + job["result_url"], headers=key).json() if "result_url" in job else job',
    );
  } else {
    lines.push(
      `response = requests.post(base + "${url}", json=body, headers=key)`,
      "response.raise_for_status()",
      "answer = response.json()",
    );
  }
  lines.push("print(json.dumps({k: v for k, v in answer.items() if k != \"meta\"}, indent=2))");
  return lines.join("\n") + "\n";
}

// ---- History: this browser's jobs, kept by the service --------------------------------

/** The history's listing: the URL of its next page, while there is one, and the count of
 *  listings asked (the last one asked is the one shown). */
const listing = { next: null, asked: 0 };

/** The first page of the history as the filters ask. */
function historyUrl() {
  const params = new URLSearchParams({ limit: "20" });
  for (const [name, id] of [["kind", "#history-kind"], ["status", "#history-status"]]) {
    if ($(id).value) params.set(name, $(id).value);
  }
  return `/v1/jobs?${params}`;
}

/** Lists this browser's jobs: the first page, or (`more`) the next one below those shown. */
async function loadHistory(more = false) {
  const area = $("#panel-history").area;
  const url = more ? listing.next : historyUrl();
  if (!url) return;
  const asked = ++listing.asked;
  const read = await readJson(await api(url, { headers: owned({ accept: "application/json" }) }));
  // A later listing (another filter, a refresh) wins over this one.
  if (asked !== listing.asked) return;
  if (!read.ok) return area.problem(read.body);
  const rows = $("#history-jobs tbody");
  if (!more) rows.replaceChildren();
  for (const view of read.body.jobs) rows.append(historyRow(view));
  listing.next = read.body.next || null;
  $("#history-more").hidden = !listing.next;
  $("#history-jobs").closest(".table-box").hidden = rows.rows.length === 0;
  $("#history-count").textContent = read.body.total
    ? `${rows.rows.length} of ${read.body.total} jobs shown.`
    : "No jobs here yet: the sweeps and fits run in this browser are listed.";
}

/** A job's row: when, what, how far and how it ended; open, download or delete it. */
function historyRow(view) {
  const row = document.createElement("tr");
  row.dataset.id = view.id;
  const when = (t) => (t ? new Date(t).toLocaleString() : "—");
  const { done, total } = view.progress;
  const cells = [when(view.submitted_at), view.kind, view.status + (view.partial ? " (partial)" : ""), total ? `${done} / ${total}` : "—", when(view.finished_at)];
  for (const text of cells) row.insertCell().textContent = text;
  // A cell holds its buttons in a box of its own: a cell laid out as flex leaves the table.
  const actions = row.insertCell().appendChild(Object.assign(document.createElement("div"), { className: "actions" }));
  const open = Object.assign(document.createElement("button"), { type: "button", textContent: "Open" });
  open.addEventListener("click", () => guarded($("#panel-history").area, () => openJob(view.id)));
  actions.append(open);
  if (view.result_url) {
    for (const format of ["json", "csv", "svg"]) {
      const link = Object.assign(document.createElement("a"), { href: `${view.result_url}?format=${format}`, textContent: format.toUpperCase() });
      link.download = `${view.kind}-${view.id}.${format}`;
      // A link sends no header: with a key, the file is fetched with it, then saved.
      link.addEventListener("click", (event) => {
        if (!apiKey()) return;
        event.preventDefault();
        guarded($("#panel-history").area, async () => {
          const response = await api(link.href);
          if (!response.ok) return $("#panel-history").area.problem((await readJson(response)).body);
          const saved = Object.assign(document.createElement("a"), { href: URL.createObjectURL(await response.blob()), download: link.download });
          saved.click();
          setTimeout(() => URL.revokeObjectURL(saved.href), 10000);
        });
      });
      actions.append(link);
    }
  }
  const remove = Object.assign(document.createElement("button"), { type: "button", textContent: "Delete" });
  remove.addEventListener("click", () => guarded($("#panel-history").area, () => deleteJob(view)));
  actions.append(remove);
  return row;
}

/** Opens job `id` in the history's answer area, its link in the address bar; a job not
 *  finished is followed to its end. */
async function openJob(id) {
  const area = $("#panel-history").area;
  const token = area.begin("Opening the job…");
  history.replaceState(null, "", `#job=${id}`);
  const read = await readJson(await api(`/v1/jobs/${id}`, { headers: { accept: "application/json" } }));
  if (!area.current(token)) return;
  if (!read.ok) return area.problem(read.body);
  if (["queued", "running"].includes(read.body.status)) return follow(area, token, id);
  await finished(area, token, read.body);
}

/** Opens the answer to the input whose hash is `hash` (its stable link). */
async function openInput(hash) {
  const area = $("#panel-history").area;
  const token = area.begin("Opening the answer…");
  const url = `/v1/results/${hash}`;
  const read = await readJson(await api(url, { headers: { accept: "application/json" } }));
  if (!area.current(token)) return;
  if (!read.ok) return area.problem(read.body);
  area.status(`The answer to input ${hash.slice(0, 12)}…`);
  await showAnswer(area, token, read.body, () => api(`${url}?format=svg`), (accept) => api(url, { headers: { accept } }), `answer-${hash.slice(0, 12)}`);
}

/** Deletes the job of `view` (after asking); the history is listed again without it. */
async function deleteJob(view) {
  const job = `the ${view.kind} job of ${new Date(view.submitted_at).toLocaleString()}`;
  if (!confirm(`Delete ${job} and its answer?`)) return;
  const area = $("#panel-history").area;
  const read = await readJson(await api(`/v1/jobs/${view.id}`, { method: "DELETE", headers: owned({ accept: "application/json" }) }));
  if (!read.ok) return area.problem(read.body);
  area.status(`Deleted ${job}.`);
  await loadHistory();
}

/** A link to a job (`#job=id`) or an input's answer (`#input=hash`) opens it in the history. */
function openLinked() {
  const [, what, value] = location.hash.match(/^#(job|input)=([\w-]+)$/) || [];
  if (!what) return;
  selectTab($("#tab-history"));
  guarded($("#panel-history").area, () => (what === "job" ? openJob(value) : openInput(value)));
}

// ---- Figures, tabs, start-up ---------------------------------------------------------

async function figure(area, n) {
  const token = area.begin(`Figure ${n}…`);
  const url = `/v1/figures/${n}`;
  const read = await readJson(await api(url, { headers: { accept: "application/json" } }));
  if (!area.current(token)) return;
  if (!read.ok) return area.problem(read.body);
  const answer = read.body;
  area.status(`Figure ${n}: ${answer.title}`);
  // Its table says which figure and how many series; the series are in the downloads.
  const summary = { figure: answer.figure, series: answer.series.length, meta: answer.meta };
  await showAnswer(area, token, summary, () => api(`${url}?format=svg`), (accept) => api(url, { headers: { accept } }), `figure-${n}`);
}

/** Selects `tab` and shows its panel (and its own answer); `focus` moves the keyboard there.
 *  The history is listed afresh each time it is shown. */
function selectTab(tab, focus = false) {
  for (const other of document.querySelectorAll("[role=tab]")) {
    const selected = other === tab;
    other.setAttribute("aria-selected", String(selected));
    other.tabIndex = selected ? 0 : -1;
    document.getElementById(other.getAttribute("aria-controls")).hidden = !selected;
  }
  if (focus) tab.focus();
  if (tab.id === "tab-history") guarded($("#panel-history").area, () => loadHistory());
}

/** The tabs as the ARIA pattern has them: arrows, Home and End move between them. */
function tabKeys(event) {
  const tabs = [...document.querySelectorAll("[role=tab]")];
  const at = tabs.indexOf(event.target);
  const to = { ArrowRight: at + 1, ArrowLeft: at - 1, Home: 0, End: tabs.length - 1 }[event.key];
  if (to === undefined) return;
  event.preventDefault();
  selectTab(tabs[(to + tabs.length) % tabs.length], true);
}

/** Runs `work`; a field that cannot be read, or an exception (the server unreachable),
 *  reads as an error in `area`. */
function guarded(area, work) {
  // The request `work` begins is the next one asked; one asked after it wins.
  const before = area.asked;
  work().catch((e) => {
    if (area.asked > before + 1) return;
    area.problem(e instanceof InputError ? e.problem : failure(e));
  });
}

document.addEventListener("DOMContentLoaded", () => {
  buildFieldsets();
  buildBounds();
  const template = $("#answer-area");
  for (const panel of document.querySelectorAll("[role=tabpanel]")) {
    const root = template.content.firstElementChild.cloneNode(true);
    panel.append(root);
    panel.area = new Area(root);
  }
  for (const tab of document.querySelectorAll("[role=tab]")) {
    tab.addEventListener("click", () => selectTab(tab));
    tab.addEventListener("keydown", tabKeys);
  }
  selectTab(document.querySelector("[role=tab][aria-selected=true]"));
  for (const form of document.querySelectorAll("main form")) {
    form.addEventListener("submit", (event) => {
      event.preventDefault();
      guarded(areaOf(form), async () => (isJob(form) ? runJob(form) : solve(form)));
    });
    for (const button of form.querySelectorAll("[data-copy]")) {
      button.addEventListener("click", () => guarded(areaOf(form), () => copy(form, button.dataset.copy)));
    }
    switchParts(form);
    // A CSV file read into the text it stands for.
    for (const file of form.querySelectorAll("input[data-csv-file]")) {
      file.addEventListener("change", () => guarded(areaOf(form), async () => {
        if (file.files.length) form.querySelector("textarea[data-csv]").value = await file.files[0].text();
      }));
    }
  }
  const rolling = $("#form-rolling");
  $("#compare").addEventListener("click", () => guarded(areaOf(rolling), () => compare(rolling)));
  const buttons = $("#figure-buttons");
  for (let n = 3; n <= 9; n++) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = `Figure ${n}`;
    button.addEventListener("click", () => guarded(areaOf(buttons), () => figure(areaOf(buttons), n)));
    buttons.append(button);
  }
  const historyArea = $("#panel-history").area;
  for (const id of ["#history-kind", "#history-status"]) $(id).addEventListener("change", () => guarded(historyArea, () => loadHistory()));
  $("#history-refresh").addEventListener("click", () => guarded(historyArea, () => loadHistory()));
  $("#history-more").addEventListener("click", () => guarded(historyArea, () => loadHistory(true)));
  $("#history-token").addEventListener("click", () => guarded(historyArea, async () => {
    await navigator.clipboard.writeText(ownerToken());
    historyArea.status("Copied this browser's token: set THIRDBODY_OWNER to it, and the jobs of copied commands are listed here. Keep it to yourself: it lists your jobs.");
  }));
  setUpApiKey();
  openLinked();
  window.addEventListener("hashchange", openLinked);
});
