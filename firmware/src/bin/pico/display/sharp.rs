//! A Sharp memory LCD (LS027B7DH01, 400x240; LS013B7DH03, 128x128) as the render loop's draw
//! target, on SPI0 with its chip select active high (the `sharp-400x240` and `sharp-128x128`
//! features). The LCD keeps what it was sent and takes whole lines: each band of tiles is
//! gathered here (parts of a band wait for the rest) and sent as line writes once its last
//! column is in: the mode byte (M0 write, M1 VCOM), then per line its address, its pixels and
//! a dummy byte, then a dummy byte. The LCD takes every byte LSB first and SPI0 sends MSB first,
//! so the mode and address bytes are sent bit-reversed, and the pixels packed leftmost pixel in
//! the top bit (1: white). VCOM must be inverted at least once a second or the picture
//! degrades: every command carries it, inverted every [`VCOM_US`], and between frames the
//! probe sends a display-mode command when an inversion is due.

use super::{Band, SetUp, BAND_ROWS};
use crate::wiring::Interface;
use display_interface::DisplayError;
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiBus;
use firmware::app::{HEIGHT, WIDTH};

/// Bytes of one line's pixels.
const LINE: usize = WIDTH as usize / 8;
/// How often VCOM is inverted: twice a second (the LCD needs it at least once a second).
const VCOM_US: u32 = 500_000;
/// The mode byte's bits as sent (bit-reversed: M0 is the LCD's first bit): write lines.
const WRITE: u8 = 0x80;
/// M1: VCOM's level.
const VCOM: u8 = 0x40;
/// M2: clear the whole memory (white).
const CLEAR: u8 = 0x20;
/// Clock cycles of the chip select's set-up before the first clock (3 µs) and hold after the
/// last (1 µs), at 125 MHz.
const SCS_SETUP: u32 = 375;
/// See [`SCS_SETUP`].
const SCS_HOLD: u32 = 125;

const _: () =
    assert!(WIDTH.is_multiple_of(8) && HEIGHT <= 255, "a Sharp LCD line is whole bytes, its address one byte");

/// Gathers each band of tiles until its last column is in, then writes its lines.
pub struct LineTiles {
    bus: Interface,
    /// The band being gathered: [`LINE`] bytes a row.
    band: [u8; LINE * BAND_ROWS],
    /// VCOM's level and when it was last inverted (the timer's microseconds).
    vcom: (bool, u32),
    /// The memory has been cleared since power-on (it starts with noise).
    cleared: bool,
}

impl LineTiles {
    /// The LCD on `bus`, not yet shown (DISP low) and not yet cleared.
    pub fn new(bus: Interface) -> Self {
        LineTiles { bus, band: [0; LINE * BAND_ROWS], vcom: (false, crate::sleep::micros()), cleared: false }
    }

    /// The mode byte `mode` with VCOM, inverted first if [`VCOM_US`] have passed.
    fn mode(&mut self, mode: u8) -> u8 {
        let now = crate::sleep::micros();
        if now.wrapping_sub(self.vcom.1) >= VCOM_US {
            self.vcom = (!self.vcom.0, now);
        }
        mode | if self.vcom.0 { VCOM } else { 0 }
    }

    /// One command: the chip select high around `bytes`' parts.
    fn command(&mut self, parts: &[&[u8]]) {
        let bus = &mut self.bus;
        // The pins' and the bus's error type is Infallible.
        let _ = bus.cs.set_high();
        cortex_m::asm::delay(SCS_SETUP);
        for part in parts {
            let _ = bus.spi.write(part);
        }
        let _ = bus.spi.flush();
        cortex_m::asm::delay(SCS_HOLD);
        let _ = bus.cs.set_low();
    }

    /// Writes the gathered band's first `rows` rows as lines from row `y0`.
    fn write_lines(&mut self, y0: usize, rows: usize) {
        let mode = self.mode(WRITE);
        let bus = &mut self.bus;
        let _ = bus.cs.set_high();
        cortex_m::asm::delay(SCS_SETUP);
        let _ = bus.spi.write(&[mode]);
        for (r, line) in self.band.chunks(LINE).take(rows).enumerate() {
            let _ = bus.spi.write(&[((y0 + r + 1) as u8).reverse_bits()]);
            let _ = bus.spi.write(line);
            let _ = bus.spi.write(&[0]);
        }
        let _ = bus.spi.write(&[0]);
        let _ = bus.spi.flush();
        cortex_m::asm::delay(SCS_HOLD);
        let _ = bus.cs.set_low();
    }
}

impl SetUp for LineTiles {
    /// DISP high and, once after power-on, the memory cleared (it starts with noise). The LCD
    /// has nothing else to set up and SPI cannot tell whether it is there.
    fn set_up(&mut self) -> Result<(), DisplayError> {
        let _ = self.bus.disp.set_high();
        if !self.cleared {
            let mode = self.mode(CLEAR);
            self.command(&[&[mode, 0]]);
            self.cleared = true;
        }
        Ok(())
    }

    /// VCOM inverted when it is due (a display-mode command); the LCD cannot answer.
    fn answers(&mut self) -> bool {
        let before = self.vcom.0;
        let mode = self.mode(0);
        if self.vcom.0 != before {
            self.command(&[&[mode, 0]]);
        }
        true
    }
}

impl Band for LineTiles {
    fn band(
        &mut self,
        (x0, y0): (usize, usize),
        (w, h): (usize, usize),
        colors: &mut dyn Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError> {
        for y in 0..h {
            let row = &mut self.band[y * LINE..(y + 1) * LINE];
            for x in x0..x0 + w {
                let bit = 0x80 >> (x % 8);
                if colors.next().is_some_and(|c| c.is_on()) {
                    row[x / 8] |= bit;
                } else {
                    row[x / 8] &= !bit;
                }
            }
        }
        if x0 + w == LINE * 8 {
            self.write_lines(y0, h);
        }
        Ok(())
    }
}
