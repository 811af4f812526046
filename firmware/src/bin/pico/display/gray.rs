//! The gray mode (`gray`): four shades on an SSD1306 over SPI. A frame is dithered to steps
//! 0..=3 and kept as two bit planes (the step's low and high bit, in the controller's page
//! layout); the panel shows them as three subframes, one per refresh: the low plane once, the
//! high plane twice, so a pixel of step k is lit in k of every three refreshes and reads as
//! k / 3 of white.
//!
//! **In step with the panel.** The SSD1306 scans its rows one after another, each for a row
//! period of D x (phase 1 + phase 2 + 50) display clocks (datasheet rev 1.1, section 8.3: the
//! divide ratio D and the oscillator from 0xD5, the phases from 0xD9), the multiplex ratio's
//! rows per refresh, and takes each row from RAM as it comes to it. Without its FR pin the
//! firmware cannot see the scan, so it keeps its own copy of it: the scan starts at row 0 when
//! the display is switched on (0xAF), and from then every refresh takes `ROWS` row periods of
//! [`ROW_NS`]. A timer interrupt (alarm 1, on core 0, while both cores trace) addresses each
//! page of the next subframe and starts its bytes by DMA, half a refresh ahead of the row scan: after the scan has left the page
//! in the refresh before and well before it comes back, so every refresh shows one subframe
//! whole, with (ROWS - 8) / 2 rows of slack either side for a clock that runs a little off.
//! A new frame is taken at the start of a three-subframe cycle only, so no refresh and no cycle
//! mixes two frames; frames are kept three deep (one shown, one finished, one being drawn), so
//! the cores never wait for the cycle to end.
//!
//! **Calibration.** Panels' oscillators differ (the datasheet gives 333..407 kHz at the reset
//! setting, and their highest setting is not specified). `FIRMWARE_GRAY_ROW_NS` at build time
//! sets the row period the firmware assumes; docs/flashing.md says how to find it with the test
//! pattern. The emulated board (`run.mjs --osc-error PCT`) runs panels whose clocks are off.

use super::controller::{self, CLOCK, PANEL, PRECHARGE};
use super::SetUp;
use crate::bus::Interface;
use crate::hal::pac;
use crate::wiring::Wiring;
use core::cell::{RefCell, UnsafeCell};
use core::sync::atomic::{AtomicBool, AtomicU32, AtomicU8, Ordering};
use cortex_m::interrupt::Mutex;
use display_interface::{DataFormat, DisplayError, WriteOnlyDataCommand};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{Gray2, GrayColor};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use firmware::app::{HEIGHT, WIDTH};
use pac::interrupt;

#[cfg(any(
    feature = "pico2",
    feature = "sh1106",
    feature = "ssd1309",
    feature = "sharp",
    feature = "uc8151",
    feature = "progressive",
    feature = "orbit"
))]
compile_error!("the gray mode is for the Pico with an SSD1306 on SPI, showing stills");

/// Rows the panel scans per refresh: its multiplex ratio, the glass's height.
const ROWS: u64 = HEIGHT as u64;
/// Pages of RAM the glass shows.
const PAGES: usize = HEIGHT as usize / 8;
/// Bytes of one bit plane.
const PLANE: usize = WIDTH as usize * PAGES;
/// The plane each subframe of a cycle shows: the low bit once, the high bit twice.
const SUBFRAMES: [usize; 3] = [0, 1, 1];

/// The oscillator's typical frequency at [`CLOCK`]'s setting, in Hz: 370 kHz at the reset
/// setting 0x8 (the datasheet's typical figure), 530 kHz at 0xF (the figure the Thumby's
/// grayscale library works with), and in between in even steps. A real panel's differs:
/// `FIRMWARE_GRAY_ROW_NS`.
const FOSC_HZ: u64 = 370_000 + ((CLOCK >> 4) as u64).saturating_sub(8) * 160_000 / 7;
/// Display clocks per row: phase 1 + phase 2 + 50 (datasheet section 8.3), times the divide
/// ratio.
const CLOCKS_PER_ROW: u64 = ((CLOCK & 0x0f) as u64 + 1) * ((PRECHARGE & 0x0f) as u64 + (PRECHARGE >> 4) as u64 + 50);
/// The row period the firmware keeps step with, in nanoseconds: `FIRMWARE_GRAY_ROW_NS` if the
/// build sets it (a calibrated panel), else the typical one (100,000 ns at 0xF0 and 0x21: a
/// refresh every 6.4 ms on 64 rows, 156 a second, a gray cycle at 52 Hz).
pub const ROW_NS: u64 = match option_env!("FIRMWARE_GRAY_ROW_NS") {
    Some(ns) => parse_ns(ns),
    None => CLOCKS_PER_ROW * 1_000_000_000 / FOSC_HZ,
};

/// A decimal number of nanoseconds (a build with a malformed one fails to compile).
const fn parse_ns(s: &str) -> u64 {
    let (b, mut i, mut v) = (s.as_bytes(), 0, 0u64);
    assert!(!b.is_empty(), "FIRMWARE_GRAY_ROW_NS is empty");
    while i < b.len() {
        assert!(b[i].is_ascii_digit(), "FIRMWARE_GRAY_ROW_NS: nanoseconds, digits only");
        v = v * 10 + (b[i] - b'0') as u64;
        i += 1;
    }
    assert!(v >= 10_000 && v <= 1_000_000, "FIRMWARE_GRAY_ROW_NS: 10000..=1000000 ns");
    v
}

/// The DMA channel the pages go by (the Sharp LCD's is 0; an image drives one panel).
const CHANNEL: usize = 1;

/// Rows ahead of the scan a page is written: half the slack between the scan leaving the page
/// and coming back to it, and one more for the write itself.
const LEAD_ROWS: u64 = (ROWS - 8) / 2 + 1;

/// Three frames of two planes each: the one shown, one finished and waiting for a cycle's
/// start, one being drawn. Which is which is [`SHOWN`], [`READY`] and the draw target's own.
struct Frames(UnsafeCell<[[[u8; PLANE]; 2]; 3]>);

// SAFETY: frame [`SHOWN`] is read only by the refresh interrupt, the others written only by the
// draw target on core 0; the indices change hands inside critical sections (`Gray::flush`) or
// in the interrupt, which those exclude.
#[allow(unsafe_code)]
unsafe impl Sync for Frames {}

static FRAMES: Frames = Frames(UnsafeCell::new([[[0; PLANE]; 2]; 3]));
/// The frame the refresh shows.
static SHOWN: AtomicU8 = AtomicU8::new(0);
/// A finished frame for the next cycle's start, or [`NONE`].
static READY: AtomicU8 = AtomicU8::new(NONE);
/// No frame.
const NONE: u8 = 3;
/// Microseconds core 0 has spent in the refresh interrupt (written by the interrupt alone).
static REFRESH_US: AtomicU32 = AtomicU32::new(0);
/// Whether the refresh runs.
static RUNNING: AtomicBool = AtomicBool::new(false);

/// The refresh's own state: the display's bus (the interrupt's alone once it runs), when the
/// scan started and the next page write.
struct Refresh {
    bus: Interface,
    on_ns: u64,
    next: u64,
}

static REFRESH: Mutex<RefCell<Option<Refresh>>> = Mutex::new(RefCell::new(None));

/// Microseconds the refresh interrupt has taken of core 0 so far (a frame's share: the
/// difference across it).
pub fn refresh_us() -> u32 {
    REFRESH_US.load(Ordering::Relaxed)
}

/// The panel in the gray mode: a draw target of four shades into the frame being drawn, and the
/// refresh that shows the finished ones.
pub struct Gray {
    /// The display's bus until the refresh takes it.
    bus: Option<Interface>,
    /// The frame being drawn.
    back: u8,
}

impl Gray {
    /// The gray mode on the display's bus; nothing is sent until [`SetUp::set_up`].
    pub fn new(bus: Interface) -> Self {
        Gray { bus: Some(bus), back: 1 }
    }

    /// The planes of the frame being drawn.
    fn planes(&mut self) -> &mut [[u8; PLANE]; 2] {
        // SAFETY: frame `back` is neither shown nor ready (`flush` keeps it so), so the
        // interrupt never reads it while it is written here.
        #[allow(unsafe_code)]
        unsafe {
            &mut (*FRAMES.0.get())[self.back as usize]
        }
    }
}

impl SetUp for Gray {
    /// The first call sets the panel up and starts the refresh; later ones change nothing: the
    /// refresh owns the bus from then on, and a set-up in its midst would move the RAM pointer
    /// under it (a panel that lost power stays dark: see docs/board.md).
    fn set_up(&mut self) -> Result<(), DisplayError> {
        let Some(mut bus) = self.bus.take() else { return Ok(()) };
        for command in PANEL.set_up.iter().copied().flatten() {
            bus.send_commands(DataFormat::U8(command))?;
        }
        // Every byte has left the bus (each SPI write waits for it): the scan starts now.
        let on_ns = now_us() * 1000;
        super::spi_dma::enable();
        cortex_m::interrupt::free(|cs| {
            REFRESH.borrow(cs).replace(Some(Refresh { bus, on_ns, next: 0 }));
        });
        RUNNING.store(true, Ordering::Relaxed);
        schedule(on_ns + write_ns(0));
        // SAFETY: the handler only touches the refresh's own state, behind its mutex.
        #[allow(unsafe_code)]
        unsafe {
            (*pac::TIMER::ptr()).inte().modify(|_, w| w.alarm_1().set_bit());
            cortex_m::peripheral::NVIC::unmask(pac::Interrupt::TIMER_IRQ_1);
        }
        Ok(())
    }

    /// SPI has no acknowledge, and the bus is the refresh's.
    fn answers(&mut self) -> bool {
        true
    }

    /// The frame drawn is finished: it is shown from the next cycle's start, and another frame
    /// is drawn into.
    fn flush(&mut self) -> Result<(), DisplayError> {
        cortex_m::interrupt::free(|_| {
            let shown = SHOWN.load(Ordering::Relaxed);
            READY.store(self.back, Ordering::Relaxed);
            self.back = (0..3).find(|&i| i != shown && i != self.back).unwrap_or(self.back);
        });
        Ok(())
    }
}

impl OriginDimensions for Gray {
    fn size(&self) -> Size {
        Size::new(WIDTH as u32, HEIGHT as u32)
    }
}

impl DrawTarget for Gray {
    type Color = Gray2;
    type Error = DisplayError;

    fn draw_iter<I: IntoIterator<Item = Pixel<Gray2>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        let planes = self.planes();
        for Pixel(p, c) in pixels {
            if (0..WIDTH as i32).contains(&p.x) && (0..HEIGHT as i32).contains(&p.y) {
                put(planes, p.x as usize, p.y as usize, c.luma());
            }
        }
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = Gray2>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let (x0, y0, w) = (area.top_left.x, area.top_left.y, area.size.width as i32);
        let planes = self.planes();
        for (i, c) in (0..area.size.height as i32 * w).zip(colors) {
            let (x, y) = (x0 + i % w, y0 + i / w);
            if (0..WIDTH as i32).contains(&x) && (0..HEIGHT as i32).contains(&y) {
                put(planes, x as usize, y as usize, c.luma());
            }
        }
        Ok(())
    }
}

/// Step `k` (0..=3) of pixel `(x, y)` into the planes: bit 0 to the low plane, bit 1 to the
/// high (a byte is 8 rows of one column, LSB on top).
fn put(planes: &mut [[u8; PLANE]; 2], x: usize, y: usize, k: u8) {
    let (i, bit) = (y / 8 * WIDTH as usize + x, 1u8 << (y % 8));
    for (plane, on) in planes.iter_mut().zip([k & 1 != 0, k & 2 != 0]) {
        if on {
            plane[i] |= bit;
        } else {
            plane[i] &= !bit;
        }
    }
}

/// Drives the pins in `high` high and those in `low` low (the display's chip select and
/// data/command lines, between the interface's transfers).
fn set_pins(high: u32, low: u32) {
    // SAFETY: SIO's atomic set and clear registers, for pins the interface leaves as they are
    // between its transfers.
    #[allow(unsafe_code)]
    unsafe {
        let sio = &*pac::SIO::ptr();
        sio.gpio_out_set().write(|w| w.bits(high));
        sio.gpio_out_clr().write(|w| w.bits(low));
    }
}

/// When page write `j` is due, from the scan's start: page `j % PAGES` of refresh
/// `1 + j / PAGES`, [`LEAD_ROWS`] rows before the scan reaches it.
fn write_ns(j: u64) -> u64 {
    let (refresh, page) = (1 + j / PAGES as u64, j % PAGES as u64);
    (refresh * ROWS + page * 8 - LEAD_ROWS) * ROW_NS
}

/// The timer's microseconds, all 64 bits (TIMERAWH read again until it held still).
fn now_us() -> u64 {
    // SAFETY: reads of the raw timer registers, which have no side effects.
    #[allow(unsafe_code)]
    let t = unsafe { &*pac::TIMER::ptr() };
    loop {
        let hi = t.timerawh().read().bits();
        let lo = t.timerawl().read().bits();
        if t.timerawh().read().bits() == hi {
            return (u64::from(hi) << 32) | u64::from(lo);
        }
    }
}

/// Arms alarm 1 for `at_ns` (timer time), or for 2 us from now if that has passed (a late
/// write goes out at once rather than after the timer's 71-minute wrap). The alarm fires only
/// when the timer's low word equals it, so an alarm written after its moment never fires and
/// the refresh would stop for good: the timer is read after the target is worked out (its
/// 64-bit division takes microseconds on a Cortex-M0+), and again after the write, which is
/// made again while the moment has passed.
fn schedule(at_ns: u64) {
    let want = at_ns / 1000;
    loop {
        let at = want.max(now_us() + 2);
        // SAFETY: alarm 1 is the refresh's alone; writing it arms it.
        #[allow(unsafe_code)]
        unsafe {
            (*pac::TIMER::ptr()).alarm1().write(|w| w.bits(at as u32));
        }
        if now_us() < at {
            return;
        }
    }
}

/// Alarm 1: the next page of the next subframe to the panel, and the alarm armed for the one
/// after.
#[interrupt]
fn TIMER_IRQ_1() {
    let start = now_us();
    // SAFETY: a write-1-to-clear of alarm 1's bit, which only this handler clears.
    #[allow(unsafe_code)]
    unsafe {
        (*pac::TIMER::ptr()).intr().write(|w| w.alarm_1().clear_bit_by_one())
    };
    if !RUNNING.load(Ordering::Relaxed) {
        return;
    }
    cortex_m::interrupt::free(|cs| {
        let mut state = REFRESH.borrow(cs).borrow_mut();
        let Some(r) = state.as_mut() else { return };
        let j = r.next;
        let (refresh, page) = (1 + j / PAGES as u64, (j % PAGES as u64) as u8);
        let subframe = ((refresh - 1) % SUBFRAMES.len() as u64) as usize;
        if subframe == 0 && page == 0 {
            // Inside the critical section: a load and a store (a Cortex-M0+ has no swap).
            let ready = READY.load(Ordering::Relaxed);
            READY.store(NONE, Ordering::Relaxed);
            if ready != NONE {
                SHOWN.store(ready, Ordering::Relaxed);
            }
        }
        // SAFETY: frame SHOWN is never drawn into (`Gray::flush`).
        #[allow(unsafe_code)]
        let planes = unsafe { &(*FRAMES.0.get())[SHOWN.load(Ordering::Relaxed) as usize] };
        let plane = &planes[SUBFRAMES[subframe]];
        let bytes = &plane[page as usize * WIDTH as usize..(page as usize + 1) * WIDTH as usize];
        let (columns, rows) = controller::window(0, WIDTH as u8, page, page);
        // The last page's bytes have left: its chip select goes up, and the bus is the
        // interface's for the window's commands (SPI has no acknowledge: they cannot fail on a
        // working bus, and a lost page is written again a cycle later).
        super::spi_dma::finish(CHANNEL);
        set_pins(1 << Wiring::CS, 0);
        let _ = r.bus.send_commands(DataFormat::U8(&columns));
        let _ = r.bus.send_commands(DataFormat::U8(&rows));
        // Data, selected: the page's bytes go by DMA while core 0 traces on.
        set_pins(1 << Wiring::DC, 1 << Wiring::CS);
        // SAFETY: frame SHOWN's planes stay as they are until the next interrupt has seen the
        // channel stop (`finish` above), before any new frame is shown.
        #[allow(unsafe_code)]
        unsafe {
            super::spi_dma::start(CHANNEL, bytes.as_ptr(), bytes.len())
        };
        r.next = j + 1;
        schedule(r.on_ns + write_ns(r.next));
    });
    let spent = now_us().saturating_sub(start) as u32;
    REFRESH_US.store(REFRESH_US.load(Ordering::Relaxed).wrapping_add(spent), Ordering::Relaxed);
}
