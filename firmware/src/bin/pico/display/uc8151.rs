//! The Badger 2040's e-paper, a UC8151 (IL0373) with 296x128 glass, on SPI0 (the `uc8151`
//! feature; its CS, DC and RES where the SPI modules have theirs, BUSY on GP26). The glass keeps
//! its picture without power and a refresh takes most of a second, so the frame is gathered in
//! RAM in the controller's order (for each of the 296 gates, the glass's columns, 16 bytes of
//! its rows, 1 white) and sent whole when it is finished: then the refresh starts and the cores
//! go on with the next frame while it runs; the next frame's bytes wait for BUSY to go high.
//! The waveform is in registers (a short one: 93 frames at 100 Hz, 0.93 s), so the refresh's
//! length is known and not the OTP's 4.5 s.
//!
//! Only what changed is refreshed: the bands note the gates and source bytes whose pixels
//! changed since the frame on the glass ([`Changed`]), and a frame sends that window alone as
//! a partial refresh (PTIN, PTL, its bytes, DRF; PTOUT before the next command that is not),
//! or nothing at all when no pixel changed, so a scene drawn again does not flash the glass.
//! The first frame after reset, and one whose changes span the glass, are refreshed whole.

use super::{Band, SetUp};
use crate::bus::Interface;
use crate::wiring::Wiring;
use display_interface::{DataFormat, DisplayError, WriteOnlyDataCommand};
use embedded_graphics_core::pixelcolor::BinaryColor;
use firmware::app::{HEIGHT, WIDTH};

/// Bytes of one gate (one column of the glass).
const STRIDE: usize = HEIGHT as usize / 8;
/// Bytes of the controller's RAM: the whole frame.
const RAM: usize = WIDTH as usize * STRIDE;

const _: () = assert!(WIDTH == 296 && HEIGHT == 128, "the UC8151's glass is 296x128");

// Orbit mode's image at 296x128 left core 0 3.5 KiB of stack on the RP2040 and faulted at boot
// (with core 1's stack at 32 KiB; it is 16 KiB in images that set scenes up on the board now,
// and orbit at 296x128 has not been tried since).
#[cfg(feature = "orbit")]
compile_error!("orbit mode at the e-paper's 296x128 does not fit the RP2040's RAM");
// So does a scene parsed and its lattice built on the board (the `parse` and `slot` images)
// with the tracer's code in RAM: the linker would refuse it with the stack's end above its
// start. With the code in flash (`code-in-flash`) it fits, and the camera turns.
#[cfg(all(feature = "parse", not(feature = "code-in-flash")))]
compile_error!("a scene parsed on the board at the e-paper's 296x128 (`parse`) does not fit the RP2040's RAM with the code in RAM: add `code-in-flash` (the code then runs from flash, through the XIP cache)");
// The slot image (which has its code in flash) stays refused: `host-sim uf2 --scene` checks a
// slot's scene at 128x64, and no run checks the slot at 296x128.
#[cfg(feature = "slot")]
compile_error!("the scene slot (`slot`) is not built for the e-paper's 296x128: `host-sim uf2 --scene` checks the slot's scenes at 128x64");

/// Panel setting: 128x296, the waveform from registers, black and white, shift right and scan
/// down (the Badger's upright picture), booster on, no soft reset.
const PSR: u8 = 0x80 | 0x20 | 0x10 | 0x04 | 0x02 | 0x01;
/// A waveform group's phase times in frames and its repeat count (the LUT's bytes 1 to 5).
const PHASES: [[u8; 5]; 3] = [[4, 4, 7, 0, 1], [12, 12, 0, 0, 2], [4, 4, 7, 0, 2]];

/// A LUT of the three groups of [`PHASES`] with the level selections `levels`, `N` bytes long
/// (the VCOM LUT has two more than the others).
const fn lut<const N: usize>(levels: [u8; 3]) -> [u8; N] {
    let mut out = [0u8; N];
    let mut g = 0;
    while g < 3 {
        out[g * 6] = levels[g];
        let mut i = 0;
        while i < 5 {
            out[g * 6 + 1 + i] = PHASES[g][i];
            i += 1;
        }
        g += 1;
    }
    out
}

/// VCOM's waveform.
const LUT_VCOM: [u8; 44] = lut([0, 0, 0]);
/// A pixel that ends white (from white or black).
const LUT_TO_WHITE: [u8; 42] = lut([0x54, 0x60, 0xa8]);
/// A pixel that ends black.
const LUT_TO_BLACK: [u8; 42] = lut([0xa8, 0x60, 0x54]);

/// The set-up after the reset, command by command with its parameters; then PON.
const SET_UP: [(u8, &[u8]); 13] = [
    (0x00, &[PSR]),
    // Power: internal source and gate voltages, VGH/VGL 16 V, VSH/VSL and VSHR 11 V.
    (0x01, &[0x03, 0x00, 0x2b, 0x2b, 0x2b]),
    // Booster soft start: 10 ms, strength 3, off time 6.58 us, for each phase.
    (0x06, &[0x17, 0x17, 0x17]),
    // Power off sequence: one frame.
    (0x03, &[0x00]),
    // The internal temperature sensor.
    (0x41, &[0x00]),
    // Source and gate non-overlap.
    (0x60, &[0x22]),
    // VCOM and data interval; data polarity as written (1 white).
    (0x50, &[0x4c]),
    // 100 frames a second.
    (0x30, &[0x3a]),
    (0x20, &LUT_VCOM),
    (0x21, &LUT_TO_WHITE),
    (0x22, &LUT_TO_WHITE),
    (0x23, &LUT_TO_BLACK),
    (0x24, &LUT_TO_BLACK),
];
/// Power on.
const PON: u8 = 0x04;
/// Data start transmission 2 (the new picture).
const DTM2: u8 = 0x13;
/// Data stop.
const DSP: u8 = 0x11;
/// Display refresh.
const DRF: u8 = 0x12;
/// Partial window: its first and last source (whole bytes), first and last gate (two bytes
/// each), and the gate scan's extent.
const PTL: u8 = 0x90;
/// Partial mode in: refreshes and data go to the window alone.
const PTIN: u8 = 0x91;
/// Partial mode out.
const PTOUT: u8 = 0x92;
/// PTL's last byte, PT_SCAN: the gates scan inside and outside the window (the window's
/// pixels get the waveform; those outside keep their picture).
const PT_SCAN: u8 = 0x01;

/// The gates (columns) and source bytes (8 rows each) holding a pixel that changed since the
/// frame on the glass: inclusive ranges, empty while the first is past the last.
#[derive(Clone, Copy)]
struct Changed {
    gates: (u16, u16),
    bytes: (u8, u8),
}

impl Changed {
    /// No pixel changed.
    const NONE: Changed = Changed { gates: (u16::MAX, 0), bytes: (u8::MAX, 0) };
    /// The whole glass.
    const ALL: Changed = Changed { gates: (0, WIDTH - 1), bytes: (0, STRIDE as u8 - 1) };

    /// Gate `x`'s source byte `byte` changed.
    fn include(&mut self, x: usize, byte: usize) {
        let (x, byte) = (x as u16, byte as u8);
        self.gates = (self.gates.0.min(x), self.gates.1.max(x));
        self.bytes = (self.bytes.0.min(byte), self.bytes.1.max(byte));
    }

    /// Whether no pixel changed.
    fn is_empty(&self) -> bool {
        self.gates.0 > self.gates.1
    }

    /// Whether the window is the whole glass.
    fn is_all(&self) -> bool {
        self.gates == Changed::ALL.gates && self.bytes == Changed::ALL.bytes
    }
}

/// The e-paper: the frame gathered in RAM, sent at its end.
pub struct Gates {
    bus: Interface,
    /// The frame in the controller's order (a static: 4.6 KiB off core 0's stack). Between
    /// frames it is the frame on the glass, which the next frame's bands are told from.
    ram: &'static mut [u8; RAM],
    /// Set up and powered on since reset.
    ready: bool,
    /// A frame has been refreshed whole since reset: the glass shows `ram`.
    shown: bool,
    /// The controller is in partial mode (the last refresh was partial).
    partial: bool,
    /// Where this frame differs from the glass.
    changed: Changed,
}

/// Whether the controller works (BUSY low: powering on or refreshing).
fn busy() -> bool {
    // SAFETY: a read of SIO's GPIO inputs, which has no side effects.
    #[allow(unsafe_code)]
    let levels = unsafe { (*crate::hal::pac::SIO::ptr()).gpio_in().read().bits() };
    levels & (1 << Wiring::BUSY) == 0
}

/// Waits until BUSY is high, the watchdog fed.
fn wait() {
    while busy() {
        crate::guard::feed();
    }
}

impl Gates {
    /// The e-paper on `bus`, not yet set up.
    pub fn new(bus: Interface) -> Self {
        let Some(ram) = cortex_m::singleton!(: [u8; RAM] = [0; RAM]) else {
            defmt::panic!("the e-paper's frame is taken");
        };
        Gates { bus, ram, ready: false, shown: false, partial: false, changed: Changed::NONE }
    }

    /// Command `c` with its parameters `p`.
    fn command(&mut self, c: u8, p: &[u8]) -> Result<(), DisplayError> {
        self.bus.send_commands(DataFormat::U8(&[c]))?;
        if p.is_empty() {
            return Ok(());
        }
        self.bus.send_data(DataFormat::U8(p))
    }
}

impl SetUp for Gates {
    /// Once after reset: the panel's settings and waveform, and power on. Later frames need
    /// nothing: the glass keeps its picture, and a command now could land in a refresh.
    fn set_up(&mut self) -> Result<(), DisplayError> {
        if self.ready {
            return Ok(());
        }
        wait();
        for (c, p) in SET_UP {
            self.command(c, p)?;
        }
        self.command(PON, &[])?;
        wait();
        self.ready = true;
        Ok(())
    }

    /// SPI cannot tell; the glass keeps its picture without power.
    fn answers(&mut self) -> bool {
        true
    }

    /// The frame's changes to the controller once the last refresh has ended, and their
    /// refresh started (the cores go on while it runs): the whole frame the first time, the
    /// window of its changes after, nothing when it is the frame on the glass.
    fn flush(&mut self) -> Result<(), DisplayError> {
        let changed = if self.shown { core::mem::replace(&mut self.changed, Changed::NONE) } else { Changed::ALL };
        if changed.is_empty() {
            defmt::info!("e-paper: the glass shows this frame already, no refresh");
            return Ok(());
        }
        wait();
        let partial = !changed.is_all();
        if self.partial && !partial {
            self.command(PTOUT, &[])?;
        }
        if partial {
            let ((g0, g1), (b0, b1)) = (changed.gates, changed.bytes);
            let [v0h, v0l] = g0.to_be_bytes();
            let [v1h, v1l] = g1.to_be_bytes();
            self.command(PTIN, &[])?;
            self.command(PTL, &[b0 * 8, b1 * 8 + 7, v0h, v0l, v1h, v1l, PT_SCAN])?;
            self.bus.send_commands(DataFormat::U8(&[DTM2]))?;
            for x in usize::from(g0)..=usize::from(g1) {
                let gate = x * STRIDE;
                self.bus.send_data(DataFormat::U8(&self.ram[gate + usize::from(b0)..=gate + usize::from(b1)]))?;
            }
            defmt::info!("e-paper: partial refresh of gates {}..={}, rows {}..={}", g0, g1, b0 * 8, b1 * 8 + 7);
        } else {
            self.bus.send_commands(DataFormat::U8(&[DTM2]))?;
            self.bus.send_data(DataFormat::U8(&self.ram[..]))?;
        }
        self.command(DSP, &[])?;
        self.command(DRF, &[])?;
        (self.shown, self.partial, self.changed) = (true, partial, Changed::NONE);
        Ok(())
    }
}

impl Band for Gates {
    fn band(
        &mut self,
        (x0, y0): (usize, usize),
        (w, h): (usize, usize),
        mut colors: impl Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError> {
        for y in y0..y0 + h {
            let (byte, bit) = (y / 8, 0x80u8 >> (y % 8));
            for x in x0..x0 + w {
                let at = &mut self.ram[x * STRIDE + byte];
                let was = *at;
                if colors.next().is_some_and(|c| c.is_on()) {
                    *at |= bit;
                } else {
                    *at &= !bit;
                }
                if *at != was {
                    self.changed.include(x, byte);
                }
            }
        }
        Ok(())
    }
}
