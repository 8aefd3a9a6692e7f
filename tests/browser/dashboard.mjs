// The dashboard end to end, as a user at a browser: Debian's chromium driven by
// playwright-core against `thirdbody serve` on a port the system chooses. Fails on a console
// error or on any request that leaves the server. Screenshots go to target/browser/.
import { spawn } from "node:child_process";
import { createHash } from "node:crypto";
import { mkdirSync, mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { chromium } from "playwright-core";

const root = new URL("../../", import.meta.url).pathname;
const bin = process.env.THIRDBODY_BIN || `${root}target/release/thirdbody`;
const shots = `${root}target/browser`;
mkdirSync(shots, { recursive: true });

function fail(message) {
  console.error(`FAILED: ${message}`);
  process.exitCode = 1;
}

/** Starts the service on `bind` (with `flags`) and resolves with its base URL (from its log). */
function serve(flags = [], bind = "127.0.0.1:0") {
  const child = spawn(bin, ["serve", "--bind", bind, "--log-format", "json", ...flags], {
    stdio: ["ignore", "ignore", "pipe"],
  });
  return new Promise((resolve, reject) => {
    let log = "";
    child.stderr.on("data", (chunk) => {
      log += chunk;
      const found = log.match(/"address":"(127\.0\.0\.1:\d+)"/);
      if (found) resolve({ child, base: `http://${found[1]}` });
    });
    child.on("exit", (code) => reject(new Error(`thirdbody serve exited ${code}: ${log}`)));
  });
}

/** Stops `child` as an operator would (SIGTERM, the drain) and resolves when it has exited. */
function stop(child) {
  return new Promise((resolve) => {
    child.on("exit", resolve);
    child.kill("SIGTERM");
  });
}

// Every process this test starts, stopped at its end whatever happens.
const started = [];
const data = mkdtempSync(`${tmpdir()}/thirdbody-dashboard-`);
process.on("exit", () => {
  started.forEach((child) => child.kill());
  rmSync(data, { recursive: true, force: true });
});
// The database of saved analyses in a file, as `thirdbody serve` keeps it by default.
const database = ["--database", `${data}/analyses.db`];
const { child, base } = await serve(database);
started.push(child);
// A second service whose jobs must end within 300 ms: a long sweep there fails.
const strict = await serve(["--job-deadline", "300ms", "--database", ":memory:"]);
started.push(strict.child);
// A third that asks every caller for an API key (its keys given inline, hashed).
const apiKey = "tb_key-of-the-browser-test-0001";
const keys = { keys: [{ name: "lab", sha256: createHash("sha256").update(apiKey).digest("hex"), scopes: ["submit", "read"] }] };
const keyed = await serve(["--anonymous", "none", "--api-keys", JSON.stringify(keys), "--database", ":memory:"]);
started.push(keyed.child);
// The answer area of a tab's panel, and a part of it.
const area = (panel, part = "") => `#panel-${panel} .answer-area${part ? " ." + part : ""}`;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1366, height: 900 } });
  const errors = [];
  // Refusals the test asks for on purpose are logged by chromium as failed loads: counted
  // apart, and checked against those asked for.
  const refusals = [];
  page.on("console", (message) => {
    if (message.type() !== "error") return;
    const refusal = message.text().match(/^Failed to load resource: the server responded with a status of (4\d\d)/);
    (refusal ? refusals : errors).push(refusal ? refusal[1] : message.text());
  });
  page.on("pageerror", (error) => errors.push(String(error)));
  const outside = [];
  page.on("request", (request) => {
    const url = request.url();
    if (!url.startsWith(base) && !url.startsWith("blob:") && !url.startsWith("data:")) outside.push(url);
  });

  // The default rolling contact: a table and its picture.
  await page.goto(`${base}/`);
  const csp = (await page.request.get(`${base}/`)).headers()["content-security-policy"];
  if (csp !== "default-src 'self'; frame-ancestors 'self'") fail(`Content-Security-Policy is ${csp}`);
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForSelector(`${area("rolling", "picture")} svg .series`);
  const mu = await page.locator(`${area("rolling", "table")} tr`, { hasText: "friction_coefficient" }).first().textContent();
  if (!/0\.0947/.test(mu)) fail(`the default friction coefficient is shown as ${mu}`);
  // How it moves (docs/model.md §11): it rolls, and its own friction is μ_roll.
  const mode = await page.locator(`${area("rolling", "table")} tr`, { hasText: "motion.mode" }).first().textContent();
  if (!/rolls/.test(mode)) fail(`the default particle's motion reads ${mode}`);
  const own = await page.locator(`${area("rolling", "table")} tr`, { hasText: "motion.friction" }).first().textContent();
  if (!/0\.02138/.test(own)) fail(`the default particle's own friction reads ${own}`);
  await page.screenshot({ path: `${shots}/rolling.png`, fullPage: true });

  // An error after a success: the message names the field, and the old answer is gone.
  await page.fill("#form-rolling input[name='load']", "-1 nN");
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForSelector(`${area("rolling", "status")}.error`);
  const refusal = await page.locator(area("rolling", "status")).textContent();
  if (!refusal.includes("load")) fail(`the refusal of a negative load reads ${refusal}`);
  const stale = await page.locator(`${area("rolling", "table")} tr, ${area("rolling", "picture")} svg, ${area("rolling", "warnings")} p`).count();
  if (stale !== 0) fail(`${stale} rows, pictures or warnings of the earlier answer stay under the error`);
  const beside = await page.locator("#form-rolling label:has(input[name='load'][aria-invalid='true']) .field-error").textContent();
  if (!beside.includes("> 0 N")) fail(`beside the load field: ${beside}`);
  await page.screenshot({ path: `${shots}/rolling-error.png`, fullPage: true });
  await page.fill("#form-rolling input[name='load']", "1 nN");

  // The same particle on the layer as a continuum: about 8.3 nm², its accuracy said.
  await page.selectOption("#form-rolling select[name='layer.model']", "continuum");
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction((s) => document.querySelector(s).textContent.includes("continuum"), area("rolling", "status"));
  const continuumArea = await page.locator(`${area("rolling", "table")} tr`, { hasText: "contact_area" }).first().textContent();
  if (!/8\.[1-4]\d*\s*nm²/.test(continuumArea)) fail(`the continuum's contact area is shown as ${continuumArea}`);
  const slides = await page.locator(`${area("rolling", "table")} tr`, { hasText: "motion.mode" }).first().textContent();
  if (!/slides_at_layer/.test(slides)) fail(`on the continuum the particle's motion reads ${slides}`);
  const warned = await page.locator(area("rolling", "warnings")).textContent();
  if (!/slides on the layer/.test(warned)) fail(`the pure-rolling warning reads ${warned}`);
  if (await page.locator("#form-rolling [aria-invalid], #form-rolling .field-error").count()) fail("the load stays marked invalid after a success");
  await page.screenshot({ path: `${shots}/rolling-continuum.png`, fullPage: true });

  // Both laws together: two regions on one plane, their numbers side by side.
  await page.getByRole("button", { name: "Compare both laws" }).click();
  await page.waitForFunction((s) => document.querySelectorAll(`${s} svg polygon.series`).length === 2, area("rolling", "picture"));
  const compared = await page.locator(`${area("rolling", "table")} tr`, { hasText: "friction_coefficient" }).first().textContent();
  if (!/0\.0947/.test(compared) || !/0\.0091/.test(compared)) fail(`the compared μ reads ${compared}`);
  await page.screenshot({ path: `${shots}/rolling-compare.png`, fullPage: true });
  await page.selectOption("#form-rolling select[name='layer.model']", "local");

  // A layer from a Prony series typed as CSV: its Kelvin times are then not sent.
  const series = "10 ms, 6 GPa\n100 ms, 4.5 GPa\n1 s, 3 GPa\n10 s, 1.5 GPa";
  await page.fill("#form-rolling textarea[name='layer.prony_csv']", series);
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction((s) => [...document.querySelectorAll(`${s} tr`)]
    .some((row) => row.textContent.includes("friction_coefficient") && /0\.0737/.test(row.textContent)), area("rolling", "table"));
  await page.screenshot({ path: `${shots}/rolling-prony.png`, fullPage: true });
  await page.fill("#form-rolling textarea[name='layer.prony_csv']", "");

  // A three-body system: its distribution of diameters.
  await page.getByRole("tab", { name: "Three-body system" }).click();
  await page.locator("#form-three-body").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction((s) => (document.querySelector(`${s} svg title`) || {}).textContent?.startsWith("Three-body"), area("three-body", "picture"));
  // The particles that roll and those that slide (docs/model.md §11), shaded apart on its
  // picture, and the system's own friction beside eq. 12's.
  const populations = await page.locator(`${area("three-body", "picture")} svg`).textContent();
  if (!/in contact: rolls/.test(populations) || !/in contact: slides/.test(populations)) fail(`the three-body picture's populations: ${populations.slice(0, 300)}`);
  if (!(await page.locator(`${area("three-body", "table")} tr`, { hasText: "motion.friction" }).count())) fail("the three-body table has no motion.friction");
  await page.screenshot({ path: `${shots}/three-body.png`, fullPage: true });
  const localMu = await page.locator(`${area("three-body", "table")} tr`, { hasText: "friction_coefficient" }).first().textContent();
  // Each quantity in the unit of its magnitude: W = 0.99999…e-3 N is 1 mN (not 1000 µN), and
  // a zero area is in the unit of the other areas (not m²).
  const bodyRow = async (name) => page.locator(`${area("three-body", "table")} tr`, { hasText: name }).first().textContent();
  if ((await bodyRow("loads.total")) !== "loads.total1mN") fail(`the total load reads ${await bodyRow("loads.total")}`);
  if ((await bodyRow("areas.surface_surface")) !== "areas.surface_surface0µm²") fail(`a zero area reads ${await bodyRow("areas.surface_surface")}`);
  // The form says which modulus the layer's is.
  if (!(await page.locator("#form-three-body label[data-field='elastic_modulus']").textContent()).includes("constrained")) fail("the three-body form does not say which modulus E_L is");

  // The same system on the continuum layer contact: its μ several times lower, its error said.
  await page.selectOption("#form-three-body select[name='layer_contact']", "continuum");
  await page.locator("#form-three-body").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction(([s, before]) => {
    const row = [...document.querySelectorAll(`${s} tr`)].find((r) => r.textContent.includes("friction_coefficient"));
    return row && row.textContent !== before;
  }, [area("three-body", "table"), localMu], { timeout: 30000 });
  const continuumMu = await page.locator(`${area("three-body", "table")} tr`, { hasText: "friction_coefficient" }).first().textContent();
  const first = (text) => Number((text.match(/\d\.\d+(e-?\d+)?/) || ["NaN"])[0]);
  if (!(first(localMu) > 3 * first(continuumMu))) fail(`three-body μ: local ${localMu}, continuum ${continuumMu}`);
  await page.screenshot({ path: `${shots}/three-body-continuum.png`, fullPage: true });
  await page.selectOption("#form-three-body select[name='layer_contact']", "kelvin_layer");

  // A 200-point sweep as a job: the progress bar reaches 100 %, its points fill a table
  // that sorts by a column.
  await page.getByRole("tab", { name: "Sweep" }).click();
  const loads = Array.from({ length: 10 }, (_, i) => `${(0.5 + 0.25 * i).toFixed(2)} nN`).join(", ");
  const speeds = Array.from({ length: 20 }, (_, i) => `${i} nm/s`).join(", ");
  await page.fill("input[name='vary.load']", loads);
  await page.fill("input[name='vary.velocity']", speeds);
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction((s) => {
    const bar = document.querySelector("#progress");
    return bar.max === 200 && bar.value === 200 && document.querySelector(`${s} svg .series`);
  }, area("sweep", "picture"), { timeout: 60000 });
  const progress = await page.locator("#progress-text").textContent();
  if (!progress.includes("200 / 200 (100 %)")) fail(`progress reads ${progress}`);
  const pointRows = await page.locator(`${area("sweep", "table")} tbody tr`).count();
  if (pointRows !== 200) fail(`the sweep's table has ${pointRows} rows, not its 200 points`);
  const muHead = page.locator(`${area("sweep", "table")} th`, { hasText: /^friction_coefficient/ }).first();
  const muColumn = await muHead.evaluate((th) => th.cellIndex);
  const column = () => page.$$eval(`${area("sweep", "table")} tbody tr`, (rows, i) => rows.map((r) => Number(r.cells[i].textContent)), muColumn);
  await muHead.getByRole("button").click();
  const ascending = await column();
  if (ascending.some((v, i) => i > 0 && v < ascending[i - 1])) fail(`sorted by μ the column reads ${ascending.slice(0, 5)}…`);
  await muHead.getByRole("button").click();
  const descending = await column();
  if (descending[0] !== Math.max(...ascending) || (await muHead.getAttribute("aria-sort")) !== "descending") fail(`sorted again by μ the column starts ${descending[0]}`);
  await page.screenshot({ path: `${shots}/sweep.png`, fullPage: true });

  // The sweep's plot to explore: a line per load, then any quantity against any varied input.
  const plot = `${area("sweep", "picture")} svg.plot`;
  const lines = await page.locator(`${plot} path.series`).count();
  if (lines !== 10) fail(`the sweep's plot draws ${lines} lines, not one per load (10)`);
  // The legend writes each load in one unit, the largest's (0.5 nN, not 500 pN).
  const names = await page.$$eval(`${plot} path.series`, (paths) => paths.map((p) => p.dataset.name));
  if (names[0] !== "load = 0.5 nN" || names.some((n) => !n.endsWith(" nN"))) fail(`the sweep's legend reads ${names}`);
  await page.selectOption(`${area("sweep", "picture")} select[name='y']`, "contact_area");
  await page.selectOption(`${area("sweep", "picture")} select[name='x']`, "load");
  const yLabel = await page.locator(`${plot} .y-label`).textContent();
  if (yLabel !== "contact_area [nm²]") fail(`the plot's y axis reads ${yLabel}`);
  const perSpeed = await page.locator(`${plot} path.series`).count();
  if (perSpeed !== 20) fail(`against the load the plot draws ${perSpeed} lines, not one per speed (20)`);
  const speedNames = await page.$$eval(`${plot} path.series`, (paths) => paths.map((p) => p.dataset.name));
  if (speedNames[0] !== "velocity = 0 nm/s") fail(`the legend's first speed reads ${speedNames[0]}`);
  if (!(await page.locator(`${area("sweep", "picture")} .colour-bar`).count())) fail("20 lines are not told by a colour bar");
  // Hover reads the nearest point with its units.
  const dot = await page.locator(`${plot} circle.point`).nth(5).boundingBox();
  await page.mouse.move(dot.x + dot.width / 2, dot.y + dot.height / 2);
  const tip = await page.locator(`${plot} g.tip`).textContent();
  if ((await page.locator(`${plot} g.tip`).getAttribute("visibility")) !== "visible" || !/load = [\d.]+ nN/.test(tip) || !/contact_area = [\d.]+ nm²/.test(tip)) fail(`hovering a point reads ${tip}`);
  // A drag zooms in, Reset zoom goes back.
  const xTicks = () => page.$$eval(`${plot} .axes text`, (nodes) => nodes.map((n) => n.textContent).join(" "));
  const whole = await xTicks();
  const frame = await page.locator(plot).boundingBox();
  await page.mouse.move(frame.x + frame.width * 0.3, frame.y + frame.height * 0.2);
  await page.mouse.down();
  await page.mouse.move(frame.x + frame.width * 0.6, frame.y + frame.height * 0.6, { steps: 5 });
  await page.mouse.up();
  const zoomed = await xTicks();
  if (zoomed === whole) fail("a drag over the plot does not zoom");
  await page.getByRole("button", { name: "Reset zoom" }).click();
  if ((await xTicks()) !== whole) fail("Reset zoom does not restore the axes");
  await page.check(`${area("sweep", "picture")} input[name='logY']`);
  if (!(await page.locator(`${plot} .y-label`).textContent()).endsWith("(log)")) fail("log y does not make the y axis logarithmic");
  // Two varied inputs: a heat map, a cell per point.
  await page.selectOption(`${area("sweep", "picture")} select[name='view']`, "heat");
  const cells = await page.locator(`${plot} rect.cell`).count();
  if (cells !== 200) fail(`the heat map has ${cells} cells, not 200`);
  await page.screenshot({ path: `${shots}/sweep-heat-map.png`, fullPage: true });

  // A one-point sweep is drawn: its point.
  await page.fill("input[name='vary.load']", "1 nN");
  await page.fill("input[name='vary.velocity']", "4 nm/s");
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction((s) => document.querySelectorAll(`${s} circle.point`).length === 1
    && document.querySelector("#progress-text").textContent.includes("1 / 1"), plot, { timeout: 30000 });

  // A sweep with a point the model refuses: the other points are answered, the refusal said
  // in the warnings and on the point's row.
  await page.fill("input[name='vary.load']", "1 nN, 1 mN, 2 nN");
  await page.fill("input[name='vary.velocity']", "4 nm/s");
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction((s) => document.querySelector(s).textContent.includes("refused"), area("sweep", "warnings"), { timeout: 60000 });
  const refused = await page.locator(area("sweep", "warnings")).textContent();
  if (!refused.includes("1 of 3 points refused")) fail(`the refused point reads ${refused}`);
  const refusedRow = await page.locator(`${area("sweep", "table")} tbody tr`, { hasText: "refused" }).first().textContent();
  if (!refusedRow.includes("rigid base")) fail(`the refused point's row reads ${refusedRow}`);
  await page.screenshot({ path: `${shots}/sweep-refused.png`, fullPage: true });

  // A long sweep cancelled: the bar and the status say so, in the colours of an end that
  // is not a success.
  const manySpeeds = Array.from({ length: 100 }, (_, i) => `${i} nm/s`).join(", ");
  await page.fill("input[name='vary.load']", "1 nN, 2 nN, 3 nN");
  await page.fill("input[name='vary.velocity']", manySpeeds);
  await page.selectOption("#form-sweep select[name='base.layer.model']", "continuum");
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction((s) => document.querySelector(s).textContent.includes("running"), area("sweep", "status"), { timeout: 30000 });
  await page.getByRole("button", { name: "Cancel" }).click();
  // Its end: the points it finished drawn, or none finished (a cancel before the first).
  await page.waitForFunction((s) => {
    const said = document.querySelector(`${s} .status`).textContent;
    return document.querySelector("#progress-text").textContent.startsWith("cancelled")
      && (said.includes("No point was finished") || (said.includes("partial") && document.querySelector(`${s} .picture svg`)));
  }, area("sweep"), { timeout: 30000 });
  const cancelled = await page.locator(area("sweep", "status")).textContent();
  if (!cancelled.includes("Job cancelled after")) fail(`the cancelled sweep's status reads ${cancelled}`);
  if ((await page.locator("#progress").getAttribute("class")) !== "cancelled") fail("the cancelled sweep's bar is not marked cancelled");
  await page.screenshot({ path: `${shots}/sweep-cancelled.png`, fullPage: true });

  // A job that does not exist (a link to one dropped, or from another server) reads as an
  // error, not as an answer.
  await page.evaluate(() => {
    const sweep = areaOf(document.querySelector("#form-sweep"));
    follow(sweep, sweep.begin("Following…"), "00000000-0000-4000-8000-000000000000");
  });
  await page.waitForSelector(`${area("sweep", "status")}.error`, { timeout: 30000 });
  const unknown = await page.locator(area("sweep", "status")).textContent();
  if (!unknown.startsWith("Not found")) fail(`an unknown job reads ${unknown}`);
  if (await page.locator(`${area("sweep", "table")} tr`).count()) fail("an unknown job leaves a table on screen");

  // Switching tabs shows each tab's own answer: the sweep's error is not under Figures.
  await page.getByRole("tab", { name: "Figures 3–9" }).click();
  if (await page.locator(`${area("figures", "status")}`).textContent()) fail("the Figures tab shows another tab's status");
  if (!(await page.locator(area("three-body", "picture")).isHidden())) fail("the three-body picture shows under Figures");

  // A sweep of three-body systems: their own lists and base, the plot against the total load.
  await page.getByRole("tab", { name: "Sweep" }).click();
  await page.selectOption("#form-sweep select[name='kind']", "three_body");
  if (!(await page.locator("#form-sweep input[name='vary.radius']").isHidden())) fail("a three-body sweep shows the rolling radii");
  await page.fill("#form-sweep input[name='vary.total_load']", "0.5 mN, 1 mN");
  await page.fill("input[name='vary.velocity']", "4 nm/s");
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction((s) => document.querySelector(`${s} svg.plot`)?.dataset.x === "operating.total_load"
    && document.querySelectorAll(`${s} circle.point`).length === 2, area("sweep", "picture"), { timeout: 60000 });
  await page.selectOption("#form-sweep select[name='kind']", "rolling");

  // Every input of a three-body system: asperities sent when given.
  await page.getByRole("tab", { name: "Three-body system" }).click();
  for (const [name, value] of [["asperities.density", "1e12 m^-2"], ["asperities.tip_radius", "1 um"], ["asperities.height_std", "20 nm"], ["asperities.hardness", "2 GPa"], ["upper_surface.elastic_modulus", "200 GPa"]]) {
    await page.fill(`#form-three-body input[name='${name}']`, value);
  }
  // Its discretisation too.
  await page.fill("#form-three-body input[name='options.diameter_nodes']", "24");
  await page.selectOption("#form-three-body select[name='options.quadrature']", "midpoint");
  const sent = page.waitForRequest((r) => r.url().endsWith("/v1/three-body") && r.method() === "POST");
  await page.locator("#form-three-body").getByRole("button", { name: "Solve" }).click();
  const options = JSON.parse((await sent).postData()).options;
  if (options?.diameter_nodes !== 24 || options?.quadrature !== "midpoint") fail(`the three-body options sent: ${JSON.stringify(options)}`);
  await page.waitForFunction((s) => document.querySelector(`${s} .status`).textContent.startsWith("Solved")
    && [...document.querySelectorAll(`${s} .table tr`)].some((r) => r.textContent.startsWith("loads.asperities")), area("three-body"), { timeout: 30000 });
  const asperityLoad = await page.locator(`${area("three-body", "table")} tr`, { hasText: "loads.asperities" }).first().textContent();
  if (!/[1-9]/.test(asperityLoad)) fail(`the asperities carry no load: ${asperityLoad}`);


  // Copy as Python: a script that posts the form's body as it is.
  await page.getByRole("tab", { name: "Rolling contact" }).click();
  await page.context().grantPermissions(["clipboard-read", "clipboard-write"], { origin: base });
  await page.locator("#form-rolling").getByRole("button", { name: "Copy as Python" }).click();
  const script = await page.evaluate(() => navigator.clipboard.readText());
  const embedded = (script.match(/json\.loads\(r"""([\s\S]*?)"""\)/) || [])[1];
  if (!embedded || JSON.parse(embedded).load !== "1 nN" || !script.includes(`requests.post(base + "/v1/rolling", json=body, headers=key)`)) fail(`Copy as Python gives ${script}`);

  // A fit from an uploaded CSV: the parameters with their intervals, the picture.
  await page.getByRole("tab", { name: "Fit" }).click();
  await page.setInputFiles("#form-fit input[type='file']", { name: "measured.csv", mimeType: "text/csv", buffer: Buffer.from("radius, load, velocity, value, uncertainty\n25 nm, 0.8 nN, 0 nm/s, 0.1173, 0.0015\n25 nm, 0.8 nN, 0.5 nm/s, 0.1139, 0.0015\n25 nm, 0.8 nN, 1 nm/s, 0.1063, 0.0015\n25 nm, 0.8 nN, 1.5 nm/s, 0.1058, 0.0015\n25 nm, 0.8 nN, 2 nm/s, 0.1036, 0.0015\n25 nm, 0.8 nN, 3 nm/s, 0.0973, 0.0015\n25 nm, 0.8 nN, 4 nm/s, 0.0896, 0.0015\n25 nm, 0.8 nN, 5 nm/s, 0.085, 0.0015\n25 nm, 0.8 nN, 6 nm/s, 0.0821, 0.0015\n25 nm, 0.8 nN, 8 nm/s, 0.0725, 0.0015\n25 nm, 0.8 nN, 10 nm/s, 0.0686, 0.0015\n25 nm, 0.8 nN, 12 nm/s, 0.0622, 0.0015\n25 nm, 0.8 nN, 15 nm/s, 0.0603, 0.0015\n25 nm, 0.8 nN, 20 nm/s, 0.0538, 0.0015\n25 nm, 0.8 nN, 30 nm/s, 0.0514, 0.0015\n25 nm, 1.2 nN, 0 nm/s, 0.0968, 0.0015\n25 nm, 1.2 nN, 0.5 nm/s, 0.0944, 0.0015\n25 nm, 1.2 nN, 1 nm/s, 0.0915, 0.0015\n25 nm, 1.2 nN, 1.5 nm/s, 0.0847, 0.0015\n25 nm, 1.2 nN, 2 nm/s, 0.0858, 0.0015\n25 nm, 1.2 nN, 3 nm/s, 0.0794, 0.0015\n25 nm, 1.2 nN, 4 nm/s, 0.074, 0.0015\n25 nm, 1.2 nN, 5 nm/s, 0.0725, 0.0015\n25 nm, 1.2 nN, 6 nm/s, 0.0698, 0.0015\n25 nm, 1.2 nN, 8 nm/s, 0.0663, 0.0015\n25 nm, 1.2 nN, 10 nm/s, 0.0578, 0.0015\n25 nm, 1.2 nN, 12 nm/s, 0.0567, 0.0015\n25 nm, 1.2 nN, 15 nm/s, 0.0452, 0.0015\n25 nm, 1.2 nN, 20 nm/s, 0.0461, 0.0015\n25 nm, 1.2 nN, 30 nm/s, 0.0426, 0.0015\n") });
  await page.waitForFunction(() => document.querySelector("#form-fit textarea[name='series.csv']").value.includes("30 nm/s, 0.0426"));
  await page.locator("#form-fit").getByRole("button", { name: "Fit" }).click();
  await page.waitForFunction((s) => [...document.querySelectorAll(`${s} .table tr`)].some((r) => r.textContent.startsWith("parameters.elastic_modulus.value")), area("fit"), { timeout: 60000 });
  const modulus = await page.locator(`${area("fit", "table")} tr`, { hasText: "parameters.elastic_modulus.value" }).first().textContent();
  if (!/2\.53\d*\s*GPa/.test(modulus)) fail(`the fitted modulus reads ${modulus} (examples/fit.json: 2.53 GPa)`);
  const interval = await page.locator(`${area("fit", "table")} tr`, { hasText: "parameters.elastic_modulus.interval_95" }).first().textContent();
  if (!/2\.476 to 2\.59\s*GPa/.test(interval)) fail(`the modulus's 95 % interval reads ${interval}`);
  await page.waitForSelector(`${area("fit", "picture")} svg`);
  const fitNotes = await page.locator(`${area("fit", "picture")} svg .notes`).textContent();
  if (!fitNotes.includes("E_L = 2.533 GPa") || !fitNotes.includes("bars: ± the uncertainty given")) fail(`the fit's picture notes read ${fitNotes}`);
  await page.screenshot({ path: `${shots}/fit.png`, fullPage: true });
  // A CSV row short of a value: refused before sending, the CSV marked.
  await page.fill("#form-fit textarea[name='series.csv']", "velocity, value, uncertainty\n1 nm/s, 0.1");
  await page.locator("#form-fit").getByRole("button", { name: "Fit" }).click();
  await page.waitForSelector("#form-fit textarea[name='series.csv'][aria-invalid='true']");
  const csvError = await page.locator(area("fit", "status")).textContent();
  if (!csvError.includes("row 1 has 2 values")) fail(`a short CSV row reads ${csvError}`);
  if (await page.locator(`${area("fit", "table")} tr`).count()) fail("the fit's table stays under the CSV's error");

  // A fit measured on a three-body system: the friction the service gives for the default
  // system, fitted from E_L = 1 GPa alone, gives back the default layer's 3 GPa.
  const systemSweep = await (await page.request.post(`${base}/v1/sweeps`, { data: {
    kind: "three_body", vary: { total_load: ["0.5 mN", "1 mN"], velocity: ["1 nm/s", "4 nm/s", "10 nm/s"] } } })).json();
  const systemCsv = ["total_load, velocity, value, uncertainty",
    ...systemSweep.points.map((p) => `${p.operating.total_load}, ${p.velocity}, ${p.friction_coefficient.rolling}, 0.0001`)].join("\n");
  await page.selectOption("#form-fit select[name='series.on']", "system");
  if (await page.locator("#form-fit input[name='series.system.distribution.mean_diameter']").isHidden()) fail("a system fit does not show the system's fields");
  await page.fill("#form-fit textarea[name='series.csv']", systemCsv);
  for (const name of ["relaxation_time", "retardation_time"]) await page.fill(`#form-fit input[name='parameters.${name}.start']`, "");
  const fitSent = page.waitForRequest((r) => r.url().endsWith("/v1/jobs") && r.method() === "POST");
  await page.locator("#form-fit").getByRole("button", { name: "Fit" }).click();
  const systemSeries = JSON.parse((await fitSent).postData()).input.series;
  if (!systemSeries.length || !systemSeries.every((s) => s.system && s.points.every((p) => p.total_load !== undefined || s.total_load !== undefined))) fail(`the system fit's series sent: ${JSON.stringify(systemSeries)}`);
  await page.waitForFunction((s) => [...document.querySelectorAll(`${s} .table tr`)].some((r) => r.textContent.startsWith("parameters.elastic_modulus.value") && /(^|[^\d.])(2\.99\d*|3(\.00\d*)?)\s*GPa/.test(r.textContent)), area("fit"), { timeout: 60000 });
  if (await page.locator(`${area("fit", "table")} tr`, { hasText: "parameters.relaxation_time" }).count()) fail("the system fit fitted T_σ, whose start was cleared");
  await page.screenshot({ path: `${shots}/fit-system.png`, fullPage: true });

  // Figure 6 from the gallery.
  await page.getByRole("tab", { name: "Figures 3–9" }).click();
  await page.getByRole("button", { name: "Figure 6" }).click();
  await page.waitForFunction((s) => (document.querySelector(`${s} svg title`) || {}).textContent?.startsWith("Fig. 6"), area("figures", "picture"));
  const entries = await page.locator(`${area("figures", "picture")} svg .legend .entry`).count();
  // Every tab's picture is in the page at once: no id twice (a clip path's url(#…) would
  // find another picture's).
  const ids = await page.$$eval("[id]", (nodes) => nodes.map((n) => n.id));
  const twice = ids.filter((id, i) => ids.indexOf(id) !== i);
  if (twice.length) fail(`ids found twice in the page: ${twice.join(", ")}`);
  if (entries !== 10) fail(`Figure 6 has ${entries} legend entries, not 10`);
  await page.screenshot({ path: `${shots}/figure-6.png`, fullPage: true });

  // The keyboard reaches the forms: Tab from the page start lands on a link or a control,
  // and the arrow keys move between the tabs.
  await page.goto(`${base}/`);
  await page.keyboard.press("Tab");
  const focused = await page.evaluate(() => document.activeElement.tagName);
  if (!["A", "BUTTON", "INPUT"].includes(focused)) fail(`Tab focuses a ${focused}`);
  await page.getByRole("tab", { name: "History" }).focus();
  await page.keyboard.press("ArrowRight");
  const wrapped = await page.evaluate(() => [document.activeElement.id, document.activeElement.getAttribute("aria-selected")]);
  if (wrapped[0] !== "tab-rolling" || wrapped[1] !== "true") fail(`ArrowRight from the last tab reaches ${wrapped}`);
  if (await page.locator("#panel-rolling").isHidden()) fail("the rolling panel stays hidden when its tab is selected by key");

  // The history: every sweep and fit run above, newest first, filtered by kind.
  await page.getByRole("tab", { name: "History" }).click();
  await page.waitForFunction(() => document.querySelectorAll("#history-jobs tbody tr").length > 5);
  const listedRows = () => page.$$eval("#history-jobs tbody tr", (rows) => rows.map((r) => ({
    id: r.dataset.id, kind: r.cells[1].textContent, status: r.cells[2].textContent, points: r.cells[3].textContent })));
  const listed = await listedRows();
  if (listed[0].kind !== "fit" || listed[0].status !== "succeeded") fail(`the newest job listed is ${JSON.stringify(listed[0])}, not the fit`);
  const cancelledRow = listed.find((r) => r.kind === "sweep" && r.status.startsWith("cancelled"));
  const bigSweep = listed.find((r) => r.kind === "sweep" && r.points === "200 / 200");
  if (!cancelledRow || !bigSweep) fail(`the cancelled sweep or the 200-point one is not listed: ${JSON.stringify(listed)}`);
  const shown = await page.locator("#history-count").textContent();
  if (shown !== `${listed.length} of ${listed.length} jobs shown.`) fail(`the history's count reads ${shown}`);
  await page.selectOption("#history-kind", "fit");
  await page.waitForFunction(() => {
    const rows = [...document.querySelectorAll("#history-jobs tbody tr")];
    return rows.length && rows.every((r) => r.cells[1].textContent === "fit");
  });
  await page.selectOption("#history-kind", "");
  await page.waitForFunction((n) => document.querySelectorAll("#history-jobs tbody tr").length === n, listed.length);

  // Across a restart (the same database and port, so the same origin and its token): the
  // fit's link opens it, the history lists the same jobs, their answers download.
  const address = new URL(base).host;
  await stop(child);
  const restarted = await serve(database, address);
  started.push(restarted.child);
  await page.goto("about:blank");
  await page.goto(`${base}/#job=${listed[0].id}`);
  await page.waitForFunction((s) => [...document.querySelectorAll(`${s} .table tr`)].some((r) => r.textContent.startsWith("parameters.elastic_modulus.value")), area("history"), { timeout: 30000 });
  const reopened = await page.locator(`${area("history", "table")} tr`, { hasText: "parameters.elastic_modulus.value" }).first().textContent();
  // The newest job is the fit measured on the three-body system: E_L back at 3 GPa.
  if (!/(^|[^\d.])(2\.99\d*|3(\.00\d*)?)\s*GPa/.test(reopened)) fail(`the reopened fit's modulus reads ${reopened}`);
  if (await page.locator("#panel-history").isHidden()) fail("a job's link does not show the history");
  // Shared with another browser (no token of this one): the answer with the inputs that made
  // it, and no empty history table under it.
  const elsewhere = await browser.newPage({ viewport: { width: 1366, height: 900 } });
  elsewhere.on("pageerror", (error) => errors.push(String(error)));
  await elsewhere.goto(`${base}/#job=${listed[0].id}`);
  await elsewhere.waitForSelector(`${area("history")} .inputs tr`, { timeout: 30000 });
  const inputs = await elsewhere.locator(`${area("history")} .inputs`).textContent();
  if (!inputs.includes("Inputs of this answer") || !/series|parameters/.test(inputs)) fail(`a shared link shows the inputs ${inputs.slice(0, 200)}`);
  await elsewhere.waitForFunction(() => document.querySelector("#history-count").textContent !== "");
  if (!(await elsewhere.locator("#history-jobs").isHidden())) fail("a shared link shows an empty history table");
  await elsewhere.screenshot({ path: `${shots}/shared-link.png`, fullPage: true });
  await elsewhere.close();
  await page.waitForFunction((n) => document.querySelectorAll("#history-jobs tbody tr").length === n, listed.length);
  const relisted = await listedRows();
  if (relisted.map((r) => r.id).join() !== listed.map((r) => r.id).join()) fail("the history after the restart is not the one before");
  const csvLink = await page.locator(`#history-jobs tbody tr[data-id='${bigSweep.id}'] a`, { hasText: "CSV" }).getAttribute("href");
  const csv = await page.request.get(`${base}${csvLink}`);
  const csvLines = (await csv.text()).trim().split("\n");
  if (csv.status() !== 200 || !csvLines[0].startsWith("radius [m]") || csvLines.length !== 201) fail(`the 200-point sweep's CSV after the restart: ${csv.status()}, ${csvLines.length} lines`);
  await page.locator(`#history-jobs tbody tr[data-id='${bigSweep.id}']`).getByRole("button", { name: "Open" }).click();
  await page.waitForSelector(`${area("history", "picture")} svg.plot`);
  if (!(await page.evaluate(() => location.hash)).endsWith(bigSweep.id)) fail("opening a job does not put its link in the address");
  await page.screenshot({ path: `${shots}/history.png`, fullPage: true });
  // The token is given on asking, and never inside a copied command.
  await page.click("#history-token");
  await page.waitForFunction(() => document.querySelector("#panel-history .status").textContent.startsWith("Copied this browser's token"));
  const token = await page.evaluate(() => localStorage.getItem("thirdbody-owner"));
  if (!/^[0-9a-f]{32}$/.test(token) || (await page.evaluate(() => navigator.clipboard.readText())) !== token) fail(`the copied token is not this browser's: ${token}`);
  await page.getByRole("tab", { name: "Sweep" }).click();
  await page.locator("#form-sweep").getByRole("button", { name: "Copy as curl" }).click();
  const curl = await page.evaluate(() => navigator.clipboard.readText());
  if (curl.includes(token) || !curl.includes('"thirdbody-owner: $THIRDBODY_OWNER"')) fail(`the copied curl command: ${curl}`);
  await page.getByRole("tab", { name: "History" }).click();
  // Deleted (after a confirmation): gone from the list, and from the service.
  page.once("dialog", (dialog) => dialog.accept());
  await page.locator(`#history-jobs tbody tr[data-id='${cancelledRow.id}']`).getByRole("button", { name: "Delete" }).click();
  await page.waitForFunction((n) => document.querySelectorAll("#history-jobs tbody tr").length === n, listed.length - 1);
  if ((await page.request.get(`${base}/v1/jobs/${cancelledRow.id}`)).status() !== 404) fail("a deleted job is still served");

  // A job that cannot end within the server's deadline fails: the bar and the status say so.
  const second = await browser.newPage({ viewport: { width: 1366, height: 900 } });
  second.on("pageerror", (error) => errors.push(String(error)));
  second.on("console", (message) => { if (message.type() === "error") errors.push(message.text()); });
  await second.goto(`${strict.base}/`);
  await second.getByRole("tab", { name: "Sweep" }).click();
  await second.fill("input[name='vary.load']", "1 nN, 2 nN, 3 nN");
  await second.fill("input[name='vary.velocity']", manySpeeds);
  await second.selectOption("#form-sweep select[name='base.layer.model']", "continuum");
  await second.getByRole("button", { name: "Run" }).click();
  await second.waitForFunction((s) => {
    const said = document.querySelector(`${s} .status`).textContent;
    return said.includes("No point was finished") || (said.includes("partial") && document.querySelector(`${s} .picture svg`));
  }, area("sweep"), { timeout: 30000 });
  if (!(await second.locator(`${area("sweep", "status")}.error`).count())) fail("the failed sweep's status is not shown as an error");
  const failed = await second.locator(area("sweep", "status")).textContent();
  if (!failed.startsWith("Job failed") || !/deadline/i.test(failed)) fail(`the failed sweep's status reads ${failed}`);
  const failedBar = await second.locator("#progress-text").textContent();
  if (!failedBar.startsWith("failed at") || (await second.locator("#progress").getAttribute("class")) !== "failed") fail(`the failed sweep's bar reads ${failedBar}`);
  await second.screenshot({ path: `${shots}/sweep-failed.png`, fullPage: true });

  // A service that asks for a key: refused and told where to enter it; with it, a solve,
  // a sweep listed in the history and its CSV downloaded with the key.
  const third = await browser.newPage({ viewport: { width: 1366, height: 900 } });
  const unauthorized = [];
  third.on("pageerror", (error) => errors.push(String(error)));
  third.on("console", (message) => {
    if (message.type() !== "error") return;
    (message.text().includes("status of 401") ? unauthorized : errors).push(`${message.text()} (${message.location().url})`);
  });
  await third.context().grantPermissions(["clipboard-read", "clipboard-write"], { origin: keyed.base });
  await third.goto(`${keyed.base}/`);
  await third.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await third.waitForSelector(`${area("rolling", "status")}.error`);
  const asked = await third.locator(area("rolling", "status")).textContent();
  if (!asked.includes("Enter an API key with “API key” at the top of the page")) fail(`without a key the dashboard says ${asked}`);
  await third.getByRole("button", { name: "API key" }).click();
  await third.fill("#api-key", apiKey);
  await third.getByRole("button", { name: "Use this key" }).click();
  await third.waitForFunction(() => document.querySelector("#api-key-status").textContent.startsWith("Key accepted"));
  if ((await third.locator("#api-key-button").textContent()) !== "API key (in use)") fail("the key button does not say a key is in use");
  await third.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await third.waitForSelector(`${area("rolling", "picture")} svg .series`);
  const keyedMu = await third.locator(`${area("rolling", "table")} tr`, { hasText: "friction_coefficient" }).first().textContent();
  if (!/0\.0947/.test(keyedMu)) fail(`with the key, μ reads ${keyedMu}`);
  await third.getByRole("tab", { name: "Sweep" }).click();
  await third.fill("input[name='vary.load']", "1 nN, 2 nN, 3 nN");
  await third.getByRole("button", { name: "Run" }).click();
  await third.waitForSelector(`${area("sweep", "picture")} svg .series`, { timeout: 60000 });
  await third.locator("#form-sweep").getByRole("button", { name: "Copy as curl" }).click();
  const keyedCurl = await third.evaluate(() => navigator.clipboard.readText());
  if (keyedCurl.includes(apiKey) || !keyedCurl.includes('"x-api-key: $THIRDBODY_API_KEY"')) fail(`the copied curl command with a key: ${keyedCurl}`);
  await third.getByRole("tab", { name: "History" }).click();
  await third.waitForSelector("#history-jobs tbody tr a");
  const [download] = await Promise.all([
    third.waitForEvent("download"),
    third.locator("#history-jobs tbody tr").first().locator("a", { hasText: "CSV" }).click(),
  ]);
  const { readFileSync } = await import("node:fs");
  const keyedCsv = readFileSync(await download.path(), "utf8").trim().split("\n");
  if (!keyedCsv[0].startsWith("radius [m]") || keyedCsv.length < 4) fail(`the CSV downloaded with the key: ${keyedCsv.slice(0, 2)}`);
  await third.screenshot({ path: `${shots}/api-key.png`, fullPage: true });
  if (unauthorized.length !== 1) fail(`requests refused for want of a key: ${unauthorized.join(" | ")} (1 expected: the solve before the key)`);

  if (errors.length) fail(`console errors: ${errors.join(" | ")}`);
  // The negative load (422), the unknown job's events and its record (404 each).
  if (refusals.sort().join() !== "404,404,422") fail(`refused requests: ${refusals.join()}`);
  if (outside.length) fail(`requests left the server: ${outside.join(", ")}`);
  if (!process.exitCode) console.log(`dashboard: rolling (both laws, compared, a Prony series), three-body (both laws), an error after a success, a 200-point sweep sorted and explored (hover, zoom, log, heat map), a one-point and a three-body sweep, a refused point, a cancelled, a failed and an unknown job, every three-body input, copy as Python, a fit from an uploaded CSV and a bad CSV, a fit measured on a three-body system, Figure 6, the history across a restart (listed, filtered, reopened by link, downloaded, deleted), a service that asks for an API key, and the tabs by keyboard work; screenshots in ${shots}`);
} finally {
  await browser.close();
  started.forEach((child) => child.kill());
}
