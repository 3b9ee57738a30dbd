// Drives the pages `robodyn view` wrote in a headless Chromium (the system's, through
// playwright-core: no browser download) and reports what it saw as JSON; the Rust test
// crates/robodyn-cli/tests/cli_view.rs writes the job and judges the report.
//
//   node view_check.mjs job.json report.json
//
// job: { chromium, pages: [{ name, html, joints: [[q...], ...], slider, trajectory }] }
// report: { pages: [{ name, errors, requests, stats, transforms, joint_transforms, slider, trajectory }] }
import { chromium } from 'playwright-core';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

const [jobFile, reportFile] = process.argv.slice(2);
const job = JSON.parse(readFileSync(jobFile, 'utf8'));
const profile = mkdtempSync(join(tmpdir(), 'robodyn-view-profile-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: job.chromium,
  headless: true,
  viewport: { width: 1280, height: 860 },
  deviceScaleFactor: 1,
  args: ['--no-sandbox', '--disable-gpu', '--enable-unsafe-swiftshader', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--no-first-run'],
});

// Pixel statistics of PNG screenshots, decoded by the browser itself (an <img> drawn on a 2D
// canvas): the fraction of non-white pixels, the pixels of the x (red) and z (blue) axes, and the
// fraction of pixels that differ between two shots.
const decoder = await context.newPage();
async function pixels(a, b = null) {
  return decoder.evaluate(async ([a64, b64]) => {
    const load = async (s) => {
      const img = new Image();
      img.src = `data:image/png;base64,${s}`;
      await img.decode();
      const c = document.createElement('canvas');
      c.width = img.width; c.height = img.height;
      const ctx = c.getContext('2d');
      ctx.drawImage(img, 0, 0);
      return ctx.getImageData(0, 0, c.width, c.height).data;
    };
    const p = await load(a64);
    let nonWhite = 0, red = 0, blue = 0, changed = 0;
    const q = b64 ? await load(b64) : null;
    for (let i = 0; i < p.length; i += 4) {
      const [r, g, bl] = [p[i], p[i + 1], p[i + 2]];
      if (r < 235 || g < 235 || bl < 235) nonWhite++;
      if (r > 150 && g < 90 && bl < 90) red++;
      if (bl > 150 && r < 90 && g < 150) blue++;
      if (q && (Math.abs(r - q[i]) > 24 || Math.abs(g - q[i + 1]) > 24 || Math.abs(bl - q[i + 2]) > 24)) changed++;
    }
    const n = p.length / 4;
    return { nonWhite: nonWhite / n, red, blue, changed: changed / n };
  }, [a.toString('base64'), b ? b.toString('base64') : null]);
}

const report = { pages: [] };
for (const spec of job.pages) {
  const out = { name: spec.name, errors: [], requests: [] };
  const page = await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') out.errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => out.errors.push(`page: ${e.message}`));
  page.on('request', (r) => { if (!/^(data|file|blob):/.test(r.url())) out.requests.push(r.url()); });
  try {
    await page.goto(pathToFileURL(spec.html).href);
    await page.waitForFunction(() => window.robodynView && window.robodynView.ready, null, { timeout: 120000 });
    const view = page.locator('#view');
    const shot = async () => { await page.evaluate(() => window.robodynView.render()); return view.screenshot(); };
    const first = await shot();
    if (spec.png) writeFileSync(spec.png, first);
    out.stats = await pixels(first);
    out.transforms = await page.evaluate(() => window.robodynView.frameTransforms());
    out.joint_transforms = [];
    for (const q of spec.joints || []) {
      out.joint_transforms.push(await page.evaluate((v) => { window.robodynView.setJoints(v); return window.robodynView.frameTransforms(); }, q));
    }
    if (spec.slider) {
      await page.evaluate((v) => window.robodynView.setJoints(v), spec.slider.start);
      const before = await shot();
      const input = page.locator('#sliders input[type=range]').first();
      const box = await input.boundingBox(); // a click at 80 % of the track, as a user would
      await input.click({ position: { x: 0.8 * box.width, y: box.height / 2 } });
      const after = await shot();
      out.slider = { ...(await pixels(before, after)), joints: await page.evaluate(() => window.robodynView.joints()) };
    }
    if (spec.trajectory) {
      const t0 = await page.evaluate(() => window.robodynView.time());
      const before = await shot();
      await page.click('#play');
      // until the time has advanced by a tenth of the trajectory (it loops at the end)
      const step = await page.evaluate(() => { const v = window.robodynView; return 0.1 * (v.duration()); });
      // and paused in the same turn of the page's loop as the check: a pause clicked from here
      // arrives frames later, and on a loaded machine the play may have looped back to t0 by then
      const paused = await page.waitForFunction((t) => {
        const v = window.robodynView;
        if (!(v.time() > t)) return false;
        const playing = v.playing();
        document.getElementById('play').click();
        return { playing };
      }, t0 + step, { timeout: 30000 });
      const { playing } = await paused.jsonValue();
      const t1 = await page.evaluate(() => window.robodynView.time());
      const sample = await page.evaluate(() => window.robodynView.sample());
      const transforms = await page.evaluate(() => window.robodynView.frameTransforms());
      const after = await shot();
      out.trajectory = { t0, t1, playing, sample, transforms, samples: await page.evaluate(() => window.robodynView.samples()), ...(await pixels(before, after)) };
    }
  } catch (e) {
    out.errors.push(`driver: ${e.message}`);
  }
  await page.close();
  report.pages.push(out);
}
await context.close();
rmSync(profile, { recursive: true, force: true });
writeFileSync(reportFile, JSON.stringify(report));
