// bench/viewer_cost.sh's browser: opens the viewer page at URL in headless Chromium (software
// WebGL) and stays until the page shows the run's final state.
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../web');
const { chromium } = createRequire(path.join(web, 'package.json'))('playwright-core');
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(process.argv[2]);
  await page.waitForFunction(() => window.plslamViewer?.final === true, null, { timeout: 600000, polling: 500 });
} finally {
  await browser.close();
}
