//! A Sharp memory LCD (LS027B7DH01, 400x240; LS013B7DH03, 128x128) as the render loop's draw
//! target, on SPI0 with its chip select active high (the `sharp-400x240` and `sharp-128x128`
//! features). The LCD keeps what it was sent and takes whole lines: each band of tiles is
//! gathered here (parts of a band wait for the rest) and sent as line writes once its last
//! column is in: the mode byte (M0 write, M1 VCOM), then per line its address, its pixels and
//! a dummy byte, then a dummy byte. The LCD takes every byte LSB first and SPI0 sends MSB first,
//! so the mode and address bytes are sent bit-reversed, and the pixels packed leftmost pixel in
//! the top bit (1: white). VCOM must be inverted at least once a second or the picture
//! degrades, whatever the cores are doing (a band of a slow scene can take longer than that):
//! timer alarm 1's interrupt on core 0 inverts it every [`VCOM_US`] with a display-mode command,
//! a millisecond later when a band's lines are still on the bus, and every command carries its
//! level. A band's line writes are built in one buffer and sent by DMA (channel 0, paced by
//! SPI0's TX requests) while the cores trace on: at 2 MHz a 400x240 frame's 12.5 KB take 6.4 M
//! cycles, which core 0 no longer waits out. The bus is the interrupt's and the render loop's
//! in turn: each touches it with core 0's interrupts masked.

use super::{Band, SetUp};
use crate::bus::Interface;
use crate::bus::BAND_ROWS;
use crate::hal;
use core::cell::RefCell;
use cortex_m::interrupt::Mutex;
use display_interface::DisplayError;
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiBus;
use firmware::app::{HEIGHT, WIDTH};
use hal::pac::interrupt;

/// Bytes of one line's pixels.
const LINE: usize = WIDTH as usize / 8;
/// How often VCOM is inverted: twice a second (the LCD needs it at least once a second).
const VCOM_US: u32 = 500_000;
/// How soon the interrupt tries again when a band's lines are still on the bus (they take at
/// most 3.4 ms: 832 bytes at 2 MHz).
const RETRY_US: u32 = 1_000;
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

/// The LCD's bus and what the VCOM interrupt shares with the render loop (core 0's alone).
struct Lcd {
    bus: Interface,
    /// A band's line writes are on their way by DMA (chip select high until [`Lcd::end`]).
    sending: bool,
    /// VCOM's level, which every command carries.
    vcom: bool,
}

/// The LCD, once [`LineTiles::new`] has it.
static LCD: Mutex<RefCell<Option<Lcd>>> = Mutex::new(RefCell::new(None));

/// `f` on the LCD with core 0's interrupts masked (`None` before [`LineTiles::new`]).
fn with<R>(f: impl FnOnce(&mut Lcd) -> R) -> Option<R> {
    cortex_m::interrupt::free(|cs| LCD.borrow(cs).borrow_mut().as_mut().map(f))
}

impl Lcd {
    /// The mode byte `mode` with VCOM's level.
    fn mode(&self, mode: u8) -> u8 {
        mode | if self.vcom { VCOM } else { 0 }
    }

    /// Ends the line writes on their way once the DMA and the bus are done with them: lets the
    /// chip select go and empties SPI0's receive FIFO (the DMA only sends). True when nothing
    /// is on its way any more.
    fn end(&mut self) -> bool {
        if !self.sending {
            return true;
        }
        // SAFETY: reads of channel 0's and SPI0's status, and of SPI0's data register (what it
        // received, which nothing wants), and a write of its interrupt clear register.
        #[allow(unsafe_code)]
        unsafe {
            let (dma, spi) = (&*hal::pac::DMA::ptr(), &*hal::pac::SPI0::ptr());
            if dma.ch(CHANNEL).ch_ctrl_trig().read().busy().bit_is_set() || spi.sspsr().read().bsy().bit_is_set() {
                return false;
            }
            while spi.sspsr().read().rne().bit_is_set() {
                spi.sspdr().read();
            }
            spi.sspicr().write(|w| w.roric().clear_bit_by_one());
        }
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
        cortex_m::asm::delay(SCS_HOLD);
        let _ = self.bus.cs.set_low();
        self.sending = false;
        true
    }

    /// One short command (a clear, a display-mode command), sent without DMA; nothing may be
    /// on its way ([`Lcd::end`]).
    fn command(&mut self, bytes: &[u8]) {
        let bus = &mut self.bus;
        // The pins' and the bus's error type is Infallible.
        let _ = bus.cs.set_high();
        cortex_m::asm::delay(SCS_SETUP);
        let _ = bus.spi.write(bytes);
        let _ = bus.spi.flush();
        cortex_m::asm::delay(SCS_HOLD);
        let _ = bus.cs.set_low();
    }
}

/// Gathers each band of tiles until its last column is in, then writes its lines.
pub struct LineTiles {
    /// Two bands' line writes, each built in place as its parts come and sent from there by
    /// DMA, so core 0 gathers the next band while the last is on the bus (statics, so no move
    /// of this value can pull them from under the DMA's reads).
    commands: &'static mut [[u8; COMMAND]; 2],
    /// The one the next band is gathered in (the other's may be on the bus).
    gathering: usize,
    /// The memory has been cleared since power-on (it starts with noise), and VCOM's interrupt
    /// runs.
    cleared: bool,
}

impl LineTiles {
    /// The LCD on `bus`, not yet shown (DISP low) and not yet cleared; the DMA block out of
    /// reset and SPI0's TX requests on.
    pub fn new(bus: Interface) -> Self {
        let Some(commands) = cortex_m::singleton!(: [[u8; COMMAND]; 2] = [[0; COMMAND]; 2]) else {
            defmt::panic!("the Sharp LCD's command buffers are taken");
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
        cortex_m::interrupt::free(|cs| LCD.borrow(cs).replace(Some(Lcd { bus, sending: false, vcom: false })));
        LineTiles { commands, gathering: 0, cleared: false }
    }

    /// Starts the line writes of the gathered band's first `rows` rows, from row `y0`, by DMA
    /// once the last band's have ended; the next band is gathered in the other buffer.
    fn send_lines(&mut self, y0: usize, rows: usize) {
        let command = &mut self.commands[self.gathering];
        for r in 0..rows {
            command[pixels(r) - 1] = ((y0 + r + 1) as u8).reverse_bits();
            command[pixels(r) + LINE] = 0;
        }
        // The rows' lines and the final dummy byte (where a next row's address would be).
        let len = pixels(rows);
        command[len - 1] = 0;
        finish();
        with(|lcd| {
            let _ = lcd.bus.cs.set_high();
            let raised = crate::sleep::micros();
            command[0] = lcd.mode(WRITE);
            // 3 µs at least: the timer counts whole microseconds, so 4 of its ticks.
            while crate::sleep::micros().wrapping_sub(raised) < SCS_SETUP_US + 1 {}
            core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
            // SAFETY: channel 0 reads `len` bytes of a static command buffer, which nothing
            // writes until the other's band is sent, after `end` has seen the channel stop,
            // into SPI0's data register, paced by its TX requests.
            #[allow(unsafe_code)]
            unsafe {
                let ch = (*hal::pac::DMA::ptr()).ch(CHANNEL);
                ch.ch_read_addr().write(|w| w.bits(command.as_ptr() as u32));
                ch.ch_write_addr().write(|w| w.bits((*hal::pac::SPI0::ptr()).sspdr().as_ptr() as u32));
                ch.ch_trans_count().write(|w| w.bits(len as u32));
                ch.ch_ctrl_trig().write(|w| {
                    w.data_size().size_byte().incr_read().set_bit().treq_sel().bits(DREQ_SPI0_TX);
                    w.chain_to().bits(CHANNEL as u8).en().set_bit()
                });
            }
            lcd.sending = true;
        });
        self.gathering ^= 1;
    }
}

/// Waits until the line writes on their way have ended (by here or by the interrupt), with
/// core 0's interrupts let through between looks.
fn finish() {
    while with(Lcd::end) == Some(false) {}
}

/// Arms alarm 1 for `us` microseconds from now.
fn arm(us: u32) {
    // SAFETY: alarm 1 is VCOM's alone (the gray mode, its other user, drives no Sharp LCD);
    // writing it arms it.
    #[allow(unsafe_code)]
    unsafe {
        (*crate::sleep::TimerBlock::ptr()).alarm1().write(|w| w.bits(crate::sleep::micros().wrapping_add(us)));
    }
}

/// Starts VCOM's interrupt: alarm 1, every [`VCOM_US`].
fn start_vcom() {
    arm(VCOM_US);
    // SAFETY: the handler touches the LCD only behind its mutex, and alarm 1 alone.
    #[allow(unsafe_code)]
    unsafe {
        (*crate::sleep::TimerBlock::ptr()).inte().modify(|_, w| w.alarm_1().set_bit());
        cortex_m::peripheral::NVIC::unmask(VCOM_IRQ);
    }
}

/// Alarm 1's interrupt on the Pico.
#[cfg(feature = "pico")]
const VCOM_IRQ: hal::pac::Interrupt = hal::pac::Interrupt::TIMER_IRQ_1;
/// Alarm 1's interrupt on the Pico 2 (TIMER0's).
#[cfg(feature = "pico2")]
const VCOM_IRQ: hal::pac::Interrupt = hal::pac::Interrupt::TIMER0_IRQ_1;

/// Alarm 1: VCOM inverted by a display-mode command, or again a moment later while a band's
/// lines are on the bus.
fn invert_vcom() {
    // SAFETY: a write-1-to-clear of alarm 1's bit, which only this handler clears.
    #[allow(unsafe_code)]
    unsafe {
        (*crate::sleep::TimerBlock::ptr()).intr().write(|w| w.alarm_1().clear_bit_by_one());
    }
    let inverted = with(|lcd| {
        if !lcd.end() {
            return false;
        }
        lcd.vcom = !lcd.vcom;
        let mode = lcd.mode(0);
        lcd.command(&[mode, 0]);
        true
    });
    arm(if inverted == Some(false) { RETRY_US } else { VCOM_US });
}

/// See [`invert_vcom`].
#[cfg(feature = "pico")]
#[interrupt]
fn TIMER_IRQ_1() {
    invert_vcom();
}

/// See [`invert_vcom`].
#[cfg(feature = "pico2")]
#[interrupt]
fn TIMER0_IRQ_1() {
    invert_vcom();
}

impl SetUp for LineTiles {
    /// DISP high and, once after power-on, the memory cleared (it starts with noise) and VCOM's
    /// interrupt started. The LCD has nothing else to set up and SPI cannot tell whether it is
    /// there.
    fn set_up(&mut self) -> Result<(), DisplayError> {
        finish();
        let cleared = self.cleared;
        with(|lcd| {
            let _ = lcd.bus.disp.set_high();
            if !cleared {
                let mode = lcd.mode(CLEAR);
                lcd.command(&[mode, 0]);
            }
        });
        if !cleared {
            self.cleared = true;
            start_vcom();
        }
        Ok(())
    }

    /// The LCD cannot answer; VCOM is its interrupt's.
    fn answers(&mut self) -> bool {
        true
    }

    /// The last band's line writes ended.
    fn flush(&mut self) -> Result<(), DisplayError> {
        finish();
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
        for y in 0..h {
            let row = &mut self.commands[self.gathering][pixels(y)..pixels(y) + LINE];
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
