// The playground page: the scene editor, the panel the core renders (WebAssembly, built from
// playground/src/lib.rs) and the exact Pico image on an emulated RP2040 (board-worker.js).
// `window.playground` holds what the browser test (playground/test.mjs) reads.
import init, { panel, scene_names, scene_text, default_settings, slot_uf2 } from './pkg/playground.js';

/** The emulated Pico's panel (the board's image drives the SSD1306 128x64). */
const W = 128;
const H = 64;
const $ = (id) => document.getElementById(id);
const state = { settings: null, bits: null, report: null, error: null, renderMs: null, firstPanelMs: null, board: { frames: [], status: 'not started' } };
window.playground = state;

/** What a 128x64 canvas shows, as a packed 1-bit frame (a pixel is lit when it is bright). */
function readBits(canvas) {
  const data = canvas.getContext('2d').getImageData(0, 0, W, H).data;
  const bits = new Array((W / 8) * H).fill(0);
  for (let p = 0; p < W * H; p++) if (data[p * 4] > 127) bits[p >> 3] |= 0x80 >> (p & 7);
  return bits;
}

/**
 * How each kind of panel looks: its dark and its lit (white) pixel. An OLED lights its pixels
 * on black; a Sharp memory LCD reflects the room where a pixel is white; e-paper is ink on paper.
 */
const LOOKS = {
  oled: { dark: [0, 0, 0], lit: [235, 242, 255], frame: '#111' },
  sharp: { dark: [38, 40, 38], lit: [196, 202, 194], frame: '#555' },
  epaper: { dark: [28, 28, 30], lit: [236, 233, 222], frame: '#ddd' },
};
/** A panel's look, by the firmware's panel name. */
const lookOf = (panel) => (panel.startsWith('sharp') ? LOOKS.sharp : panel === 'uc8151' ? LOOKS.epaper : LOOKS.oled);

/** The colour of a pixel lit `share` of the time (0: dark, 1: the panel's white) in `look`. */
const shade = (share, look = LOOKS.oled) => look.dark.map((d, i) => Math.round(d + (look.lit[i] - d) * share));

/**
 * Shows a canvas at the largest whole scale, at most 4x, at which its glass and border (6
 * pixels a side) fit the width its section has: a 400-pixel glass beside the editor in a
 * 1280-pixel window at 1x, never running off the page.
 */
function fit(canvas) {
  const room = (canvas.parentElement?.clientWidth ?? 4 * canvas.width) - 12;
  const scale = Math.max(1, Math.min(4, Math.floor(room / canvas.width)));
  canvas.style.width = `${canvas.width * scale}px`;
  canvas.style.height = `${canvas.height * scale}px`;
}
addEventListener('resize', () => document.querySelectorAll('canvas').forEach(fit));

/**
 * Draws a frame of `w` x `h` pixels on a canvas (sized to it): a packed 1-bit frame (rows of
 * w / 8 bytes, MSB first, 1 lit), or with `steps` (a step per pixel, 0..=top) its shades, a
 * pixel of step k lit k / top of the time (the gray mode's subframes, as the eye sums them),
 * in the panel's `look`.
 */
function draw(canvas, bits, steps = null, top = 1, w = W, h = H, look = LOOKS.oled) {
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  fit(canvas);
  canvas.style.borderColor = look.frame;
  const ctx = canvas.getContext('2d');
  const img = ctx.createImageData(w, h);
  const stride = Math.ceil(w / 8);
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      const on = (bits[y * stride + (x >> 3)] >> (7 - (x & 7))) & 1;
      const [r, g, b] = shade(steps ? steps[y * w + x] / top : on, look);
      const i = (y * w + x) * 4;
      img.data[i] = r;
      img.data[i + 1] = g;
      img.data[i + 2] = b;
      img.data[i + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
}

function settings() {
  return {
    scalar: $('scalar').value,
    dither: $('dither').value,
    lines: $('lines').checked,
    gamma: Number($('gamma').value),
    sampling: $('sampling').value,
    turn: Number($('orbit').value) / 36,
    shades: Number($('shades').value),
    panel: $('glass').value,
  };
}

function applySettings(s) {
  $('scalar').value = s.scalar;
  $('dither').value = s.dither;
  $('lines').checked = s.lines;
  $('gamma').value = String(s.gamma);
  $('sampling').value = s.sampling;
  $('orbit').value = String(Math.round(s.turn * 36));
  $('shades').value = String(s.shades);
  $('glass').value = s.panel ?? 'ssd1306';
}

const fmt = (n) => n.toLocaleString('en-US');

/** Estimated instructions on the Pico's Cortex-M0+ (cost.json: per ray and per object test, fitted to the firmware report). */
function boardCost(cost, r) {
  if (!cost) return 'unknown (cost.json missing)';
  const rays = r.rays.reduce((a, b) => a + b, 0);
  const instr = rays * cost.perRay + r.objectTests * cost.perTest;
  return `≈ ${(instr / 1e6).toFixed(1)} M instructions on its Cortex-M0+ (${fmt(Math.round(cost.perRay))} per ray and ${fmt(Math.round(cost.perTest))} per object test, ${cost.source})`;
}

function showReport(r, ms, cost) {
  const rays = r.rays.reduce((a, b) => a + b, 0);
  const rows = [
    ['objects', `${r.objects} (${r.composites} composites), ${r.lights} lights`],
    ['effects the scene calls for', r.effects],
    ['lattices (cells per axis)', r.lattices.map((n, i) => `${i === 0 ? 'world' : 'sub ' + (i - 1)} ${n.join('×')}`).join(', ')],
    ['cells, references', `${fmt(r.cells)}, ${fmt(r.references)}`],
    ['lattice bytes', `${fmt(r.bytes)} (${r.scalar})`],
    ['rays', `${fmt(rays)}: eye ${fmt(r.rays[0])}, shadow ${fmt(r.rays[1])}, reflection ${fmt(r.rays[2])}, refraction ${fmt(r.rays[3])}`],
    ['object tests per ray', (r.objectTests / Math.max(rays, 1)).toFixed(2) + ` (${fmt(r.objectTests)} tests, ${fmt(r.culled)} skipped by eye windows)`],
    ['cells visited per ray', (r.cellsVisited / Math.max(rays, 1)).toFixed(2)],
    ['on the Pico', boardCost(cost, r)],
    ['in this page', `${ms.toFixed(1)} ms`],
  ];
  const body = $('report').tBodies[0];
  body.replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    for (const t of [k, v]) {
      const td = document.createElement('td');
      td.textContent = t;
      tr.append(td);
    }
    return tr;
  }));
}

function showError(e) {
  const box = $('error');
  // While a mistake shows, the panel still shows the last scene that had none: marked stale.
  $('panel').classList.toggle('stale', Boolean(e));
  $('stale').hidden = !e;
  if (!e) {
    box.hidden = true;
    box.textContent = '';
    return;
  }
  box.hidden = false;
  // The core's message says the line and column, as host-sim's does.
  box.textContent = e.message;
}

/** Selects line `line` of the editor (where a mistake is). */
function selectLine(line) {
  const t = $('text');
  const lines = t.value.split('\n');
  const start = lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0);
  t.focus();
  t.setSelectionRange(start, start + (lines[line - 1] ?? '').length);
}

function rerender(cost) {
  const s = settings();
  $('orbit-at').textContent = `${$('orbit').value} / 36`;
  const t0 = performance.now();
  try {
    const p = panel($('text').value, s.scalar, s.dither, s.lines, s.gamma, s.sampling, s.turn, s.shades, s.panel);
    const [w, h] = [p.width(), p.height()];
    const ms = performance.now() - t0;
    state.bits = p.bits();
    state.shades = Array.from(p.shades());
    state.report = JSON.parse(p.report());
    state.error = null;
    state.renderMs = ms;
    state.settings = s;
    p.free();
    state.size = [w, h];
    draw($('panel'), state.bits, s.shades === 4 ? state.shades : null, s.shades - 1, w, h, lookOf(s.panel));
    showReport(state.report, ms, cost);
    showError(null);
  } catch (err) {
    // A scene's mistake (ScriptError) keeps the last good panel on screen.
    state.error = typeof err.message === 'function' ? { line: err.line(), col: err.col(), message: err.message() } : { line: 0, col: 0, message: String(err) };
    showError(state.error);
  }
  if (state.firstPanelMs === null && state.bits) state.firstPanelMs = performance.now();
}

/** The bytes of file `f` of the page. */
const fetchBytes = (f) => fetch(f).then((r) => {
  if (!r.ok) throw new Error(`${f}: ${r.status}`);
  return r.arrayBuffer();
});

/** The slot image's UF2 file with the editor's scene in its slot (throws the scene's mistake). */
async function mySlotUf2(info) {
  const image = new Uint8Array(await fetchBytes(info.slotUf2));
  return slot_uf2(image, $('text').value);
}

/** Runs the UF2 file `uf2` (or `info.uf2`, fetched) on the emulated board for `names` frames. */
function startBoard(info, uf2 = null, names = info.scenes) {
  const status = $('board-status');
  // One board at a time: a new run stops the one before.
  state.worker?.terminate();
  state.board = { frames: [], status: 'loading' };
  const worker = new Worker('board-worker.js');
  state.worker = worker;
  Promise.all([uf2 ? Promise.resolve(uf2) : fetchBytes(info.uf2), fetchBytes(info.bootrom)]).then(([uf2, bootrom]) => {
    worker.postMessage({ uf2, bootrom, frames: names.length });
  }, (e) => {
    state.board.status = `cannot load the image: ${e.message}`;
    state.board.ended = true;
    status.textContent = state.board.status;
  });
  const t0 = performance.now();
  worker.onmessage = ({ data: m }) => {
    const secs = ((performance.now() - t0) / 1e3).toFixed(1);
    if (m.kind === 'panel') {
      if (m.pixels) draw($('board-panel'), m.pixels);
      state.board.status = `running: ${fmt(m.cycles)} cycles, ${m.ms.toFixed(1)} ms of board time (${secs} s in this page), ${m.frames} frames shown`;
    } else if (m.kind === 'frame') {
      const scene = names[m.index] ?? `frame ${m.index}`;
      draw($('board-panel'), m.pixels);
      // What the canvas showed when the frame was done (the board goes straight on to the next).
      state.board.frames.push({ scene, pixels: Array.from(m.pixels), cycles: m.cycles, canvas: readBits($('board-panel')) });
      state.board.last = `${scene}: ${fmt(m.cycles)} cycles, ${(125e6 / m.cycles).toFixed(2)} frames per second at 125 MHz`;
    } else if (m.kind === 'end') {
      state.board.status = `${m.ok ? 'done' : 'stopped'}: ${m.reason}`;
      state.board.ended = true;
      worker.terminate();
    }
    status.textContent = state.board.status + (state.board.last ? ` — last frame ${state.board.last}` : '');
  };
}

/** Where the page keeps the editor's text between visits. */
const KEPT_TEXT = 'lattice-rt.scene';

/** Scene text as URL-safe base64 of its UTF-8 bytes. */
function encodeScene(text) {
  const bytes = new TextEncoder().encode(text);
  let bin = '';
  for (const b of bytes) bin += String.fromCharCode(b);
  return btoa(bin).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

/** The scene a shared link carries (`#scene=...`), or null. */
function sharedScene() {
  const m = /^#scene=([A-Za-z0-9_-]*)$/.exec(location.hash);
  if (!m) return null;
  try {
    const bin = atob(m[1].replace(/-/g, '+').replace(/_/g, '/'));
    return new TextDecoder('utf-8', { fatal: true }).decode(Uint8Array.from(bin, (c) => c.charCodeAt(0)));
  } catch {
    return null;
  }
}

async function main() {
  await init();
  const [info, cost] = await Promise.all([
    fetch('board.json').then((r) => r.json()),
    fetch('cost.json').then((r) => (r.ok ? r.json() : null)).catch(() => null),
  ]);
  const defaults = JSON.parse(default_settings());
  for (const d of defaults.dithers.split(',')) $('dither').append(new Option(d, d));
  for (const n of scene_names().split(',')) $('scene').append(new Option(n, n));
  applySettings(defaults);
  // The scene: from the address (a shared link), else the edits kept in this browser, else the
  // first built-in.
  const shared = sharedScene();
  const kept = localStorage.getItem(KEPT_TEXT);
  $('text').value = shared ?? kept ?? scene_text($('scene').value);
  state.source = shared !== null ? 'link' : kept !== null ? 'kept' : 'built-in';
  // What the editor held when a built-in was loaded last: anything else is the user's edit.
  let loaded = shared === null && kept === null ? $('text').value : null;
  $('board-scenes').textContent = info.scenes.join(', ');
  const go = () => rerender(cost);
  // Redraw as the user types, once per animation frame at most.
  let pending = false;
  const soon = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      go();
    });
  };
  $('text').addEventListener('input', () => {
    localStorage.setItem(KEPT_TEXT, $('text').value);
    soon();
  });
  for (const id of ['dither', 'lines', 'gamma', 'scalar', 'sampling', 'orbit', 'shades', 'glass']) $(id).addEventListener('input', soon);
  let shown = $('scene').value;
  $('scene').addEventListener('change', () => {
    const edited = loaded === null ? $('text').value.trim() !== '' : $('text').value !== loaded;
    if (edited && !confirm(`Replace your scene in the editor with the built-in ${$('scene').value}? Your edits are lost.`)) {
      $('scene').value = shown;
      return;
    }
    shown = $('scene').value;
    $('text').value = loaded = scene_text(shown);
    localStorage.removeItem(KEPT_TEXT);
    go();
  });
  $('share').addEventListener('click', async () => {
    history.replaceState(null, '', `#scene=${encodeScene($('text').value)}`);
    state.sharedUrl = location.href;
    try {
      await navigator.clipboard.writeText(location.href);
      $('share').textContent = 'Link copied';
    } catch {
      $('share').textContent = 'Link in the address bar';
    }
  });
  $('run-mine').addEventListener('click', async () => {
    // The board's state is the new run's from the click on.
    state.worker?.terminate();
    state.board = { frames: [], status: 'writing your scene beside the slot image' };
    try {
      startBoard(info, await mySlotUf2(info), ['your scene']);
    } catch (e) {
      state.board = { frames: [], status: `your scene cannot go on the Pico: ${e.message ?? e}`, ended: true };
      $('board-status').textContent = state.board.status;
    }
  });
  $('download-mine').addEventListener('click', async () => {
    try {
      const bytes = await mySlotUf2(info);
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([bytes], { type: 'application/octet-stream' }));
      a.download = 'lattice-rt-pico-scene.uf2';
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
      $('board-status').textContent = `downloaded lattice-rt-pico-scene.uf2 (${fmt(bytes.length)} bytes)`;
    } catch (e) {
      $('board-status').textContent = `your scene cannot go on the Pico: ${e.message ?? e}`;
    }
  });
  $('pico-settings').addEventListener('click', () => {
    applySettings(defaults);
    go();
  });
  $('error').addEventListener('click', () => state.error?.line && selectLine(state.error.line));
  $('run-board').addEventListener('click', () => startBoard(info));
  go();
}

state.ready = main().catch((e) => {
  showError({ line: 0, col: 0, message: `the playground did not start: ${e.message ?? e}` });
  throw e;
});
