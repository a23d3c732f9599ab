// Opens the viewer page in Debian's Chromium (headless, WebGL in software) with
// Playwright and reports, as JSON, what the page drew: snapshots of its drawn
// skeletons (stream, person, frame number, joints), its frame rate, and what
// the layer toggle, pause and a malformed request did. Saves a screenshot.
//   node check_viewer.mjs URL SCREENSHOT.png [SECONDS]
import { chromium } from 'playwright-core';

const [url, screenshot, secondsArg] = process.argv.slice(2);
if (!url || !screenshot) {
  console.error('usage: node check_viewer.mjs URL SCREENSHOT.png [SECONDS]');
  process.exit(2);
}
const seconds = Number(secondsArg || 5);
const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const browser = await chromium.launch({
  executablePath,
  headless: true,
  // Root in a container: no sandbox. WebGL without a GPU: SwiftShader.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const out = { console_errors: [], page_errors: [] };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('console', (m) => { if (m.type() === 'error') out.console_errors.push(m.text()); });
  page.on('pageerror', (e) => out.page_errors.push(String(e)));
  // The page's own condition below is what counts: not the 'load' event, which a suite at -j6
  // beside the viewer once kept from firing for the default 30 s.
  await page.goto(url, { waitUntil: 'domcontentloaded', timeout: 60000 });
  await page.waitForFunction(() => window.skelgraphViewer && window.skelgraphViewer.framesDrawn > 10, null,
                             { timeout: 60000 });
  const stats = () => page.evaluate(() => JSON.parse(JSON.stringify(window.skelgraphViewer)));

  // Frame rate: frames received and drawn over SECONDS.
  const a = await stats();
  const t0 = Date.now();
  const snapshots = [];
  // SECONDS, and at least 12 snapshots however slowly a busy machine answers (at most 30 s).
  while (Date.now() - t0 < seconds * 1000 || (snapshots.length < 12 && Date.now() - t0 < 30000)) {
    await sleep(250);
    snapshots.push((await stats()).drawn);
  }
  const b = await stats();
  const dt = (Date.now() - t0) / 1000;
  out.received = b.framesReceived - a.framesReceived;
  out.drawn = b.framesDrawn - a.framesDrawn;
  out.received_per_s = out.received / dt;
  out.drawn_per_s = out.drawn / dt;
  out.page_fps = b.fps;
  out.sensors = b.sensors;
  out.streams = b.streams;  // what the viewer received: kind and rate per stream
  out.gl = b.gl;
  out.gestures = { events: b.gestures.length, drawn: b.drawnGestures,
                   text: await page.locator('#gestures').innerText() };
  out.software_gl = b.software;
  out.robots = { drawn: b.drawnRobots, text: await page.locator('#robots').innerText() };
  out.snapshots = snapshots;

  // Waits (bounded) until what the page draws satisfies `pred`; a busy machine
  // draws late, so the checks wait on the drawing, never on a fixed time.
  const drawnUntil = async (pred, ms = 15000) => {
    const t = Date.now();
    let d = (await stats()).drawn;
    while (!pred(d) && Date.now() - t < ms) {
      await sleep(50);
      d = (await stats()).drawn;
    }
    return d;
  };

  // Layer toggle: hide the first sensor's skeleton; the other streams drawn before stay drawn.
  // (Compared by stream, not by count: on a busy machine a stream missing from one frame is back in the next.)
  const before = (await stats()).drawn;
  const hidden = before.list.find((s) => s.kind === 'raw');
  if (hidden) {
    const has = (d) => d.list.some((s) => s.stream === hidden.stream);
    const others = [...new Set(before.list.map((s) => s.stream))].filter((st) => st !== hidden.stream);
    const keepsOthers = (d) => others.every((st) => d.list.some((s) => s.stream === st));
    await page.uncheck(`input[data-layer="${hidden.stream}"]`);
    const after = await drawnUntil((d) => !has(d) && keepsOthers(d));
    out.toggle = { stream: hidden.stream, before: before.skeletons, others,
                   after: after.skeletons, still_drawn: has(after), others_kept: keepsOthers(after) };
    await page.check(`input[data-layer="${hidden.stream}"]`);
    out.toggle.restored = has(await drawnUntil(has));
  }

  // The uncertainty layer: each fused joint's 95 % sphere, hidden and shown again.
  const spheres = (d) => d.list.reduce((n, s) => n + s.uncertainty, 0);
  const u0 = (await stats()).drawn;
  await page.uncheck('input[data-layer="uncertainty"]');
  const u1 = await drawnUntil((d) => spheres(d) === 0);
  await page.check('input[data-layer="uncertainty"]');
  const u2 = await drawnUntil((d) => spheres(d) > 0);
  out.uncertainty = { before: spheres(u0), hidden: spheres(u1), restored: spheres(u2) };

  // Pause freezes the view while frames keep arriving.
  // Waits on what arrives, not on time: a busy machine delivers fewer frames a second.
  await page.click('#pause');
  const p0 = await stats();
  await page.waitForFunction((n) => window.skelgraphViewer.framesReceived >= n, p0.framesReceived + 20,
                             { timeout: 15000 }).catch(() => {});
  const p1 = await stats();
  await page.click('#pause');
  await page.waitForFunction((n) => window.skelgraphViewer.framesDrawn > n, p1.framesDrawn,
                             { timeout: 15000 }).catch(() => {});
  const p2 = await stats();
  out.pause = { drawn_while_paused: p1.framesDrawn - p0.framesDrawn, received_while_paused: p1.framesReceived - p0.framesReceived,
                drawn_after_resume: p2.framesDrawn - p1.framesDrawn };

  // A malformed request is answered with an error; the stream goes on.
  await page.evaluate(() => window.skelgraphSend('{"cmd":"rewind"}'));
  await page.waitForFunction(() => window.skelgraphViewer.errors.length > 0, null, { timeout: 15000 }).catch(() => {});
  await page.waitForFunction((n) => window.skelgraphViewer.framesReceived > n, p2.framesReceived,
                             { timeout: 15000 }).catch(() => {});
  const e = await stats();
  out.malformed = { errors: e.errors, still_receiving: e.framesReceived > p2.framesReceived, connected: e.connected };

  await page.screenshot({ path: screenshot });
  out.screenshot = screenshot;
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
