// The dashboard end to end, as a user at a browser: Debian's chromium driven by
// playwright-core against `thirdbody serve` on a port the system chooses. Fails on a console
// error or on any request that leaves the server. Screenshots go to target/browser/.
import { spawn } from "node:child_process";
import { mkdirSync } from "node:fs";
import { chromium } from "playwright-core";

const root = new URL("../../", import.meta.url).pathname;
const bin = process.env.THIRDBODY_BIN || `${root}target/release/thirdbody`;
const shots = `${root}target/browser`;
mkdirSync(shots, { recursive: true });

function fail(message) {
  console.error(`FAILED: ${message}`);
  process.exitCode = 1;
}

/** Starts the service on 127.0.0.1:0 and resolves with its base URL (from its log). */
function serve() {
  const child = spawn(bin, ["serve", "--bind", "127.0.0.1:0", "--log-format", "json"], {
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

const { child, base } = await serve();
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1366, height: 900 } });
  const errors = [];
  page.on("console", (message) => { if (message.type() === "error") errors.push(message.text()); });
  page.on("pageerror", (error) => errors.push(String(error)));
  const outside = [];
  page.on("request", (request) => {
    const url = request.url();
    if (!url.startsWith(base) && !url.startsWith("blob:") && !url.startsWith("data:")) outside.push(url);
  });

  // The default rolling contact: a table and its picture.
  await page.goto(`${base}/`);
  const csp = (await page.request.get(`${base}/`)).headers()["content-security-policy"];
  if (csp !== "default-src 'self'") fail(`Content-Security-Policy is ${csp}`);
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForSelector("#picture svg .series");
  const mu = await page.locator("#table tr", { hasText: "friction_coefficient" }).first().textContent();
  if (!/0\.0947/.test(mu)) fail(`the default friction coefficient is shown as ${mu}`);
  await page.screenshot({ path: `${shots}/rolling.png`, fullPage: true });

  // The same particle on the layer as a continuum: about 8.3 nm², its accuracy said.
  await page.selectOption("#form-rolling select[name='layer.model']", "continuum");
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction(() => document.querySelector("#status").textContent.includes("continuum"));
  const area = await page.locator("#table tr", { hasText: "contact_area" }).first().textContent();
  if (!/8\.[1-4]\d*\s*nm²/.test(area)) fail(`the continuum's contact area is shown as ${area}`);
  await page.screenshot({ path: `${shots}/rolling-continuum.png`, fullPage: true });

  // Both laws together: two regions on one plane, their numbers side by side.
  await page.getByRole("button", { name: "Compare both laws" }).click();
  await page.waitForFunction(() => document.querySelectorAll("#picture svg polygon.series").length === 2);
  const compared = await page.locator("#table tr", { hasText: "friction_coefficient" }).first().textContent();
  if (!/0\.0947/.test(compared) || !/0\.0091/.test(compared)) fail(`the compared μ reads ${compared}`);
  await page.screenshot({ path: `${shots}/rolling-compare.png`, fullPage: true });
  await page.selectOption("#form-rolling select[name='layer.model']", "local");

  // A layer from a Prony series typed as CSV: its Kelvin times are then not sent.
  const series = "10 ms, 6 GPa\n100 ms, 4.5 GPa\n1 s, 3 GPa\n10 s, 1.5 GPa";
  await page.fill("#form-rolling textarea[name='layer.prony_csv']", series);
  await page.locator("#form-rolling").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction(() => [...document.querySelectorAll("#table tr")]
    .some((row) => row.textContent.includes("friction_coefficient") && /0\.0737/.test(row.textContent)));
  await page.screenshot({ path: `${shots}/rolling-prony.png`, fullPage: true });
  await page.fill("#form-rolling textarea[name='layer.prony_csv']", "");

  // A three-body system: its distribution of diameters.
  await page.getByRole("tab", { name: "Three-body system" }).click();
  await page.locator("#form-three-body").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction(() => (document.querySelector("#picture svg title") || {}).textContent?.startsWith("Three-body"));
  await page.screenshot({ path: `${shots}/three-body.png`, fullPage: true });
  const localMu = await page.locator("#table tr", { hasText: "friction_coefficient" }).first().textContent();

  // The same system on the continuum layer contact: its μ several times lower, its error said.
  await page.selectOption("#form-three-body select[name='layer_contact']", "continuum");
  await page.locator("#form-three-body").getByRole("button", { name: "Solve" }).click();
  await page.waitForFunction((before) => {
    const row = [...document.querySelectorAll("#table tr")].find((r) => r.textContent.includes("friction_coefficient"));
    return row && row.textContent !== before;
  }, localMu, { timeout: 30000 });
  const continuumMu = await page.locator("#table tr", { hasText: "friction_coefficient" }).first().textContent();
  const first = (text) => Number((text.match(/\d\.\d+(e-?\d+)?/) || ["NaN"])[0]);
  if (!(first(localMu) > 3 * first(continuumMu))) fail(`three-body μ: local ${localMu}, continuum ${continuumMu}`);
  await page.screenshot({ path: `${shots}/three-body-continuum.png`, fullPage: true });
  await page.selectOption("#form-three-body select[name='layer_contact']", "kelvin_layer");

  // A 200-point sweep as a job: the progress bar reaches 100 %.
  await page.getByRole("tab", { name: "Sweep" }).click();
  const loads = Array.from({ length: 10 }, (_, i) => `${(0.5 + 0.25 * i).toFixed(2)} nN`).join(", ");
  const speeds = Array.from({ length: 20 }, (_, i) => `${i} nm/s`).join(", ");
  await page.fill("input[name='vary.load']", loads);
  await page.fill("input[name='vary.velocity']", speeds);
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction(() => {
    const bar = document.querySelector("#progress");
    return bar.max === 200 && bar.value === 200 && document.querySelector("#picture svg .series");
  }, null, { timeout: 60000 });
  const progress = await page.locator("#progress-text").textContent();
  if (!progress.includes("200 / 200 (100 %)")) fail(`progress reads ${progress}`);
  await page.screenshot({ path: `${shots}/sweep.png`, fullPage: true });

  // A sweep with a point the model refuses: the other points are answered, the refusal said.
  await page.fill("input[name='vary.load']", "1 nN, 1 mN, 2 nN");
  await page.fill("input[name='vary.velocity']", "4 nm/s");
  await page.getByRole("button", { name: "Run" }).click();
  await page.waitForFunction(() => document.querySelector("#warnings").textContent.includes("refused"), null, { timeout: 60000 });
  const refused = await page.locator("#warnings").textContent();
  if (!refused.includes("1 of 3 points refused")) fail(`the refused point reads ${refused}`);
  const answered = await page.locator("#table tr", { hasText: "points.warn" }).first().textContent();
  if (!/2/.test(answered)) fail(`the sweep's table reads ${answered}`);
  await page.screenshot({ path: `${shots}/sweep-refused.png`, fullPage: true });

  // Figure 6 from the gallery.
  await page.getByRole("tab", { name: "Figures 3–9" }).click();
  await page.getByRole("button", { name: "Figure 6" }).click();
  await page.waitForFunction(() => (document.querySelector("#picture svg title") || {}).textContent?.startsWith("Fig. 6"));
  const entries = await page.locator("#picture svg .legend .entry").count();
  if (entries !== 10) fail(`Figure 6 has ${entries} legend entries, not 10`);
  await page.screenshot({ path: `${shots}/figure-6.png`, fullPage: true });

  // The keyboard reaches the forms: Tab from the page start lands on a link or a control.
  await page.keyboard.press("Tab");
  const focused = await page.evaluate(() => document.activeElement.tagName);
  if (!["A", "BUTTON", "INPUT"].includes(focused)) fail(`Tab focuses a ${focused}`);

  if (errors.length) fail(`console errors: ${errors.join(" | ")}`);
  if (outside.length) fail(`requests left the server: ${outside.join(", ")}`);
  if (!process.exitCode) console.log(`dashboard: rolling (both laws, compared, a Prony series), three-body (both laws), a 200-point sweep, a sweep with a refused point and Figure 6 work; screenshots in ${shots}`);
} finally {
  await browser.close();
  child.kill();
}
