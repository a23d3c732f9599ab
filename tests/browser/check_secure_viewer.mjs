// Opens a secure viewer (HTTPS/WSS, issue 39) in Debian's Chromium with
// Playwright, trusting exactly the viewer's server key (its SPKI pin, as
// `openssl x509 -pubkey | openssl dgst -sha256 -binary | base64` gives it),
// with one kind of credential, and reports as JSON whether the page was let
// in and drew frames.
//   node check_secure_viewer.mjs URL SPKI_PIN none|token|cert [CERT.pem KEY.pem]
// token: the token is in URL (?token=...); cert: a client certificate for the page's origin.
import { chromium } from 'playwright-core';

const [url, pin, mode, certPath, keyPath] = process.argv.slice(2);
if (!url || !pin || !['none', 'token', 'cert'].includes(mode)) {
  console.error('usage: node check_secure_viewer.mjs URL SPKI_PIN none|token|cert [CERT.pem KEY.pem]');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
         `--ignore-certificate-errors-spki-list=${pin}`],
});
const out = { mode, page_errors: [] };
try {
  const options = { viewport: { width: 800, height: 600 } };
  if (mode === 'cert') options.clientCertificates = [{ origin: new URL(url).origin, certPath, keyPath }];
  const context = await browser.newContext(options);
  const page = await context.newPage();
  page.on('pageerror', (e) => out.page_errors.push(String(e)));
  const response = await page.goto(url);
  out.status = response.status();
  out.final_url = page.url();
  out.cookie = (await context.cookies()).some((c) => c.name === 'skelgraph_token' && c.secure && c.httpOnly);
  if (out.status === 200) {
    try {
      await page.waitForFunction(() => window.skelgraphViewer && window.skelgraphViewer.framesDrawn > 10, null,
                                 { timeout: 30000 });
    } catch (e) {
      out.wait_error = String(e).split('\n')[0];
    }
    const v = await page.evaluate(() => window.skelgraphViewer ? JSON.parse(JSON.stringify(window.skelgraphViewer)) : null);
    out.frames_drawn = v ? v.framesDrawn : 0;
    out.skeletons = v && v.drawn ? v.drawn.skeletons : 0;
    out.protocol = new URL(page.url()).protocol;
  } else {
    out.body = (await response.text()).slice(0, 300);
  }
} catch (e) {
  out.error = String(e).split('\n')[0];
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
