//! How the display is wired to the board: the one place for its pins, bus, address and clock
//! (the Pico and the Pico 2 share the pin-out). The log messages and docs/flashing.md name what
//! is here.

use crate::hal;
use hal::fugit::RateExtU32;
use hal::pac;

/// The display's bus, address and clock.
pub struct Wiring;

impl Wiring {
    /// The GPIO the display's SDA is on.
    pub const SDA: u8 = 4;
    /// The GPIO the display's SCL is on.
    pub const SCL: u8 = 5;
    /// The display's I2C address (0x3D for modules with the address jumper moved).
    pub const ADDRESS: u8 = 0x3C;
    /// The bus clock: 400 kHz, the SSD1306's specified fast mode; 1 MHz (fast mode plus, which
    /// many modules take) with the `i2c-1mhz` feature.
    pub const I2C_HZ: u32 = if cfg!(feature = "i2c-1mhz") { 1_000_000 } else { 400_000 };
}

/// I2C0 on [`Wiring::SDA`] and [`Wiring::SCL`] at [`Wiring::I2C_HZ`].
pub type DisplayBus = hal::I2C<
    pac::I2C0,
    (
        hal::gpio::Pin<hal::gpio::bank0::Gpio4, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
        hal::gpio::Pin<hal::gpio::bank0::Gpio5, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
    ),
>;

/// The on-board LED as an output.
pub type Led = hal::gpio::Pin<hal::gpio::bank0::Gpio25, hal::gpio::FunctionSioOutput, hal::gpio::PullDown>;

/// Sets the pins up as [`Wiring`] says: the display's bus, and the on-board LED on GP25 (lit
/// while a frame renders; `cargo xtask board` watches it).
pub fn connect(pins: hal::gpio::Pins, i2c0: pac::I2C0, resets: &mut pac::RESETS, system_clock: &hal::clocks::SystemClock) -> (DisplayBus, Led) {
    let sda = pins.gpio4.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let scl = pins.gpio5.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
    let bus = hal::I2C::i2c0(i2c0, sda, scl, Wiring::I2C_HZ.Hz(), resets, system_clock);
    (bus, pins.gpio25.into_push_pull_output())
}
