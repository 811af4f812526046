// An SSD1306 128x64 OLED controller on I2C or 4-wire SPI, as its datasheet (rev 1.1) describes
// it: on I2C the control byte after the address (Co and D/C# bits), on SPI the D/C# pin and
// RES#; the fundamental, addressing, hardware configuration, timing and scrolling commands with
// their arguments, and the 1 KiB GDDRAM written through the page/horizontal/vertical addressing
// modes. `shown()` is what the module's glass displays (128x64, or the 128x32 and 72x40 glass of
// `GLASSES`), as a packed 1-bit raster (rows MSB first, lit pixel = 1: the raster of host-sim's
// BitFrame), after segment remap, COM scan direction, start line, offset and inversion.
//
// Anything the model does not understand is an error, never silently ignored: an unknown
// command byte, a command cut off by a STOP, a data byte before any display set-up, a read.
//
// The refresh (`scan`): the controller drives its rows one at a time, each for a row period of
// D x (phase 1 + phase 2 + 50) display clocks (datasheet section 8.3: the divide ratio D and
// the oscillator's setting from 0xD5, the phases from 0xD9), the row counter running from 0 to
// the multiplex ratio and back to 0 (past it, on to 63 first), and each row shows the GDDRAM row
// it maps to as the counter reaches it. The scan starts at row 0 when the display is switched
// on and stops when it is switched off. The oscillator runs at its typical frequency (370 kHz at
// the reset setting 0x8, 530 kHz at 0xF, even steps between; `oscScale` for a panel whose clock
// is off). With `scan(onRefresh)` the model hands every finished refresh (every row of the glass
// as it was when driven) to `onRefresh`: what the eye integrates.

export const WIDTH = 128; // columns of RAM
export const HEIGHT = 64; // rows of RAM
const PAGES = HEIGHT / 8;

/**
 * The glass a module puts on the controller: its size, the first RAM column it shows (with
 * segment remap 0xA1), the COM pins configuration its wiring needs (0xDA), and whether its
 * controller has the internal current reference command (0xAD, on the 72x40 modules).
 */
export const GLASSES = {
  '128x64': { width: 128, height: 64, column: 0, comPins: 0x12, iref: false },
  '128x32': { width: 128, height: 32, column: 0, comPins: 0x02, iref: false },
  '72x40': { width: 72, height: 40, column: 28, comPins: 0x12, iref: true },
};

/** Arguments each command takes (commands not listed take none; unlisted bytes are unknown). */
function argumentCount(cmd) {
  if (cmd <= 0x1f) return 0; // lower/higher column start (page addressing)
  if (cmd >= 0x40 && cmd <= 0x7f) return 0; // display start line
  if (cmd >= 0xb0 && cmd <= 0xb7) return 0; // page start (page addressing)
  switch (cmd) {
    case 0x20: // memory addressing mode
    case 0x81: // contrast
    case 0x8d: // charge pump
    case 0xa8: // multiplex ratio
    case 0xd3: // display offset
    case 0xd5: // clock divide / oscillator
    case 0xd9: // pre-charge period
    case 0xda: // COM pins configuration
    case 0xdb: // VCOMH deselect level
      return 1;
    case 0x21: // column address window
    case 0x22: // page address window
    case 0xa3: // vertical scroll area
      return 2;
    case 0x29: // vertical and right horizontal scroll
    case 0x2a: // vertical and left horizontal scroll
      return 5;
    case 0x26: // right horizontal scroll
    case 0x27: // left horizontal scroll
      return 6;
    case 0x2e: // deactivate scroll
    case 0x2f: // activate scroll
    case 0xa0: case 0xa1: // segment remap
    case 0xa4: case 0xa5: // entire display on
    case 0xa6: case 0xa7: // normal / inverse
    case 0xae: case 0xaf: // display off / on
    case 0xc0: case 0xc8: // COM scan direction
    case 0xe3: // no operation
      return 0;
    default:
      return -1;
  }
}

export const hex = (b) => '0x' + b.toString(16).padStart(2, '0');

export class Ssd1306 {
  constructor(address = 0x3c, glass = GLASSES['128x64'], now = null) {
    this.now = now; // emulated nanoseconds, for the refresh (`scan`)
    this.oscScale = 1; // the oscillator's frequency against its typical one
    this.onRefresh = null;
    this.address = address;
    this.glass = glass;
    this.gddram = new Uint8Array(this.ramColumns * PAGES); // [page * columns + column], bit k = COM row 8*page + k
    this.commands = 0; // command bytes received (arguments included)
    this.dataBytes = 0; // GDDRAM bytes received
    this.bytes = 0; // every byte addressed to the display, control bytes included
    this.transfers = 0;
    this.everOn = false; // the display has been switched on with its charge pump
    this.error = null; // the first protocol error
    this.absent = false; // without power: the panel answers nothing (powerOff, powerOn)
    this.reset();
  }

  /** Columns of display RAM. */
  get ramColumns() {
    return WIDTH;
  }

  /** Argument bytes command `cmd` takes; -1 for a byte that is no command of this controller. */
  argumentCount(cmd) {
    if (cmd === 0xad) return this.glass.iref ? 1 : -1;
    return argumentCount(cmd);
  }

  /** Power lost (a loose wire): the panel answers nothing until `powerOn`. */
  powerOff() {
    this.absent = true;
    this.endTransfer();
  }

  /**
   * Power back: a freshly powered panel, its registers at their reset values, its GDDRAM
   * cleared and the display off until it is set up again (charge pump, 0xAF).
   */
  powerOn() {
    this.absent = false;
    this.gddram.fill(0);
    this.everOn = false;
    this.reset();
  }

  /** RES# low: every register to its reset value (GDDRAM keeps what it holds), as after power-on. */
  reset() {
    this.displayOn = false;
    this.chargePump = false;
    this.mode = 2; // page addressing after reset
    this.col = 0;
    this.page = 0;
    this.colStart = 0;
    this.colEnd = WIDTH - 1;
    this.pageStart = 0;
    this.pageEnd = PAGES - 1;
    this.segmentRemap = false;
    this.comReverse = false;
    this.startLine = 0;
    this.offset = 0;
    this.multiplex = 63;
    this.inverse = false;
    this.entireOn = false;
    this.scrolling = false;
    this.comPins = 0x12;
    this.clock = 0x80; // 0xD5: oscillator setting, divide ratio - 1
    this.precharge = 0x22; // 0xD9: phase 2, phase 1
    this.scanAt = null; // when the next row is driven (null: not scanning)
    this.endTransfer();
    this.cmd = null;
  }

  endTransfer() {
    this.selected = false;
    this.expectControl = true;
    this.continuation = false; // Co = 0: the rest of the transfer is of one kind
    this.isData = false;
    this.cmd = null;
    this.args = [];
  }

  fail(message) {
    if (!this.error) this.error = message;
  }

  /** An I2C START (or repeated start). */
  start() {
    this.endTransfer();
  }

  /** The address phase: whether the display ACKs. */
  connect(address, read) {
    if (address !== this.address || this.absent) return false;
    if (read) {
      this.fail('a read from the display (the SSD1306 on I2C is write-only)');
      return false;
    }
    this.selected = true;
    this.transfers++;
    return true;
  }

  /** A byte written to the addressed device: whether it is ACKed. */
  write(byte) {
    if (!this.selected) return false;
    this.advance();
    this.bytes++;
    if (this.expectControl) {
      if ((byte & 0x3f) !== 0) this.fail(`control byte ${hex(byte)}: its low six bits must be 0`);
      this.continuation = (byte & 0x80) !== 0;
      this.isData = (byte & 0x40) !== 0;
      this.expectControl = false;
      return true;
    }
    if (this.isData) this.data(byte);
    else this.command(byte);
    if (this.continuation && this.cmd === null) this.expectControl = true;
    return true;
  }

  /**
   * A byte on the 4-wire SPI interface (chip selected): a GDDRAM byte when D/C# is high, a
   * command or command argument when it is low (no control bytes on SPI).
   */
  spiByte(byte, isData) {
    if (this.absent) return;
    this.advance();
    this.bytes++;
    if (isData) {
      if (this.cmd !== null) this.fail(`data byte while command ${hex(this.cmd)} waits for ${this.argumentCount(this.cmd) - this.args.length} more argument bytes`);
      this.data(byte);
    } else this.command(byte);
  }

  /**
   * A transfer cut off by a fault on the bus (a byte it did not acknowledge, SDA held low):
   * the command it was collecting arguments for is dropped, with no error.
   */
  interrupted() {
    this.cmd = null;
    this.args = [];
  }

  /** An I2C STOP. */
  stop() {
    if (this.selected && this.cmd !== null) {
      this.fail(`command ${hex(this.cmd)} cut off by STOP after ${this.args.length} of ${this.argumentCount(this.cmd)} argument bytes`);
    }
    this.endTransfer();
  }

  command(byte) {
    this.commands++;
    if (this.cmd !== null) {
      this.args.push(byte);
    } else {
      const n = this.argumentCount(byte);
      if (n < 0) {
        this.fail(`unknown command byte ${hex(byte)}`);
        return;
      }
      this.cmd = byte;
      this.args = [];
    }
    if (this.args.length === this.argumentCount(this.cmd)) {
      this.execute(this.cmd, this.args);
      this.cmd = null;
    }
  }

  execute(c, a) {
    if (c <= 0x0f) this.col = (this.col & 0xf0) | c;
    else if (c <= 0x1f) this.col = (this.col & 0x0f) | ((c & 0x0f) << 4);
    else if (c >= 0x40 && c <= 0x7f) this.startLine = c - 0x40;
    else if (c >= 0xb0 && c <= 0xb7) this.page = c - 0xb0;
    else
      switch (c) {
        case 0x20:
          if (a[0] > 2) this.fail(`addressing mode ${hex(a[0])} (0 horizontal, 1 vertical, 2 page)`);
          this.mode = a[0] & 3;
          break;
        case 0x21:
          if (a[0] > 127 || a[1] > 127 || a[0] > a[1]) this.fail(`column window ${a[0]}..${a[1]}`);
          this.colStart = this.col = a[0] & 0x7f;
          this.colEnd = a[1] & 0x7f;
          break;
        case 0x22:
          if (a[0] > 7 || a[1] > 7 || a[0] > a[1]) this.fail(`page window ${a[0]}..${a[1]}`);
          this.pageStart = this.page = a[0] & 7;
          this.pageEnd = a[1] & 7;
          break;
        case 0x81: break; // contrast: brightness only
        case 0x8d:
          if ((a[0] & ~0x04) !== 0x10) this.fail(`charge pump setting ${hex(a[0])} (0x10 off, 0x14 on)`);
          this.chargePump = (a[0] & 0x04) !== 0;
          break;
        case 0xa0: case 0xa1: this.segmentRemap = c === 0xa1; break;
        case 0xa4: case 0xa5: this.entireOn = c === 0xa5; break;
        case 0xa6: case 0xa7: this.inverse = c === 0xa7; break;
        case 0xa8:
          if (a[0] < 15 || a[0] > 63) this.fail(`multiplex ratio ${a[0] + 1} (16..64)`);
          this.multiplex = a[0] & 0x3f;
          break;
        case 0xae:
          this.displayOn = false;
          this.scanAt = null;
          break;
        case 0xaf:
          if (!this.displayOn) this.startScan();
          this.displayOn = true;
          if (this.chargePump) this.everOn = true;
          break;
        case 0xd5: this.clock = a[0]; break;
        case 0xd9:
          if ((a[0] & 0x0f) === 0 || (a[0] & 0xf0) === 0) this.fail(`pre-charge periods ${hex(a[0])}: phase 1 and phase 2 are 1..15 clocks`);
          this.precharge = a[0];
          break;
        case 0xc0: case 0xc8: this.comReverse = c === 0xc8; break;
        case 0xad:
          if ((a[0] & ~0x30) !== 0) this.fail(`IREF setting ${hex(a[0])} (0x00 external, 0x30 internal)`);
          break;
        case 0xd3: this.offset = a[0] & 0x3f; break;
        case 0xda: this.comPins = a[0]; break;
        case 0x2e: this.scrolling = false; break;
        case 0x2f: this.scrolling = true; break;
        default: break; // timing, VCOMH, scroll set-up and NOP change nothing shown
      }
  }

  data(byte) {
    this.dataBytes++;
    this.gddram[this.page * WIDTH + this.col] = byte;
    if (this.mode === 0) {
      // horizontal: along the column window, then to the next page of the page window
      if (this.col >= this.colEnd) {
        this.col = this.colStart;
        this.page = this.page >= this.pageEnd ? this.pageStart : this.page + 1;
      } else this.col++;
    } else if (this.mode === 1) {
      // vertical: down the page window, then to the next column
      if (this.page >= this.pageEnd) {
        this.page = this.pageStart;
        this.col = this.col >= this.colEnd ? this.colStart : this.col + 1;
      } else this.page++;
    } else {
      // page: along the page only, back to column 0 of the same page after column 127
      this.col = this.col >= WIDTH - 1 ? 0 : this.col + 1;
    }
  }

  /** The oscillator's frequency in Hz (typical, times `oscScale`). */
  oscillatorHz() {
    return (370_000 + ((this.clock >> 4) - 8) * (160_000 / 7)) * this.oscScale;
  }

  /** A row period in nanoseconds, from the display clock and pre-charge registers. */
  rowNanos() {
    const clocks = ((this.clock & 0x0f) + 1) * ((this.precharge & 0x0f) + (this.precharge >> 4) + 50);
    return (clocks * 1e9) / this.oscillatorHz();
  }

  /** Hands every finished refresh to `onRefresh(pixels, startNanos)` (packed like `shown()`). */
  scan(onRefresh) {
    this.onRefresh = onRefresh;
  }

  startScan() {
    if (!this.now || !this.onRefresh) return;
    this.scanAt = this.now();
    this.scanRow = 0;
    this.refreshAt = this.scanAt;
    this.refresh = new Uint8Array(Math.ceil(this.glass.width / 8) * this.glass.height);
  }

  /** Drives every row due by now (before a byte changes what rows show, and on `tick`). */
  advance() {
    if (this.scanAt === null || !this.now) return;
    const t = this.now();
    while (this.scanAt <= t) {
      const r = this.scanRow;
      const y = this.comReverse ? r : this.glass.height - 1 - r;
      if (y >= 0 && y < this.glass.height) this.rowPixels(y, this.refresh);
      this.scanRow = r === this.multiplex ? 0 : (r + 1) % HEIGHT;
      if (this.scanRow === 0) {
        this.onRefresh(this.refresh, this.refreshAt);
        this.refresh = new Uint8Array(this.refresh.length);
        this.refreshAt = this.scanAt + this.rowNanos();
      }
      this.scanAt += this.rowNanos();
    }
  }

  tick() {
    this.advance();
  }

  /** Why what the panel shows is not a plain picture, or null. */
  notShowable() {
    if (this.error) return this.error;
    if (!this.everOn) return 'the display was never switched on with its charge pump (0x8D 0x14, 0xAF)';
    if (!this.displayOn) return 'the display is switched off (0xAE)';
    if (this.scrolling) return 'scrolling is active (0x2F)';
    const { width, height, comPins } = this.glass;
    if (this.multiplex !== height - 1) return `multiplex ratio ${this.multiplex + 1}, not ${height}`;
    if (this.comPins !== comPins) return `COM pins configuration ${hex(this.comPins)}: a ${width}x${height} panel needs ${hex(comPins)}`;
    return null;
  }

  /** The RAM column that panel column `x` shows (segment remap 0xA1: the glass's first + x). */
  glassColumn(x) {
    const first = this.glass.column;
    return this.segmentRemap ? first + x : WIDTH - 1 - first - x;
  }

  /**
   * What the glass shows, its rows packed MSB first: row y of the panel is COM line y; with
   * reversed COM scan (0xC8) the top row is driven from the last multiplexed line. Upright for a module whose init uses the
   * common segment remap 0xA1 and scan direction 0xC8 (the Adafruit and `ssd1306` crate set-up).
   */
  shown() {
    const { width, height } = this.glass;
    const out = new Uint8Array(Math.ceil(width / 8) * height);
    for (let y = 0; y < height; y++) this.rowPixels(y, out);
    return out;
  }

  /** Row `y` of the glass as it shows now, into `out` (packed as `shown()`'s). */
  rowPixels(y, out) {
    const { width, height } = this.glass;
    const stride = Math.ceil(width / 8);
    const com = this.comReverse ? y : height - 1 - y;
    const row = (com + this.startLine + this.offset) % HEIGHT;
    out.fill(0, y * stride, (y + 1) * stride);
    for (let x = 0; x < width; x++) {
      let on = (this.gddram[(row >> 3) * this.ramColumns + this.glassColumn(x)] >> (row & 7)) & 1;
      if (this.entireOn) on = 1;
      if (this.inverse) on ^= 1;
      if (on) out[y * stride + (x >> 3)] |= 0x80 >> (x & 7);
    }
  }
}
