// The viewer page driving a player of a recording (`skelgraph view FILE --paused`)
// through its own controls: Play, speed, Pause, the timeline (seek), Step.
// Prints a JSON list of what each control did to the player's state.
//   node check_timeline.mjs URL SCREENSHOT.png
import { chromium } from 'playwright-core';

const [url, screenshot] = process.argv.slice(2);
if (!url || !screenshot) {
  console.error('usage: node check_timeline.mjs URL SCREENSHOT.png');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const out = { steps: [], page_errors: [] };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('pageerror', (e) => out.page_errors.push(String(e)));
  await page.goto(url);
  const player = () => page.evaluate(() => (window.skelgraphViewer.players || [])[0] || null);
  const skeletons = () => page.evaluate(() => window.skelgraphViewer.drawn.skeletons);
  // Waits (at most 10 s) until the player's state passes `test`; records it.
  const expect = async (what, test) => {
    const t0 = Date.now();
    let p = null;
    while (Date.now() - t0 < 10000) {
      p = await player();
      if (p && test(p)) break;
      await sleep(100);
    }
    out.steps.push({ what, ok: !!(p && test(p)), state: p, skeletons: await skeletons() });
    return p;
  };
  await expect('player listed, paused at the start', (p) => p.paused && p.frames === 0);
  const button = (k) => page.locator(`#players button[data-k="${k}"]`).click();
  await button('resume');
  await expect('Play: playing, skeletons drawn', (p) => !p.paused && p.position_s > 0.5);
  await page.locator('#players select').selectOption('2');
  await expect('speed 2', (p) => p.speed === 2);
  await button('pause');
  const paused = await expect('Pause', (p) => p.paused);
  await sleep(1000);
  const still = await player();
  out.steps.push({ what: 'position holds while paused', ok: still.position_s === paused.position_s, state: still });
  // The timeline: put the slider at 1 s and let go.
  await page.locator('#players .timeline').evaluate((el) => {
    el.value = 1.0;
    el.dispatchEvent(new Event('input'));
    el.dispatchEvent(new Event('change'));
  });
  await expect('seek to 1 s on the timeline', (p) => p.paused && Math.abs(p.position_s - 1.0) < 0.05);
  const before = await player();
  await button('step');
  await expect('Step: one message, still paused', (p) => p.paused && p.frames === before.frames + 1 && p.position_s >= 1.0 && p.position_s < 1.1);
  await button('resume');
  await expect('play on to the end', (p) => p.at_end);
  await page.screenshot({ path: screenshot });
  out.screenshot = screenshot;
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
