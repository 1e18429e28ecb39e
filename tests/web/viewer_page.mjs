#!/usr/bin/env node
// Drives the browser map viewer (web/) in headless chromium and checks what it shows.
//
//   node tests/web/viewer_page.mjs --cli build/apps/plslam --view RUN_DIR_OR_MAP \
//        --expect-json counts.json --out ARTEFACT_DIR --name NAME
//   node tests/web/viewer_page.mjs --url http://127.0.0.1:PORT/ --expect-json counts.json ...
//   node tests/web/viewer_page.mjs --cli build/plslam --live DATASET --expect-growth 60 --out DIR --name live
//
// With --live it starts `plslam run DATASET --viewer --port 0` (outputs in OUT/NAME-run), watches
// the live page, waits for the final state and checks its counts against the run's stats.json.
// With --cli it starts `plslam view TARGET --port 0`, waits for its
// "viewer: http://127.0.0.1:PORT/" line and stops it (SIGTERM) at the end.
// Options: --web DIR (the web/ folder holding node_modules, default: this repo's),
// --chromium PATH (default /usr/bin/chromium), --expect-growth SECONDS (live runs:
// keyframes must grow at least twice), --measure-fps SECONDS (prints the orbit frame rate).
// Exits 1 with one line per failure; prints one summary line when all is well.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import readline from 'node:readline';
import { fileURLToPath } from 'node:url';

const READY_TIMEOUT_MS = 20000;
const SERVER_START_TIMEOUT_MS = 30000;
const LIVE_RUN_TIMEOUT_MS = 240000;
const FINAL_TIMEOUT_MS = 120000;         // a live run must end within this to check its counts
// A blank canvas has a pixel standard deviation of 0. A map drawn over a uniform background
// moves it by Δ·sqrt(p(1-p)) for a fraction p of pixels differing by Δ in luma: 3 needs e.g.
// 0.1 % of the pixels 100 levels off the background, which a few thousand points or a single
// frustum outline already give, while a stray line or a cleared canvas stays well below.
const MIN_PIXEL_STD = 3;
const TOGGLED_LAYERS = ['points', 'lines', 'keyframes', 'trajectory', 'loops', 'covisibility', 'ground-truth'];

function parseArguments(argv) {
  const options = { out: '.', name: 'viewer', chromium: '/usr/bin/chromium' };
  const names = { '--url': 'url', '--cli': 'cli', '--view': 'view', '--expect-json': 'expectJson',
                  '--expect': 'expectJson', '--out': 'out', '--name': 'name', '--web': 'web',
                  '--chromium': 'chromium', '--expect-growth': 'expectGrowth', '--measure-fps': 'measureFps',
                  '--live': 'live' };
  for (let i = 0; i < argv.length; i += 2) {
    const key = names[argv[i]];
    if (!key || i + 1 >= argv.length) throw new Error(`bad argument ${argv[i]} (see the head of ${process.argv[1]})`);
    options[key] = argv[i + 1];
  }
  if (!options.url && !(options.cli && (options.view || options.live))) {
    throw new Error('need --url, or --cli and --view or --live');
  }
  options.web ??= path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../web');
  return options;
}

function loadPlaywright(webDir) {
  const require = createRequire(path.join(path.resolve(webDir), 'package.json'));
  try {
    return require('playwright-core');
  } catch {
    throw new Error(`playwright-core not found under ${webDir}/node_modules: run "npm ci" in ${webDir}`);
  }
}

// Spawns `plslam ARGS` (view TARGET --port 0, or run ... --viewer --port 0) and resolves with its
// URL once printed.
function startServer(cli, args) {
  const child = spawn(cli, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  const tail = [];
  const keep = (line) => { tail.push(line); if (tail.length > 20) tail.shift(); };
  readline.createInterface({ input: child.stderr }).on('line', keep);
  const url = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no viewer URL from ${cli} within ${SERVER_START_TIMEOUT_MS} ms: ${tail.join(' | ')}`)),
                             SERVER_START_TIMEOUT_MS);
    readline.createInterface({ input: child.stdout }).on('line', (line) => {
      keep(line);
      const match = line.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (match) { clearTimeout(timer); resolve(match[0]); }
    });
    child.on('error', (error) => { clearTimeout(timer); reject(error); });
    child.on('exit', (code, signal) => {
      clearTimeout(timer);
      reject(new Error(`${cli} view exited (${signal ?? code}) before printing its URL: ${tail.join(' | ')}`));
    });
  });
  return { child, url };
}

// SIGTERM, and a failure if the server is still there 5 s later (then SIGKILL).
async function stopServer(child, fail) {
  const exited = new Promise((resolve) => child.once('exit', resolve));
  child.kill('SIGTERM');
  const timer = setTimeout(() => {
    fail('the viewer server did not exit within 5 s of SIGTERM');
    child.kill('SIGKILL');
  }, 5000);
  await exited;
  clearTimeout(timer);
}

// ---- code run inside the page ----

// Renders, reads the WebGL canvas back through a 2D canvas and keeps the pixels under `key`.
// Returns the luma standard deviation and, when `against` names an earlier snapshot, how
// many pixels differ from it.
function snapshotInPage([key, against]) {
  const viewer = window.plslamViewer;
  viewer.render();
  const source = document.querySelector('#view canvas');
  const store = (window.__viewerTest ??= { canvas: document.createElement('canvas'), shots: {} });
  store.canvas.width = source.width;
  store.canvas.height = source.height;
  const context = store.canvas.getContext('2d', { willReadFrequently: true });
  context.drawImage(source, 0, 0);
  const pixels = context.getImageData(0, 0, source.width, source.height).data;
  store.shots[key] = pixels;
  let sum = 0, sumSquares = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    const luma = 0.299 * pixels[i] + 0.587 * pixels[i + 1] + 0.114 * pixels[i + 2];
    sum += luma; sumSquares += luma * luma;
  }
  const n = pixels.length / 4;
  const std = Math.sqrt(Math.max(0, sumSquares / n - (sum / n) ** 2));
  let changed = null;
  const reference = store.shots[against];
  if (reference) {
    changed = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      if (pixels[i] !== reference[i] || pixels[i + 1] !== reference[i + 1] || pixels[i + 2] !== reference[i + 2]) changed++;
    }
  }
  return { std, changed, width: source.width, height: source.height };
}

// Orbits for `seconds`: first through requestAnimationFrame as a user's drag would (frames
// actually shown), then synchronously with a 1-pixel read after each render so the GPU
// (swiftshader here) has to finish the frame (raw render rate).
async function measureFpsInPage(seconds) {
  const viewer = window.plslamViewer;
  const step = 0.02;
  const startFrames = viewer.rendered;
  let start = performance.now();
  await new Promise((resolve) => {
    const tick = () => {
      viewer.orbit(step);
      if (performance.now() - start < seconds * 1000) requestAnimationFrame(tick);
      else resolve();
    };
    requestAnimationFrame(tick);
  });
  const shownFps = (viewer.rendered - startFrames) / ((performance.now() - start) / 1000);
  const thinned = viewer.thinWhileMoving;
  const gl = document.querySelector('#view canvas').getContext('webgl2');
  const pixel = new Uint8Array(4);
  let renders = 0;
  start = performance.now();
  while (performance.now() - start < seconds * 1000) {
    viewer.orbit(step);
    viewer.render();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    renders++;
  }
  return { shownFps, thinned, renderFps: renders / ((performance.now() - start) / 1000) };
}

// ---- the checks ----

async function checkPage(page, options, fail) {
  const snapshot = (key, against) => page.evaluate(snapshotInPage, [key, against ?? null]);
  const screenshot = (suffix) => page.screenshot({ path: path.join(options.out, `${options.name}${suffix}.png`) });
  const viewer = () => page.evaluate(() => {
    const { ready, revision, counts, layers, drawn, final, loadMs } = window.plslamViewer;
    return { ready, revision, counts, layers, drawn, final, loadMs };
  });

  await page.goto(options.url, { waitUntil: 'load' });
  try {
    await page.waitForFunction(() => window.plslamViewer?.ready === true, null, { timeout: READY_TIMEOUT_MS });
  } catch {
    fail(`window.plslamViewer.ready not true within ${READY_TIMEOUT_MS} ms`);
    return null;
  }
  let state = await viewer();
  const result = { loadMs: state.loadMs, toggles: 0 };

  if (options.expectGrowth) await checkGrowth(page, Number(options.expectGrowth), fail);
  if (options.live) {
    await screenshot('-during-run');
    // The run is over once the page is final; its stats.json is written by then.
    await page.waitForFunction(() => window.plslamViewer.final, null, { timeout: LIVE_RUN_TIMEOUT_MS })
      .catch(() => fail(`the live run did not end within ${LIVE_RUN_TIMEOUT_MS} ms`));
    const stats = JSON.parse(fs.readFileSync(path.join(liveRunFolder(options), 'stats.json'), 'utf8'));
    await checkCounts(page, { keyframes: stats.keyframes, points: stats.map_points, lines: stats.map_lines,
                              loops: stats.loops.length, relocalizations: stats.relocalizations.count }, fail);
  }
  if (options.expectJson) {
    if (!state.final) {
      await page.waitForFunction(() => window.plslamViewer.final, null, { timeout: FINAL_TIMEOUT_MS })
        .catch(() => fail(`the scene did not become final within ${FINAL_TIMEOUT_MS} ms (counts checked as they are)`));
    }
    await checkCounts(page, JSON.parse(fs.readFileSync(options.expectJson, 'utf8')), fail);
  }
  state = await viewer();
  result.counts = state.counts;
  // Once final the picture only changes when we change something, so restores must match exactly.
  const still = state.final;

  for (const name of ['points', 'lines', 'keyframes']) {
    if (state.counts?.[name] > 0 && !state.drawn[name]) fail(`counts.${name} is ${state.counts[name]} but the ${name} layer has nothing to draw`);
  }

  const base = await snapshot('base');
  result.std = base.std;
  if (!(base.std > MIN_PIXEL_STD)) fail(`canvas looks blank: pixel std ${base.std.toFixed(2)} <= ${MIN_PIXEL_STD}`);
  await screenshot('');

  for (const layer of TOGGLED_LAYERS) {
    if (!state.drawn[layer]) continue;                       // nothing to draw: toggling shows nothing
    const wasOn = state.layers[layer];
    await page.click(`#layer-${layer}`);
    const nowOn = await page.evaluate((name) => window.plslamViewer.layers[name], layer);
    if (nowOn === wasOn) fail(`clicking #layer-${layer} did not switch the layer`);
    const shot = await snapshot(`layer-${layer}`, 'base');
    if (shot.changed === 0) fail(`turning ${layer} ${nowOn ? 'on' : 'off'} did not change the picture`);
    await screenshot(nowOn ? `-with-${layer}` : `-no-${layer}`);
    await page.click(`#layer-${layer}`);
    const restored = await snapshot(`restored-${layer}`, 'base');
    if (still && restored.changed !== 0) fail(`turning ${layer} back did not restore the picture (${restored.changed} pixels differ)`);
    result.toggles++;
  }

  await page.click('#view-top');
  const top = await snapshot('top', 'base');
  if (top.changed === 0) fail('the top view button did not change the picture');
  await screenshot('-top');
  await page.click('#view-fit');
  await snapshot('fit');

  // Against the picture just before, so that only the colours can make the difference.
  await page.selectOption('#point-colour', 'age');
  const age = await snapshot('age', 'fit');
  if (state.drawn.points && age.changed === 0) fail('colouring points by age did not change the picture');
  await screenshot('-age');
  await page.selectOption('#point-colour', 'height');

  if (options.measureFps) {
    const seconds = Number(options.measureFps);
    const fps = await page.evaluate(measureFpsInPage, seconds);
    console.log(`viewer_page ${options.name}: orbit ${fps.shownFps.toFixed(1)} fps shown (requestAnimationFrame` +
                `${fps.thinned ? ', thinned while moving' : ''}), ${fps.renderFps.toFixed(1)} full renders/s ` +
                `(synchronous), over ${seconds} s each`);
  }
  return result;
}

function liveRunFolder(options) {
  return path.join(options.out, `${options.name}-run`);
}

async function checkCounts(page, expected, fail) {
  for (const name of ['keyframes', 'points', 'lines', 'loops', 'relocalizations']) {
    if (expected[name] === undefined || expected[name] === null) continue;
    const shown = (await page.textContent(`#count-${name}`)).trim();
    if (shown !== String(expected[name])) fail(`#count-${name} shows "${shown}", expected ${expected[name]}`);
  }
}

// Live runs: the keyframe count must go up at least twice within `seconds`.
async function checkGrowth(page, seconds, fail) {
  const read = async () => Number((await page.textContent('#count-keyframes')).trim());
  let last = await read(), increases = 0;
  const deadline = Date.now() + seconds * 1000;
  while (increases < 2 && Date.now() < deadline) {
    await page.waitForTimeout(250);
    const now = await read();
    if (now > last) increases++;
    if (Number.isFinite(now)) last = now;
  }
  if (increases < 2) fail(`#count-keyframes increased ${increases} time(s) in ${seconds} s, expected at least 2`);
}

// Console messages chromium prints on its own, not the page's doing. Each entry says why.
function ignoredConsoleMessage(text) {
  // With --disable-gpu chromium composites in software and reads every WebGL frame back
  // from SwiftShader, then logs that readback as "GL Driver Message (OpenGL, Performance,
  // ...): GPU stall due to ReadPixels". A bare page that only clears a WebGL canvas prints
  // it too, so it says nothing about the viewer.
  return /^\[\.WebGL-0x[0-9a-f]+\]GL Driver Message \(OpenGL, Performance, GL_CLOSE_PATH_NV, High\): GPU stall due to ReadPixels( \(this message will no longer repeat\))?$/.test(text);
}

async function main() {
  let options;
  try {
    options = parseArguments(process.argv.slice(2));
  } catch (error) {
    console.error(`viewer_page: ${error.message}`);
    process.exitCode = 2;
    return;
  }
  const failures = [];
  // One line per failure: Playwright's errors carry a multi-line call log after the first line.
  const fail = (message) => {
    const line = String(message).split('\n')[0];
    failures.push(line);
    console.error(`viewer_page ${options.name}: ${line}`);
  };
  fs.mkdirSync(options.out, { recursive: true });

  let server = null;
  let browser = null;
  let result = null;
  const running = () => server && server.exitCode === null && server.signalCode === null;
  process.on('exit', () => { if (running()) server.kill('SIGKILL'); });     // only if we died early
  try {
    const { chromium } = loadPlaywright(options.web);
    if (options.cli) {
      const args = options.live
        ? ['run', options.live, '--out', liveRunFolder(options), '--viewer', '--port', '0', '--viewer-linger', '120',
           '--quiet']
        : ['view', options.view, '--port', '0'];
      const started = startServer(options.cli, args);
      server = started.child;
      options.url = await started.url;
    }
    browser = await chromium.launch({
      executablePath: options.chromium,
      headless: true,
      args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
             '--disable-background-networking', '--disable-component-update', '--disable-sync',
             '--no-first-run', '--disable-quic'],
    });
    const page = await browser.newPage({ viewport: { width: 1280, height: 800 }, deviceScaleFactor: 1 });
    page.on('console', (message) => {
      if ((message.type() === 'error' || message.type() === 'warning') && !ignoredConsoleMessage(message.text())) {
        fail(`console ${message.type()}: ${message.text()}`);
      }
    });
    page.on('pageerror', (error) => fail(`page error: ${error.message}`));

    result = await checkPage(page, options, fail);
  } catch (error) {
    fail(error.message);
  } finally {
    if (browser) await browser.close();
    if (running()) await stopServer(server, fail);
  }
  // Printed last, so that nothing reported while closing can follow an "ok".
  if (failures.length === 0 && result) {
    const c = result.counts ?? {};
    console.log(`viewer_page ${options.name}: ok, keyframes ${c.keyframes} points ${c.points} lines ${c.lines}, ` +
                `pixel std ${result.std.toFixed(1)}, ${result.toggles} toggles checked, load ms ${Math.round(result.loadMs)}`);
  }
  process.exitCode = failures.length === 0 ? 0 : 1;
}

main();
