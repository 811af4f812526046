// A UC8151 (IL0373) e-paper controller with the Badger 2040's 296x128 glass, on 4-wire SPI, as
// its datasheet describes it. A byte with D/C low is a command, the bytes after it with D/C high
// its parameters; chip select low frames the bytes it hears and may rise between them (drivers
// that select each byte do so), and a command takes effect once its parameters are in. BUSY (an
// output of the controller, low while it works) is low from power-on (PON) until the booster is
// up and from a display refresh (DRF) until its waveform has run; a command sent while it is
// low fails the run. The RAM holds one bit per pixel, written by Data Start Transmission 2
// (DTM2) in gate order: for each of the 296 gates (the glass's columns, left to right with
// PSR's SHIFT_RIGHT and SCAN_DOWN) 16 bytes of sources (its rows, top to bottom, each byte's top
// bit first), a 1 white (CDI's DDX 00, as the Badger's driver sets it). A partial window (PTIN,
// PTL) limits DTM2 to a rectangle of whole source bytes, and a refresh in partial mode drives
// that window alone: the glass outside it keeps what it showed (unknown, if nothing was ever
// refreshed whole). A refresh shows the RAM as it was when DRF came; it lasts the register LUT's frames (the VCOM LUT's seven groups: the four phase
// times of each, times its repeat count) at the PLL's frame rate, or 4.5 s with the LUT in OTP
// (what Pimoroni measured of the Badger's panel: the model knows no OTP waveform).
//
// `shown()` is the last refresh's picture as a packed 1-bit raster (rows MSB first, 1 white).
// Anything the model does not understand fails the run: an unknown command, a command cut
// short, a resolution other than 128x296, a refresh with the booster off, data past the RAM.

/** Sources (the glass's rows) and gates (its columns). */
const SOURCES = 128;
const GATES = 296;
const STRIDE = SOURCES / 8;
/** The OTP LUT's refresh, in nanoseconds. */
const OTP_REFRESH_NANOS = 4.5e9;
/** The booster's start after PON (BTST's soft start: 10 ms a phase, three phases). */
const PON_NANOS = 30e6;
/** PLL settings and their frame rates in Hz (the datasheet's table, as the Badger's driver names them). */
const PLL_HZ = { 0x3f: 29, 0x3e: 33, 0x3d: 40, 0x3c: 50, 0x3b: 67, 0x3a: 100, 0x39: 200, 0x29: 150 };

/** Parameter bytes each command takes (null: any number, a data stream). */
const COMMANDS = {
  0x00: [1, 2], // PSR (the second byte, resolution override, optional)
  0x01: [5, 5], // PWR
  0x02: [0, 0], // POF
  0x03: [1, 1], // PFS
  0x04: [0, 0], // PON
  0x06: [3, 3], // BTST
  0x07: [1, 1], // DSLP
  0x10: null, // DTM1
  0x11: [0, 0], // DSP
  0x12: [0, 0], // DRF
  0x13: null, // DTM2
  0x20: [44, 44], // LUT VCOM
  0x21: [42, 42], // LUT WW
  0x22: [42, 42], // LUT BW
  0x23: [42, 42], // LUT WB
  0x24: [42, 42], // LUT BB
  0x30: [1, 1], // PLL
  0x41: [1, 1], // TSE
  0x50: [1, 1], // CDI
  0x60: [1, 1], // TCON
  0x61: [3, 3], // TRES
  0x90: [7, 7], // PTL
  0x91: [0, 0], // PTIN
  0x92: [0, 0], // PTOU
};

export class Uc8151 {
  /**
   * The controller; `now()` gives emulated nanoseconds, `after(nanos, fn)` runs `fn` that
   * much later, `busy(level)` drives the BUSY pin (true: high, idle).
   */
  constructor(now, after, busy) {
    this.now = now;
    this.after = after;
    this.busyPin = busy;
    this.width = GATES;
    this.height = SOURCES;
    this.error = null;
    this.absent = false;
    this.refreshes = []; // each refresh: its start and end, and when its DTM2 came (ns)
    this.dataBytes = 0;
    this.powerOn();
  }

  fail(message) {
    if (!this.error) this.error = message;
  }

  /** The state after power-on or a reset: registers at their defaults, BUSY high. */
  resetState() {
    this.ram = new Uint8Array(GATES * STRIDE);
    this.picture = null;
    this.outsideUnknown = false;
    this.psr = null;
    this.vcomLut = null;
    this.pll = 0x3c;
    this.cdi = 0x97; // the datasheet's default (DDX 01)
    this.powered = false;
    this.partial = false;
    this.window = null;
    this.busyUntil = 0;
    this.command = null;
    this.params = [];
    this.busyPin(true);
  }

  /** Power back (or first): RAM and picture unknown until written and refreshed. */
  powerOn() {
    this.absent = false;
    this.resetState();
  }

  /** Power lost: the controller hears nothing; the glass keeps its picture (e-paper). */
  powerOff() {
    this.absent = true;
  }

  /** RST low: the registers back to their defaults. */
  reset() {
    if (!this.absent) this.resetState();
  }

  /**
   * BUSY driven again on a chip that just booted (a reset of the RP2040 does not reset the
   * panel): its level now and, while the controller works, its rise when the work ends.
   */
  drive() {
    const left = this.busyUntil - this.now();
    if (left <= 0) return this.busyPin(true);
    this.work(left);
  }

  /** Low BUSY for `nanos` from now. */
  work(nanos) {
    const until = this.now() + nanos;
    this.busyUntil = until;
    this.busyPin(false);
    this.after(nanos, () => {
      if (this.busyUntil === until) this.busyPin(true);
    });
  }

  /** A command with parameters still to come when the next command came fails the run. */
  cutShort() {
    const c = this.command;
    const want = c === null ? null : COMMANDS[c];
    if (want && this.params.length < want[0]) {
      this.fail(`command 0x${c.toString(16)} cut short: ${this.params.length} of its ${want[0]} parameter bytes`);
    }
  }

  /** Command `c` takes effect with its parameters `p`. */
  apply(c, p) {
    switch (c) {
      case 0x00:
        this.psr = p[0];
        if ((p[0] & 0xc0) !== 0x80) this.fail(`PSR 0x${p[0].toString(16)}: a resolution other than 128x296`);
        if ((p[0] & 0x10) === 0) this.fail('PSR: black, white and red format on black and white glass');
        if ((p[0] & 0x0c) !== 0x04) this.fail('PSR: a scan other than SHIFT_RIGHT and SCAN_DOWN (the picture would be mirrored)');
        break;
      case 0x20:
        this.vcomLut = p.slice();
        break;
      case 0x30:
        if (PLL_HZ[p[0]] === undefined) this.fail(`PLL 0x${p[0].toString(16)}: not a frame rate the datasheet lists`);
        else this.pll = p[0];
        break;
      case 0x50:
        this.cdi = p[0];
        break;
      case 0x61:
        if (p[0] !== SOURCES || ((p[1] << 8) | p[2]) !== GATES) this.fail(`TRES ${p[0]}x${(p[1] << 8) | p[2]}: the glass is 128x296`);
        break;
      case 0x02:
        this.powered = false;
        break;
      case 0x04:
        this.powered = true;
        this.work(PON_NANOS);
        break;
      case 0x12:
        this.refresh();
        break;
      case 0x90: {
        const [hs, he, vs1, vs0, ve1, ve0] = p;
        const window = { hs, he, vs: (vs1 << 8) | vs0, ve: (ve1 << 8) | ve0 };
        if (hs % 8 !== 0 || he % 8 !== 7 || he < hs || he >= SOURCES || window.ve < window.vs || window.ve >= GATES) {
          this.fail(`PTL: window sources ${hs}..${he}, gates ${window.vs}..${window.ve} (whole bytes within 128x296)`);
        }
        this.window = window;
        break;
      }
      case 0x91:
        this.partial = true;
        break;
      case 0x92:
        this.partial = false;
        break;
      default:
    }
  }

  /** DRF: the RAM's picture from now, BUSY low while the waveform runs. */
  refresh() {
    if (this.psr === null) return this.fail('DRF before PSR: the panel is not set up');
    if (!this.powered) return this.fail('DRF with the power off (no PON)');
    if ((this.cdi & 0x30) !== 0) return this.fail(`DRF with CDI 0x${this.cdi.toString(16)}: data polarity (DDX) other than 00, the one this model takes`);
    let nanos = OTP_REFRESH_NANOS;
    if (this.psr & 0x20) {
      if (this.vcomLut === null) return this.fail('DRF with the LUT in registers but no VCOM LUT sent');
      let frames = 0;
      for (let g = 0; g < 7; g++) {
        const [, t0, t1, t2, t3, repeat] = this.vcomLut.slice(g * 6, g * 6 + 6);
        frames += (t0 + t1 + t2 + t3) * repeat;
      }
      nanos = (frames / PLL_HZ[this.pll]) * 1e9;
    }
    const start = this.now();
    const window = this.partial ? this.window : null;
    if (this.partial && !window) return this.fail('DRF in partial mode (PTIN) with no window (PTL)');
    this.refreshes.push({ start, end: start + nanos, dataAt: this.dataAt ?? start, window });
    if (window) {
      // The window's gates and source bytes from the RAM; outside it, the glass as it was.
      if (this.picture === null) {
        this.picture = new Uint8Array(this.ram.length);
        this.outsideUnknown = true;
      }
      for (let gate = window.vs; gate <= window.ve; gate++) {
        const at = gate * STRIDE;
        this.picture.set(this.ram.subarray(at + window.hs / 8, at + (window.he + 1) / 8), at + window.hs / 8);
      }
    } else {
      this.picture = this.ram.slice();
      this.outsideUnknown = false;
    }
    this.work(nanos);
  }

  /** A byte on the bus, `dc` high for a parameter or data. */
  spiByte(b, dc) {
    if (this.absent) return;
    if (!dc) {
      this.cutShort();
      this.command = null;
      if (this.now() < this.busyUntil) return this.fail(`command 0x${b.toString(16)} while BUSY is low (the controller works ${((this.busyUntil - this.now()) / 1e6).toFixed(1)} ms more)`);
      if (!(b in COMMANDS)) return this.fail(`command 0x${b.toString(16)}: not one this model knows`);
      this.command = b;
      this.params = [];
      if (b === 0x13 || b === 0x10) this.cursor = 0;
      if (b === 0x13) this.dataAt = this.now();
      if (COMMANDS[b]?.[1] === 0) this.apply(b, []);
      return;
    }
    const c = this.command;
    if (c === null) return this.fail(`data byte 0x${b.toString(16)} with no command`);
    if (c === 0x13 || c === 0x10) return this.data(b);
    const [least, most] = COMMANDS[c];
    if (this.params.length === most) return this.fail(`command 0x${c.toString(16)}: more than its ${most} parameter bytes`);
    this.params.push(b);
    if (this.params.length >= least) this.apply(c, this.params);
  }

  /** One byte of DTM2 (DTM1, the old picture, is taken and not shown). */
  data(b) {
    this.dataBytes++;
    const i = this.cursor++;
    let at = i;
    if (this.partial && this.window) {
      const { hs, he, vs, ve } = this.window;
      const per = (he - hs + 1) / 8;
      const gate = vs + Math.floor(i / per);
      if (gate > ve) return this.fail(`DTM byte ${i} past the partial window's ${(ve - vs + 1) * per}`);
      at = gate * STRIDE + hs / 8 + (i % per);
    } else if (i >= this.ram.length) return this.fail(`DTM byte ${i} past the RAM's ${this.ram.length}`);
    if (this.command === 0x13) this.ram[at] = b;
  }

  /** Why the glass shows no picture, or null. */
  notShowable() {
    if (this.error) return this.error;
    if (this.picture === null) return 'no refresh since power-on: the glass shows whatever it last had';
    if (this.outsideUnknown) return 'only partial refreshes since power-on: outside their windows the glass shows whatever it last had';
    return null;
  }

  /** The last refresh's picture: rows MSB first, 1 = white (gate x, source y). */
  shown() {
    const stride = GATES / 8;
    const out = new Uint8Array(stride * SOURCES);
    for (let x = 0; x < GATES; x++) {
      for (let y = 0; y < SOURCES; y++) {
        if ((this.picture[x * STRIDE + (y >> 3)] >> (7 - (y & 7))) & 1) out[y * stride + (x >> 3)] |= 0x80 >> (x & 7);
      }
    }
    return out;
  }
}
