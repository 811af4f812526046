//! A Sharp memory LCD (LS027B7DH01, 400x240; LS013B7DH03, 128x128) as the render loop's draw
//! target, on SPI0 with its chip select active high (the `sharp-400x240` and `sharp-128x128`
//! features). The LCD keeps what it was sent and takes whole lines: each band of tiles is
//! gathered here (parts of a band wait for the rest) and sent as line writes once its last
//! column is in: the mode byte (M0 write, M1 VCOM), then per line its address, its pixels and
//! a dummy byte, then a dummy byte. The LCD takes every byte LSB first and SPI0 sends MSB first,
//! so the mode and address bytes are sent bit-reversed, and the pixels packed leftmost pixel in
//! the top bit (1: white). VCOM must be inverted at least once a second or the picture
//! degrades: every command carries it, inverted every [`VCOM_US`], and between frames the
//! probe sends a display-mode command when an inversion is due. A band's line writes are built
//! in one buffer and sent by DMA (channel 0, paced by SPI0's TX requests) while the cores trace
//! on: at 2 MHz a 400x240 frame's 12.5 KB take 6.4 M cycles, which core 0 no longer waits out.

use super::{Band, SetUp, BAND_ROWS};
use crate::hal;
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
/// The system clock in MHz (rp2040-hal's and rp235x-hal's default clocks).
const CLK_MHZ: u32 = if cfg!(feature = "pico2") { 150 } else { 125 };
/// The chip select's set-up before the first clock, in microseconds.
const SCS_SETUP_US: u32 = 3;
/// Clock cycles of the chip select's set-up (3 µs) and of its hold after the last clock (1 µs).
const SCS_SETUP: u32 = SCS_SETUP_US * CLK_MHZ;
/// See [`SCS_SETUP`].
const SCS_HOLD: u32 = CLK_MHZ;

const _: () =
    assert!(WIDTH.is_multiple_of(8) && HEIGHT <= 255, "a Sharp LCD line is whole bytes, its address one byte");

/// Bytes of one band's line writes: the mode byte, per line its address, its pixels and a dummy
/// byte, and the final dummy byte.
const COMMAND: usize = 1 + BAND_ROWS * (LINE + 2) + 1;

/// Where line `r`'s pixels start in the command.
const fn pixels(r: usize) -> usize {
    1 + r * (LINE + 2) + 1
}

/// The DMA channel the line writes go by.
const CHANNEL: usize = 0;
/// TREQ_SEL: SPI0's TX requests.
const DREQ_SPI0_TX: u8 = 16;

/// Gathers each band of tiles until its last column is in, then writes its lines.
pub struct LineTiles {
    bus: Interface,
    /// The band's line writes, built in place as its parts come and sent from here by DMA
    /// (a static, so no move of this value can pull it from under the DMA's reads).
    command: &'static mut [u8; COMMAND],
    /// A command is on its way (chip select high until it ends: [`LineTiles::finish`]).
    sending: bool,
    /// VCOM's level and when it was last inverted (the timer's microseconds).
    vcom: (bool, u32),
    /// The memory has been cleared since power-on (it starts with noise).
    cleared: bool,
}

impl LineTiles {
    /// The LCD on `bus`, not yet shown (DISP low) and not yet cleared; the DMA block out of
    /// reset and SPI0's TX requests on.
    pub fn new(bus: Interface) -> Self {
        let Some(command) = cortex_m::singleton!(: [u8; COMMAND] = [0; COMMAND]) else {
            defmt::panic!("the Sharp LCD's command buffer is taken");
        };
        // SAFETY: RESETS' DMA bit (nothing else in the image uses the DMA) and SPI0's DMA
        // control, which the HAL's SPI driver leaves alone.
        #[allow(unsafe_code)]
        unsafe {
            let resets = &*hal::pac::RESETS::ptr();
            resets.reset().modify(|_, w| w.dma().clear_bit());
            while resets.reset_done().read().dma().bit_is_clear() {}
            (*hal::pac::SPI0::ptr()).sspdmacr().modify(|_, w| w.txdmae().set_bit());
        }
        LineTiles { bus, command, sending: false, vcom: (false, crate::sleep::micros()), cleared: false }
    }

    /// The mode byte `mode` with VCOM, inverted first if [`VCOM_US`] have passed.
    fn mode(&mut self, mode: u8) -> u8 {
        let now = crate::sleep::micros();
        if now.wrapping_sub(self.vcom.1) >= VCOM_US {
            self.vcom = (!self.vcom.0, now);
        }
        mode | if self.vcom.0 { VCOM } else { 0 }
    }

    /// One short command (a clear, a display-mode command), sent without DMA once the last
    /// has ended.
    fn command(&mut self, bytes: &[u8]) {
        self.finish();
        let bus = &mut self.bus;
        // The pins' and the bus's error type is Infallible.
        let _ = bus.cs.set_high();
        cortex_m::asm::delay(SCS_SETUP);
        let _ = bus.spi.write(bytes);
        let _ = bus.spi.flush();
        cortex_m::asm::delay(SCS_HOLD);
        let _ = bus.cs.set_low();
    }

    /// Starts the line writes of the gathered band's first `rows` rows, from row `y0`, by DMA.
    fn send_lines(&mut self, y0: usize, rows: usize) {
        // The chip select's set-up time passes while the lines' addresses are written.
        let _ = self.bus.cs.set_high();
        let raised = crate::sleep::micros();
        let mode = self.mode(WRITE);
        self.command[0] = mode;
        for r in 0..rows {
            self.command[pixels(r) - 1] = ((y0 + r + 1) as u8).reverse_bits();
            self.command[pixels(r) + LINE] = 0;
        }
        // The rows' lines and the final dummy byte (where a next row's address would be).
        let len = pixels(rows);
        self.command[len - 1] = 0;
        // 3 µs at least: the timer counts whole microseconds, so 4 of its ticks.
        while crate::sleep::micros().wrapping_sub(raised) < SCS_SETUP_US + 1 {}
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
        // SAFETY: channel 0 reads `len` bytes of the static command buffer, which nothing
        // writes until `finish` has seen the channel stop, into SPI0's data register, paced by
        // its TX requests.
        #[allow(unsafe_code)]
        unsafe {
            let ch = (*hal::pac::DMA::ptr()).ch(CHANNEL);
            ch.ch_read_addr().write(|w| w.bits(self.command.as_ptr() as u32));
            ch.ch_write_addr().write(|w| w.bits((*hal::pac::SPI0::ptr()).sspdr().as_ptr() as u32));
            ch.ch_trans_count().write(|w| w.bits(len as u32));
            ch.ch_ctrl_trig().write(|w| {
                w.data_size().size_byte().incr_read().set_bit().treq_sel().bits(DREQ_SPI0_TX);
                w.chain_to().bits(CHANNEL as u8).en().set_bit()
            });
        }
        self.sending = true;
    }

    /// Ends the command on its way: waits for the DMA and the bus, lets the chip select go and
    /// empties SPI0's receive FIFO (the DMA only sends).
    fn finish(&mut self) {
        if !self.sending {
            return;
        }
        // SAFETY: reads of channel 0's and SPI0's status, and of SPI0's data register (what it
        // received, which nothing wants), and a write of its interrupt clear register.
        #[allow(unsafe_code)]
        unsafe {
            let (dma, spi) = (&*hal::pac::DMA::ptr(), &*hal::pac::SPI0::ptr());
            while dma.ch(CHANNEL).ch_ctrl_trig().read().busy().bit_is_set() {}
            while spi.sspsr().read().bsy().bit_is_set() {}
            while spi.sspsr().read().rne().bit_is_set() {
                spi.sspdr().read();
            }
            spi.sspicr().write(|w| w.roric().clear_bit_by_one());
        }
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
        cortex_m::asm::delay(SCS_HOLD);
        let _ = self.bus.cs.set_low();
        self.sending = false;
    }
}

impl SetUp for LineTiles {
    /// DISP high and, once after power-on, the memory cleared (it starts with noise). The LCD
    /// has nothing else to set up and SPI cannot tell whether it is there.
    fn set_up(&mut self) -> Result<(), DisplayError> {
        let _ = self.bus.disp.set_high();
        if !self.cleared {
            let mode = self.mode(CLEAR);
            self.command(&[mode, 0]);
            self.cleared = true;
        }
        Ok(())
    }

    /// VCOM inverted when it is due (a display-mode command); the LCD cannot answer.
    fn answers(&mut self) -> bool {
        let before = self.vcom.0;
        let mode = self.mode(0);
        if self.vcom.0 != before {
            self.command(&[mode, 0]);
        }
        true
    }

    /// The last band's line writes ended.
    fn flush(&mut self) -> Result<(), DisplayError> {
        self.finish();
        Ok(())
    }
}

impl Band for LineTiles {
    fn band(
        &mut self,
        (x0, y0): (usize, usize),
        (w, h): (usize, usize),
        mut colors: impl Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError> {
        self.finish();
        for y in 0..h {
            let row = &mut self.command[pixels(y)..pixels(y) + LINE];
            // A byte at a time: the area's pixels in it gathered, then merged (a band's parts
            // start on tiles, so nearly every byte is whole).
            let mut x = x0;
            while x < x0 + w {
                let (first, n) = (x % 8, (8 - x % 8).min(x0 + w - x));
                let mut bits = 0u8;
                for i in 0..n {
                    if colors.next().is_some_and(|c| c.is_on()) {
                        bits |= 0x80 >> (first + i);
                    }
                }
                let mask = ((0xffu16 >> first) & !(0xffu16 >> (first + n))) as u8;
                row[x / 8] = (row[x / 8] & !mask) | bits;
                x += n;
            }
        }
        if x0 + w == LINE * 8 {
            self.send_lines(y0, h);
        }
        Ok(())
    }
}
