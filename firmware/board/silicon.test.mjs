// Unit tests of what silicon.mjs adds to rp2040js, each against the RP2040 datasheet
// (`npm test` in firmware/board; `.ci/run` runs them). The firmware itself is the rest of the
// test: `cargo xtask board` requires its two-core frames to be bit-identical to host-sim's.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { Divider, Fifos, SiliconBoard, XipCache } from './silicon.mjs';

test('each core reads what the other wrote, in order, 8 words deep', () => {
  const f = new Fifos();
  assert.equal(f.status(0) & 3, 2, 'empty: RDY, not VLD');
  for (let i = 0; i < 8; i++) f.write(0, 100 + i);
  assert.equal(f.status(0) & 2, 0, 'full: core 0 may not write');
  assert.equal(f.status(1) & 1, 1, 'core 1 has data');
  f.write(0, 999);
  assert.equal(f.status(0) & 4, 4, 'a write to a full FIFO sets WOF');
  for (let i = 0; i < 8; i++) assert.equal(f.read(1), 100 + i);
  assert.equal(f.status(1) & 1, 0);
  f.read(1);
  assert.equal(f.status(1) & 8, 8, 'a read of an empty FIFO sets ROE');
  f.clear(1, 8);
  f.clear(0, 4);
  assert.equal(f.status(0) & 12, 0);
  assert.equal(f.status(1) & 12, 0, 'writing 1 clears the sticky flags');
});

test('the divider divides signed and unsigned, and by zero as the datasheet says', () => {
  const d = new Divider();
  d.write(0x068, -7 >>> 0);
  d.write(0x06c, 2);
  assert.equal(d.read(0x070) | 0, -3);
  assert.equal(d.read(0x074) | 0, -1);
  d.write(0x060, 0xffffffff);
  d.write(0x064, 16);
  assert.equal(d.read(0x070), 0x0fffffff);
  assert.equal(d.read(0x074), 15);
  d.write(0x060, 5);
  d.write(0x064, 0);
  assert.equal(d.read(0x070), 0xffffffff);
  assert.equal(d.read(0x074), 5);
});

/** An SSI as boot2 for the Pico's W25Q080 leaves it: quad continuous read, SCK = clk_sys / 2. */
const W25Q080_XIP = { baudr: 2, crtlr0: (2 << 21) | (31 << 16), spictlr0: (4 << 11) | (0 << 8) | (8 << 2) | 2 };

test('a line fill takes 28 SCK periods of clk_sys / 2 after boot2', () => {
  // 32 address and mode bits and 64 data bits on four lanes, 4 wait cycles: 8 + 4 + 16.
  assert.equal(new XipCache(W25Q080_XIP).missCycles(), 56);
  assert.equal(new XipCache({ baudr: 0, crtlr0: 0, spictlr0: 0 }).missCycles(), 0);
});

test('16 KiB, 2-way, 8-byte lines: a third line on a set evicts the least recently used', () => {
  const c = new XipCache(W25Q080_XIP);
  const way = 8192; // addresses this far apart share a set
  assert.equal(c.access(0x10000000, 0), 56, 'cold miss');
  assert.equal(c.access(0x10000004, 100), 0, 'same line');
  c.access(0x10000000 + way, 200);
  assert.equal(c.access(0x10000000, 300), 0, 'both ways hold a line');
  c.access(0x10000000 + 2 * way, 400); // evicts the line at +way (least recently used)
  assert.equal(c.access(0x10000000, 500), 0);
  assert.equal(c.access(0x10000000 + way, 600), 56);
  assert.deepEqual([c.hits, c.misses], [3, 4]);
});

test('misses count against their line in flash while missLines is a Map, in any cached alias', () => {
  const c = new XipCache(W25Q080_XIP);
  c.access(0x10000100, 0); // before counting: not counted
  c.missLines = new Map();
  c.access(0x10000104, 100); // a hit
  c.access(0x1100020c, 200); // XIP_NOALLOC: missed, and not kept
  c.access(0x10000208, 300); // the same line: missed again
  c.access(0x10004000, 400);
  assert.deepEqual([...c.missLines.entries()], [[0x10000208, 2], [0x10004000, 1]]);
  assert.equal(c.misses, 4);
});

test('no-allocate and no-cache aliases, and misses queue on the one flash interface', () => {
  const c = new XipCache(W25Q080_XIP);
  c.access(0x11000100, 0);
  assert.equal(c.access(0x10000100, 1000), 56, 'XIP_NOALLOC does not fill the cache');
  assert.equal(c.access(0x12000100, 2000), 56, 'XIP_NOCACHE always goes to the flash');
  assert.equal(c.uncached, 1);
  // Two misses at the same moment (one per core): the second waits for the first.
  assert.equal(c.access(0x10002000, 5000), 56);
  assert.equal(c.access(0x10003000, 5000), 112);
});

test('an SPI byte reaches the display 8 SCK periods later, with chip select and D/C as they are then', () => {
  const board = new SiliconBoard({ dualCore: false });
  const mcu = board.mcu;
  const got = [];
  let resets = 0;
  const device = { spiByte: (b, dc) => got.push([b, dc]), reset: () => resets++ };
  board.attachSpi(0, device, { cs: 17, dc: 20, res: 21 });
  // GP17, GP20 and GP21 as SIO outputs (IO_BANK0 FUNCSEL 5); CS low, D/C high, RES high.
  for (const pin of [17, 20, 21]) mcu.writeUint32(0x40014004 + 8 * pin, 5);
  mcu.writeUint32(0xd0000010, (1 << 20) | (1 << 21)); // GPIO_OUT, then GPIO_OE: no glitch on RES
  mcu.writeUint32(0xd0000020, (1 << 17) | (1 << 20) | (1 << 21));
  assert.equal(resets, 0);
  // SPI0 as rp2040-hal sets 10 MHz from 125 MHz: 8-bit frames, CPSDVSR 2, SCR 6 (8.9 MHz).
  mcu.writeUint32(0x4003c000, (6 << 8) | 7);
  mcu.writeUint32(0x4003c010, 2);
  mcu.writeUint32(0x4003c004, 2);
  assert.equal(board.spiFrameCycles(0), 8 * 2 * 7);
  const nanos = (cycles) => (cycles * 1e9) / mcu.clkSys;
  mcu.writeUint32(0x4003c008, 0x5a);
  mcu.clock.tick(nanos(111));
  assert.deepEqual(got, [], 'not before its 8 bits are on the wire');
  mcu.clock.tick(nanos(1));
  assert.deepEqual(got, [[0x5a, true]]);
  mcu.writeUint32(0xd0000010, 1 << 21); // D/C low: a command
  mcu.writeUint32(0x4003c008, 0xaf);
  mcu.clock.tick(nanos(112));
  assert.deepEqual(got[1], [0xaf, false]);
  mcu.writeUint32(0xd0000010, (1 << 17) | (1 << 21)); // CS high: the display does not listen
  mcu.writeUint32(0x4003c008, 0x11);
  mcu.clock.tick(nanos(112));
  assert.equal(got.length, 2);
  assert.equal(board.busCycles, 3 * 112);
  mcu.writeUint32(0xd0000010, 0); // RES low
  assert.equal(resets, 1);
});

test('I2C TX_EMPTY follows the FIFO level and reaches the NVIC when IC_INTR_MASK lets it', () => {
  const board = new SiliconBoard({ dualCore: false });
  const i2c = board.mcu.i2c[0];
  const base = 0x40044000;
  board.mcu.writeUint32(base + 0x3c, 2); // IC_TX_TL: at most 2 entries waiting
  assert.equal(i2c.intRaw & 0x10, 0x10, 'an empty FIFO is at or below the threshold');
  assert.equal(i2c.intStatus, 0, 'masked at first');
  board.mcu.writeUint32(base + 0x30, 0x10); // IC_INTR_MASK: TX_EMPTY on
  assert.equal(i2c.intStatus, 0x10);
  // The controller is disabled, so the FIFO only fills: three entries are above the threshold.
  for (let i = 0; i < 3; i++) board.mcu.writeUint32(base + 0x10, 0x41);
  assert.equal(i2c.intRaw & 0x10, 0, 'above the threshold: clear');
  board.mcu.writeUint32(base + 0x30, 0);
  assert.equal(i2c.intStatus, 0);
});

test('a panel that loses power answers nothing, and comes back dark with its settings and RAM lost', async () => {
  const { Ssd1306 } = await import('./ssd1306.mjs');
  const d = new Ssd1306(0x3c);
  const send = (bytes) => {
    d.start();
    assert.equal(d.connect(0x3c, false), true);
    for (const b of bytes) assert.equal(d.write(b), true);
    d.stop();
  };
  // Charge pump on, horizontal addressing, display on; then a data byte.
  send([0x00, 0x8d, 0x14, 0x20, 0x00, 0xaf]);
  send([0x40, 0xff]);
  assert.equal(d.notShowable(), null);
  d.start();
  assert.equal(d.connect(0x3c, false), true);
  d.powerOff();
  assert.equal(d.write(0x40), false, 'a byte after the power went NACKs');
  d.stop();
  d.start();
  assert.equal(d.connect(0x3c, false), false, 'no power: the address NACKs');
  d.powerOn();
  assert.match(d.notShowable(), /never switched on/, 'back dark, its set-up lost');
  assert.equal(d.gddram.every((b) => b === 0), true, 'its RAM lost');
  assert.equal(d.connect(0x3c, false), true, 'power back: it answers');
});

test('a panel holding SDA low keeps the controller from its START until the pins clock it free and make a STOP', () => {
  const board = new SiliconBoard({ dualCore: false });
  const mcu = board.mcu;
  const bus = board.buses[0]; // writes as core 0 makes them (RESETS reaches the board first)
  const seen = [];
  const device = {
    start: () => seen.push('start'),
    connect: (a) => (seen.push(`connect ${a.toString(16)}`), true),
    write: (b) => (seen.push(`write ${b.toString(16)}`), true),
    stop: () => seen.push('stop'),
    interrupted: () => seen.push('interrupted'),
  };
  const events = [];
  board.attachI2c(0, device, { timed: false, pins: { sda: 4, scl: 5 }, listen: { released: () => events.push('released') } });
  const I2C = 0x40044000;
  const ACTIVITY = 1;
  const line = (pin) => (bus.readUint32(0xd0000004) >>> pin) & 1; // SIO GPIO_IN
  for (const pin of [4, 5]) bus.writeUint32(0x4001c004 + 4 * pin, 0x4a); // pads: input enabled, pull-up
  assert.equal(line(4), 1, 'an idle bus reads high');
  board.holdSda(0, 2);
  assert.deepEqual(seen, ['interrupted']);
  assert.equal(line(4), 0, 'SDA reads low while the panel holds it');
  bus.writeUint32(I2C + 0x04, 0x3c); // IC_TAR
  bus.writeUint32(I2C + 0x6c, 1); // IC_ENABLE
  bus.writeUint32(I2C + 0x10, 0x200 | 0x80); // one byte, then STOP
  assert.equal(bus.readUint32(I2C + 0x70) & ACTIVITY, ACTIVITY, 'the controller waits for the bus');
  assert.deepEqual(seen, ['interrupted'], 'no START while SDA is held');
  // The pins as GPIOs (FUNCSEL 5), outputs at 0: a pin is driven low by enabling its output.
  for (const pin of [4, 5]) bus.writeUint32(0x40014004 + 8 * pin, 5);
  const drive = (pin, low) => bus.writeUint32(low ? 0xd0000024 : 0xd0000028, 1 << pin); // GPIO_OE_SET/CLR
  drive(5, true);
  drive(5, false);
  assert.equal(line(4), 0, 'one pulse of the two it needs');
  drive(5, true);
  assert.deepEqual(events, ['released'], 'the second falling edge ends its byte');
  drive(5, false);
  assert.equal(line(4), 1);
  // STOP: SDA low while SCL is low, SCL high, then SDA high.
  drive(5, true);
  drive(4, true);
  drive(5, false);
  drive(4, false);
  assert.deepEqual(seen, ['interrupted', 'stop', 'start', 'connect 3c', 'write 80', 'stop'], 'the STOP frees the bus: the held START goes out');
});

test('RESETS drops a START the I2C controller holds back for a busy bus', () => {
  const board = new SiliconBoard({ dualCore: false });
  const bus = board.buses[0];
  const seen = [];
  const device = { start: () => seen.push('start'), connect: () => true, write: () => true, stop: () => seen.push('stop'), interrupted() {} };
  board.attachI2c(0, device, { timed: false, pins: { sda: 4, scl: 5 } });
  const I2C = 0x40044000;
  board.holdSda(0, 1);
  bus.writeUint32(I2C + 0x6c, 1);
  bus.writeUint32(I2C + 0x10, 0x200);
  assert.equal(bus.readUint32(I2C + 0x70) & 1, 1);
  bus.writeUint32(0x4000c000 + 0x2000, 1 << 3); // RESETS set alias: I2C0 into reset
  assert.equal(bus.readUint32(I2C + 0x70) & 1, 0, 'idle after its reset');
  assert.equal(bus.readUint32(I2C + 0x6c), 0, 'IC_ENABLE back to 0');
  assert.equal(board.mcu.i2c[0].txFIFO.itemCount, 0, 'its FIFO emptied');
  assert.deepEqual(seen, []);
});

test('a byte the panel does not acknowledge aborts the transfer, and the panel drops its half command', () => {
  const board = new SiliconBoard({ dualCore: false });
  const bus = board.buses[0];
  const seen = [];
  const device = {
    start: () => seen.push('start'),
    connect: () => true,
    write: (b) => (seen.push(b), true),
    stop: () => seen.push('stop'),
    interrupted: () => seen.push('interrupted'),
  };
  board.attachI2c(0, device, { timed: false });
  const I2C = 0x40044000;
  bus.writeUint32(I2C + 0x6c, 1);
  bus.writeUint32(I2C + 0x10, 0x00);
  board.nackNext(0);
  bus.writeUint32(I2C + 0x10, 0x81);
  assert.deepEqual(seen, ['start', 0x00, 'interrupted', 'stop']);
  assert.equal(bus.readUint32(I2C + 0x80) & (1 << 3), 1 << 3, 'IC_TX_ABRT_SOURCE: ABRT_TXDATA_NOACK');
});

/** Sends `bytes` to an I2C panel model as one transfer (a control byte first). */
function i2cSend(d, bytes) {
  d.start();
  assert.equal(d.connect(0x3c, false), true);
  for (const b of bytes) d.write(b);
  d.stop();
}

test('SH1106: page addressing only, 132 columns that stop at 131, the glass from column 2', async () => {
  const { Sh1106 } = await import('./sh1106.mjs');
  const d = new Sh1106(0x3c);
  assert.equal(d.gddram.length, 132 * 8);
  i2cSend(d, [0x00, 0xa1, 0xc8, 0xaf]);
  assert.equal(d.notShowable(), null, 'DC-DC is on after reset');
  // Page 0 from column 2 (0x02, 0x10): the first byte is the glass's left column.
  i2cSend(d, [0x00, 0xb0, 0x02, 0x10]);
  i2cSend(d, [0x40, 0x01]);
  assert.equal(d.shown()[0], 0x80, 'top left pixel');
  // From column 130: the counter stops at 131, so the third byte overwrites the second.
  i2cSend(d, [0x00, 0xb1, 0x02, 0x18]);
  i2cSend(d, [0x40, 0xaa, 0xbb, 0xcc]);
  assert.deepEqual([...d.gddram.slice(132 + 130, 132 + 132)], [0xaa, 0xcc]);
  assert.equal(d.error, null);
  const e = new Sh1106(0x3c);
  i2cSend(e, [0x00, 0x20, 0x00]);
  assert.match(e.error, /unknown command byte 0x20/, 'no horizontal addressing');
  const f = new Sh1106(0x3c);
  i2cSend(f, [0x00, 0x8d, 0x14]);
  assert.match(f.error, /unknown command byte 0x8d/, 'no charge pump command');
});

test('SSD1309: no charge pump command, and a command lock', async () => {
  const { Ssd1309 } = await import('./ssd1309.mjs');
  const d = new Ssd1309(0x3c);
  i2cSend(d, [0x00, 0xfd, 0x16, 0xaf]);
  assert.match(d.notShowable(), /never switched on/, 'locked: 0xAF ignored');
  i2cSend(d, [0x00, 0xfd, 0x12, 0xaf]);
  assert.equal(d.notShowable(), null);
  const e = new Ssd1309(0x3c);
  i2cSend(e, [0x00, 0x8d, 0x14]);
  assert.match(e.error, /unknown command byte 0x8d/);
});

test('Sharp memory LCD: SCS active high, LSB-first mode and addresses, whole lines, VCOM inverted each second', async () => {
  const { SharpMemoryLcd } = await import('./sharp.mjs');
  let now = 0;
  const d = new SharpMemoryLcd(16, 4, () => now);
  const rev = (b) => parseInt(b.toString(2).padStart(8, '0').split('').reverse().join(''), 2);
  const send = (bytes) => {
    d.select(true);
    for (const b of bytes) d.spiByte(b);
    d.select(false);
  };
  d.display(true);
  assert.match(d.notShowable(), /noise/, 'noise until cleared');
  send([rev(0b100), 0]); // M2: clear all
  assert.equal(d.notShowable(), null);
  // M0 write with VCOM (M1) high: line 2, then line 4, each 2 bytes and a dummy; a final dummy.
  now = 0.4e9;
  send([rev(0b011), rev(2), 0xf0, 0x01, 0, rev(4), 0xaa, 0x55, 0, 0]);
  assert.equal(d.error, null);
  assert.deepEqual([...d.shown()], [0xff, 0xff, 0xf0, 0x01, 0xff, 0xff, 0xaa, 0x55]);
  d.spiByte(0x12);
  assert.equal(d.memory[0], 0xff, 'bytes with SCS low are not heard');
  now = 1.3e9;
  send([rev(0b000), 0]); // display mode, VCOM low: inverted 0.9 s after it went high
  assert.equal(d.error, null);
  now = 2.5e9;
  assert.match(d.notShowable(), /VCOM not inverted for 1200 ms/);
  const e = new SharpMemoryLcd(16, 4, () => 0);
  e.select(true);
  e.spiByte(rev(0b001));
  e.spiByte(rev(5));
  assert.match(e.error, /line address 5/);
  const f = new SharpMemoryLcd(16, 4, () => 0);
  f.select(true);
  for (const b of [rev(0b001), rev(1), 0, 0, 0]) f.spiByte(b);
  f.select(false);
  assert.match(f.error, /no dummy byte after the last line/);
});

test('SSD1306 refresh: a row every D x (phase 1 + phase 2 + 50) clocks, each showing its RAM row as it is then', async () => {
  const { Ssd1306 } = await import('./ssd1306.mjs');
  let t = 0;
  const d = new Ssd1306(0x3c, undefined, () => t);
  const refreshes = [];
  d.scan((pixels, at) => refreshes.push({ pixels: pixels.slice(), at }));
  const cmd = (...bytes) => bytes.forEach((b) => d.spiByte(b, false));
  // The gray image's set-up: oscillator 0xF (530 kHz typical), D = 1, phases 1 and 2: 53 clocks.
  cmd(0xae, 0xd5, 0xf0, 0xa8, 63, 0xd3, 0, 0x40, 0x8d, 0x14, 0x20, 0x00, 0xda, 0x12, 0xa1, 0xc8, 0xd9, 0x21, 0xaf);
  assert.equal(Math.round(d.rowNanos()), 100_000);
  // Page 0 lit while row 0 is driven (50 us after the display came on): rows 1..7 show it in
  // this refresh, row 0 from the next.
  t = 50_000;
  cmd(0x21, 0, 127, 0x22, 0, 0);
  for (let i = 0; i < 128; i++) d.spiByte(0xff, true);
  t = 2 * 6_400_000 + 1;
  d.tick();
  assert.equal(refreshes.length, 2, 'two refreshes of 64 rows in 12.8 ms');
  const lit = (px, y) => px.subarray(y * 16, y * 16 + 16).every((b) => b === 0xff);
  const [first, second] = refreshes.map((r) => r.pixels);
  assert.deepEqual([0, 1, 7, 8].map((y) => lit(first, y)), [false, true, true, false], 'the first refresh is torn at row 1');
  assert.deepEqual([0, 7, 8].map((y) => lit(second, y)), [true, true, false]);
  assert.equal(Math.round(refreshes[1].at), 6_400_000);
  // Halving the divide ratio's clock (D = 2) doubles the row period; 3 % fast shortens it.
  cmd(0xd5, 0xf1);
  assert.equal(Math.round(d.rowNanos()), 200_000);
  d.oscScale = 1.03;
  assert.equal(Math.round(d.rowNanos()), Math.round(200_000 / 1.03));
  // Display off stops the scan; a pre-charge phase of 0 clocks does not exist.
  cmd(0xae);
  t += 50_000_000;
  d.tick();
  assert.equal(refreshes.length, 2, 'no refresh while the display is off');
  assert.equal(d.error, null);
  cmd(0xd9, 0x20);
  assert.match(d.error ?? '', /pre-charge/);
});

test('UC8151: BUSY low through PON and a refresh as long as its LUT, gate-ordered RAM, strict commands', async () => {
  const { Uc8151 } = await import('./uc8151.mjs');
  let now = 0;
  const timers = [];
  let busyHigh = null;
  const advance = (to) => {
    now = to;
    for (const t of timers.splice(0)) (t[0] <= now ? t[1]() : timers.push(t));
  };
  // A controller and its command function: the command byte with D/C low, then its parameters.
  const make = () => {
    const d = new Uc8151(() => now, (ns, fn) => timers.push([now + ns, fn]), (level) => (busyHigh = level));
    const cmd = (c, ...p) => {
      d.spiByte(c, false);
      for (const b of p) d.spiByte(b, true);
    };
    return [d, cmd];
  };
  // Three groups: (4+4+7)x1 + (12+12)x2 + (4+4+7)x2 = 93 frames: 930 ms at 100 Hz.
  const groups = [[4, 4, 7, 0, 1], [12, 12, 0, 0, 2], [4, 4, 7, 0, 2]];
  const setUp = (cmd) => {
    cmd(0x00, 0xb7); // 128x296, LUT in registers, black and white, shift right, scan down
    cmd(0x50, 0x4c);
    cmd(0x30, 0x3a); // 100 Hz
    cmd(0x20, ...groups.flatMap((g) => [0, ...g]), ...new Array(44 - 18).fill(0));
  };
  const [d, cmd] = make();
  assert.equal(busyHigh, true);
  assert.match(d.notShowable(), /no refresh/);
  setUp(cmd);
  cmd(0x04); // PON
  assert.equal(busyHigh, false, 'BUSY low while the booster starts');
  cmd(0x13);
  assert.match(d.error, /while BUSY is low/);
  const [e, ecmd] = make();
  setUp(ecmd);
  ecmd(0x12);
  assert.match(e.error, /power off/, 'no refresh without PON');
  const [f, fcmd] = make();
  setUp(fcmd);
  fcmd(0x04);
  advance(now + 30e6);
  assert.equal(busyHigh, true, 'BUSY high once the booster is up');
  // Gate 0 (column 0): its first byte 0x80, the top pixel white; gate 1's last byte 0x01.
  const ram = new Array(296 * 16).fill(0);
  ram[0] = 0x80;
  ram[16 + 15] = 0x01;
  fcmd(0x13, ...ram);
  // A partial window: sources 8..15 of gates 2..3 get 0xff.
  fcmd(0x91);
  fcmd(0x90, 8, 15, 0, 2, 0, 3, 1);
  fcmd(0x13, 0xff, 0xff);
  fcmd(0x92);
  const start = now;
  fcmd(0x12);
  assert.equal(f.error, null);
  assert.equal(busyHigh, false);
  assert.equal(f.refreshes[0].end - start, 930e6, "the LUT's 93 frames at 100 Hz");
  advance(start + 929e6);
  assert.equal(busyHigh, false);
  advance(start + 930e6);
  assert.equal(busyHigh, true);
  const shown = f.shown();
  const px = (x, y) => (shown[y * 37 + (x >> 3)] >> (7 - (x & 7))) & 1;
  assert.equal(px(0, 0), 1);
  assert.equal(px(1, 127), 1);
  assert.equal(px(0, 1), 0);
  for (let y = 8; y < 16; y++) assert.equal(px(2, y) + px(3, y), 2, 'the partial window');
  assert.equal(px(4, 8), 0);
  // A refresh in partial mode drives its window alone: gate 0's top pixel goes black in the
  // RAM, outside the window, and stays white on the glass; the window's gate 5 goes white.
  fcmd(0x13, ...new Array(296 * 16).fill(0));
  fcmd(0x91);
  fcmd(0x90, 0, 7, 0, 5, 0, 5, 1);
  fcmd(0x13, 0x80);
  fcmd(0x12);
  assert.equal(f.error, null);
  assert.deepEqual(f.refreshes[1].window, { hs: 0, he: 7, vs: 5, ve: 5 });
  advance(now + 930e6);
  const after = f.shown();
  const px2 = (x, y) => (after[y * 37 + (x >> 3)] >> (7 - (x & 7))) & 1;
  assert.equal(px2(0, 0), 1, 'outside the window: the glass as it was');
  assert.equal(px2(5, 0), 1, 'inside the window: the RAM');
  assert.equal(px2(5, 1), 0);
  fcmd(0x92);
  fcmd(0x05);
  assert.match(f.error, /0x5: not one this model knows/);
  // Partial refreshes alone since power-on: the glass outside their windows is unknown.
  const [p, pcmd] = make();
  setUp(pcmd);
  pcmd(0x04);
  advance(now + 30e6);
  pcmd(0x91);
  pcmd(0x90, 0, 7, 0, 0, 0, 0, 1);
  pcmd(0x13, 0xff);
  pcmd(0x12);
  assert.match(p.notShowable(), /only partial refreshes since power-on/);
  const [g, gcmd] = make();
  gcmd(0x01, 3, 0);
  gcmd(0x04);
  assert.match(g.error, /0x1 cut short: 2 of its 5/);
});

test('an access past the XIP windows, below the SRAM (where an overflowing stack goes), stops the board as a bus fault', () => {
  const board = new SiliconBoard({ dualCore: false });
  const bus = board.buses[0];
  bus.readUint32(0x10000100); // flash, through the cache
  bus.writeUint32(0x15000000, 7); // XIP SRAM
  assert.equal(board.stop, null, 'the XIP windows answer');
  bus.writeUint32(0x1ffffffc, 1); // a push one word below the SRAM
  assert.match(board.stop, /core 0 accessed 0x1ffffffc, where nothing answers .*a bus fault: just below the SRAM/);
  const reads = new SiliconBoard({ dualCore: false });
  reads.buses[0].readUint8(0x19000000);
  assert.match(reads.stop, /0x19000000, where nothing answers/);
});
