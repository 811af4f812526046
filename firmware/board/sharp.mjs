// A Sharp memory LCD (LS027B7DH01, 400x240; LS013B7DH03, 128x128) on 3-wire SPI, as its
// datasheet describes it: SCS active high frames a command; the LCD takes every byte LSB first
// (the model receives the bytes as an MSB-first controller sends them and reverses them); a
// command is the mode byte (M0 write lines, M1 VCOM, M2 clear all; the rest dummy bits), then
// for a write each line's address (1-based), its pixels (leftmost first, 1 white) and 8 dummy
// bits, and 8 more dummy bits after the last line; a clear or display-mode command is the mode
// byte and 8 dummy bits. DISP high shows the memory. VCOM must be inverted at least once a
// second (by M1, this model's mode: EXTMODE low) or the liquid crystal degrades: a gap longer
// than that fails the run. Its memory holds noise after power-on until cleared or written.
//
// `shown()` is the memory as a packed 1-bit raster (rows MSB first, 1 = white = a lit pixel of
// host-sim's BitFrame). Anything the model does not understand fails the run: a line address
// out of range, a command cut off by SCS, bytes after a command's end.

/** The longest VCOM may stay as it is (1 s). */
const VCOM_NANOS = 1e9;

const reverse = (b) => {
  let r = 0;
  for (let i = 0; i < 8; i++) r |= ((b >> i) & 1) << (7 - i);
  return r;
};

export class SharpMemoryLcd {
  /** A `width` x `height` LCD; `now()` gives emulated nanoseconds (for VCOM's inversions). */
  constructor(width, height, now) {
    this.width = width;
    this.height = height;
    this.stride = width / 8;
    this.now = now;
    this.memory = new Uint8Array(this.stride * height);
    this.written = new Uint8Array(height); // lines written (or cleared) since power-on
    this.error = null;
    this.absent = false;
    this.disp = false;
    this.everOn = false; // DISP has been high
    this.vcom = null; // [level, when it last changed]
    this.commands = 0;
    this.dataBytes = 0;
    this.selected = false;
    this.state = 'idle';
  }

  fail(message) {
    if (!this.error) this.error = message;
  }

  /** SCS: high starts a command, low ends it (a command cut off is an error). */
  select(on) {
    if (this.absent || on === this.selected) return;
    this.selected = on;
    if (on) {
      this.state = 'mode';
      this.lines = 0;
    } else {
      if (this.state !== 'mode' && this.state !== 'end') this.fail(`a command cut off by SCS low (${this.state === 'address' ? 'no dummy byte after the last line' : `in its ${this.state}`})`);
      this.state = 'idle';
    }
  }

  /** DISP: high shows the memory. */
  display(on) {
    this.disp = on;
    if (on && !this.everOn) {
      this.everOn = true;
      this.vcom ??= [null, this.now()];
    }
  }

  /** VCOM's level as a command gives it: how long it had been left as it was is checked. */
  setVcom(level) {
    const now = this.now();
    this.tick();
    if (this.vcom === null || this.vcom[0] !== level) this.vcom = [level, now];
  }

  /** Fails the run when VCOM has not been inverted for longer than a second while shown. */
  tick() {
    if (!this.everOn || this.vcom === null) return;
    const gap = this.now() - this.vcom[1];
    if (gap > VCOM_NANOS) this.fail(`VCOM not inverted for ${(gap / 1e6).toFixed(0)} ms (at most 1000 ms): the picture degrades`);
  }

  /** A byte on the bus (`dc` has no meaning here). */
  spiByte(wire) {
    if (this.absent || !this.selected) return;
    const b = reverse(wire);
    switch (this.state) {
      case 'mode':
        this.commands++;
        this.setVcom((b & 2) !== 0);
        if (b & 4) {
          this.memory.fill(0xff);
          this.written.fill(1);
          this.state = 'dummy-end';
        } else this.state = b & 1 ? 'address' : 'dummy-end';
        break;
      case 'address':
        if (b === 0 && this.lines > 0) this.state = 'end';
        else if (b < 1 || b > this.height) this.fail(`line address ${b} (1..${this.height})`);
        else {
          this.line = b - 1;
          this.col = 0;
          this.state = 'data';
        }
        break;
      case 'data':
        this.dataBytes++;
        this.memory[this.line * this.stride + this.col] = wire; // leftmost pixel first: MSB first as sent
        if (++this.col === this.stride) {
          this.written[this.line] = 1;
          this.state = 'dummy';
        }
        break;
      case 'dummy':
        this.lines++;
        this.state = 'address';
        break;
      case 'dummy-end':
        this.state = 'end';
        break;
      default:
        this.fail(`byte ${wire} after the command's end`);
    }
  }

  /** Power lost: the LCD answers nothing (SPI cannot tell) and its memory is lost. */
  powerOff() {
    this.absent = true;
    this.selected = false;
    this.state = 'idle';
  }

  /** Power back: the memory holds noise until it is cleared or written. */
  powerOn() {
    this.absent = false;
    for (let i = 0; i < this.memory.length; i++) this.memory[i] = (i * 151 + 17) & 0xff;
    this.written.fill(0);
  }

  /** Nothing to reset: the LCD has no reset line. */
  reset() {}

  /** Why the LCD shows no plain picture, or null. */
  notShowable() {
    this.tick();
    if (this.error) return this.error;
    if (!this.everOn) return 'DISP was never high: the LCD shows nothing';
    if (!this.disp) return 'DISP is low: the LCD shows nothing';
    const noise = this.written.indexOf(0);
    if (noise >= 0) return `line ${noise + 1} neither written nor cleared since power-on (noise)`;
    return null;
  }

  /** The memory: rows MSB first, 1 = white. */
  shown() {
    return this.memory.slice();
  }
}
