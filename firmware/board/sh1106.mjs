// An SH1106 132x64 OLED controller (Sino Wealth SH1106 datasheet V2.3) on a 128x64 module, on
// I2C (the same control byte as the SSD1306: Co and D/C#) or 4-wire SPI: its command set with
// their arguments, and its 132x64 RAM written through page addressing, the only mode it has
// (the column counter counts up to 131 and stops there; the page does not change). The
// module's glass is driven by SEG2 to SEG129, so `shown()` gives 128 columns: with the common
// segment remap 0xA1, RAM columns 2 to 129.
//
// As strict as the SSD1306 model: a byte that is no SH1106 command (the SSD1306's addressing
// modes 0x20-0x22 and charge pump 0x8D among them), an argument out of its range, a command cut
// off by a STOP fail the run.

import { Ssd1306, HEIGHT, hex } from './ssd1306.mjs';

const COLUMNS = 132;
/** The first RAM column the glass shows, with segment remap (0xA1): SEG129 is its left edge. */
const GLASS_OFFSET = 2;

/** Arguments each command takes (-1: no SH1106 command). */
function argumentCount(cmd) {
  if (cmd <= 0x1f) return 0; // lower / higher column address
  if (cmd >= 0x30 && cmd <= 0x33) return 0; // pump voltage
  if (cmd >= 0x40 && cmd <= 0x7f) return 0; // display start line
  if (cmd >= 0xb0 && cmd <= 0xb7) return 0; // page address
  if (cmd >= 0xc0 && cmd <= 0xcf) return 0; // common output scan direction (bit 3)
  switch (cmd) {
    case 0x81: // contrast
    case 0xa8: // multiplex ratio
    case 0xad: // DC-DC control
    case 0xd3: // display offset
    case 0xd5: // clock divide / oscillator
    case 0xd9: // discharge / pre-charge period
    case 0xda: // common pads hardware configuration
    case 0xdb: // VCOM deselect level
      return 1;
    case 0xa0: case 0xa1: // segment remap
    case 0xa4: case 0xa5: // entire display on
    case 0xa6: case 0xa7: // normal / reverse
    case 0xae: case 0xaf: // display off / on
    case 0xe0: // read-modify-write
    case 0xe3: // no operation
    case 0xee: // end (of read-modify-write)
      return 0;
    default:
      return -1;
  }
}

export class Sh1106 extends Ssd1306 {
  get ramColumns() {
    return COLUMNS;
  }

  argumentCount(cmd) {
    return argumentCount(cmd);
  }

  /** Every register to its power-on value: DC-DC on (0x8B), display off, page 0, column 0. */
  reset() {
    super.reset();
    this.dcdc = true;
    this.rmw = null; // the column read-modify-write started at
  }

  execute(c, a) {
    if (c <= 0x1f) {
      const col = c <= 0x0f ? (this.col & 0xf0) | c : (this.col & 0x0f) | ((c & 0x0f) << 4);
      if (col >= COLUMNS) this.fail(`column address ${col} (0..131)`);
      this.col = Math.min(col, COLUMNS - 1);
    } else if (c >= 0x30 && c <= 0x33) {
      // pump voltage: brightness only
    } else if (c >= 0x40 && c <= 0x7f) this.startLine = c - 0x40;
    else if (c >= 0xb0 && c <= 0xb7) this.page = c - 0xb0;
    else if (c >= 0xc0 && c <= 0xcf) this.comReverse = (c & 0x08) !== 0;
    else
      switch (c) {
        case 0xa0: case 0xa1: this.segmentRemap = c === 0xa1; break;
        case 0xa4: case 0xa5: this.entireOn = c === 0xa5; break;
        case 0xa6: case 0xa7: this.inverse = c === 0xa7; break;
        case 0xa8:
          if (a[0] > 0x3f) this.fail(`multiplex ratio byte ${hex(a[0])} (0x00..0x3F)`);
          this.multiplex = a[0] & 0x3f;
          break;
        case 0xad:
          if ((a[0] & 0xfe) !== 0x8a) this.fail(`DC-DC setting ${hex(a[0])} (0x8A off, 0x8B on)`);
          this.dcdc = (a[0] & 1) !== 0;
          break;
        case 0xae: this.displayOn = false; break;
        case 0xaf:
          this.displayOn = true;
          if (this.dcdc) this.everOn = true;
          break;
        case 0xd3: this.offset = a[0] & 0x3f; break;
        case 0xda:
          if ((a[0] & ~0x10) !== 0x02) this.fail(`common pads configuration ${hex(a[0])} (0x02 or 0x12)`);
          this.comPins = a[0];
          break;
        case 0xe0: this.rmw = this.col; break;
        case 0xee:
          if (this.rmw !== null) this.col = this.rmw;
          this.rmw = null;
          break;
        default: break; // contrast, timing, VCOM and NOP change nothing shown
      }
  }

  data(byte) {
    this.dataBytes++;
    this.gddram[this.page * COLUMNS + this.col] = byte;
    if (this.col < COLUMNS - 1) this.col++;
  }

  notShowable() {
    if (this.error) return this.error;
    if (!this.everOn) return 'the display was never switched on with its DC-DC converter on (0xAD 0x8B, 0xAF)';
    if (!this.displayOn) return 'the display is switched off (0xAE)';
    if (this.multiplex !== HEIGHT - 1) return `multiplex ratio ${this.multiplex + 1}, not ${HEIGHT}`;
    if (this.comPins !== 0x12) return `common pads configuration ${hex(this.comPins)}: a 128x64 panel needs 0x12`;
    return null;
  }

  /** The RAM column behind panel column `x`: the glass is SEG129 (left) to SEG2. */
  glassColumn(x) {
    return this.segmentRemap ? x + GLASS_OFFSET : COLUMNS - 1 - GLASS_OFFSET - x;
  }
}
