// bench/viewer_cost.sh's browser: opens the viewer page at URL in headless Chromium (software
// WebGL) and stays until the page shows the run's final state.
//
//   node bench/viewer_follow.mjs URL            the server is up: open the page now
//   node bench/viewer_follow.mjs URL --before   launch the browser, print "browser ready", then
//                                               open the page as soon as a server answers at URL
//                                               (a page left open while the run starts)
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../web');
const { chromium } = createRequire(path.join(web, 'package.json'))('playwright-core');
const [url, mode] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  if (mode === '--before') {
    console.log('browser ready');
    const deadline = Date.now() + 60000;
    for (;;) {
      try {
        await page.goto(url);
        break;
      } catch (error) {
        if (Date.now() > deadline) throw error;
        await new Promise((resolve) => setTimeout(resolve, 50));
      }
    }
  } else {
    await page.goto(url);
  }
  await page.waitForFunction(() => window.plslamViewer?.final === true, null, { timeout: 600000, polling: 500 });
} finally {
  await browser.close();
}
