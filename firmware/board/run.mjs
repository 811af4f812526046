#!/usr/bin/env node
// Runs the Pico image a user flashes (its UF2 file) on an RP2040 as silicon runs it
// (silicon.mjs: rp2040js with core 1, the XIP cache and timed display buses), with the B1
// bootrom and one SSD1306 wired both ways a module can be: on I2C0 at 0x3C, and on SPI0 with
// chip select on GP17, data/command on GP20 and reset on GP21 (the `spi` build's wiring,
// firmware/src/bin/pico/wiring.rs); the image drives whichever it was built for. It reports on
// stdout, one JSON object a line:
//   {"event":"frame", ...}  each frame the panel shows: the moment the board's LED (GP25, lit
//                           while a frame is being rendered) goes out, with the cycles the frame
//                           took, each core's busy and idle cycles, the XIP cache's hits,
//                           misses and stall, the display bus's bytes and busy cycles, and the
//                           panel's pixels as hex rows
//   {"event":"epaper", ...} with --panel uc8151, before the end: each refresh's start and end
//                           and when its frame's bytes began (emulated ms)
//   {"event":"end", ...}    why the run ended, with totals
// The device's defmt log (the RTT up channel, read as a probe reads it) goes to --log as raw
// bytes for people, and its typed records (the board_records channel at --records ADDR) to
// --records-log, for `cargo xtask board` to decode. Exit code 0 when the run ended as asked, 1
// otherwise.
//
// rp2040js has no SSI flash model, so core 0 starts at boot2 (PC = 0x10000000) with the
// bootrom's stack pointer, as on silicon after the bootrom has found a valid boot2; core 1
// starts in the bootrom and waits there for the launch sequence.
//
// --panel NAME puts another panel on the buses in place of the SSD1306 128x64: sh1106 (the 1.3"
// modules: 132 columns of RAM, page addressing only), ssd1309 (the 2.42" modules: no charge
// pump), ssd1306-128x32 or ssd1306-72x40 (smaller glass: the frame's pixels are its size); the
// image must be built for it (its `sh1106`, `ssd1309`, `ssd1306-128x32` or `ssd1306-72x40` feature);
// sharp-400x240 or sharp-128x128 puts a Sharp memory LCD on SPI0 alone (its own wiring); uc8151
// the Badger 2040's e-paper on SPI0 (the SPI modules' CS, DC and RES; its BUSY drives GP26);
// thumby the Thumby's 72x40 SSD1306 on SPI0 on its own pins (CS GP16, DC GP17, RES GP20), its A
// button (GP27) the one --press presses and its B button (GP24) --press-turn's (the `thumby`
// image). The Badger's buttons close to 3V3 (its C on GP14, up on GP15), the others to ground.
// --no-cache and --untimed-bus leave a model out (to measure what each adds); --no-core1
// leaves core 1 in reset (the firmware then waits for it forever: a deadlock the run reports).
// --panel-off START_MS:LEN_MS (repeatable) cuts the display's power at START_MS of emulated
// time for LEN_MS: it answers nothing meanwhile (every I2C address NACKs, SPI bytes are lost)
// and comes back as a freshly powered panel (registers reset, GDDRAM cleared, display off). A
// frame the panel cannot show then is reported with its reason and the run goes on.
// --reset-at MS (repeatable) resets the chip at MS of emulated time, as the RUN pin does, and
// --hang-core1-at MS stops core 1 for good (it makes no more progress): either way the board
// boots again (SRAM and the watchdog's scratch registers kept, as on silicon; the watchdog's
// REASON says TIMER after its own reset, nothing after the RUN pin) and the run goes on, with an
// {"event":"reset"} line and the emulated time running on.
// --sda-stuck START_MS:PULSES (repeatable) has the display hold SDA low at START_MS, as a panel
// whose transfer was cut off in the middle of a byte does, until it has seen PULSES (1 to 9)
// falling SCL edges: the controller sees a busy bus and sends nothing until the firmware clears
// it through the pins (I2C0's SDA on GP4, SCL on GP5). --nack-at MS (repeatable): the display
// does not acknowledge the first byte written to it after MS. Each gives an {"event":"bus"}
// line when it happens (what: "sda held", "sda released", "nack").
// --look-at MS (repeatable): an {"event":"look","ms":MS,"pixels":...} line with what the
// panel shows at MS, whatever the firmware is doing (a power cut no transfer saw shows here).
// --press MS[:LEN_MS] (repeatable) presses the board's next-scene button (GP14 to ground, the
// firmware's `Wiring::NEXT`) at MS for LEN_MS (100 by default), with an {"event":"button",
// "which":"next"} line; --press-turn MS[:LEN_MS] the camera-turn button (GP15, `Wiring::TURN`),
// with "which":"turn". A released button's pin reads what its pad's pull gives it (a pull-up
// high, a pull-down low), as on silicon: a firmware that pulls it the wrong way sees it pressed.
// --panic-at MS with --panic-request ADDR writes 1 to the word at ADDR (the firmware's
// PANIC_REQUEST) at MS: the firmware panics at its next check between frames.
// --pass-bytes N shows a picture every N GDDRAM bytes the display receives while the LED is lit
// (1024: a progressive frame's passes, each a whole panel), instead of when the LED goes out.
// With --profile FILE it also samples core 0's program counter every 97th instruction of the
// first frame (--profile-frames N: of the first N frames; while the LED is lit) and writes the
// counts as JSON pairs [pc, samples]. With --miss-lines FILE it counts the XIP cache's misses
// of the first frame (--profile-frames N: of the first N) by the flash address of the line
// missed and writes them as JSON pairs [address, misses].
//
// Usage: node run.mjs --uf2 FILE --bootrom FILE --rtt ADDR --log FILE
//                     [--records ADDR --records-log FILE] [--frames N] [--max-cycles N]
//                     [--no-display] [--until-ms T] [--profile FILE] [--miss-lines FILE]
//                     [--profile-frames N] [--no-core1] [--no-cache] [--untimed-bus]
//                     [--pass-bytes N] [--panel-off START_MS:LEN_MS] [--reset-at MS]
//                     [--hang-core1-at MS] [--panic-at MS --panic-request ADDR]
//                     [--sda-stuck START_MS:PULSES] [--nack-at MS] [--look-at MS] [--panel NAME]
//                     [--press MS[:LEN_MS]] [--press-turn MS[:LEN_MS]] [--scan] [--osc-error PERCENT]
import { readFileSync, writeFileSync } from 'node:fs';
import { SiliconBoard, GPIOPinState, loadUf2, FLASH } from './silicon.mjs';
import { Ssd1306, GLASSES } from './ssd1306.mjs';
import { Sh1106 } from './sh1106.mjs';
import { Ssd1309 } from './ssd1309.mjs';
import { SharpMemoryLcd } from './sharp.mjs';
import { Uc8151 } from './uc8151.mjs';

/** A Sharp memory LCD's wiring (the `sharp` builds'): SCS (active high) on GP17, DISP on GP20. */
const SHARP_SPI = { cs: 17, disp: 20, csActiveHigh: true };
/** The Badger 2040's e-paper: the SPI modules' CS, DC and RES, and BUSY (the panel's output) on GP26. */
const BUSY_PIN = 26;

/**
 * The panels --panel chooses from (the image must drive the same one): each made with the
 * time (`now`: emulated nanoseconds), on both buses with the SSD1306 modules' wiring, or on SPI
 * alone with its own.
 */
const PANELS = {
  ssd1306: { make: (now) => new Ssd1306(0x3c, GLASSES['128x64'], now) },
  'ssd1306-128x32': { make: (now) => new Ssd1306(0x3c, GLASSES['128x32'], now) },
  'ssd1306-72x40': { make: (now) => new Ssd1306(0x3c, GLASSES['72x40'], now) },
  sh1106: { make: () => new Sh1106(0x3c) },
  ssd1309: { make: () => new Ssd1309(0x3c) },
  'sharp-400x240': { make: (now) => new SharpMemoryLcd(400, 240, now), spi: SHARP_SPI },
  'sharp-128x128': { make: (now) => new SharpMemoryLcd(128, 128, now), spi: SHARP_SPI },
  uc8151: {
    make: (now, mcu) =>
      new Uc8151(now, (ns, fn) => mcu().clock.createAlarm(fn).schedule(ns), (high) => mcu()?.gpio[BUSY_PIN].setInputValue(high)),
    spi: { cs: 17, dc: 20, res: 21 },
    // Its buttons close to 3V3 (Pimoroni's examples read them with pull-downs, on rising edges).
    buttons: { next: 14, turn: 15, activeHigh: true },
  },
  // The Thumby: its 72x40 SSD1306 on SPI0 with its own control pins, its A and B buttons on
  // GP27 and GP24 (to ground).
  thumby: {
    make: (now) => new Ssd1306(0x3c, GLASSES['72x40'], now),
    spi: { cs: 16, dc: 17, res: 20 },
    buttons: { next: 27, turn: 24, activeHigh: false },
  },
};

const LED_PIN = 25;
/** The SPI display's control pins (firmware/src/bin/pico/wiring.rs, `spi`). */
const SPI_DISPLAY = { cs: 17, dc: 20, res: 21 };
/** The I2C display's pins (wiring.rs): I2C0's SDA and SCL. */
const I2C_PINS = { sda: 4, scl: 5 };
/** The board's buttons (wiring.rs `Wiring::NEXT` and `Wiring::TURN`): push buttons to ground (a
 * panel's board may have them elsewhere, or to 3V3: its `buttons`). */
const BUTTONS = { next: 14, turn: 15, activeHigh: false };
/**
 * A push button from a GPIO to a rail: ground, or 3V3 when `activeHigh`. Pressed, the pin reads
 * the rail; released, what the pad's pull gives it (the PADS_BANK0 register the firmware sets): a
 * pull-up high, a pull-down low, both (the bus keeper) or neither its last level.
 */
class PushButton {
  constructor(gpio, activeHigh) {
    this.gpio = gpio;
    this.activeHigh = activeHigh;
    this.down = false;
    gpio.addListener(() => this.settle());
    this.settle();
  }

  /** Presses (`down`) or releases the button. */
  press(down) {
    this.down = down;
    this.settle();
  }

  /** Sets the pin's input level from the button and the pad's pull. */
  settle() {
    const { gpio } = this;
    let level = gpio.rawInputValue;
    if (this.down) level = this.activeHigh;
    else if (gpio.pullupEnabled !== gpio.pulldownEnabled) level = gpio.pullupEnabled;
    if (level !== gpio.rawInputValue) gpio.setInputValue(level);
  }
}

// Every how many instructions --profile samples the program counter (a prime, so no loop of
// the renderer beats in step with it).
const PROFILE_EVERY = 97;

function parseArgs(argv) {
  const o = { frames: 1, maxCycles: 20e9, display: true, untilMs: null, profileFrames: 1, core1: true, cache: true, timedBus: true, panelOff: [], resetAt: [], hangAt: [], panicAt: [], sdaStuck: [], nackAt: [], looks: [], presses: [], panel: 'ssd1306' };
  for (let i = 2; i < argv.length; i++) {
    const a = argv[i];
    const next = () => {
      if (i + 1 >= argv.length) throw new Error(`${a} needs a value`);
      return argv[++i];
    };
    if (a === '--uf2') o.uf2 = next();
    else if (a === '--bootrom') o.bootrom = next();
    else if (a === '--rtt') o.rtt = Number(next());
    else if (a === '--log') o.log = next();
    else if (a === '--records') o.records = Number(next());
    else if (a === '--records-log') o.recordsLog = next();
    else if (a === '--frames') o.frames = Number(next());
    else if (a === '--max-cycles') o.maxCycles = Number(next());
    else if (a === '--until-ms') o.untilMs = Number(next());
    else if (a === '--no-display') o.display = false;
    else if (a === '--profile') o.profile = next();
    else if (a === '--profile-frames') o.profileFrames = Number(next());
    else if (a === '--miss-lines') o.missLines = next();
    else if (a === '--no-core1') o.core1 = false;
    else if (a === '--no-cache') o.cache = false;
    else if (a === '--pass-bytes') o.passBytes = Number(next());
    else if (a === '--untimed-bus') o.timedBus = false;
    else if (a === '--scan') o.scan = true;
    else if (a === '--osc-error') {
      const v = next();
      if (!/^-?\d+(\.\d+)?$/.test(v)) throw new Error(`--osc-error ${v}: a percentage expected`);
      o.oscError = Number(v);
    }
    else if (a === '--panel-off') {
      const v = next();
      const m = /^(\d+(?:\.\d+)?):(\d+(?:\.\d+)?)$/.exec(v);
      if (!m) throw new Error(`--panel-off ${v}: START_MS:LEN_MS expected`);
      o.panelOff.push({ startMs: Number(m[1]), lenMs: Number(m[2]) });
    } else if (a === '--sda-stuck') {
      const v = next();
      const m = /^(\d+(?:\.\d+)?):([1-9])$/.exec(v);
      if (!m) throw new Error(`--sda-stuck ${v}: START_MS:PULSES expected (PULSES 1 to 9)`);
      o.sdaStuck.push({ startMs: Number(m[1]), pulses: Number(m[2]) });
    } else if (a === '--nack-at') o.nackAt.push(Number(next()));
    else if (a === '--look-at') o.looks.push(Number(next()));
    else if (a === '--press' || a === '--press-turn') {
      const v = next();
      const m = /^(\d+(?:\.\d+)?)(?::(\d+(?:\.\d+)?))?$/.exec(v);
      if (!m) throw new Error(`${a} ${v}: MS or MS:LEN_MS expected`);
      const which = a === '--press' ? 'next' : 'turn';
      o.presses.push({ which, startMs: Number(m[1]), lenMs: m[2] === undefined ? 100 : Number(m[2]) });
    } else if (a === '--panel') {
      o.panel = next();
      if (!PANELS[o.panel]) throw new Error(`--panel ${o.panel}: one of ${Object.keys(PANELS).join(', ')} expected`);
    }
    else if (a === '--reset-at') o.resetAt.push(Number(next()));
    else if (a === '--hang-core1-at') o.hangAt.push(Number(next()));
    else if (a === '--panic-at') o.panicAt.push(Number(next()));
    else if (a === '--panic-request') o.panicRequest = Number(next());
    else throw new Error(`unknown argument ${a}`);
  }
  for (const k of ['uf2', 'bootrom', 'log']) if (!o[k]) throw new Error(`--${k} is required`);
  if ((o.records === undefined) !== (o.recordsLog === undefined)) throw new Error('--records ADDR and --records-log FILE go together');
  if (!Number.isInteger(o.rtt)) throw new Error('--rtt ADDR (the _SEGGER_RTT symbol) is required');
  if (o.panicAt.length > 0 && !Number.isInteger(o.panicRequest)) throw new Error('--panic-at needs --panic-request ADDR');
  return o;
}

/** Reads what the firmware wrote to the RTT up channel since the last call, as a probe does. */
class RttReader {
  constructor(mcu, address) {
    this.mcu = mcu;
    this.address = address;
    this.chunks = [];
    this.bytes = 0;
  }
  poll() {
    const m = this.mcu;
    const a = this.address;
    // "SEGGER RTT" id written by the firmware's .data initialisation
    if (m.readUint32(a) !== 0x47474553) return;
    const ch = a + 24;
    const buf = m.readUint32(ch + 4);
    const size = m.readUint32(ch + 8);
    const write = m.readUint32(ch + 12);
    let read = m.readUint32(ch + 16);
    if (size === 0 || write >= size || read >= size) return;
    // Block when full, as probe-rs sets it: nothing is lost while the runner keeps reading.
    if ((m.readUint32(ch + 20) & 3) !== 2) m.writeUint32(ch + 20, (m.readUint32(ch + 20) & ~3) | 2);
    while (read !== write) {
      const end = write > read ? write : size;
      const out = new Uint8Array(end - read);
      for (let i = 0; i < out.length; i++) out[i] = m.readUint8(buf + read + i);
      this.chunks.push(out);
      this.bytes += out.length;
      read = end % size;
    }
    m.writeUint32(ch + 16, read);
  }
  save(path) {
    writeFileSync(path, Buffer.concat(this.chunks.map((c) => Buffer.from(c))));
  }
}

/**
 * Reads the board's record channel (board_records::Channel at the `BOARD_RECORDS` symbol: magic,
 * size, write offset, read offset, dropped, buffer) as a probe would: what lies between the
 * read and the write offset, then the read offset moved on.
 */
class RecordReader {
  constructor(mcu, address) {
    this.mcu = mcu;
    this.address = address;
    this.chunks = [];
  }
  poll() {
    const m = this.mcu;
    const a = this.address;
    const magic = Array.from({ length: 8 }, (_, i) => m.readUint8(a + i));
    if (String.fromCharCode(...magic) !== 'LRT-RECS') return;
    const size = m.readUint32(a + 8);
    const write = m.readUint32(a + 12);
    let read = m.readUint32(a + 16);
    if (size === 0 || write >= size || read >= size) return;
    while (read !== write) {
      const end = write > read ? write : size;
      const out = new Uint8Array(end - read);
      for (let i = 0; i < out.length; i++) out[i] = m.readUint8(a + 24 + read + i);
      this.chunks.push(out);
      read = end % size;
    }
    m.writeUint32(a + 16, read);
  }
  dropped() {
    return this.mcu.readUint32(this.address + 20);
  }
  save(path) {
    writeFileSync(path, Buffer.concat(this.chunks.map((c) => Buffer.from(c))));
  }
}

const emit = (o) => process.stdout.write(JSON.stringify(o) + '\n');
const toHex = (bytes) => Buffer.from(bytes).toString('hex');

function main() {
  const opt = parseArgs(process.argv);
  let board = null;
  let mcu = null;
  /** The board's buttons by name ('next', 'turn'), made at each boot. */
  const buttons = {};
  let core = null;
  const bootrom = readFileSync(opt.bootrom);
  if (bootrom.length !== 16384) throw new Error(`${opt.bootrom}: ${bootrom.length} bytes, a bootrom is 16384`);
  const bootWords = new Uint32Array(bootrom.buffer, bootrom.byteOffset, 4096);
  const uf2 = readFileSync(opt.uf2);
  let flashBytes = 0;
  const warnings = [];
  const logger = { debug() {}, info() {}, warn() {}, error: (c, m) => warnings.push(`${c}: ${m}`) };
  // rp2040js prints some complaints itself (a read of an SIO register it lacks): the first 20
  // go to stderr, the rest are counted, so that a firmware gone astray cannot fill the disk.
  let complaints = 0;
  const warn = console.warn;
  console.warn = (...a) => {
    if (++complaints <= 20) warn(...a);
    else if (complaints === 21) warn('run.mjs: further complaints of the emulator are counted, not printed');
  };
  // Cycles and nanoseconds of the boots before this one (a reset starts a new board at 0).
  let epoch = { cycles: 0, nanos: 0 };
  let resets = 0;
  let pendingReset = null; // why the chip resets after this step ('watchdog', 'reset pin')

  // The display model on I2C0 and SPI0 (or nothing: every I2C address NACKs), bytes delivered
  // when the bus would deliver them.
  const panel = PANELS[opt.panel];
  const display = opt.display ? panel.make(() => mcu.clock.nanos + epoch.nanos, () => mcu) : null;
  // --scan: every refresh the panel makes, as the row scan drove it (ssd1306.mjs `scan`). Each
  // distinct picture once ('image'), then a 'refresh' line wherever the picture changes from
  // the refresh before; --osc-error runs the panel's oscillator that many percent fast (or slow).
  let refreshes = 0;
  if (opt.scan || opt.oscError !== undefined) {
    if (!display?.scan) throw new Error(`--scan: the ${opt.panel} model has no refresh`);
    display.oscScale = 1 + (opt.oscError ?? 0) / 100;
    const images = new Map();
    let last = -1;
    display.scan((pixels, nanos) => {
      const hex = toHex(pixels);
      let id = images.get(hex);
      if (id === undefined) {
        id = images.size;
        images.set(hex, id);
        emit({ event: 'image', id, pixels: hex });
      }
      if (id !== last) emit({ event: 'refresh', index: refreshes, ms: nanos / 1e6, image: id });
      last = id;
      refreshes++;
    });
  }
  let busBytes = 0; // bytes the display heard (on I2C, those after an address byte)
  let i2cTransfers = 0; // address bytes sent (each START or repeated START)
  let naks = 0;
  let ledOn = false;
  const missLines = opt.missLines ? new Map() : null;
  let firstByteOfFrame = null;
  const snapshot = () => {
    const s = board.snapshot();
    return { ...s, cycles: s.cycles + epoch.cycles, nanos: s.nanos + epoch.nanos, busBytes, i2cTransfers };
  };
  const byte = () => {
    if (ledOn && firstByteOfFrame === null) firstByteOfFrame = snapshot();
    busBytes++;
  };
  const rtt = new RttReader(null, opt.rtt);
  const records = opt.records === undefined ? null : new RecordReader(null, opt.records);
  const frames = [];
  let frameStart = null;
  let ledToggles = 0;
  let ok = false;
  // After the last frame: run on until core 0 sleeps (it logs the frame first), or at most
  // DRAIN instructions, so the log holds the last frame's line.
  let draining = false;
  let drainLeft = 50_000_000;

  // A picture the panel shows: from `frameStart` to now. With --pass-bytes N, every N GDDRAM
  // bytes the display receives while the LED is lit is one (a progressive frame's passes, each
  // a whole panel of page bytes); else the LED going out ends one.
  const capture = () => {
    const end = snapshot();
    const why = display.notShowable();
    const first = firstByteOfFrame ?? end;
    const d = (k) => end[k] - frameStart[k];
    const frame = {
      event: 'frame',
      index: frames.length,
      cycles: d('cycles'),
      instructions: d('instructions'),
      busy: [0, 1].map((i) => end.busy[i] - frameStart.busy[i]),
      idle: [0, 1].map((i) => end.idle[i] - frameStart.idle[i]),
      coreInstructions: [0, 1].map((i) => end.coreInstructions[i] - frameStart.coreInstructions[i]),
      xipHits: end.xip.hits - frameStart.xip.hits,
      xipMisses: end.xip.misses - frameStart.xip.misses,
      xipStallCycles: end.xip.stallCycles - frameStart.xip.stallCycles,
      setupCycles: first.cycles - frameStart.cycles,
      setupInstructions: first.instructions - frameStart.instructions,
      busBytes: d('busBytes'),
      busCycles: d('busCycles'),
      i2cTransfers: d('i2cTransfers'),
      startMs: frameStart.nanos / 1e6,
      endMs: end.nanos / 1e6,
      error: why,
      pixels: why ? null : toHex(display.shown()),
    };
    frames.push(frame);
    emit(frame);
    frameStart = opt.passBytes ? end : null;
    firstByteOfFrame = null;
    const faults = [opt.panelOff, opt.resetAt, opt.hangAt, opt.panicAt, opt.sdaStuck, opt.nackAt];
    if (why && faults.every((f) => f.length === 0)) board.stop = `display: ${why}`;
    else if (frames.length >= opt.frames && !opt.passBytes) draining = true;
  };
  let passData = 0; // GDDRAM bytes since the LED went on (--pass-bytes)
  if (display && opt.passBytes) {
    const data = display.data.bind(display);
    display.data = (b) => {
      data(b);
      if (ledOn && frameStart && ++passData % opt.passBytes === 0) capture();
    };
  }

  const onLed = (state) => {
    const on = state === GPIOPinState.High;
    if (on === ledOn) return;
    ledOn = on;
    ledToggles++;
    if (!display) return;
    if (missLines && board.xip) board.xip.missLines = on && frames.length < opt.profileFrames ? missLines : null;
    if (on) {
      frameStart = snapshot();
      firstByteOfFrame = null;
      passData = 0;
      return;
    }
    if (!frameStart) return;
    if (!opt.passBytes) capture();
    else if (frames.length >= opt.frames) draining = true;
    frameStart = null;
  };

  // What happens at a moment of emulated time (from the first boot): the display's power cuts,
  // resets, core 1 stopping. Scheduled on each boot's clock as alarms (a sleeping board wakes
  // for them).
  const moments = [];
  for (const { startMs, lenMs } of display ? opt.panelOff : []) {
    moments.push({ nanos: startMs * 1e6, fn: () => display.powerOff() });
    moments.push({ nanos: (startMs + lenMs) * 1e6, fn: () => display.powerOn() });
  }
  for (const ms of opt.resetAt) moments.push({ nanos: ms * 1e6, fn: () => (pendingReset ??= 'reset pin') });
  for (const ms of opt.hangAt) moments.push({ nanos: ms * 1e6, fn: () => (board.held[1] = true) });
  for (const ms of opt.panicAt) moments.push({ nanos: ms * 1e6, fn: () => mcu.writeUint32(opt.panicRequest, 1) });
  const busEvent = (what) => emit({ event: 'bus', what, ms: (mcu.clock.nanos + epoch.nanos) / 1e6 });
  for (const { startMs, pulses } of display ? opt.sdaStuck : []) {
    moments.push({ nanos: startMs * 1e6, fn: () => (board.holdSda(0, pulses), busEvent('sda held')) });
  }
  for (const ms of display ? opt.nackAt : []) moments.push({ nanos: ms * 1e6, fn: () => board.nackNext(0) });
  // --look-at: what the panel shows at that moment, whether or not a frame is being sent.
  for (const ms of display ? opt.looks : []) {
    moments.push({ nanos: ms * 1e6, fn: () => {
      const why = display.notShowable();
      emit({ event: 'look', ms, error: why, pixels: why ? null : toHex(display.shown()) });
    } });
  }
  for (const { which, startMs, lenMs } of opt.presses) {
    moments.push({ nanos: startMs * 1e6, fn: () => (buttons[which].press(true), emit({ event: 'button', which, ms: startMs })) });
    moments.push({ nanos: (startMs + lenMs) * 1e6, fn: () => buttons[which].press(false) });
  }

  /** A board from power-on (or, with `kept`, after a reset: SRAM and the watchdog's scratch and reason). */
  const boot = (kept) => {
    board = new SiliconBoard({ cache: opt.cache, dualCore: opt.core1 });
    mcu = board.mcu;
    board.loadBootrom(bootWords);
    flashBytes = loadUf2(mcu, uf2);
    mcu.logger = logger;
    board.attachI2c(0, panel.spi ? null : display, {
      timed: opt.timedBus,
      listen: {
        connect: (ack) => {
          i2cTransfers++;
          if (!ack) naks++;
        },
        byte,
        nack: () => busEvent('nack'),
        released: () => busEvent('sda released'),
      },
      pins: I2C_PINS,
    });
    board.attachSpi(0, display, { ...(panel.spi ?? SPI_DISPLAY), timed: opt.timedBus, listen: { byte } });
    board.gpio(LED_PIN).addListener(onLed);
    // The buttons, released at power-on (their pins read what the pads' pulls give them).
    const wired = panel.buttons ?? BUTTONS;
    for (const which of ['next', 'turn']) buttons[which] = new PushButton(mcu.gpio[wired[which]], wired.activeHigh);
    display?.drive?.();
    const watchdog = mcu.peripherals[0x40058];
    // The watchdog resets the chip: its timer stops here (rp2040js would re-arm it at 0 and
    // fire again at once), and the board boots again after this step.
    watchdog.onWatchdogTrigger = () => {
      watchdog.alarm.enable = false;
      watchdog.timer.enable = false;
      pendingReset ??= 'watchdog';
    };
    if (kept) {
      mcu.sram.set(kept.sram);
      watchdog.scratchData.set(kept.scratch);
      watchdog.reason = kept.reason;
      if (kept.sdaStuck) board.holdSda(0, kept.sdaStuck);
    }
    rtt.mcu = mcu;
    if (records) records.mcu = mcu;
    for (const m of moments) {
      if (m.nanos >= epoch.nanos) mcu.clock.createAlarm(m.fn).schedule(m.nanos - epoch.nanos);
    }
    // Core 0 at boot2 with the stack pointer the bootrom would leave; core 1 in the bootrom.
    board.start(FLASH, mcu.readUint32(0));
    core = board.cores[0];
  };

  /** The chip resets (`why`): what the logs hold so far is read, and the board boots again. */
  const reboot = (why) => {
    rtt.poll();
    records?.poll();
    const s = board.snapshot();
    epoch = { cycles: epoch.cycles + s.cycles, nanos: epoch.nanos + s.nanos };
    const watchdog = mcu.peripherals[0x40058];
    const kept = {
      sram: mcu.sram.slice(),
      scratch: watchdog.scratchData.slice(),
      reason: why === 'watchdog' ? watchdog.reason : 0,
      sdaStuck: board.i2cBuses[0]?.stuck ?? 0, // the panel does not reset with the chip
    };
    emit({ event: 'reset', reason: why, ms: epoch.nanos / 1e6, frames: frames.length });
    resets++;
    // A frame under way is lost; the display sees its transfer cut off (no STOP).
    ledOn = false;
    frameStart = null;
    firstByteOfFrame = null;
    display?.endTransfer?.();
    boot(kept);
  };

  boot(null);

  const profile = opt.profile ? new Map() : null;
  const untilNanos = opt.untilMs === null ? Infinity : opt.untilMs * 1e6;
  let steps = 0;
  let nextPoll = 0;
  while (board.stop === null) {
    if (draining && (core.waiting || --drainLeft <= 0)) {
      board.stop = `${frames.length} frames shown`;
      ok = true;
      break;
    }
    if (profile && ledOn && frames.length < opt.profileFrames && steps % PROFILE_EVERY === 0 && board.runnable(0)) {
      const pc = core.PC >>> 0;
      profile.set(pc, (profile.get(pc) || 0) + 1);
    }
    if (board.step() < 0) {
      if (!board.wake()) {
        board.stop = 'both cores sleep (wfi/wfe) with no timer alarm to wake them';
        break;
      }
      if (mcu.clock.nanos + epoch.nanos >= untilNanos) nextPoll = 0; // time is up while asleep: check now
    }
    if (pendingReset) {
      const why = pendingReset;
      pendingReset = null;
      reboot(why);
      continue;
    }
    steps++;
    if (steps >= nextPoll) {
      nextPoll = steps + 200000;
      rtt.poll();
      records?.poll();
      board.stop ??= board.fault();
      if (board.time + epoch.cycles > opt.maxCycles) board.stop ??= `no result within ${opt.maxCycles} cycles`;
      else {
        display?.tick?.();
        if (display?.error) board.stop ??= `display: ${display.error}`;
      }
      if (mcu.clock.nanos + epoch.nanos >= untilNanos && board.stop === null) {
        board.stop = `${opt.untilMs} ms of emulated time`;
        ok = true;
      }
    }
  }
  rtt.poll();
  rtt.save(opt.log);
  records?.poll();
  if (records) records.save(opt.recordsLog);
  if (profile) writeFileSync(opt.profile, JSON.stringify([...profile.entries()]));
  if (missLines) writeFileSync(opt.missLines, JSON.stringify([...missLines.entries()]));
  const total = board.snapshot();
  for (const r of display?.refreshes ?? []) emit({ event: 'epaper', startMs: r.start / 1e6, endMs: r.end / 1e6, dataMs: r.dataAt / 1e6, window: r.window });
  emit({
    event: 'end',
    ok,
    reason: board.stop,
    frames: frames.length,
    cycles: total.cycles,
    instructions: total.instructions,
    coreInstructions: total.coreInstructions,
    busy: total.busy,
    idle: total.idle,
    xip: total.xip,
    xipMissCycles: board.xip ? board.xip.missCycles() : 0,
    sclPeriodCycles: board.sclPeriod(0),
    spiByteCycles: board.spiFrameCycles(0),
    models: { core1: opt.core1, cache: opt.cache, timedBus: opt.timedBus },
    emulatedMs: (mcu.clock.nanos + epoch.nanos) / 1e6,
    resets,
    idleMs: (Math.min(...total.idle.slice(0, opt.core1 ? 2 : 1)) * 1e3) / mcu.clkSys,
    clkSysHz: mcu.clkSys,
    flashBytes,
    logBytes: rtt.bytes,
    recordsDropped: records ? records.dropped() : 0,
    busBytes,
    naks,
    ledToggles,
    displayInitialised: display ? display.everOn : false,
    displayCommands: display ? display.commands : 0,
    refreshes,
    warnings: complaints > 20 ? [...warnings.slice(0, 20), `the emulator complained ${complaints} times`] : warnings.slice(0, 20),
  });
  process.exitCode = ok ? 0 : 1;
}

try {
  main();
} catch (e) {
  emit({ event: 'end', ok: false, reason: String(e.message ?? e) });
  process.exitCode = 1;
}
