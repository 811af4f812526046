// An SSD1309 128x64 OLED controller (Solomon Systech SSD1309 datasheet rev 1.2) on a 2.42"
// module, on I2C or 4-wire SPI. Its RAM, addressing modes and display commands are the
// SSD1306's (ssd1306.mjs); it differs where a driver written for the SSD1306 goes wrong: it has
// no charge pump (the module's own supply makes VCC), so 0x8D is no command of its, and it has
// a command lock (0xFD 0x16: every command but 0xFD ignored until 0xFD 0x12).

import { Ssd1306, hex } from './ssd1306.mjs';

export class Ssd1309 extends Ssd1306 {
  argumentCount(cmd) {
    if (cmd === 0x8d) return -1;
    if (cmd === 0xfd) return 1;
    return super.argumentCount(cmd);
  }

  reset() {
    super.reset();
    this.locked = false;
  }

  command(byte) {
    // Locked: every byte but the unlock command (and its argument) is ignored.
    if (this.locked && this.cmd === null && byte !== 0xfd) return;
    super.command(byte);
  }

  execute(c, a) {
    if (c === 0xfd) {
      if ((a[0] & ~0x04) !== 0x12) this.fail(`command lock ${hex(a[0])} (0x12 unlock, 0x16 lock)`);
      this.locked = (a[0] & 0x04) !== 0;
    } else if (c === 0xaf) {
      this.displayOn = true;
      this.everOn = true;
    } else super.execute(c, a);
  }

  notShowable() {
    if (!this.error && !this.everOn) return 'the display was never switched on (0xAF)';
    return super.notShowable();
  }
}
