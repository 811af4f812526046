//! How the display is wired to the board: the one place for its pins, bus, address and clock
//! (the Pico and the Pico 2 share the pin-out). The log messages and docs/flashing.md name what
//! is here. A module on I2C is the default; the `spi` feature is for the 4-wire SPI modules,
//! `thumby` for the Thumby's own panel and button, on its pins.

use crate::hal;
use hal::fugit::RateExtU32;
use hal::gpio::bank0;
use hal::gpio::{Pin, PullDown};
use hal::pac;

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

/// An output pin as `connect` sets it up.
type Output<P> = Pin<P, hal::gpio::FunctionSioOutput, PullDown>;

/// The SPI display's chip select ([`Wiring::CS`]), data/command ([`Wiring::DC`]) and reset
/// ([`Wiring::RES`]) pins, as types: GP17, GP20, GP21.
#[cfg(all(feature = "spi", not(feature = "sharp"), not(feature = "thumby")))]
mod spi_pins {
    use super::bank0;
    pub type Cs = bank0::Gpio17;
    pub type Dc = bank0::Gpio20;
    pub type Res = bank0::Gpio21;
}
/// The Thumby's chip select ([`Wiring::CS`]), data/command ([`Wiring::DC`]) and reset
/// ([`Wiring::RES`]) pins, as types: GP16, GP17, GP20.
#[cfg(feature = "thumby")]
mod spi_pins {
    use super::bank0;
    pub type Cs = bank0::Gpio16;
    pub type Dc = bank0::Gpio17;
    pub type Res = bank0::Gpio20;
}

/// I2C0 on [`Wiring::SDA`] and [`Wiring::SCL`] at [`Wiring::I2C_HZ`], through the display's
/// queue.
#[cfg(not(feature = "spi"))]
pub type Interface = ssd1306::prelude::I2CInterface<
    crate::display::QueuedI2c<(
        Pin<bank0::Gpio4, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
        Pin<bank0::Gpio5, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
    )>,
>;

/// SPI0 on [`Wiring::MOSI`] and [`Wiring::SCK`] at [`Wiring::SPI_HZ`].
#[cfg(feature = "spi")]
pub type Spi0 = hal::spi::Spi<
    hal::spi::Enabled,
    pac::SPI0,
    (Pin<bank0::Gpio19, hal::gpio::FunctionSpi, PullDown>, Pin<bank0::Gpio18, hal::gpio::FunctionSpi, PullDown>),
    8,
>;

/// A Sharp memory LCD's bus: SPI0, its chip select (active high) on [`Wiring::CS`] and its
/// DISP on [`Wiring::DISP`].
#[cfg(feature = "sharp")]
pub struct Interface {
    /// SPI0.
    pub spi: Spi0,
    /// SCS: high while a command is sent.
    pub cs: Output<bank0::Gpio17>,
    /// DISP: high shows the memory's picture.
    pub disp: Output<bank0::Gpio20>,
}

/// SPI0 on [`Wiring::MOSI`] and [`Wiring::SCK`] at [`Wiring::SPI_HZ`], chip select on
/// [`Wiring::CS`], data/command on [`Wiring::DC`].
#[cfg(all(feature = "spi", not(feature = "sharp")))]
pub type Interface = ssd1306::prelude::SPIInterface<
    embedded_hal_bus::spi::ExclusiveDevice<Spi0, Output<spi_pins::Cs>, embedded_hal_bus::spi::NoDelay>,
    Output<spi_pins::Dc>,
>;

/// The on-board LED as an output.
pub type Led = Output<bank0::Gpio25>;

/// The display's reset line (`spi`: [`Wiring::RES`]; an I2C module resets itself at power-on).
#[cfg(all(feature = "spi", not(feature = "sharp")))]
pub type Reset = Output<spi_pins::Res>;
/// The display's reset line (none on an I2C module, which resets itself at power-on, nor on a
/// Sharp memory LCD).
#[cfg(any(not(feature = "spi"), feature = "sharp"))]
pub type Reset = ();

/// What [`connect`] sets up.
pub struct Connected {
    /// The display's bus, ready for the `ssd1306` driver.
    pub display: Interface,
    /// The on-board LED on GP25 (lit while a frame renders; `cargo xtask board` watches it).
    pub led: Led,
    /// The display's reset line, if it has one.
    pub reset: Reset,
}

/// Sets the pins up as [`Wiring`] says: the display's bus (I2C0 on the default build, SPI0 with
/// `spi`; the other controller is left in reset), the on-board LED and the button's input.
#[allow(unused_variables)]
pub fn connect(
    pins: hal::gpio::Pins,
    i2c0: pac::I2C0,
    spi0: pac::SPI0,
    resets: &mut pac::RESETS,
    clocks: &hal::clocks::ClocksManager,
) -> Connected {
    #[cfg(not(feature = "spi"))]
    let (display, reset) = {
        let sda = pins.gpio4.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
        let scl = pins.gpio5.reconfigure::<hal::gpio::FunctionI2C, hal::gpio::PullUp>();
        let bus = hal::I2C::i2c0(i2c0, sda, scl, Wiring::I2C_HZ.Hz(), resets, &clocks.system_clock);
        let queued = crate::display::QueuedI2c::new(bus, Wiring::ADDRESS);
        (ssd1306::I2CDisplayInterface::new_custom_address(queued, Wiring::ADDRESS), ())
    };
    #[cfg(feature = "spi")]
    let spi = {
        use hal::Clock;
        let pins_spi = (
            pins.gpio19.into_function::<hal::gpio::FunctionSpi>(),
            pins.gpio18.into_function::<hal::gpio::FunctionSpi>(),
        );
        hal::spi::Spi::<_, _, _, 8>::new(spi0, pins_spi).init(
            resets,
            clocks.peripheral_clock.freq(),
            Wiring::SPI_HZ.Hz(),
            embedded_hal::spi::MODE_0,
        )
    };
    #[cfg(all(feature = "spi", not(feature = "sharp"), not(feature = "thumby")))]
    let (cs, dc, res) = (pins.gpio17, pins.gpio20, pins.gpio21);
    #[cfg(feature = "thumby")]
    let (cs, dc, res) = (pins.gpio16, pins.gpio17, pins.gpio20);
    #[cfg(all(feature = "spi", not(feature = "sharp")))]
    let (display, reset) = {
        let cs = cs.into_push_pull_output_in_state(hal::gpio::PinState::High);
        let Ok(device) = embedded_hal_bus::spi::ExclusiveDevice::new_no_delay(spi, cs);
        let dc = dc.into_push_pull_output();
        (ssd1306::prelude::SPIInterface::new(device, dc), res.into_push_pull_output_in_state(hal::gpio::PinState::High))
    };
    #[cfg(feature = "sharp")]
    let (display, reset) = {
        let cs = pins.gpio17.into_push_pull_output_in_state(hal::gpio::PinState::Low);
        let disp = pins.gpio20.into_push_pull_output_in_state(hal::gpio::PinState::Low);
        (Interface { spi, cs, disp }, ())
    };
    // The buttons' pins: inputs pulled away from the rail a press closes them to (read by
    // `button::pressed`); a pin's setting stays when its value is dropped.
    #[cfg(not(any(feature = "thumby", feature = "uc8151")))]
    let _ = (pins.gpio14.into_pull_up_input(), pins.gpio15.into_pull_up_input());
    #[cfg(feature = "uc8151")]
    let _ = (pins.gpio14.into_pull_down_input(), pins.gpio15.into_pull_down_input());
    #[cfg(feature = "thumby")]
    let _ = (pins.gpio27.into_pull_up_input(), pins.gpio24.into_pull_up_input());
    #[cfg(feature = "uc8151")]
    {
        let _ = pins.gpio26.into_pull_up_input();
        let _ = pins.gpio10.into_push_pull_output_in_state(hal::gpio::PinState::High);
    }
    Connected { display, led: pins.gpio25.into_push_pull_output(), reset }
}

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
