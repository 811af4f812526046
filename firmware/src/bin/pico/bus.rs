//! The display's bus on the wired pins ([`crate::wiring`]): I2C0 through a queue in RAM
//! (`i2c`, with the bus clear of `clear`) on the default build, SPI0 (`spi`) with the `spi`
//! feature; [`connect`] sets the pins up and hands the panel drivers of [`crate::display`] their
//! [`Interface`].

#[cfg(not(feature = "spi"))]
mod clear;
#[cfg(not(feature = "spi"))]
mod i2c;
#[cfg(feature = "spi")]
mod spi;
#[cfg(not(feature = "spi"))]
pub use i2c::{flush, reset, Pump, QueuedI2c};
#[cfg(feature = "spi")]
pub use spi::{flush, reset, Pump};

use crate::hal;
#[cfg(all(feature = "spi", not(feature = "sharp")))]
use crate::wiring::spi_pins;
#[cfg(feature = "spi")]
use crate::wiring::Output;
use crate::wiring::{Led, Reset, Wiring};
use hal::fugit::RateExtU32;
use hal::gpio::bank0;
use hal::gpio::Pin;
#[cfg(feature = "spi")]
use hal::gpio::PullDown;
use hal::pac;

/// The most rows drawn at once: a band of tiles (what the I2C queue holds, and what a panel
/// driver of [`crate::display`] takes at a time).
#[cfg(not(feature = "gray"))]
pub const BAND_ROWS: usize = firmware::app::RENDERED.tile as usize;

/// I2C0 on [`Wiring::SDA`] and [`Wiring::SCL`] at [`Wiring::I2C_HZ`], through the display's
/// queue.
#[cfg(not(feature = "spi"))]
pub type Interface = ssd1306::prelude::I2CInterface<
    QueuedI2c<(
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
        let queued = QueuedI2c::new(bus, Wiring::ADDRESS);
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
