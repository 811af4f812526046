#!/usr/bin/env node
// The playground in a real browser: serves the built page (`cargo xtask playground`), opens it
// in headless Chromium (puppeteer-core) and requires
//   - the first panel within 1 s of the page's load (the time is printed);
//   - each scene's panel, read back from the canvas, bit-identical to `host-sim render` with the
//     same settings (the Pico's: fixed point, coarse sampling, Floyd-Steinberg, lines; and one
//     other set of switches);
//   - a scene typed with a mistake on line 3 to show the error at line 3, column 15;
//   - the exact Pico image, run in the page, to show a first frame bit-identical to host-sim's;
//   - an edited scene run in the slot image on the emulated Pico ("run my scene"), its frame
//     host-sim's;
//   - edits kept across a reload, a shared link that carries the scene, the panel marked stale
//     while a mistake shows, a question before a built-in replaces edits, no failed request;
//   - the server answering a malformed request with 400 and going on.
// Usage: node playground/test.mjs --dist DIR --host-sim BIN [--chromium BIN] [--screenshot PNG]
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, renameSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';
import { serve } from './serve.mjs';

const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const FIRST_PANEL_MS = 1000;
// The emulated board is slower than silicon: the chair's first frame takes a minute or two here.
const BOARD_TIMEOUT_MS = 15 * 60 * 1000;

function args() {
  const o = { chromium: null };
  const a = process.argv.slice(2);
  for (let i = 0; i < a.length; i++) {
    const next = () => a[++i] ?? (() => { throw new Error(`${a[i - 1]} needs a value`); })();
    if (a[i] === '--dist') o.dist = next();
    else if (a[i] === '--host-sim') o.hostSim = next();
    else if (a[i] === '--chromium') o.chromium = next();
    else if (a[i] === '--screenshot') o.screenshot = next();
    else throw new Error(`unknown argument ${a[i]}`);
  }
  if (!o.dist || !o.hostSim) throw new Error('usage: node playground/test.mjs --dist DIR --host-sim BIN [--chromium BIN] [--screenshot PNG]');
  if (!o.chromium) {
    for (const name of ['chromium', 'chromium-browser', 'google-chrome']) {
      try {
        o.chromium = execFileSync('sh', ['-c', `command -v ${name}`]).toString().trim();
        break;
      } catch { /* not this one */ }
    }
    if (!o.chromium) throw new Error('no Chromium found (apt-get install chromium, or --chromium BIN)');
  }
  return o;
}

/** host-sim's `w` x `h` 1-bit frame of `scene` with `flags`, packed as the page packs it (1 lit). */
function hostFrame(hostSim, scene, flags, work, [w, h] = [128, 64], file = join(ROOT, `scenes/${scene}.scene`)) {
  const pbm = join(work, `${scene}.pbm`);
  execFileSync(hostSim, ['render', file, '-o', join(work, `${scene}.png`), '--pbm', pbm, ...flags], { stdio: ['ignore', 'ignore', 'inherit'] });
  const bytes = readFileSync(pbm);
  const header = `${w} ${h}\n`;
  const start = bytes.indexOf(header) + header.length;
  if (!bytes.subarray(0, 3).equals(Buffer.from('P4\n')) || start < header.length) throw new Error(`${pbm}: not a ${w}x${h} P4 file`);
  return Array.from(bytes.subarray(start, start + Math.ceil(w / 8) * h), (b) => b ^ 0xff); // PBM: 1 is black
}

/** The `w` x `h` canvas `id` read back as a packed 1-bit frame (a pixel is lit when it is bright). */
const readCanvas = (page, id, w = 128, h = 64) =>
  page.evaluate(
    (id, w, h) => {
      const data = document.getElementById(id).getContext('2d').getImageData(0, 0, w, h).data;
      const stride = Math.ceil(w / 8);
      const bits = new Array(stride * h).fill(0);
      for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) if (data[(y * w + x) * 4] > 127) bits[y * stride + (x >> 3)] |= 0x80 >> (x & 7);
      return bits;
    },
    id,
    w,
    h,
  );

const differing = (a, b) => a.reduce((n, x, i) => n + popcount(x ^ b[i]), 0);
const popcount = (x) => x.toString(2).split('1').length - 1;

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
}

async function main() {
  const o = args();
  const work = mkdtempSync(join(tmpdir(), 'playground-test-'));
  const server = await serve(o.dist, '127.0.0.1', 0);
  const url = `http://127.0.0.1:${server.address().port}/`;
  const browser = await puppeteer.launch({ executablePath: o.chromium, headless: true, args: ['--no-sandbox', '--disable-gpu'] });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1500, height: 1180 });
    const problems = [];
    page.on('pageerror', (e) => problems.push(String(e)));
    // Every request the page makes must succeed (no 404 in the console).
    const failed = [];
    const watch = (p) => p.on('response', (r) => r.status() >= 400 && failed.push(`${r.status()} ${r.url()}`));
    watch(page);
    let dialogs = 0;
    page.on('dialog', (d) => {
      dialogs++;
      d.accept();
    });

    // The server: a malformed escape is a bad request, and the server goes on.
    const bad = await fetch(`${url}%E0%A4%A`);
    const post = await fetch(url, { method: 'POST', body: 'x' });
    const after = await fetch(url);
    check(bad.status === 400 && post.status === 405 && after.status === 200, `the server answers /%E0%A4%A with ${bad.status}, a POST with ${post.status}, and goes on (${after.status})`);
    await page.goto(url, { waitUntil: 'load' });
    await page.waitForFunction(() => window.playground?.firstPanelMs !== null && window.playground?.firstPanelMs !== undefined, { timeout: 30000 });
    const firstPanel = await page.evaluate(() => window.playground.firstPanelMs);
    check(firstPanel <= FIRST_PANEL_MS, `page load to first panel: ${firstPanel.toFixed(0)} ms (at most ${FIRST_PANEL_MS})`);

    // The Pico image first: it runs in a worker while the scenes are checked.
    await page.click('#run-board');
    const boardStart = Date.now();

    // The page renders the boards' frame, whose cutoff (board_frame::CUTOFF, 2^-7) leaves out
    // branches below half a gray step: host-sim is asked for the same.
    const pico = ['--scalar', 'fixed', '--sampling', 'coarse', '--dither', 'fs', '--tile', '16', '--cutoff', '7'];
    const scenes = await page.evaluate(() => Array.from(document.querySelectorAll('#scene option'), (o) => o.value));
    check(scenes.length === 5, `the page offers ${scenes.length} scenes: ${scenes.join(', ')}`);
    for (const scene of scenes) {
      await page.select('#scene', scene);
      await page.waitForFunction(() => window.playground.error === null);
      const want = hostFrame(o.hostSim, scene, pico, work);
      const got = await readCanvas(page, 'panel');
      const ms = await page.evaluate(() => window.playground.renderMs);
      check(differing(got, want) === 0, `${scene}: the panel equals host-sim render ${pico.join(' ')} (${differing(got, want)} pixels differ; ${ms.toFixed(1)} ms in the page)`);
    }
    // Other switches: f32, blue noise, no lines, gamma 0.8, one ray per pixel, on the desk.
    await page.select('#scene', 'desk');
    await page.select('#scalar', 'f32');
    await page.select('#dither', 'blue-noise');
    await page.click('#lines');
    await page.select('#gamma', '8');
    await page.select('#sampling', 'one');
    await page.waitForFunction(() => JSON.stringify(window.playground.settings) === JSON.stringify({ scalar: 'f32', dither: 'blue-noise', lines: false, gamma: 8, sampling: 'one', turn: 0, shades: 2, panel: 'ssd1306' }));
    const other = ['--scalar', 'f32', '--sampling', 'one', '--dither', 'blue-noise', '--no-outline', '--gamma', '8', '--tile', '16', '--cutoff', '7'];
    const wantOther = hostFrame(o.hostSim, 'desk', other, work);
    const gotOther = await readCanvas(page, 'panel');
    check(differing(gotOther, wantOther) === 0, `desk: the panel equals host-sim render ${other.join(' ')} (${differing(gotOther, wantOther)} pixels differ)`);
    await page.click('#pico-settings');

    // Four shades (the gray mode; the core's unit test holds them to host-sim's): the page
    // draws each pixel's step as its share of the panel's white.
    await page.select('#shades', '4');
    await page.waitForFunction(() => window.playground.settings?.shades === 4 && window.playground.error === null);
    const gray = await page.evaluate(() => {
      const data = document.getElementById('panel').getContext('2d').getImageData(0, 0, 128, 64).data;
      const steps = window.playground.shades;
      const seen = new Set(steps);
      let wrong = 0;
      for (let p = 0; p < 128 * 64; p++) if (data[p * 4] !== Math.round((235 * steps[p]) / 3)) wrong++;
      return { wrong, seen: [...seen].sort().join(', ') };
    });
    check(gray.wrong === 0 && gray.seen === '0, 1, 2, 3', `four shades: the panel draws every pixel's step (${gray.wrong} pixels wrong; steps ${gray.seen})`);
    await page.select('#shades', '2');
    await page.waitForFunction(() => window.playground.settings?.shades === 2);

    // The other panels: the frame takes each glass's size (host-sim render --board pico
    // --panel NAME gives that image's frame) and the panel's look.
    await page.select('#scene', 'chair');
    for (const [name, w, h] of [['uc8151', 296, 128], ['sharp-400x240', 400, 240], ['ssd1306-72x40', 72, 40]]) {
      await page.select('#glass', name);
      await page.waitForFunction((name) => window.playground.settings?.panel === name && window.playground.error === null, {}, name);
      const size = await page.evaluate(() => window.playground.size.join('x'));
      const wantGlass = hostFrame(o.hostSim, 'chair', ['--board', 'pico', '--panel', name], work, [w, h]);
      const gotGlass = await readCanvas(page, 'panel', w, h);
      check(size === `${w}x${h}` && differing(gotGlass, wantGlass) === 0, `${name}: a ${size} panel equal to host-sim render --board pico --panel ${name} (${differing(gotGlass, wantGlass)} pixels differ)`);
      // In a window 1280 pixels wide, the panel stays inside its section and the window.
      await page.setViewport({ width: 1280, height: 900 });
      // The page fits its panels again when the window's size changes (its resize event).
      const inside = () => document.getElementById('panel').getBoundingClientRect().right <= document.getElementById('view').getBoundingClientRect().right;
      await page.waitForFunction(inside, { timeout: 5000 }).catch(() => {});
      const fit = await page.evaluate(() => {
        const c = document.getElementById('panel').getBoundingClientRect();
        const s = document.getElementById('view').getBoundingClientRect();
        return { right: Math.round(c.right), section: Math.round(s.right), window: window.innerWidth };
      });
      check(fit.right <= fit.section && fit.right <= fit.window, `${name}: in a 1280-pixel window the panel ends at ${fit.right}, inside its section (${fit.section}) and the window (${fit.window})`);
      await page.setViewport({ width: 1500, height: 1180 });
    }
    await page.select('#glass', 'ssd1306');
    await page.waitForFunction(() => window.playground.settings?.panel === 'ssd1306');

    // A mistake typed into the editor.
    await page.$eval('#text', (t) => { t.value = ''; });
    await page.type('#text', 'camera eye 0 0 -4\nlight directional dir -1 -1 1\nsphere radius -1\n');
    await page.waitForFunction(() => window.playground.error?.message.includes('positive'), { timeout: 10000 }).catch(() => {});
    const shown = await page.$eval('#error', (e) => (e.hidden ? '' : e.textContent));
    const at = await page.evaluate(() => window.playground.error && [window.playground.error.line, window.playground.error.col]);
    check(shown.startsWith('line 3, column 15') && shown.includes('size must be positive') && at?.join(':') === '3:15', `a typed mistake shows where: "${shown}"`);
    const stale = await page.evaluate(() => document.getElementById('panel').classList.contains('stale') && !document.getElementById('stale').hidden);
    check(stale, 'while the mistake shows, the panel is marked stale');
    // Loading a built-in over edits asks first (the test accepts).
    const asked = dialogs;
    await page.select('#scene', 'chair');
    await page.waitForFunction(() => window.playground.error === null);
    check(dialogs === asked + 1, `loading a built-in over edits asked first (${dialogs - asked} question)`);

    // The Pico image's first frame (the chair, the Pico's settings).
    await page.waitForFunction(() => window.playground.board.frames.length > 0 || window.playground.board.ended, { timeout: BOARD_TIMEOUT_MS, polling: 500 });
    const board = await page.evaluate(() => window.playground.board);
    const secs = ((Date.now() - boardStart) / 1000).toFixed(0);
    if (board.frames.length === 0) {
      check(false, `the Pico image showed no frame: ${board.status}`);
    } else {
      const f = board.frames[0];
      const want = hostFrame(o.hostSim, f.scene, pico, work);
      check(f.scene === 'chair' && differing(f.pixels, want) === 0, `the Pico image's first frame (${f.scene}, ${(f.cycles / 1e6).toFixed(1)} M cycles, shown after ${secs} s in the page) equals host-sim's (${differing(f.pixels, want)} pixels differ)`);
      check(differing(f.canvas, f.pixels) === 0, `the board canvas showed the frame the emulated panel showed (${differing(f.canvas, f.pixels)} pixels differ)`);
    }

    // The editor's own scene in the slot image on the emulated Pico: its frame is host-sim's.
    const mine = 'camera eye 2 2.2 -6 look 0 0.7 0 fov 45\nlight directional dir -0.4 -1 0.6\nsphere center -0.8 0.8 0 radius 0.8\ncone base 1 0 0.2 radius 0.6 height 1.4\nbox min -4 -0.1 -3 max 4 0 5\n';
    await page.$eval('#text', (t, v) => { t.value = v; t.dispatchEvent(new Event('input')); }, mine);
    await page.waitForFunction(() => window.playground.error === null);
    const mineStart = Date.now();
    await page.click('#run-mine');
    await page.waitForFunction(() => window.playground.board.frames.length > 0 || window.playground.board.ended, { timeout: BOARD_TIMEOUT_MS, polling: 500 });
    const slot = await page.evaluate(() => window.playground.board);
    const mineFile = join(work, 'mine.scene');
    writeFileSync(mineFile, mine);
    if (slot.frames.length === 0) {
      check(false, `my scene on the emulated Pico showed no frame: ${slot.status}`);
    } else {
      const wantMine = hostFrame(o.hostSim, 'mine', pico, work, [128, 64], mineFile);
      const f = slot.frames[0];
      check(differing(f.pixels, wantMine) === 0, `my scene in the slot image on the emulated Pico (${(f.cycles / 1e6).toFixed(1)} M cycles, after ${((Date.now() - mineStart) / 1000).toFixed(0)} s) equals host-sim's (${differing(f.pixels, wantMine)} pixels differ)`);
    }
    check(problems.length === 0, `no uncaught errors in the page${problems.length ? ': ' + problems.join('; ') : ''}`);
    if (o.screenshot) {
      const tmp = `${o.screenshot}.partial.png`;
      await page.screenshot({ path: tmp, fullPage: true });
      renameSync(tmp, o.screenshot);
      console.log(`wrote ${o.screenshot}`);
    }

    // The last edit (the slot's scene) is kept: a reload brings it back.
    await page.reload({ waitUntil: 'load' });
    await page.waitForFunction(() => window.playground?.source !== undefined && window.playground?.firstPanelMs !== null, { timeout: 30000 });
    const kept = await page.evaluate(() => [document.getElementById('text').value, window.playground.source]);
    check(kept[0] === mine && kept[1] === 'kept', `the edited scene survives a reload (${kept[1]})`);

    // A shared link carries the scene: opened in a new page, the editor holds it.
    const sharedText = 'camera eye 0 1.5 -5 look 0 0.5 0 fov 50\nlight directional dir -1 -1 1\nsphere center 0 0.8 0 radius 0.8\nbox min -3 -0.1 -3 max 3 0 3\n';
    await page.$eval('#text', (t, v) => { t.value = v; t.dispatchEvent(new Event('input')); }, sharedText);
    await page.click('#share');
    await page.waitForFunction(() => Boolean(window.playground.sharedUrl));
    const link = await page.evaluate(() => window.playground.sharedUrl);
    const second = await browser.newPage();
    watch(second);
    await second.goto(link, { waitUntil: 'load' });
    await second.waitForFunction(() => window.playground?.source !== undefined && window.playground?.firstPanelMs !== null, { timeout: 30000 });
    const got = await second.evaluate(() => [document.getElementById('text').value, window.playground.source]);
    check(got[0] === sharedText && got[1] === 'link', `a shared link opens with its scene (${got[1]}, ${link.length} characters)`);
    await second.close();
    check(failed.length === 0, `no request failed${failed.length ? ': ' + failed.join(', ') : ''}`);
  } finally {
    await browser.close();
    server.close();
    rmSync(work, { recursive: true, force: true });
  }
  if (failures) throw new Error(`${failures} checks failed`);
  console.log('playground: every check passed');
}

main().catch((e) => {
  console.error(`playground test: ${e.message ?? e}`);
  process.exit(1);
});
