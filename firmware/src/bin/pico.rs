//! Raspberry Pi Pico (RP2040, `--features pico`, fixed point) or Pico 2 (RP2350, Cortex-M33
//! with an FPU, `--features pico2`, f32) + SSD1306 128x64 OLED on I2C: renders the embedded scenes in turn, tile by
//! tile straight to the display (each 8x8 tile is one SSD1306 page high, so it is sent as eight
//! column bytes; no framebuffer), and logs per-frame time and statistics over defmt-rtt.
//!
//! The on-board LED (GP25) is lit while a frame is being rendered and goes out when the frame is
//! on the display (with the `progressive` feature, a frame is shown in four passes and the LED
//! goes out for a moment as each of the first three reaches the display); between scenes the
//! core sleeps (`wfi`) until a timer alarm. With no display answering, the log says so and the
//! LED blinks quickly while the firmware retries every second.
//! `host-sim board` runs this image in an RP2040 emulator and relies on that LED protocol.
//!
//! Wiring (change it here, in `Wiring` below, and nowhere else): SDA on GP4, SCL on GP5,
//! display address 0x3C, VCC on 3V3(OUT), GND on GND; the two boards share the pin-out.
//!
//! The two boards differ only in what their HALs name differently (boot block, timer, its
//! interrupt); each difference is one `cfg` below.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
#[cfg(feature = "ladder")]
use firmware::app::LADDER;
#[cfg(feature = "orbit")]
use firmware::app::ORBIT_FRAMES;
use firmware::app::{render_scene_at, Board, Cores, OneCore, Scalar, ShareMemory, Shot, Storage, HEIGHT, SCENES, WIDTH};
#[cfg(not(feature = "ladder"))]
use firmware::stack;
use hal::fugit::RateExtU32;
use hal::Clock;
use hal::pac;
use hal::pac::interrupt;
use embedded_hal::digital::OutputPin;
use lattice_rt::NoHooks;
use panic_probe as _;
#[cfg(feature = "pico")]
use rp2040_hal as hal;
#[cfg(feature = "pico2")]
use rp235x_hal as hal;
use ssd1306::mode::BasicMode;
use ssd1306::prelude::*;
use ssd1306::{I2CDisplayInterface, Ssd1306};

#[cfg(all(feature = "pico", feature = "pico2"))]
compile_error!("choose one board: `pico` (RP2040) or `pico2` (RP2350)");

/// The second-stage bootloader for the Pico's W25Q080 flash.
#[cfg(feature = "pico")]
#[link_section = ".boot2"]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

/// The RP2350's image definition: the boot ROM starts a secure Arm image from it.
#[cfg(feature = "pico2")]
#[link_section = ".start_block"]
#[used]
pub static IMAGE_DEF: hal::block::ImageDef = hal::block::ImageDef::secure_exe();

/// What `picotool info` shows about the Pico 2 image.
#[cfg(feature = "pico2")]
#[link_section = ".bi_entries"]
#[used]
pub static PICOTOOL_ENTRIES: [hal::binary_info::EntryAddr; 4] = [
    hal::binary_info::rp_cargo_bin_name!(),
    hal::binary_info::rp_cargo_version!(),
    hal::binary_info::rp_program_description!(c"lattice-rt: a lattice ray tracer on an SSD1306"),
    hal::binary_info::rp_cargo_homepage_url!(),
];

/// The board's name in the log.
#[cfg(feature = "pico")]
const BOARD: &str = "Pico (RP2040)";
/// The board's name in the log.
#[cfg(feature = "pico2")]
const BOARD: &str = "Pico 2 (RP2350)";

/// The timer alarm the firmware sleeps on, and its interrupt.
#[cfg(feature = "pico")]
type Alarm0 = hal::timer::Alarm0;
#[cfg(feature = "pico")]
const ALARM_IRQ: pac::Interrupt = pac::Interrupt::TIMER_IRQ_0;
/// The timer alarm the firmware sleeps on, and its interrupt.
#[cfg(feature = "pico2")]
type Alarm0 = hal::timer::Alarm0<hal::timer::CopyableTimer0>;
#[cfg(feature = "pico2")]
const ALARM_IRQ: pac::Interrupt = pac::Interrupt::TIMER0_IRQ_0;

/// The Pico's crystal.
const XTAL_FREQ_HZ: u32 = 12_000_000;
/// I2C bus speed.
const I2C_HZ: u32 = 400_000;

/// Draws whole 8-row tiles by sending SSD1306 page bytes; nothing else is supported (there is
/// no framebuffer to merge single pixels into), and anything else is refused with an error.
struct PageTiles<DI> {
    display: Ssd1306<DI, DisplaySize128x64, BasicMode>,
}

impl<DI: WriteOnlyDataCommand> OriginDimensions for PageTiles<DI> {
    fn size(&self) -> Size {
        Size::new(WIDTH as u32, HEIGHT as u32)
    }
}

impl<DI: WriteOnlyDataCommand> DrawTarget for PageTiles<DI> {
    type Color = BinaryColor;
    type Error = display_interface::DisplayError;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, _pixels: I) -> Result<(), Self::Error> {
        Err(display_interface::DisplayError::OutOfBoundsError)
    }

    fn fill_contiguous<I: IntoIterator<Item = BinaryColor>>(&mut self, area: &Rectangle, colors: I) -> Result<(), Self::Error> {
        let (x0, y0) = (area.top_left.x, area.top_left.y);
        let (w, h) = (area.size.width as usize, area.size.height as usize);
        if y0 < 0 || x0 < 0 || y0 % 8 != 0 || h > 8 || w > 16 || x0 as usize + w > WIDTH as usize {
            return Err(display_interface::DisplayError::OutOfBoundsError);
        }
        // One byte per column, bit k = row k of the page (LSB on top).
        let mut cols = [0u8; 16];
        let mut colors = colors.into_iter();
        for bit in (0..h).map(|y| 1u8 << y) {
            for col in cols[..w].iter_mut() {
                if colors.next().is_some_and(|c| c.is_on()) {
                    *col |= bit;
                }
            }
        }
        // `set_draw_area` takes pixel coordinates (it divides rows by 8 into pages itself).
        let (x1, y1) = ((x0 as usize + w) as u8, (y0 as usize + h) as u8);
        self.display.set_draw_area((x0 as u8, y0 as u8), (x1, y1))?;
        self.display.draw(&cols[..w])
    }
}

/// I2C0 that reports a device that does not answer. rp2040-hal 0.12 checks the controller's
/// abort flags only while a write waits for room in the 16-byte TX FIFO, so a shorter write to
/// an address nobody acknowledges (every SSD1306 command is one) returns `Ok` and the display
/// seems to be there. This reads the abort source after each transaction, as the hardware
/// leaves it once the STOP has gone out.
struct CheckedI2c<P>(hal::I2C<pac::I2C0, P>);

impl<P> embedded_hal::i2c::ErrorType for CheckedI2c<P> {
    type Error = hal::i2c::Error;
}

impl<P> embedded_hal::i2c::I2c for CheckedI2c<P>
where
    hal::I2C<pac::I2C0, P>: embedded_hal::i2c::I2c<Error = hal::i2c::Error>,
{
    fn transaction(&mut self, address: u8, operations: &mut [embedded_hal::i2c::Operation<'_>]) -> Result<(), Self::Error> {
        self.0.transaction(address, operations)?;
        // SAFETY: I2C0 belongs to `self.0`, and no transaction is under way; reading
        // IC_TX_ABRT_SOURCE has no side effect, reading IC_CLR_TX_ABRT clears the abort (and
        // releases the TX FIFO) exactly as the HAL itself does after an abort it noticed.
        #[allow(unsafe_code)]
        let regs = unsafe { &*pac::I2C0::ptr() };
        let reason = regs.ic_tx_abrt_source().read().bits();
        if reason != 0 {
            regs.ic_clr_tx_abrt().read();
            return Err(hal::i2c::Error::Abort(reason));
        }
        Ok(())
    }
}

/// Core 1's stack (32 KiB; a frame's tracing needs well under half of it).
static CORE1_STACK: hal::multicore::Stack<8192> = hal::multicore::Stack::new();

/// Core 1: runs each job core 0 sends through the SIO FIFO and answers when it is done.
fn core1_main() {
    // SAFETY: core 1 uses only the SIO FIFO's core-1 side, which no other code on core 1 touches.
    #[allow(unsafe_code)]
    let pac = unsafe { pac::Peripherals::steal() };
    let mut sio = hal::Sio::new(pac.SIO);
    loop {
        let job = sio.fifo.read_blocking() as usize as *mut &mut (dyn FnMut() + Send);
        // SAFETY: core 0 sent the address of a job it keeps alive, and does not touch, until
        // this core answers below (`TwoCores::join`).
        #[allow(unsafe_code)]
        unsafe {
            (*job)()
        };
        sio.fifo.write_blocking(1);
    }
}

/// Whether the inter-core FIFO behaves as the RP2040's does: its sticky error flags (WOF, ROE)
/// clear when written and room is there (RDY). rp2040js has no FIFO and reads every bit as 1.
fn fifo_answers() -> bool {
    // SAFETY: core 1 is still in the bootrom, so nothing else uses the FIFO; writing FIFO_ST
    // only clears its two error flags.
    #[allow(unsafe_code)]
    let sio = unsafe { &*pac::SIO::ptr() };
    sio.fifo_st().write(|w| w.wof().clear_bit_by_one().roe().clear_bit_by_one());
    let st = sio.fifo_st().read();
    st.rdy().bit_is_set() && st.wof().bit_is_clear() && st.roe().bit_is_clear()
}

/// Both RP2040 cores: core 1 runs the other piece of work (see [`core1_main`]).
struct TwoCores {
    fifo: hal::sio::SioFifo,
}

impl Cores for TwoCores {
    fn join(&mut self, there: &mut (dyn FnMut() + Send), here: &mut dyn FnMut()) {
        let mut job: &mut (dyn FnMut() + Send) = there;
        // Core 1 gets the address of `job` (a pointer to the closure and its vtable); both live
        // on this stack until core 1's answer has come back.
        self.fifo.write_blocking(&mut job as *mut &mut (dyn FnMut() + Send) as usize as u32);
        here();
        let _ = self.fifo.read_blocking();
    }
}

/// The pause between two scenes.
const PAUSE_MS: u32 = 3000;

/// Sleeps (`wfi`) until `alarm` has run `ms` milliseconds, instead of spinning: the core draws
/// less power, and an emulator skips the idle time. The check and the `wfi` run with interrupts
/// masked, so an alarm that fires between them still ends the `wfi` (a pending interrupt wakes
/// the core whatever PRIMASK says); the alarm's interrupt handler then clears it.
fn sleep_ms(alarm: &mut Alarm0, ms: u32) {
    use hal::timer::Alarm;
    if alarm.schedule(hal::fugit::MicrosDurationU32::millis(ms)).is_err() {
        return;
    }
    alarm.enable_interrupt();
    // SAFETY: TIMER_IRQ_0's handler touches nothing but the alarm's own interrupt flag, so
    // enabling it cannot break any critical section or data the main loop holds.
    #[allow(unsafe_code)]
    unsafe {
        cortex_m::peripheral::NVIC::unmask(ALARM_IRQ)
    };
    while !cortex_m::interrupt::free(|_| {
        let done = alarm.finished();
        if !done {
            cortex_m::asm::wfi();
        }
        done
    }) {}
    cortex_m::peripheral::NVIC::mask(ALARM_IRQ);
    alarm.disable_interrupt();
}

/// Alarm 0 has fired: clear its interrupt (the main loop only needed to wake up).
#[cfg(feature = "pico")]
#[interrupt]
fn TIMER_IRQ_0() {
    // SAFETY: a write-1-to-clear of alarm 0's bit in TIMER.INTR; no other code writes INTR
    // while this alarm is armed, and the write is a single atomic store.
    #[allow(unsafe_code)]
    unsafe {
        (*pac::TIMER::ptr()).intr().write(|w| w.alarm_0().clear_bit_by_one())
    };
}

/// Alarm 0 of TIMER0 has fired: clear its interrupt (the main loop only needed to wake up).
#[cfg(feature = "pico2")]
#[interrupt]
fn TIMER0_IRQ_0() {
    // SAFETY: as for the Pico's handler, on TIMER0.INTR.
    #[allow(unsafe_code)]
    unsafe {
        (*pac::TIMER0::ptr()).intr().write(|w| w.alarm_0().clear_bit_by_one())
    };
}

#[hal::entry]
fn main() -> ! {
    let mut pac = pac::Peripherals::take().unwrap();
    let mut watchdog = hal::Watchdog::new(pac.WATCHDOG);
    let Ok(clocks) = hal::clocks::init_clocks_and_plls(
        XTAL_FREQ_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    ) else {
        defmt::panic!("the clocks did not start (crystal or PLL)");
    };
    let sio = hal::Sio::new(pac.SIO);
    let pins = hal::gpio::Pins::new(pac.IO_BANK0, pac.PADS_BANK0, sio.gpio_bank0, &mut pac.RESETS);
    // Wiring: the two pins and the address of the display.
    let sda = pins.gpio4.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let scl = pins.gpio5.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let i2c = hal::I2C::i2c0(pac.I2C0, sda, scl, I2C_HZ.Hz(), &mut pac.RESETS, &clocks.system_clock);
    let interface = I2CDisplayInterface::new(CheckedI2c(i2c)); // address 0x3C; new_alternate_address() for 0x3D
    let mut led = pins.gpio25.into_push_pull_output();
    #[cfg(feature = "pico")]
    let mut timer = hal::Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);
    #[cfg(feature = "pico2")]
    let mut timer = hal::Timer::new_timer0(pac.TIMER0, &mut pac.RESETS, &clocks);
    let Some(mut alarm) = timer.alarm_0() else {
        defmt::panic!("timer alarm 0 is taken");
    };

    let mut display = Ssd1306::new(interface, DisplaySize128x64, DisplayRotation::Rotate0);
    while display.init().is_err() {
        defmt::error!("no SSD1306 answers on I2C0 (SDA GP4, SCL GP5, address 0x3C): check the wiring; retrying in 1 s");
        for _ in 0..5 {
            let _ = led.set_high();
            sleep_ms(&mut alarm, 100);
            let _ = led.set_low();
            sleep_ms(&mut alarm, 100);
        }
    }
    let mut target = PageTiles { display };
    let mut st = Storage::<Scalar>::new();
    defmt::info!("lattice-rt on the {}: {} scenes, {}x{}, {} MHz", BOARD, SCENES.len(), WIDTH, HEIGHT, clocks.system_clock.freq().to_MHz());
    // Core 1 renders the second tile share of every frame where the SIO FIFO answers; in
    // rp2040js, which has none, core 0 renders both shares: the same code and frames.
    let mut second = ShareMemory::new();
    let mut fifo = sio.fifo;
    let mut one = OneCore;
    let mut two = None;
    if fifo_answers() {
        let mut mc = hal::multicore::Multicore::new(&mut pac.PSM, &mut pac.PPB, &mut fifo);
        let cores = mc.cores();
        match CORE1_STACK.take().map(|stack| cores[1].spawn(stack, core1_main)) {
            Some(Ok(())) => two = Some(TwoCores { fifo }),
            Some(Err(e)) => defmt::error!("core 1 did not start ({}): rendering on core 0 alone", e),
            None => defmt::error!("core 1's stack is taken: rendering on core 0 alone"),
        }
    }
    defmt::info!("rendering on {} core(s)", if two.is_some() { 2 } else { 1 });
    let now = || timer.get_counter().ticks();
    // One frame: the LED lit while it renders. A progressive frame (the `progressive` feature)
    // puts it out for a moment as each pass but the last reaches the display, so the LED goes
    // out once per picture the panel shows.
    let mut show = |text: &'static str, shot: &Shot| {
        let t0 = timer.get_counter();
        let _ = led.set_high();
        let mut shown = |pass: u8| {
            if pass > 1 {
                let _ = led.set_low();
                let _ = led.set_high();
            }
        };
        let result = match two.as_mut() {
            Some(cores) => {
                let board = Board { cores, second: &mut second, now: &now, shown: &mut shown };
                render_scene_at(text, &mut st, &mut target, &mut NoHooks, shot, board)
            }
            None => {
                let board = Board { cores: &mut one, second: &mut second, now: &now, shown: &mut shown };
                render_scene_at(text, &mut st, &mut target, &mut NoHooks, shot, board)
            }
        };
        let _ = led.set_low();
        result.map(|r| (r, (timer.get_counter() - t0).to_micros(), r.share_us))
    };
    #[cfg(feature = "ladder")]
    loop {
        // The ladder: the first scene once per rung, from the paper's method to the default.
        let (name, text) = SCENES[0];
        for (rung, (what, tuning)) in LADDER.iter().enumerate() {
            match show(text, &Shot { turn: 0.0, tuning: *tuning }) {
                Ok((r, us, shares)) => defmt::info!(
                    "ladder {}: {}: {} us, shares {} us and {} us, object tests {}, cells {} ({})",
                    rung, name, us, shares[0], shares[1], r.stats.object_tests, r.stats.cells_visited, what
                ),
                Err(e) => defmt::error!("ladder {}: {}: {}", rung, name, e),
            }
        }
        sleep_ms(&mut alarm, PAUSE_MS);
    }
    #[cfg(all(feature = "orbit", not(feature = "ladder")))]
    loop {
        // Orbit mode: the camera circles each scene, frame after frame, for one turn.
        for (name, text) in SCENES {
            let t0 = timer.get_counter();
            for i in 0..ORBIT_FRAMES {
                let shot = Shot { turn: i as f64 / ORBIT_FRAMES as f64, ..Shot::default() };
                if let Err(e) = show(text, &shot) {
                    defmt::error!("{}: orbit frame {}: {}", name, i, e);
                    break;
                }
            }
            let us = (timer.get_counter() - t0).to_micros().max(1);
            let centi_fps = ORBIT_FRAMES as u64 * 100_000_000 / us;
            defmt::info!(
                "{}: orbit of {} frames in {} ms: {}.{=u64:02} frames per second, stack high-water {} B",
                name, ORBIT_FRAMES, us / 1000, centi_fps / 100, centi_fps % 100, stack::high_water()
            );
            sleep_ms(&mut alarm, PAUSE_MS);
        }
    }
    #[cfg(not(any(feature = "orbit", feature = "ladder")))]
    loop {
        for (name, text) in SCENES {
            match show(text, &Shot::default()) {
                Ok((r, us, shares)) => {
                    let s = r.stats;
                    defmt::info!(
                        "{}: {} ms (tile shares {} us and {} us), rays {} (shadow {}, reflection {}, refraction {}), object tests {}, cells {}, lattice {} B, stack high-water {} B",
                        name, us / 1000, shares[0], shares[1], s.total_rays(), s.rays[1], s.rays[2], s.rays[3], s.object_tests, s.cells_visited,
                        r.lattice_bytes, stack::high_water()
                    );
                }
                Err(e) => defmt::error!("{}: {}", name, e),
            }
            sleep_ms(&mut alarm, PAUSE_MS);
        }
    }
}
