//! How the display is wired to the board: the one place for its pins, bus, address and clock
//! (the Pico and the Pico 2 share the pin-out). The log messages and docs/flashing.md name what
//! is here. A module on I2C is the default; the `spi` feature is for the 4-wire SPI modules,
//! `thumby` for the Thumby's own panel and button, on its pins.

use crate::hal;
use hal::gpio::bank0;
use hal::gpio::{Pin, PullDown};

/// The display's bus, pins, address and clock.
pub struct Wiring;

#[allow(dead_code)] // every bus's pins; each build names those of its own in its log
impl Wiring {
    /// The GPIO the display's SDA is on (I2C).
    pub const SDA: u8 = 4;
    /// The GPIO the display's SCL is on (I2C).
    pub const SCL: u8 = 5;
    /// The display's I2C address (0x3D for modules with the address jumper moved).
    pub const ADDRESS: u8 = 0x3C;
    /// The I2C clock: 400 kHz, the SSD1306's specified fast mode; 1 MHz (fast mode plus, which
    /// many modules take) with the `i2c-1mhz` feature.
    pub const I2C_HZ: u32 = if cfg!(feature = "i2c-1mhz") { 1_000_000 } else { 400_000 };
    /// The GPIO the display's D0 (SPI clock) is on (`spi`: SPI0 SCK).
    pub const SCK: u8 = 18;
    /// The GPIO the display's D1 (SPI data in) is on (`spi`: SPI0 TX).
    pub const MOSI: u8 = 19;
    /// The GPIO the display's CS is on (`spi`; active low; the Thumby's on GP16).
    pub const CS: u8 = if cfg!(feature = "thumby") { 16 } else { 17 };
    /// The GPIO the display's DC (data/command) is on (`spi`; the Thumby's on GP17).
    pub const DC: u8 = if cfg!(feature = "thumby") { 17 } else { 20 };
    /// The GPIO the display's RES (reset, active low) is on (`spi`; the Thumby's on GP20).
    pub const RES: u8 = if cfg!(feature = "thumby") { 20 } else { 21 };
    /// The GPIO a push button shows the next scene on (pressed during the pause between scenes,
    /// it ends the pause): GP14 (the Badger's button C), or the Thumby's A button on GP27.
    pub const NEXT: u8 = if cfg!(feature = "thumby") { 27 } else { 14 };
    /// The GPIO a push button turns the camera on (pressed during the pause, it draws the scene
    /// again from a step further around it): GP15 (the Badger's up button), or the Thumby's B
    /// button on GP24.
    pub const TURN: u8 = if cfg!(feature = "thumby") { 24 } else { 15 };
    /// Whether a button pressed takes its pin high: the Badger 2040's close to 3V3 and are read
    /// with pull-downs; the others (a push button on a Pico, the Thumby's) close to ground and
    /// are read with pull-ups.
    pub const BUTTONS_ACTIVE_HIGH: bool = cfg!(feature = "uc8151");
    /// The GPIO a Sharp memory LCD's DISP (display on) is on (`sharp`; its SCS, active high, is
    /// on [`Wiring::CS`], its SCLK and SI on SPI0's).
    pub const DISP: u8 = 20;
    /// The GPIO the e-paper's BUSY (its output, low while it works) is on (`uc8151`).
    pub const BUSY: u8 = 26;
    /// The Badger 2040's 3V3_EN: held high, or the board switches itself off on battery
    /// (`uc8151`).
    pub const POWER_ON: u8 = 10;
    /// The SPI clock asked for: 10 MHz, the SSD1306's fastest serial clock (100 ns a cycle); for
    /// a Sharp memory LCD 2 MHz on the LS027B7DH01 (what Adafruit's and micropython-nano-gui's
    /// drivers run it at) and 1 MHz on the smaller LS013B7DH03. rp2040-hal sets the nearest clock
    /// at or under it that clk_peri divides to.
    pub const SPI_HZ: u32 = if cfg!(feature = "sharp-400x240") {
        2_000_000
    } else if cfg!(feature = "sharp") {
        1_000_000
    } else {
        10_000_000
    };
    /// The display bus's clock in kHz, as the log and the `Started` record give it.
    pub const BUS_KHZ: u32 = if cfg!(feature = "spi") { Wiring::SPI_HZ / 1000 } else { Wiring::I2C_HZ / 1000 };
    /// The display bus's name in the log.
    pub const BUS: &'static str = if cfg!(feature = "spi") { "SPI" } else { "I2C" };
}

/// An output pin as [`crate::bus::connect`] sets it up.
pub(crate) type Output<P> = Pin<P, hal::gpio::FunctionSioOutput, PullDown>;

/// The SPI display's chip select ([`Wiring::CS`]), data/command ([`Wiring::DC`]) and reset
/// ([`Wiring::RES`]) pins, as types: GP17, GP20, GP21.
#[cfg(all(feature = "spi", not(feature = "sharp"), not(feature = "thumby")))]
pub(crate) mod spi_pins {
    use super::bank0;
    pub type Cs = bank0::Gpio17;
    pub type Dc = bank0::Gpio20;
    pub type Res = bank0::Gpio21;
}
/// The Thumby's chip select ([`Wiring::CS`]), data/command ([`Wiring::DC`]) and reset
/// ([`Wiring::RES`]) pins, as types: GP16, GP17, GP20.
#[cfg(feature = "thumby")]
pub(crate) mod spi_pins {
    use super::bank0;
    pub type Cs = bank0::Gpio16;
    pub type Dc = bank0::Gpio17;
    pub type Res = bank0::Gpio20;
}

/// The on-board LED as an output.
pub type Led = Output<bank0::Gpio25>;

/// The display's reset line (`spi`: [`Wiring::RES`]; an I2C module resets itself at power-on).
#[cfg(all(feature = "spi", not(feature = "sharp")))]
pub type Reset = Output<spi_pins::Res>;
/// The display's reset line (none on an I2C module, which resets itself at power-on, nor on a
/// Sharp memory LCD).
#[cfg(any(not(feature = "spi"), feature = "sharp"))]
pub type Reset = ();

/// Logs how the display is wired, on the SPI builds (the I2C build says it only when no display
/// answers).
pub fn log() {
    #[cfg(feature = "sharp")]
    defmt::info!(
        "the Sharp memory LCD on SPI0: SCLK GP{}, SI GP{}, SCS GP{} (active high), DISP GP{}",
        Wiring::SCK,
        Wiring::MOSI,
        Wiring::CS,
        Wiring::DISP
    );
    #[cfg(all(feature = "spi", not(feature = "sharp")))]
    defmt::info!(
        "the display on SPI0: SCK GP{}, MOSI GP{}, CS GP{}, DC GP{}, RES GP{}",
        Wiring::SCK,
        Wiring::MOSI,
        Wiring::CS,
        Wiring::DC,
        Wiring::RES
    );
    #[cfg(feature = "uc8151")]
    defmt::info!("the e-paper's BUSY on GP{}, 3V3_EN held high on GP{}", Wiring::BUSY, Wiring::POWER_ON);
}

#[cfg(all(feature = "thumby", any(feature = "sharp", feature = "uc8151")))]
compile_error!("the Thumby has its own panel on its own pins: leave out `sharp` and `uc8151`");
