//! The I2C bus clear (UM10204, the I2C specification, 3.1.16): a panel whose transfer was cut off
//! in the middle of a byte (a reset, a knock on the wire) can hold SDA low, waiting for clock
//! pulses to shift out the rest of its byte. The controller then sees a busy bus and never
//! sends a START (the RP2040's I2C block has no bus clear of its own). The pins are taken from
//! the controller as plain GPIOs: SCL is pulsed, at most nine times, until the panel lets SDA
//! go, and a STOP then leaves every device on the bus idle.

use crate::hal;
use hal::pac;

/// GPIO_CTRL's FUNCSEL for the I2C controller and for SIO (the same on the RP2040 and RP2350).
const FUNC_I2C: u8 = 3;
/// See [`FUNC_I2C`].
const FUNC_SIO: u8 = 5;

/// Clock cycles of half an SCL period while the bus is cleared: 5 µs at 125 MHz (100 kHz, the
/// standard mode every device takes), 4.2 µs on the Pico 2's 150 MHz.
const HALF_PERIOD_CYCLES: u32 = 625;

/// The most SCL pulses a device needs to finish its byte (8 bits and the acknowledge).
const PULSES: u32 = 9;

/// The registers the bus clear drives (the pins' function, the SIO's output and its level).
fn regs() -> (&'static pac::io_bank0::RegisterBlock, &'static pac::sio::RegisterBlock) {
    // SAFETY: only the display's two pins are touched, and only while their controller is held
    // in reset (`QueuedI2c::recover`); SIO's set/clear registers change no other pin.
    #[allow(unsafe_code)]
    unsafe {
        (&*pac::IO_BANK0::ptr(), &*pac::SIO::ptr())
    }
}

/// Gives `pin` to `function` (FUNCSEL).
fn select(pin: u8, function: u8) {
    // SAFETY: 3 (I2C) and 5 (SIO) are valid FUNCSEL values for every bank 0 pin.
    #[allow(unsafe_code)]
    regs().0.gpio(usize::from(pin)).gpio_ctrl().modify(|_, w| unsafe { w.funcsel().bits(function) });
}

/// Drives `pin` low (open drain: output enabled with its output at 0) or lets it go, when its
/// pull-up (and the module's) takes it high unless a device holds it.
fn drive_low(pin: u8, low: bool) {
    let sio = regs().1;
    // SAFETY: one pin's bit in a set or clear register.
    #[allow(unsafe_code)]
    unsafe {
        if low {
            sio.gpio_oe_set().write(|w| w.bits(1 << pin));
        } else {
            sio.gpio_oe_clr().write(|w| w.bits(1 << pin));
        }
    }
    cortex_m::asm::delay(HALF_PERIOD_CYCLES);
}

/// Whether the line on `pin` is high.
fn high(pin: u8) -> bool {
    regs().1.gpio_in().read().bits() & (1 << pin) != 0
}

/// Whether a device holds SDA low while nobody drives the bus.
pub fn sda_held(sda: u8) -> bool {
    !high(sda)
}

/// Clears the bus on `sda` and `scl` if a device holds SDA low: SCL pulsed until SDA is
/// released (at most [`PULSES`] times), then a STOP; the pins go back to the I2C controller.
/// Returns the pulses it took, or `None` when SDA stayed low (a device that needs its power
/// cycled).
pub fn clear(sda: u8, scl: u8) -> Option<u32> {
    let sio = regs().1;
    // SAFETY: the two pins' bits: outputs at 0 (what drives the line is the output enable).
    #[allow(unsafe_code)]
    sio.gpio_out_clr().write(|w| unsafe { w.bits((1 << sda) | (1 << scl)) });
    drive_low(sda, false);
    drive_low(scl, false);
    select(sda, FUNC_SIO);
    select(scl, FUNC_SIO);
    let mut pulses = 0;
    while !high(sda) && pulses < PULSES {
        drive_low(scl, true);
        drive_low(scl, false);
        pulses += 1;
    }
    let released = high(sda);
    // STOP: SDA taken low while SCL is low (no START), then let go while SCL is high.
    drive_low(scl, true);
    drive_low(sda, true);
    drive_low(scl, false);
    drive_low(sda, false);
    select(sda, FUNC_I2C);
    select(scl, FUNC_I2C);
    released.then_some(pulses)
}
