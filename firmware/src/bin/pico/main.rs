//! Raspberry Pi Pico (RP2040, `--features pico`, fixed point) or Pico 2 (RP2350, Cortex-M33
//! with an FPU, `--features pico2`, f32) + SSD1306 128x64 OLED on I2C (or SPI, `spi`): renders the embedded
//! scenes in turn, tile by tile straight to the display (16x16 tiles, two SSD1306 pages high,
//! sent as page bytes; no framebuffer), both cores tracing the tiles as they come free and core 0
//! dithering and sending each band's traced tiles in order, and logs per-frame time and
//! statistics over defmt-rtt.
//!
//! The on-board LED is lit while a frame is being rendered and goes out when the frame is on
//! the display; between scenes the core sleeps (`wfi`) until a timer alarm. With no display
//! answering, the log says so and the LED blinks quickly while the firmware retries every
//! second. `cargo xtask board` runs this image on an emulated RP2040 (both cores, the flash cache,
//! the display bus's timing) and relies on that LED protocol.
//!
//! The rooms: [`wiring`] (the pins, address and bus clock: the one place to change them),
//! [`display`] (the panel as a draw target), [`cores`] (core 1), [`sleep`] (the timer alarm),
//! [`modes`] (what is shown: scenes, orbit or ladder), [`button`] (the next scene), [`guard`]
//! (the watchdog), [`ram_code`] (the hot code copied to SRAM). The two boards differ only in what their
//! HALs name differently (boot block, timer, its interrupt); each difference is one `cfg`.
#![no_std]
#![no_main]

mod bus;
mod button;
mod cores;
mod display;
mod guard;
mod modes;
mod ram_code;
mod sleep;
mod wiring;

use defmt_rtt as _;
use display::SetUp;
use firmware::app::{SceneMemory, ShareMemory, HEIGHT, SCENES, WIDTH};
use hal::pac;
use hal::Clock;
#[cfg(feature = "probe")]
use panic_probe as _;
#[cfg(feature = "pico")]
use rp2040_hal as hal;
#[cfg(feature = "pico2")]
use rp235x_hal as hal;
use wiring::Wiring;

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

/// What tells the slot image's UF2 file from another's (`board_records::slot::IMAGE_MARK`),
/// which `host-sim uf2 --scene` looks for in each 256-byte block before writing a scene beside
/// it: aligned to its 16 bytes, so it never straddles two blocks (it did, once the code before
/// it grew).
#[cfg(feature = "slot")]
#[used]
pub static SLOT_IMAGE: SlotMark = SlotMark(board_records::slot::IMAGE_MARK);

/// The slot image's mark, aligned to its size.
#[cfg(feature = "slot")]
#[repr(C, align(16))]
pub struct SlotMark(pub [u8; 16]);

/// The board's name in the log.
#[cfg(feature = "pico")]
const BOARD: &str = "Pico (RP2040)";
/// The board's name in the log.
#[cfg(feature = "pico2")]
const BOARD: &str = "Pico 2 (RP2350)";

/// The Pico's crystal.
const XTAL_FREQ_HZ: u32 = 12_000_000;

#[hal::entry]
fn main() -> ! {
    ram_code::load();
    let mut pac = pac::Peripherals::take().unwrap();
    guard::reset_reason(&pac.WATCHDOG);
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
    let bus::Connected { display: interface, mut led, mut reset } =
        bus::connect(pins, pac.I2C0, pac.SPI0, &mut pac.RESETS, &clocks);
    #[cfg(feature = "pico")]
    let timer_block = pac.TIMER;
    #[cfg(feature = "pico2")]
    let timer_block = pac.TIMER0;
    let (timer, mut alarm) = sleep::start(timer_block, &mut pac.RESETS, &clocks);

    display::reset(&mut reset, &mut { timer });
    #[cfg(not(any(feature = "sharp", feature = "gray", feature = "uc8151")))]
    let mut target = display::Bands(display::PageTiles::new(interface));
    #[cfg(feature = "gray")]
    let mut target = display::gray::Gray::new(interface);
    #[cfg(feature = "sharp")]
    let mut target = display::Bands(display::sharp::LineTiles::new(interface));
    #[cfg(feature = "uc8151")]
    let mut target = display::Bands(display::uc8151::Gates::new(interface));
    while target.set_up().is_err() {
        defmt::error!(
            "no {} answers on I2C0 (SDA GP{}, SCL GP{}, address {=u8:#x}): check the wiring; retrying in 1 s",
            display::NAME,
            Wiring::SDA,
            Wiring::SCL,
            Wiring::ADDRESS
        );
        sleep::blink(&mut led, &mut alarm, 5);
    }
    wiring::log();
    let cores = cores::TwoCores::start(&mut pac.PSM, &mut pac.PPB, sio.fifo);
    guard::start(watchdog);
    modes::report(board_records::Record::Started {
        scenes: SCENES.len() as u8,
        clk_mhz: clocks.system_clock.freq().to_MHz() as u16,
        bus_khz: Wiring::BUS_KHZ as u16,
    });
    defmt::info!(
        "lattice-rt on the {}: {} scenes, {}x{}, {} MHz, {} at {} kHz, both cores",
        BOARD,
        SCENES.len(),
        WIDTH,
        HEIGHT,
        clocks.system_clock.freq().to_MHz(),
        Wiring::BUS,
        Wiring::BUS_KHZ
    );
    let mut st = SceneMemory::new();
    // The second share's memory (with what trace, then dither keeps of every tile: 24 KiB) is a
    // static, counted in the image's RAM, not on core 0's stack.
    let Some(second) = cortex_m::singleton!(: ShareMemory = ShareMemory::new()) else {
        defmt::panic!("the second share's memory is taken")
    };
    let mut panel = modes::Panel { target, led, timer, alarm, cores, st: &mut st, second };
    if let Some(why) = guard::last_panic() {
        panel.report_panic(why.as_str());
    }
    modes::run(panel)
}
