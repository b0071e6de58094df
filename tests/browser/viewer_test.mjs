// The web viewer in a real browser: Debian's chromium, headless, driven by puppeteer-core against
// the real binary. Mobile view (`run --viewer`): the page connects, map points and camera images
// arrive and keep updating, and it reconnects when the run is restarted on the same port. Edge view
// (`server --viewer` with two `client` runs into one map): the map with both clients' trajectories
// and their figures arrive and keep updating; after a server restart the page reconnects and shows
// the map from the store.
//
//   node viewer_test.mjs --edgeslam BIN --dataset DIR --modules web/node_modules
//                        [--chromium PATH] [--screenshots DIR]
// Exits 77 (ctest: skipped) when chromium or web/node_modules is missing.
import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import path from 'node:path';

const SKIP = 77;
const args = Object.fromEntries(process.argv.slice(2).reduce((pairs, value, i, all) => {
  if (value.startsWith('--')) pairs.push([value.slice(2), all[i + 1]]);
  return pairs;
}, []));
const chromium = args.chromium || '/usr/bin/chromium';
if (!existsSync(chromium)) {
  console.log(`SKIPPED: no chromium at ${chromium} (scripts/deps.sh installs Debian's)`);
  process.exit(SKIP);
}
if (!args.modules || !existsSync(path.join(args.modules, 'puppeteer-core'))) {
  console.log(`SKIPPED: no puppeteer-core in ${args.modules} (run \`make deps\`: npm ci in web/)`);
  process.exit(SKIP);
}
if (!args.dataset || !existsSync(args.dataset)) {
  console.log(`SKIPPED: dataset ${args.dataset} not found`);
  process.exit(SKIP);
}
const puppeteer = createRequire(path.resolve(args.modules, 'index.js'))('puppeteer-core');

const children = new Set();
const outputs = new Map();  // name -> the output of the process last started under that name
const outDir = mkdtempSync(path.join(tmpdir(), 'edgeslam-browser-'));
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function fail(message) {
  throw new Error(message);
}

// Starts the binary; resolves once a line of its output matches `pattern` (with the match).
function start(argv, pattern, name) {
  const child = spawn(args.edgeslam, argv, { stdio: ['ignore', 'pipe', 'pipe'] });
  children.add(child);
  child.on('exit', () => children.delete(child));
  let output = '';
  outputs.set(name, () => output);
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`${name}: no /${pattern.source}/ in 60 s:\n${output}`)), 60000);
    const onData = (data) => {
      output += data;
      const match = output.match(pattern);
      if (match) {
        clearTimeout(timer);
        resolve({ child, match, output: () => output });
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    child.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`${name} exited (${code}) early:\n${output}`));
    });
  });
}

async function stop(child) {
  if (child.exitCode !== null) return;
  const exited = new Promise((resolve) => child.once('exit', resolve));
  child.kill('SIGINT');
  const timer = setTimeout(() => child.kill('SIGKILL'), 15000);
  await exited;
  clearTimeout(timer);
}

async function progress(page) {
  return page.evaluate(() => ({ ...window.edgeslamViewer }));
}

// Polls the page until `predicate(progress)` holds; fails with `what` after `ms`.
async function waitFor(page, predicate, what, ms = 60000) {
  const deadline = Date.now() + ms;
  let last = null;
  while (Date.now() < deadline) {
    last = await progress(page).catch(() => null);
    if (last && predicate(last)) return last;
    await sleep(250);
  }
  fail(`timed out waiting for ${what}; page state: ${JSON.stringify(last)}`);
}

// `frames`: a count from the start, or [range, passes] played that many times over.
function runArgs(port, frames) {
  const play = Array.isArray(frames) ? ['--frames', frames[0], '--repeat', String(frames[1])]
    : ['--max-frames', String(frames)];
  return ['run', '--dataset', args.dataset, '--mode', 'local', '--realtime', ...play, '--vocab', 'none',
    '--viewer', String(port), '--viewer-linger', '60', '--out', path.join(outDir, `run-${port}`)];
}

async function mobileView(browser) {
  // Plays on until it is stopped below: a loaded host's browser may take most of a minute to get
  // the page, and a run that had ended by then leaves nothing to update (900 frames, 30 s, were
  // not always enough in CI).
  const first = await start(runArgs(0, ['0-599', 10]), /viewer: (http:\/\/[\d.]+:(\d+)\/)/, 'run');
  const [, url, port] = first.match;
  const page = await browser.newPage();
  await page.setViewport({ width: 420, height: 900, deviceScaleFactor: 1 });  // a phone
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  const a = await waitFor(page, (p) => p.view === 'mobile' && p.points > 0 && p.frames_loaded > 0,
    'map points and a camera image');
  await sleep(2500);
  const b = await waitFor(page, (p) => p.last_version > a.last_version && p.frames_loaded > a.frames_loaded,
    'the map and the camera image to keep updating', 10000);
  console.log(`mobile: ${b.messages} snapshots, ${b.points} points, ${b.frames_loaded} camera images`);
  const text = await page.$eval('#stats', (el) => el.textContent);
  if (!/client ms/.test(text) || !/e2e ms/.test(text)) fail(`stats table lacks figures: ${text}`);
  if (args.screenshots) {
    await waitFor(page, (p) => p.last_version > b.last_version + 40, 'more frames', 20000);
    await page.screenshot({ path: path.join(args.screenshots, 'viewer-mobile.png') });
  }
  // The run goes away: the page notices; a new run on the same port: it reconnects by itself.
  await stop(first.child);
  await waitFor(page, (p) => !p.connected, 'the page to notice the run stopped', 15000);
  const before = await progress(page);
  // Long enough (10 s) that the page's retry (a few seconds) finds it still running: a finished
  // run's snapshot no longer changes, so one message would be all the page gets.
  const second = await start(runArgs(port, 300), /viewer: http/, 'second run');
  await waitFor(page, (p) => p.connected && p.messages > before.messages + 1 && p.reconnects >= 1,
    'the page to reconnect to the restarted run', 30000);
  console.log('mobile: reconnected after a restart');
  await stop(second.child);
  if (errors.length) fail(`page errors: ${errors.join('; ')}`);
  await page.close();
}

async function edgeView(browser) {
  const serverArgs = (viewerPort, listen) => ['server', '--listen', listen, '--viewer', String(viewerPort),
    '--semantic', 'off', '--vocab', 'none', '--status-every', '0', '--maps', path.join(outDir, 'maps')];
  const server = await start(serverArgs(0, '127.0.0.1:0'), /viewer: (http:\/\/[\d.]+:(\d+)\/)[\s\S]*listening on ([\d.]+:\d+)/, 'server');
  const [, url, viewerPort, address] = server.match;
  // Two clients into one map at once. They play on until the test stops them: on a loaded host
  // the page may take most of a minute to see the first session, and clients that had ended by
  // then left nothing to update.
  const clientArgs = (name, frames) => ['client', '--server', address, '--dataset', args.dataset, '--realtime',
    '--frames', frames, '--repeat', '100', '--vocab', 'none', '--map', 'shared',
    '--out', path.join(outDir, name)];
  const first = await start(clientArgs('first', '0-299'), /frame/, 'first client');
  const second = await start(clientArgs('second', '100-399'), /frame/, 'second client');
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800, deviceScaleFactor: 1 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  const a = await waitFor(page, (p) => p.view === 'edge' && p.sessions >= 2 && p.points > 0 &&
    p.map_shown === 'shared' && p.map_live && p.map_clients >= 2, 'one live map with both clients\' keyframes');
  const b = await waitFor(page, (p) => p.last_version > a.last_version + 2, 'the edge map to keep updating', 20000);
  console.log(`edge: ${b.sessions} session(s) in map '${b.map_shown}' (${b.map_clients} trajectories), ` +
    `${b.points} points, ${b.messages} snapshots`);
  const events = await page.$eval('#events', (el) => el.textContent);
  if (!/joined, map 'shared'/.test(events)) fail(`no join in the event list: ${events}`);
  if (args.screenshots) {
    await sleep(4000);
    await page.screenshot({ path: path.join(args.screenshots, 'viewer-edge.png') });
  }
  await stop(first.child);
  await stop(second.child);
  await stop(server.child);
  await waitFor(page, (p) => !p.connected, 'the page to notice the server stopped', 15000);
  const before = await progress(page);
  // Started again on the same store: the map is now one the store holds, shown when picked (the
  // first map when none is live).
  const restarted = await start(serverArgs(viewerPort, '127.0.0.1:0'), /listening on/, 'restarted server');
  await waitFor(page, (p) => p.connected && p.messages > before.messages && p.reconnects >= 1,
    'the page to reconnect to the restarted server', 30000);
  console.log('edge: reconnected after a server restart');
  const c = await waitFor(page, (p) => p.map_shown === 'shared' && p.map_live === false && p.stored_points > 0,
    'the stored map to be listed and shown', 30000);
  console.log(`edge: stored map '${c.map_shown}' shown, ${c.stored_points} points`);
  await stop(restarted.child);
  if (errors.length) fail(`page errors: ${errors.join('; ')}`);
  await page.close();
}

let browser = null;
let status = 0;
try {
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-gpu-sandbox'],
  });
  const which = args.only || 'both';
  if (which !== 'edge') await mobileView(browser);
  if (which !== 'mobile') await edgeView(browser);
  console.log('PASS');
} catch (e) {
  console.error(`FAIL: ${e.message}`);
  // What the processes said last: the cause is often there (a crash, a refused session).
  for (const [name, output] of outputs) {
    const lines = output().trimEnd().split('\n');
    console.error(`--- ${name}: the last ${Math.min(lines.length, 15)} lines of its output ---`);
    console.error(lines.slice(-15).join('\n'));
  }
  status = 1;
} finally {
  if (browser) await browser.close().catch(() => {});
  await Promise.all([...children].map(stop));
  rmSync(outDir, { recursive: true, force: true });
}
process.exit(status);
