// The RP2040 as silicon runs it, built around rp2040js (which models core 0 and the
// peripherals): what this file adds is what rp2040js lacks and a frame's cost depends on,
// each from the RP2040 datasheet (sections named below).
//
// - Core 1 (2.3.1 "SIO", 2.8.2 "Launching code on processor core 1"): a second Cortex-M0+ on
//   the same bus, started from the bootrom's reset vector, so the bootrom's wait for the launch
//   sequence and rp2040-hal's `Multicore::spawn` handshake run unchanged; held in reset while
//   PSM FRCE_OFF.PROC1 is set and restarted from the bootrom when it clears.
// - Per core: SIO CPUID, the inter-core FIFOs (8 words each way; FIFO_ST VLD, RDY and the sticky
//   WOF/ROE flags, cleared by writing 1), the hardware divider (results ready 8 cycles after the
//   divisor is written: the code that uses it waits those cycles itself, so no cycles are added
//   here), the interpolators, the event register (WFE/SEV: SEV sets the other core's event and
//   its own), the NVIC, SysTick, VTOR and the MPU registers (core 1's stack guard, which
//   rp2040-hal installs, is enforced: a core-1 access to its guard region stops the run).
//   GPIO and the spinlocks are shared. Peripheral interrupts reach both cores' NVICs.
// - The cores are stepped interleaved by cycle count: the core that is behind runs the next
//   instruction, so neither gets more than one instruction ahead and a race can show. A core
//   asleep (WFE/WFI) keeps pace with the other and counts those cycles as idle.
// - The XIP cache (2.6.3 "Cache"): 16 KiB, 2-way set-associative, 8-byte lines, one for both
//   cores, least recently used way replaced, in front of the flash at 0x10000000 (allocating),
//   0x11000000 (no allocate), 0x12000000 and 0x13000000 (no cache). A miss waits for the QSPI
//   flash to deliver the line, `missCycles()`, derived from the SSI registers boot2 programmed;
//   the two cores' misses queue on the one flash interface.
// - I2C timing (4.3 "I2C"): START, each address or data byte (8 bits and the acknowledge: 9 SCL
//   periods) and STOP take the time the controller's SCL counts give, at the configured clock;
//   the 16-entry TX FIFO fills while the bus is busy, exactly as rp2040js's controller has it,
//   and the display model receives each byte when the bus has delivered it. IC_INTR_MASK is
//   writable and TX_EMPTY follows the FIFO's level (rp2040js keeps every interrupt masked).
// - SPI timing (4.4 "SPI"): each frame of SPI0/SPI1 takes DSS + 1 periods of the clock the
//   controller's CPSDVSR and SCR give; the display model on it hears a byte when its last bit
//   is on the wire, with the chip-select and data/command pins as they are then.
//
// Not modelled: bus contention between the cores on SRAM and APB (the RP2040's striped SRAM
// banks make it rare), flash writes, DMA, and the cache's own maintenance registers.

import { RP2040, GPIOPinState } from 'rp2040js';

const SIO_BASE = 0xd0000000;
const PPB_PAGE = 0xe000e;
/** Where the RP2040's XIP flash starts. */
export const FLASH = 0x10000000;
const FLASH_REGION = 0x1; // 0x10000000..0x1fffffff; the XIP aliases are 0x10..0x13
const PSM_FRCE_OFF = 0x40010004;
const PROC1 = 1 << 16;
const I2C_FS_SPKLEN = [0x400440a0, 0x400480a0];
const RESETS_RESET = 0x4000c000;
const RESET_I2C = [1 << 3, 1 << 4]; // RESETS' bits for I2C0 and I2C1
const OP_WFE = 0xbf20;

// SIO registers this file answers per core (the rest go to rp2040js's SIO, shared).
const CPUID = 0x000;
const FIFO_ST = 0x050;
const FIFO_WR = 0x054;
const FIFO_RD = 0x058;
const DIV_FIRST = 0x060;
const DIV_LAST = 0x078;
const INTERP_FIRST = 0x080;
const INTERP_LAST = 0x0fc;
const FIFO_DEPTH = 8;
// FIFO_ST bits
const VLD = 1;
const RDY = 2;
const WOF = 4;
const ROE = 8;

// MPU registers (ARMv6-M), per core.
const MPU_TYPE = 0xd90;
const MPU_CTRL = 0xd94;
const MPU_RNR = 0xd98;
const MPU_RBAR = 0xd9c;
const MPU_RASR = 0xda0;

/** The inter-core FIFOs: `toCore[i]` holds the words core i has yet to read. */
export class Fifos {
  constructor() {
    this.toCore = [[], []];
    this.sticky = [0, 0];
  }
  status(core) {
    const rx = this.toCore[core];
    const tx = this.toCore[1 - core];
    return (rx.length > 0 ? VLD : 0) | (tx.length < FIFO_DEPTH ? RDY : 0) | this.sticky[core];
  }
  write(core, value) {
    const tx = this.toCore[1 - core];
    if (tx.length >= FIFO_DEPTH) this.sticky[core] |= WOF;
    else tx.push(value >>> 0);
  }
  read(core) {
    const rx = this.toCore[core];
    if (rx.length === 0) {
      this.sticky[core] |= ROE;
      return 0;
    }
    return rx.shift();
  }
  clear(core, value) {
    this.sticky[core] &= ~(value & (WOF | ROE));
  }
}

/** One core's hardware divider (SIO DIV_*): signed or unsigned by the register written. */
export class Divider {
  constructor() {
    this.dividend = 0;
    this.divisor = 0;
    this.quotient = 0;
    this.remainder = 0;
    this.csr = 1; // READY
  }
  run(signed) {
    const n = signed ? this.dividend | 0 : this.dividend >>> 0;
    const d = signed ? this.divisor | 0 : this.divisor >>> 0;
    if (d === 0) {
      // Datasheet 2.3.1.5: division by zero gives quotient -1 (or 1 for a negative signed
      // dividend) and the dividend as remainder.
      this.quotient = signed && n < 0 ? 1 : 0xffffffff;
      this.remainder = n;
    } else {
      this.quotient = Math.trunc(n / d);
      this.remainder = n - this.quotient * d;
    }
    this.quotient >>>= 0;
    this.remainder >>>= 0;
    this.csr = 0b11; // READY | DIRTY
  }
  read(offset) {
    switch (offset) {
      case 0x060: case 0x068: return this.dividend;
      case 0x064: case 0x06c: return this.divisor;
      case 0x070: this.csr &= ~2; return this.quotient;
      case 0x074: return this.remainder;
      case 0x078: return this.csr;
    }
    return 0;
  }
  write(offset, value) {
    switch (offset) {
      case 0x060: this.dividend = value; this.run(false); break;
      case 0x064: this.divisor = value; this.run(false); break;
      case 0x068: this.dividend = value; this.run(true); break;
      case 0x06c: this.divisor = value; this.run(true); break;
      case 0x070: this.quotient = value >>> 0; this.csr = 0b11; break;
      case 0x074: this.remainder = value >>> 0; this.csr = 0b11; break;
    }
  }
}

/**
 * The XIP cache (datasheet 2.6.3): `access` is called for every flash read, instruction fetch
 * or data, and returns the cycles the reading core stalls. While `missLines` is a Map, each
 * miss also counts against its line's flash address there (where a frame's misses come from).
 */
export class XipCache {
  constructor(ssi, { bytes = 16384, ways = 2, line = 8 } = {}) {
    this.ssi = ssi;
    this.ways = ways;
    this.lineShift = Math.log2(line);
    this.sets = bytes / line / ways;
    this.tags = new Int32Array(this.sets * ways).fill(-1);
    this.lru = new Uint8Array(this.sets); // the way to replace next
    this.hits = 0;
    this.misses = 0;
    this.uncached = 0;
    this.stallCycles = 0;
    this.busyUntil = 0; // the flash interface is busy until this cycle
    this.missLines = null;
  }

  /**
   * Cycles one line fill takes, from the SSI registers boot2 left (datasheet 4.10.10): the
   * instruction (none in continuous-read mode), the address and mode bits and the data on the
   * frame format's lines, plus the wait cycles, each SCK period BAUDR clk_sys cycles. Before
   * boot2 has set the SSI up (BAUDR 0) a fetch costs nothing: on silicon boot2 runs from SRAM.
   */
  missCycles() {
    const { baudr, crtlr0, spictlr0 } = this.ssi;
    if (!baudr) return 0;
    const lanes = [1, 2, 4, 1][(crtlr0 >>> 21) & 3]; // SPI_FRF: standard, dual, quad
    const transType = spictlr0 & 3; // 0: instruction and address on one line; 2: both on lanes
    const addrLanes = transType === 0 ? 1 : lanes;
    const instLanes = transType === 2 ? lanes : 1;
    const instBits = [0, 4, 8, 16][(spictlr0 >>> 8) & 3];
    const addrBits = ((spictlr0 >>> 2) & 0xf) * 4;
    const wait = (spictlr0 >>> 11) & 0x1f;
    const dataBits = 8 << this.lineShift;
    const sck = instBits / instLanes + addrBits / addrLanes + wait + dataBits / lanes;
    return Math.ceil(sck) * (baudr & 0xfffe);
  }

  access(address, now) {
    const alias = (address >>> 24) & 0xf;
    if (alias > 3) return 0; // XIP SRAM, control registers, the SSI's own window
    if (alias >= 2) {
      this.uncached++;
      return this.fill(now);
    }
    const line = (address & 0xffffff) >>> this.lineShift;
    const set = line % this.sets;
    const tag = (line / this.sets) | 0;
    const base = set * this.ways;
    for (let w = 0; w < this.ways; w++) {
      if (this.tags[base + w] === tag) {
        this.hits++;
        this.lru[set] = (w + 1) % this.ways;
        return 0;
      }
    }
    this.misses++;
    if (this.missLines) {
      const at = FLASH + (line << this.lineShift);
      this.missLines.set(at, (this.missLines.get(at) || 0) + 1);
    }
    if (alias === 0) {
      const w = this.lru[set];
      this.tags[base + w] = tag;
      this.lru[set] = (w + 1) % this.ways;
    }
    return this.fill(now);
  }

  /** One line from the flash, queued behind any fill under way; returns the stall. */
  fill(now) {
    const start = Math.max(now, this.busyUntil);
    this.busyUntil = start + this.missCycles();
    const stall = this.busyUntil - now;
    this.stallCycles += stall;
    return stall;
  }

  counters() {
    return { hits: this.hits, misses: this.misses, uncached: this.uncached, stallCycles: this.stallCycles };
  }
}

/**
 * The bus as one core sees it: what rp2040js's CortexM0Core calls `rp2040`. Flash reads go
 * through the XIP cache, SIO and the private peripherals are this core's own, the rest is the
 * shared chip.
 */
class CoreBus {
  constructor(board, index) {
    this.board = board;
    this.index = index;
    this.mcu = board.mcu;
    this.divider = new Divider();
    this.interp = null; // set by the board: this core's own SIO instance for the interpolators
    this.ppb = null;
    this.mpu = { ctrl: 0, rnr: 0, regions: Array.from({ length: 8 }, () => ({ rbar: 0, rasr: 0 })) };
    this.guard = null; // [from, to) the MPU forbids, when enabled
    // rp2040js executes SEV as a log line and nothing else: that line is the hook.
    this.logger = {
      debug: (...a) => board.mcu.logger.debug(...a),
      info: (component, message) => {
        if (message === 'SEV') board.sev(index);
        else board.mcu.logger.info(component, message);
      },
      warn: (...a) => board.mcu.logger.warn(...a),
      error: (...a) => board.mcu.logger.error(...a),
    };
  }
  get core() {
    return this.board.cores[this.index];
  }
  get clock() {
    return this.mcu.clock;
  }
  get clkSys() {
    return this.mcu.clkSys;
  }
  onBreak(code) {
    this.board.onBreak(this.index, code);
  }
  setInterrupt(irq, value) {
    this.core.setInterrupt(irq, value);
  }

  flash(address) {
    // Past the XIP SSI's window (0x18000000) nothing answers: silicon raises a bus fault. The
    // first word below the SRAM is where an overflowing stack goes (flip-link puts the stack
    // at the SRAM's bottom), so this stops the run instead of letting it read garbage.
    if (address >>> 24 > 0x18) return this.board.unmapped(this.index, address);
    const stall = this.board.xip?.access(address, this.core.cycles);
    if (stall) this.core.cycles += stall;
  }
  checkGuard(address) {
    const g = this.guard;
    if (g && address >= g[0] && address < g[1]) this.board.guardHit(this.index, address);
  }

  readUint32(address) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION) this.flash(address);
    else if (region === 0xd) return this.sioRead(address - SIO_BASE);
    else if (address >>> 12 === PPB_PAGE) return this.ppbRead(address & 0xfff);
    else if (region === 2) this.checkGuard(address);
    return this.mcu.readUint32(address);
  }
  readUint16(address) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION) this.flash(address);
    else if (region === 0xd || address >>> 12 === PPB_PAGE) {
      const v = this.readUint32(address & ~3);
      return address & 2 ? v >>> 16 : v & 0xffff;
    } else if (region === 2) this.checkGuard(address);
    return this.mcu.readUint16(address);
  }
  readUint8(address) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION) this.flash(address);
    else if (region === 0xd || address >>> 12 === PPB_PAGE) {
      return (this.readUint32(address & ~3) >>> ((address & 3) * 8)) & 0xff;
    } else if (region === 2) this.checkGuard(address);
    return this.mcu.readUint8(address);
  }
  writeUint32(address, value) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION && address >>> 24 > 0x18) return this.board.unmapped(this.index, address);
    if (region === 0xd) return this.sioWrite(address - SIO_BASE, value >>> 0);
    if (address >>> 12 === PPB_PAGE) return this.ppbWrite(address & 0xfff, value >>> 0);
    if (region === 2) this.checkGuard(address);
    else if (region === 4) this.board.peripheralWrite(address, value >>> 0);
    this.mcu.writeUint32(address, value);
  }
  writeUint16(address, value) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION && address >>> 24 > 0x18) return this.board.unmapped(this.index, address);
    if (region === 0xd || address >>> 12 === PPB_PAGE) return this.writeUint32(address & ~3, (value & 0xffff) * 0x10001);
    if (region === 2) this.checkGuard(address);
    this.mcu.writeUint16(address, value);
  }
  writeUint8(address, value) {
    address >>>= 0;
    const region = address >>> 28;
    if (region === FLASH_REGION && address >>> 24 > 0x18) return this.board.unmapped(this.index, address);
    if (region === 0xd || address >>> 12 === PPB_PAGE) return this.writeUint32(address & ~3, (value & 0xff) * 0x1010101);
    if (region === 2) this.checkGuard(address);
    this.mcu.writeUint8(address, value);
  }

  sioRead(offset) {
    if (offset === CPUID) return this.index;
    if (offset === FIFO_ST) return this.board.fifos.status(this.index);
    if (offset === FIFO_RD) return this.board.fifos.read(this.index);
    if (offset >= DIV_FIRST && offset <= DIV_LAST) return this.divider.read(offset);
    if (offset >= INTERP_FIRST && offset <= INTERP_LAST) return this.interp.readUint32(offset);
    return this.mcu.sio.readUint32(offset);
  }
  sioWrite(offset, value) {
    if (offset === FIFO_ST) return this.board.fifos.clear(this.index, value);
    if (offset === FIFO_WR) return this.board.fifos.write(this.index, value);
    if (offset >= DIV_FIRST && offset <= DIV_LAST) return this.divider.write(offset, value);
    if (offset >= INTERP_FIRST && offset <= INTERP_LAST) return this.interp.writeUint32(offset, value);
    if (offset === CPUID || offset === FIFO_RD) return;
    this.mcu.sio.writeUint32(offset, value);
  }

  ppbRead(offset) {
    const m = this.mpu;
    switch (offset) {
      case MPU_TYPE: return 8 << 8; // eight regions, unified
      case MPU_CTRL: return m.ctrl;
      case MPU_RNR: return m.rnr;
      case MPU_RBAR: return (m.regions[m.rnr].rbar & ~0x1f) | m.rnr;
      case MPU_RASR: return m.regions[m.rnr].rasr;
    }
    return this.ppb.readUint32(offset);
  }
  ppbWrite(offset, value) {
    const m = this.mpu;
    switch (offset) {
      case MPU_CTRL: m.ctrl = value & 7; return this.updateGuard();
      case MPU_RNR: m.rnr = value & 7; return;
      case MPU_RBAR:
        if (value & 0x10) m.rnr = value & 7; // VALID: the region number comes with the address
        m.regions[m.rnr].rbar = value & ~0xff;
        return this.updateGuard();
      case MPU_RASR: m.regions[m.rnr].rasr = value; return this.updateGuard();
    }
    this.ppb.writeUint32(offset, value);
  }
  /**
   * The one kind of region rp2040-hal programs, a stack guard: an enabled region with no access
   * permissions (AP 0), whose enabled subregions are forbidden. Any other set-up is refused.
   */
  updateGuard() {
    this.guard = null;
    if (!(this.mpu.ctrl & 1)) return;
    for (const r of this.mpu.regions) {
      if (!(r.rasr & 1)) continue;
      const size = 2 ** (((r.rasr >>> 1) & 0x1f) + 1);
      const ap = (r.rasr >>> 24) & 7;
      if (ap !== 0 || size !== 256) throw new Error(`core ${this.index} set up an MPU region this model does not know (RASR 0x${(r.rasr >>> 0).toString(16)})`);
      const srd = (r.rasr >>> 8) & 0xff;
      const base = r.rbar >>> 0;
      for (let s = 0; s < 8; s++) {
        if (!(srd & (1 << s))) {
          if (this.guard) throw new Error(`core ${this.index}: more than one MPU guard subregion`);
          this.guard = [base + s * 32, base + s * 32 + 32];
        }
      }
    }
  }
}

const IC_DATA_CMD = 0x10;
const IC_INTR_MASK = 0x30;
const IC_TX_TL = 0x3c;
const R_TX_EMPTY = 1 << 4;

/**
 * The I2C interrupts as DW_apb_i2c raises them (4.3.17 IC_INTR_MASK, IC_RAW_INTR_STAT): rp2040js
 * keeps IC_INTR_MASK at reset (every interrupt masked) and raises TX_EMPTY only when the
 * controller takes a byte from its FIFO. Here IC_INTR_MASK takes what is written, and TX_EMPTY
 * follows the FIFO's level after every write that can change it: set while at most IC_TX_TL
 * entries wait, clear above, so an interrupt-driven driver that refills the FIFO sees what it
 * would on silicon.
 */
function levelTxEmpty(i2c) {
  const write = i2c.writeUint32.bind(i2c);
  i2c.writeUint32 = (offset, value) => {
    write(offset, value);
    if (offset === IC_INTR_MASK) i2c.intEnable = value & 0x1fff;
    if (offset === IC_INTR_MASK || offset === IC_DATA_CMD || offset === IC_TX_TL) {
      if (i2c.txFIFO.itemCount <= i2c.txThreshold) i2c.setInterrupts(R_TX_EMPTY);
      else i2c.clearInterrupts(R_TX_EMPTY);
      i2c.checkInterrupts();
    }
  };
}

/**
 * An RP2040 with both cores, the XIP cache and timed I2C and SPI buses around rp2040js's chip.
 * `step()` runs one instruction of the core that is behind; `cores[i].cycles` is each core's
 * time, `busy[i]`/`idle[i]` what it did with it.
 */
export class SiliconBoard {
  constructor({ cache = true, dualCore = true } = {}) {
    const mcu = new RP2040();
    this.mcu = mcu;
    this.fifos = new Fifos();
    this.xip = cache ? new XipCache(mcu.peripherals[0x18000]) : null;
    this.dualCore = dualCore;
    this.buses = [new CoreBus(this, 0), new CoreBus(this, 1)];
    const Core = mcu.core.constructor;
    const core1 = new Core(this.buses[1]);
    this.cores = [mcu.core, core1];
    mcu.core.rp2040 = this.buses[0];
    // Private peripherals: core 0 keeps rp2040js's, core 1 gets its own of the same kind.
    this.buses[0].ppb = mcu.ppb;
    this.buses[1].ppb = new mcu.ppb.constructor(this.buses[1], 'PPB core 1');
    // The interpolators: an SIO instance per core (its divider and GPIO are not used).
    this.buses[0].interp = mcu.sio;
    this.buses[1].interp = new mcu.sio.constructor(this.buses[1]);
    // Peripheral interrupts reach both cores' NVICs.
    mcu.setInterrupt = (irq, value) => {
      for (const c of this.cores) c.setInterrupt(irq, value);
    };
    this.held = [false, true]; // core 1 starts with the bootrom, after `start`
    this.busy = [0, 0];
    this.idle = [0, 0];
    this.instructions = [0, 0];
    this.time = 0; // cycles both cores have reached
    this.spklen = [7, 7]; // IC_FS_SPKLEN as written (rp2040js drops odd values)
    this.busCycles = 0; // cycles the display buses spent: I2C START, bytes and STOP; SPI frames
    this.stop = null; // why the run must end
    for (const i2c of mcu.i2c) levelTxEmpty(i2c);
    this.i2cBuses = [null, null]; // each I2C bus's wires and faults (attachI2c)
  }

  loadBootrom(words) {
    this.mcu.loadBootrom(words);
  }

  /** Core 0 at `pc` with stack `sp` (boot2, as the bootrom leaves it); core 1 from the bootrom. */
  start(pc, sp) {
    const [c0] = this.cores;
    c0.SP = sp;
    c0.PC = pc;
    if (this.dualCore) this.resetCore1();
  }

  resetCore1() {
    const c1 = this.cores[1];
    const t = this.cores[0].cycles;
    // What the core's reset does (the bootrom's vector table at 0), with this board's time.
    c1.SP = this.mcu.readUint32(0);
    c1.PC = this.mcu.readUint32(4) & 0xfffffffe;
    c1.cycles = t;
    c1.waiting = false;
    c1.eventRegistered = false;
    c1.VTOR = 0;
    c1.PM = false;
    c1.IPSR = 0;
    c1.enabledInterrupts = 0;
    c1.pendingInterrupts = 0;
    const mpu = this.buses[1].mpu;
    mpu.ctrl = 0;
    for (const r of mpu.regions) r.rasr = 0;
    this.buses[1].guard = null;
    this.held[1] = false;
  }

  /** Writes to the APB peripherals this board reacts to before rp2040js sees them. */
  peripheralWrite(address, value) {
    const base = address & ~0x3000; // the atomic set/clear/xor aliases
    const kind = (address >>> 12) & 3;
    if (base === PSM_FRCE_OFF && this.dualCore) {
      const psm = this.mcu.peripherals[0x40010];
      const before = psm.frceOff;
      const after = [value, before ^ value, before | value, before & ~value][kind];
      if (after & PROC1) this.held[1] = true;
      else if (before & PROC1) this.resetCore1();
    }
    const i = I2C_FS_SPKLEN.indexOf(base);
    if (i >= 0 && kind === 0) this.spklen[i] = value & 0xff;
    if (base === RESETS_RESET) {
      const before = this.mcu.peripherals[0x4000c].reset;
      const after = [value, before ^ value, before | value, before & ~value][kind];
      for (const [n, bit] of RESET_I2C.entries()) if (after & bit && !(before & bit)) this.resetI2c(n);
    }
  }

  /**
   * RESETS puts I2C controller `n` in reset: every register back to its reset value, the
   * transfer under way dropped with every bus event still due for it (a START waiting for a
   * busy bus included). rp2040js's RESETS keeps peripherals as they are; silicon does not.
   */
  resetI2c(n) {
    const i2c = this.mcu.i2c[n];
    const fresh = new i2c.constructor(i2c.rp2040, i2c.name, i2c.irq);
    for (const [k, v] of Object.entries(fresh)) if (typeof v !== 'function') i2c[k] = v;
    i2c.checkInterrupts();
    this.spklen[n] = 7;
    const bus = this.i2cBuses[n];
    if (bus) {
      bus.generation++;
      bus.waiting = false;
    }
  }

  /** SEV on core `from`: both event registers are set; a core asleep in WFE wakes. */
  sev(from) {
    for (let i = 0; i < 2; i++) {
      const c = this.cores[i];
      if (i !== from && c.waiting && this.mcu.readUint16((c.PC - 2) >>> 0) === OP_WFE) c.waiting = false;
      else c.eventRegistered = true;
    }
  }

  onBreak(core, code) {
    this.stop = `core ${core} stopped at a breakpoint or undefined instruction (code ${code}) at pc 0x${(this.cores[core].PC >>> 0).toString(16)}: a panic`;
  }

  /** An access to an address nothing answers at: a bus fault on silicon. */
  unmapped(core, address) {
    const hint = address >= 0x1fff0000 ? ': just below the SRAM, where an overflowing stack goes (flip-link)' : '';
    this.stop ??= `core ${core} accessed 0x${address.toString(16)}, where nothing answers (pc 0x${(this.cores[core].PC >>> 0).toString(16)}): a bus fault${hint}`;
  }

  guardHit(core, address) {
    this.stop ??= `core ${core} touched its stack guard at 0x${address.toString(16)} (pc 0x${(this.cores[core].PC >>> 0).toString(16)}): a stack overflow`;
  }

  /** A HardFault on either core as a sentence (where it stopped), or null. */
  fault() {
    for (const [i, c] of this.cores.entries()) if (c.IPSR === 3) return `HardFault on core ${i} at pc 0x${(c.PC >>> 0).toString(16)}`;
    return null;
  }

  /** Whether core `i` can run an instruction now. */
  runnable(i) {
    return !this.held[i] && !this.cores[i].waiting && (i === 0 || this.dualCore);
  }

  /**
   * Runs one instruction on the runnable core that is behind, and brings the clock (timers,
   * alarms, the I2C bus) up to the time both cores have reached. Returns the core that ran, or
   * -1 when both sleep (the clock then jumps to the next alarm; `false` from `wake()` when there
   * is none).
   */
  step() {
    const [c0, c1] = this.cores;
    const r0 = this.runnable(0);
    const r1 = this.runnable(1);
    let k;
    if (r0 && r1) k = c1.cycles < c0.cycles ? 1 : 0;
    else if (r0) k = 0;
    else if (r1) k = 1;
    else return -1;
    const c = this.cores[k];
    const before = c.cycles;
    c.executeInstruction();
    this.busy[k] += c.cycles - before;
    this.instructions[k]++;
    this.advance();
    return k;
  }

  /** Both cores asleep: the clock jumps to the next alarm. Returns false when there is none. */
  wake() {
    const dt = this.mcu.clock.nanosToNextAlarm;
    if (!(dt > 0) || !Number.isFinite(dt)) return false;
    const cycles = Math.max(1, Math.ceil((dt * this.mcu.clkSys) / 1e9));
    for (let i = 0; i < 2; i++) {
      if (this.held[i] || (i === 1 && !this.dualCore)) continue;
      this.idle[i] += this.time + cycles - this.cores[i].cycles;
      this.cores[i].cycles = this.time + cycles;
    }
    this.advance();
    return true;
  }

  /** Moves the shared time to the slowest running core; sleeping cores keep pace, idle. */
  advance() {
    let t = Infinity;
    for (let i = 0; i < 2; i++) if (this.runnable(i)) t = Math.min(t, this.cores[i].cycles);
    if (t === Infinity) t = Math.max(...this.cores.map((c, i) => (this.held[i] ? 0 : c.cycles)));
    for (let i = 0; i < 2; i++) {
      const c = this.cores[i];
      if (!this.runnable(i) && !this.held[i] && c.cycles < t) {
        this.idle[i] += t - c.cycles;
        c.cycles = t;
      }
    }
    if (t > this.time) {
      this.mcu.clock.tick(((t - this.time) * 1e9) / this.mcu.clkSys);
      this.time = t;
    }
  }

  /** Clock cycles of one SCL period of I2C controller `n`, from the counts the firmware set. */
  sclPeriod(n) {
    const i2c = this.mcu.i2c[n];
    // DW_apb_i2c: SCL high lasts HCNT + SPKLEN + 7 ic_clk, low LCNT + 1; ic_clk is clk_sys.
    return i2c.sclHighPeriod + this.spklen[n] + 7 + i2c.sclLowPeriod + 1;
  }

  /** Runs `fn` once `periods` SCL periods of controller `n` have passed on the bus. */
  afterScl(n, periods, fn) {
    const cycles = periods * this.sclPeriod(n);
    this.busCycles += cycles;
    const nanos = (cycles * 1e9) / this.mcu.clkSys;
    this.mcu.clock.createAlarm(fn).schedule(nanos);
  }

  /**
   * Puts `device` (start, connect, write, stop, interrupted; see ssd1306.mjs) on I2C controller
   * `n`, with the bus's timing unless `timed` is false. `listen` hears each event as the bus
   * finishes it (connect, byte, nack, released). With `pins` ({sda, scl}: GPIO numbers) the
   * two wires are modelled too, pulled up, for firmware that takes the pins as GPIOs: each reads
   * its line's level, and a START or STOP made on them reaches the device. Faults:
   * `holdSda(n, pulses)` and `nackNext(n)`.
   */
  attachI2c(n, device, { timed = true, listen = {}, pins = null } = {}) {
    const i2c = this.mcu.i2c[n];
    // stuck: the falling SCL edges the device needs before it lets SDA go (0: it does not hold
    // it); waiting: a START the controller is holding back for a busy bus; generation: bumped
    // when the controller is reset, so events due for its old transfer are dropped.
    const bus = { device, stuck: 0, nack: false, waiting: false, generation: 0, update: () => {} };
    this.i2cBuses[n] = bus;
    const later = (periods, fn) => {
      const g = bus.generation;
      const run = () => {
        if (g === bus.generation) fn();
      };
      if (timed) this.afterScl(n, periods, run);
      else run();
    };
    const start = () =>
      later(1, () => {
        device?.start();
        i2c.completeStart();
      });
    // SDA held low: to the controller the bus is busy (another master's START), so it sends no
    // START and no clock until it sees a STOP; nothing it sends while SDA is held gets through
    // (it loses arbitration at its first 1 bit).
    i2c.onStart = () => {
      if (bus.stuck > 0) bus.waiting = true;
      else start();
    };
    i2c.onConnect = (address, mode) => {
      later(9, () => {
        if (bus.stuck > 0) return i2c.arbitrationLost();
        const ack = device ? device.connect(address, mode === 1) : false;
        listen.connect?.(ack);
        i2c.completeConnect(ack);
      });
    };
    i2c.onWriteByte = (value) => {
      later(9, () => {
        if (bus.stuck > 0) return i2c.arbitrationLost();
        if (bus.nack) {
          // The device does not take this byte: what it held of a command is dropped.
          bus.nack = false;
          device?.interrupted();
          listen.nack?.();
          return i2c.completeWrite(false);
        }
        listen.byte?.(value);
        i2c.completeWrite(device ? device.write(value) : false);
      });
    };
    i2c.onReadByte = () => later(9, () => i2c.completeRead(0xff));
    i2c.onStop = () => {
      later(1, () => {
        device?.stop();
        i2c.completeStop();
      });
    };
    if (pins) this.wireI2c(bus, device, pins, { start, listen });
  }

  /**
   * The SDA and SCL wires of `bus` on GPIOs `sda` and `scl`: a line is low when the chip drives
   * its pin low (SIO, output enabled) or, for SDA, while the device holds it; each falling SCL
   * edge shifts a holding device on by a bit. SDA falling while SCL is high is a START, rising a
   * STOP; a STOP frees the bus for a START the controller held back.
   */
  wireI2c(bus, device, { sda, scl }, { start, listen }) {
    const [sdaPin, sclPin] = [this.mcu.gpio[sda], this.mcu.gpio[scl]];
    let line = { sda: true, scl: true, held: false };
    bus.update = () => {
      const sclHigh = sclPin.value !== GPIOPinState.Low;
      if (!sclHigh && line.scl && bus.stuck > 0 && --bus.stuck === 0) listen.released?.();
      const held = bus.stuck > 0;
      const sdaHigh = sdaPin.value !== GPIOPinState.Low && !held;
      // A START or STOP is the chip's doing: the device taking SDA is not one to itself.
      if (sclHigh && line.scl && sdaHigh !== line.sda && held === line.held) {
        if (!sdaHigh) device?.start();
        else {
          device?.stop();
          if (bus.waiting) {
            bus.waiting = false;
            start();
          }
        }
      }
      line = { sda: sdaHigh, scl: sclHigh, held };
      sdaPin.setInputValue(sdaHigh);
      sclPin.setInputValue(sclHigh);
    };
    sdaPin.addListener(bus.update);
    sclPin.addListener(bus.update);
    bus.update();
  }

  /**
   * The device on I2C bus `n` holds SDA low (its transfer cut off in the middle of a byte)
   * until it has seen `pulses` falling SCL edges (1 to 9: the rest of its byte).
   */
  holdSda(n, pulses) {
    const bus = this.i2cBuses[n];
    bus.stuck = pulses;
    bus.device?.interrupted();
    bus.update();
  }

  /** The device on I2C bus `n` does not acknowledge the next byte written to it. */
  nackNext(n) {
    this.i2cBuses[n].nack = true;
  }

  /** Clock cycles (clk_sys) one frame of SPI controller `n` takes on its bus, from its registers. */
  spiFrameCycles(n) {
    const spi = this.mcu.spi[n];
    // PL022: SSPCLKOUT = clk_peri / (CPSDVSR * (1 + SCR)); a frame is DSS + 1 of its periods.
    const scr = (spi.control0 >> 8) & 0xff;
    const periCycles = spi.dataBits * spi.clockDivisor * (1 + scr);
    return Math.ceil((periCycles * this.mcu.clkSys) / this.mcu.clkPeri);
  }

  /**
   * Puts `device` (spiByte, reset; see ssd1306.mjs) on SPI controller `n` as a 4-wire module
   * wires it: chip select on GPIO `cs` (active low: bytes sent while it is high are not heard),
   * data/command on GPIO `dc` (sampled as each byte completes, as the SSD1306 latches it on the
   * last SCLK edge) and reset on GPIO `res` (low resets the controller). A Sharp memory LCD
   * (sharp.mjs) is wired with `csActiveHigh`, no `dc` nor `res`, and its DISP on GPIO `disp`:
   * it hears its chip select's changes (`select`) and DISP's (`display`). Each byte takes the
   * time the controller's clock divisors give, unless `timed` is false; `listen.byte` hears
   * each byte as the bus finishes it.
   */
  attachSpi(n, device, { cs, dc = null, res = null, disp = null, csActiveHigh = false, timed = true, listen = {} }) {
    const spi = this.mcu.spi[n];
    const high = (pin) => this.mcu.gpio[pin].value === GPIOPinState.High;
    const selected = () => high(cs) === csActiveHigh;
    spi.onTransmit = (value) => {
      const deliver = () => {
        if (device && selected()) {
          listen.byte?.(value);
          device.spiByte(value & 0xff, dc !== null && high(dc));
        }
        spi.completeTransmit(0);
      };
      if (!timed) return deliver();
      const cycles = this.spiFrameCycles(n);
      this.busCycles += cycles;
      this.mcu.clock.createAlarm(deliver).schedule((cycles * 1e9) / this.mcu.clkSys);
    };
    if (!device) return;
    if (res !== null) {
      this.mcu.gpio[res].addListener((state) => {
        if (state === GPIOPinState.Low) device.reset();
      });
    }
    if (device.select) this.mcu.gpio[cs].addListener(() => device.select(selected()));
    if (disp !== null && device.display) this.mcu.gpio[disp].addListener(() => device.display(high(disp)));
  }

  gpio(pin) {
    return this.mcu.gpio[pin];
  }

  /** Counters a frame report takes differences of. */
  snapshot() {
    return {
      cycles: this.time,
      busy: [...this.busy],
      idle: [...this.idle],
      instructions: this.instructions[0] + this.instructions[1],
      coreInstructions: [...this.instructions],
      nanos: this.mcu.clock.nanos,
      busCycles: this.busCycles,
      xip: this.xip ? this.xip.counters() : { hits: 0, misses: 0, uncached: 0, stallCycles: 0 },
    };
  }
}

/** Writes the blocks of a UF2 file (microsoft/uf2) into flash; returns the bytes written. */
export function loadUf2(mcu, data) {
  let written = 0;
  for (let off = 0; off + 512 <= data.length; off += 512) {
    const v = new DataView(data.buffer, data.byteOffset + off, 512);
    if (v.getUint32(0, true) !== 0x0a324655 || v.getUint32(4, true) !== 0x9e5d5157 || v.getUint32(508, true) !== 0x0ab16f30) {
      throw new Error(`UF2 block at byte ${off}: bad magic`);
    }
    const flags = v.getUint32(8, true);
    if (flags & 1) continue; // not for the main flash
    if ((flags & 0x2000) && v.getUint32(28, true) !== 0xe48bff56) throw new Error(`UF2 block at byte ${off}: not for the RP2040 family`);
    const addr = v.getUint32(12, true);
    const size = v.getUint32(16, true);
    if (addr < FLASH || addr + size > FLASH + mcu.flash.length || size > 476) throw new Error(`UF2 block at byte ${off}: ${size} bytes at ${addr.toString(16)} outside the flash`);
    mcu.flash.set(data.subarray(off + 32, off + 32 + size), addr - FLASH);
    written += size;
  }
  if (written === 0) throw new Error('UF2 file holds no flash blocks');
  return written;
}

export { GPIOPinState };
