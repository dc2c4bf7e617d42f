// Opens a cadmorph report in Debian's headless Chromium with networking disabled and
// records what the tests check; the checks themselves are in
// crates/report/tests/browser.rs, which reads what this script writes:
//
//   node browser.js REPORT.html OUTDIR POINTS.json
//
// OUTDIR/initial.png    the 3D canvas as the page opens
// OUTDIR/lattice.png    the canvas after ticking "FFD lattice (original)" and "(moved)"
// OUTDIR/result.json    { console: [...], pageErrors: [...], requests: [...],
//                         webgl: bool, projected: [[x, y], ...] (CSS pixels in the canvas
//                         of the model points of POINTS.json, a list of [x, y, z]) }
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const { chromium } = require("playwright-core");

async function main() {
  const [html, out, pointsFile] = process.argv.slice(2);
  const points = JSON.parse(fs.readFileSync(pointsFile, "utf8"));
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), "cadmorph-chromium-"));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    offline: true,
    viewport: { width: 1400, height: 900 },
    deviceScaleFactor: 1,
    args: [
      "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync",
      "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    ],
  });
  const result = { console: [], pageErrors: [], requests: [], webgl: false, projected: [] };
  try {
    const page = context.pages()[0] || (await context.newPage());
    page.on("console", (m) => result.console.push({ type: m.type(), text: m.text() }));
    page.on("pageerror", (e) => result.pageErrors.push(String(e)));
    // Every request that is not the file itself is refused and recorded.
    await page.route("**/*", (route) => {
      const url = route.request().url();
      if (url.startsWith("file:")) return route.continue();
      result.requests.push(url);
      return route.abort();
    });
    await page.goto("file://" + path.resolve(html));
    await page.waitForFunction(() => window.cadmorph && window.cadmorph.ready, null, { timeout: 30000 });
    result.webgl = await page.evaluate(() => document.documentElement.classList.contains("webgl"));
    const canvas = page.locator("#view");
    await canvas.screenshot({ path: path.join(out, "initial.png") });
    result.projected = await page.evaluate((pts) => pts.map((p) => window.cadmorph.project(p)), points);
    await page.check("#layer-lattice");
    await page.check("#layer-lattice-moved");
    await canvas.screenshot({ path: path.join(out, "lattice.png") });
  } finally {
    fs.writeFileSync(path.join(out, "result.json"), JSON.stringify(result, null, 1));
    await context.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
