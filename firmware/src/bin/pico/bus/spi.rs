//! The display on SPI0: each write waits for its bytes to leave the controller (rp2040-hal's
//! `SpiBus::write`), and a transaction ends only when the bus is idle (`embedded-hal-bus`'s
//! `ExclusiveDevice`), so when a band has been drawn it is on the panel. At 10 MHz a band's 144
//! bytes take about 16,000 cycles, under 1 % of a chair frame: nothing is queued, so there is
//! nothing to move on between tiles and nothing to wait for at the end of a frame.

/// The render's hooks with SPI: after each tile core 0 traces, the watchdog is fed (`guard`),
/// and its eye samples count as progress ([`crate::guard::alive`]); the bus needs nothing.
pub struct Pump;

impl lattice_rt::render::Hooks for Pump {
    fn progress(&mut self, _done: u32, _total: u32) -> bool {
        crate::guard::feed();
        true
    }
    #[inline(always)]
    fn sampled(&mut self) {
        crate::guard::alive();
    }
}

/// The frame is on the panel once the last band has been drawn (every write waits for the bus);
/// SPI has no acknowledge, so there is no error a missing display could report.
pub fn flush() -> Result<(), core::convert::Infallible> {
    Ok(())
}

/// A Sharp memory LCD has no reset line.
#[cfg(feature = "sharp")]
pub fn reset<D>(_line: &mut crate::wiring::Reset, _delay: &mut D) {}

/// Pulses the module's RES line (high for 1 ms, low for 10 ms, high) before the display is set
/// up, as the controllers need after power-on.
#[cfg(not(feature = "sharp"))]
pub fn reset<D: embedded_hal::delay::DelayNs>(line: &mut crate::wiring::Reset, delay: &mut D) {
    use embedded_hal::digital::OutputPin;
    // The pin's error type is Infallible.
    let _ = line.set_high();
    delay.delay_ms(1);
    let _ = line.set_low();
    delay.delay_ms(10);
    let _ = line.set_high();
}
