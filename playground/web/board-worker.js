// The exact Pico image in the page: a Web Worker that runs the UF2 file `host-sim uf2` writes on
// the same emulated RP2040 as `cargo xtask board` (firmware/board/silicon.mjs: rp2040js with
// core 1, the XIP cache and the I2C bus's timing; ssd1306.mjs: the panel), and tells the page
// what the panel shows as the board draws it. esbuild bundles it with rp2040js
// (`cargo xtask playground`).
//
// Page -> worker: {uf2: ArrayBuffer, bootrom: ArrayBuffer, frames: N}
// Worker -> page: {kind: 'panel', pixels, cycles, ms, frames}   the panel as it is now
//                 {kind: 'frame', index, pixels, cycles, ms}    a frame finished (LED off)
//                 {kind: 'end', reason, ok}                      the run stopped
import { SiliconBoard, GPIOPinState, loadUf2, FLASH } from '../../firmware/board/silicon.mjs';
import { Ssd1306 } from '../../firmware/board/ssd1306.mjs';

const LED_PIN = 25;
// Steps between two looks at the panel: about 1.6 ms of emulated time, a few ms of the page's.
const CHUNK = 200_000;
// The board's button (firmware/src/bin/pico/wiring.rs `Wiring::NEXT`).
const BUTTON_PIN = 14;

function run({ uf2, bootrom, frames = 1 }) {
  const board = new SiliconBoard();
  const mcu = board.mcu;
  if (bootrom.byteLength !== 16384) throw new Error(`the bootrom is ${bootrom.byteLength} bytes, not 16384`);
  board.loadBootrom(new Uint32Array(bootrom));
  loadUf2(mcu, new Uint8Array(uf2));
  mcu.logger = { debug() {}, info() {}, warn() {}, error() {} };
  const display = new Ssd1306(0x3c);
  board.attachI2c(0, display, { timed: true, listen: {} });
  // The board's button (GP14 to ground, pulled up): nobody presses it here.
  mcu.gpio[BUTTON_PIN].setInputValue(true);
  const ms = () => mcu.clock.nanos / 1e6;
  let shown = 0;
  // A frame runs while the board's LED is lit; it is on the panel when the LED goes out.
  let frameStart = null;
  board.gpio(LED_PIN).addListener((state) => {
    if (state === GPIOPinState.High) {
      frameStart ??= board.time;
      return;
    }
    if (frameStart === null) return;
    const cycles = board.time - frameStart;
    frameStart = null;
    const why = display.notShowable();
    if (why) {
      board.stop = `the panel cannot show the frame: ${why}`;
      return;
    }
    postMessage({ kind: 'frame', index: shown, pixels: display.shown(), cycles, ms: ms() });
    shown++;
    if (shown >= frames) board.stop = `${shown} frames shown`;
  });
  board.start(FLASH, mcu.readUint32(0));
  const chunk = () => {
    for (let i = 0; i < CHUNK && board.stop === null; i++) {
      if (board.step() < 0 && !board.wake()) board.stop = 'both cores sleep with nothing to wake them';
    }
    board.stop ??= board.fault();
    if (display.error) board.stop ??= `display: ${display.error}`;
    postMessage({ kind: 'panel', pixels: display.everOn ? display.shown() : null, cycles: board.time, ms: ms(), frames: shown });
    if (board.stop === null) setTimeout(chunk, 0);
    else postMessage({ kind: 'end', reason: board.stop, ok: shown >= frames });
  };
  chunk();
}

onmessage = (e) => {
  try {
    run(e.data);
  } catch (err) {
    postMessage({ kind: 'end', reason: String(err.message ?? err), ok: false });
  }
};
