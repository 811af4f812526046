//! Raspberry Pi Pico + SSD1306 128x64 OLED on I2C: renders the embedded scenes in turn, tile by
//! tile straight to the display (each 8x8 tile is one SSD1306 page high, so it is sent as eight
//! column bytes; no framebuffer), and logs per-frame time and statistics over defmt-rtt.
//!
//! Wiring (change it here, in `Wiring` below, and nowhere else): SDA on GP4, SCL on GP5,
//! display address 0x3C, VCC on 3V3(OUT), GND on GND.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use firmware::app::{render_scene, Scalar, Storage, HEIGHT, SCENES, WIDTH};
use firmware::stack;
use hal::fugit::RateExtU32;
use hal::pac;
use lattice_rt::render::Hooks;
use panic_probe as _;
use rp2040_hal as hal;
use ssd1306::mode::BasicMode;
use ssd1306::prelude::*;
use ssd1306::{I2CDisplayInterface, Ssd1306};

/// The second-stage bootloader for the Pico's W25Q080 flash.
#[link_section = ".boot2"]
#[used]
pub static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

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
        for (i, c) in colors.into_iter().take(w * h).enumerate() {
            if c.is_on() {
                cols[i % w] |= 1 << (i / w);
            }
        }
        let page = (y0 / 8) as u8;
        self.display.set_draw_area((x0 as u8, page), ((x0 as usize + w) as u8, page + 1))?;
        self.display.draw(&cols[..w])
    }
}

/// Logs progress every few tiles (the display shows it anyway).
struct Progress;
impl Hooks for Progress {}

#[hal::entry]
fn main() -> ! {
    let mut pac = pac::Peripherals::take().unwrap();
    let mut watchdog = hal::Watchdog::new(pac.WATCHDOG);
    let clocks = hal::clocks::init_clocks_and_plls(
        XTAL_FREQ_HZ,
        pac.XOSC,
        pac.CLOCKS,
        pac.PLL_SYS,
        pac.PLL_USB,
        &mut pac.RESETS,
        &mut watchdog,
    )
    .ok()
    .unwrap();
    let sio = hal::Sio::new(pac.SIO);
    let pins = hal::gpio::Pins::new(pac.IO_BANK0, pac.PADS_BANK0, sio.gpio_bank0, &mut pac.RESETS);
    // Wiring: the two pins and the address of the display.
    let sda = pins.gpio4.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let scl = pins.gpio5.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let i2c = hal::I2C::i2c0(pac.I2C0, sda, scl, I2C_HZ.Hz(), &mut pac.RESETS, &clocks.system_clock);
    let interface = I2CDisplayInterface::new(i2c); // address 0x3C; new_alternate_address() for 0x3D
    let timer = hal::Timer::new(pac.TIMER, &mut pac.RESETS, &clocks);

    let mut display = Ssd1306::new(interface, DisplaySize128x64, DisplayRotation::Rotate0);
    if display.init().is_err() {
        defmt::panic!("no SSD1306 answers on I2C0 (GP4 SDA, GP5 SCL, address 0x3C)");
    }
    let mut target = PageTiles { display };
    let mut st = Storage::<Scalar>::new();
    defmt::info!("lattice-rt on the Pico: {} scenes, {}x{}", SCENES.len(), WIDTH, HEIGHT);
    loop {
        for (name, text) in SCENES {
            let t0 = timer.get_counter();
            match render_scene(text, &mut st, &mut target, &mut Progress) {
                Ok(r) => {
                    let ms = (timer.get_counter() - t0).to_millis();
                    let s = r.stats;
                    defmt::info!(
                        "{}: {} ms, rays {} (shadow {}, reflection {}, refraction {}), object tests {}, cells {}, lattice {} B, stack high-water {} B",
                        name, ms, s.total_rays(), s.rays[1], s.rays[2], s.rays[3], s.object_tests, s.cells_visited,
                        r.lattice_bytes, stack::high_water()
                    );
                }
                Err(e) => defmt::error!("{}: {}", name, defmt::Display2Format(&e)),
            }
            let t1 = timer.get_counter();
            while (timer.get_counter() - t1).to_millis() < 3000 {}
        }
    }
}
