// bench/viewer_cost.sh's browser: opens the viewer page at URL in headless Chromium (software
// WebGL) and stays until the page shows the run's final state.
//
//   node bench/viewer_follow.mjs URL            the server is up: open the page now
//   node bench/viewer_follow.mjs URL --before   launch the browser, print "browser ready", then
//                                               open the page as soon as a server answers at URL
//                                               (a page left open while the run starts)
// At the end it prints Chromium's CPU time: in total, and from the moment the page was opened.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../web');
const { chromium } = createRequire(path.join(web, 'package.json'))('playwright-core');
const [url, mode] = process.argv.slice(2);

// CPU seconds used so far by this process's descendants: Chromium's browser, renderer and GPU
// processes, and those of them already reaped by their parent (cutime, cstime). Returns the split
// by Chromium's process type (--type=renderer, gpu-process, utility; none: browser), a reaped
// process's time counted under its parent's type, and the total.
function chromiumCpuSeconds() {
  const parent = new Map(), ticks = new Map(), type = new Map();
  for (const name of fs.readdirSync('/proc')) {
    if (!/^[0-9]+$/.test(name)) continue;
    let stat, cmdline;
    try {
      stat = fs.readFileSync(`/proc/${name}/stat`, 'utf8');
      cmdline = fs.readFileSync(`/proc/${name}/cmdline`, 'utf8');
    } catch { continue; }   // gone
    const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');   // f[0] is field 3, the state
    parent.set(Number(name), Number(f[1]));
    ticks.set(Number(name), Number(f[11]) + Number(f[12]) + Number(f[13]) + Number(f[14]));
    type.set(Number(name), cmdline.match(/--type=([a-z-]+)/)?.[1] ?? 'browser');
  }
  const byType = {};
  for (const [pid, t] of ticks) {
    for (let p = parent.get(pid); p !== undefined && p > 1; p = parent.get(p)) {
      if (p === process.pid) {
        byType[type.get(pid)] = (byType[type.get(pid)] ?? 0) + t / 100;   // USER_HZ, 100 on Linux
        break;
      }
    }
  }
  return { total: Object.values(byType).reduce((a, b) => a + b, 0), byType };
}

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  let cpuAtOpen = chromiumCpuSeconds();
  if (mode === '--before') {
    console.log('browser ready');
    const deadline = Date.now() + 60000;
    for (;;) {
      try {
        cpuAtOpen = chromiumCpuSeconds();
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
  const cpu = chromiumCpuSeconds();
  console.log(`chromium cpu ${cpu.total.toFixed(2)} s, ${(cpu.total - cpuAtOpen.total).toFixed(2)} s since the page was opened`);
  const split = Object.keys(cpu.byType).sort()
    .map((k) => `${k} ${(cpu.byType[k] - (cpuAtOpen.byType[k] ?? 0)).toFixed(2)} s`);
  console.log(`since the page was opened, by process: ${split.join(', ')}`);
} finally {
  await browser.close();
}
