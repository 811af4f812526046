//! How the display is wired to the board: the one place for its pins, bus, address and clock
//! (the Pico and the Pico 2 share the pin-out). The log messages and docs/flashing.md name what
//! is here. A module on I2C is the default; the `spi` feature is for the 4-wire SPI modules.

use crate::hal;
use hal::fugit::RateExtU32;
use hal::gpio::bank0;
use hal::gpio::{Pin, PullDown};
use hal::pac;

/// The display's bus, pins, address and clock.
pub struct Wiring;

#[cfg_attr(not(feature = "spi"), allow(dead_code))] // the SPI pins, named in the `spi` build's log
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
    /// The GPIO the display's CS is on (`spi`; active low).
    pub const CS: u8 = 17;
    /// The GPIO the display's DC (data/command) is on (`spi`).
    pub const DC: u8 = 20;
    /// The GPIO the display's RES (reset, active low) is on (`spi`).
    pub const RES: u8 = 21;
    /// The SPI clock asked for: 10 MHz, the SSD1306's fastest serial clock (100 ns a cycle);
    /// rp2040-hal sets the nearest clock at or under it that clk_peri divides to.
    pub const SPI_HZ: u32 = 10_000_000;
    /// The display bus's clock in kHz, as the log and the `Started` record give it.
    pub const BUS_KHZ: u32 = if cfg!(feature = "spi") { Wiring::SPI_HZ / 1000 } else { Wiring::I2C_HZ / 1000 };
    /// The display bus's name in the log.
    pub const BUS: &'static str = if cfg!(feature = "spi") { "SPI" } else { "I2C" };
}

/// An output pin as `connect` sets it up.
type Output<P> = Pin<P, hal::gpio::FunctionSioOutput, PullDown>;

/// I2C0 on [`Wiring::SDA`] and [`Wiring::SCL`] at [`Wiring::I2C_HZ`], through the display's
/// queue.
#[cfg(not(feature = "spi"))]
pub type Interface = ssd1306::prelude::I2CInterface<
    crate::display::QueuedI2c<(
        Pin<bank0::Gpio4, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
        Pin<bank0::Gpio5, hal::gpio::FunctionI2C, hal::gpio::PullUp>,
    )>,
>;

/// SPI0 on [`Wiring::MOSI`] and [`Wiring::SCK`] at [`Wiring::SPI_HZ`], chip select on
/// [`Wiring::CS`], data/command on [`Wiring::DC`].
#[cfg(feature = "spi")]
pub type Interface = ssd1306::prelude::SPIInterface<
    embedded_hal_bus::spi::ExclusiveDevice<
        hal::spi::Spi<
            hal::spi::Enabled,
            pac::SPI0,
            (
                Pin<bank0::Gpio19, hal::gpio::FunctionSpi, PullDown>,
                Pin<bank0::Gpio18, hal::gpio::FunctionSpi, PullDown>,
            ),
            8,
        >,
        Output<bank0::Gpio17>,
        embedded_hal_bus::spi::NoDelay,
    >,
    Output<bank0::Gpio20>,
>;

/// The on-board LED as an output.
pub type Led = Output<bank0::Gpio25>;

/// The display's reset line (`spi`: [`Wiring::RES`]; an I2C module resets itself at power-on).
#[cfg(feature = "spi")]
pub type Reset = Output<bank0::Gpio21>;
/// The display's reset line (none on an I2C module: it resets itself at power-on).
#[cfg(not(feature = "spi"))]
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
/// `spi`; the other controller is left in reset), and the on-board LED.
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
    let (display, reset) = {
        use hal::Clock;
        let pins_spi = (
            pins.gpio19.into_function::<hal::gpio::FunctionSpi>(),
            pins.gpio18.into_function::<hal::gpio::FunctionSpi>(),
        );
        let bus = hal::spi::Spi::<_, _, _, 8>::new(spi0, pins_spi).init(
            resets,
            clocks.peripheral_clock.freq(),
            Wiring::SPI_HZ.Hz(),
            embedded_hal::spi::MODE_0,
        );
        let cs = pins.gpio17.into_push_pull_output_in_state(hal::gpio::PinState::High);
        let Ok(device) = embedded_hal_bus::spi::ExclusiveDevice::new_no_delay(bus, cs);
        let dc = pins.gpio20.into_push_pull_output();
        (
            ssd1306::prelude::SPIInterface::new(device, dc),
            pins.gpio21.into_push_pull_output_in_state(hal::gpio::PinState::High),
        )
    };
    Connected { display, led: pins.gpio25.into_push_pull_output(), reset }
}
