//! The watchdog: started in every board image once the display is set up, and fed by core 0
//! only where it makes progress (after each tile it traces, between frames, while it waits for
//! a panel that does not answer). Core 0 waits for core 1's share of a frame without feeding it,
//! so a core that stops making progress resets the board within [`TIMEOUT_MS`]; the next boot
//! logs why ([`reset_reason`]).

use crate::hal;
use core::cell::RefCell;
use critical_section::Mutex;

/// How long core 0 may go without feeding the watchdog.
pub const TIMEOUT_MS: u32 = 1000;

/// The watchdog, once started.
static WATCHDOG: Mutex<RefCell<Option<hal::Watchdog>>> = Mutex::new(RefCell::new(None));

/// Starts the watchdog and keeps it for [`feed`].
pub fn start(mut watchdog: hal::Watchdog) {
    watchdog.start(hal::fugit::MicrosDurationU32::millis(TIMEOUT_MS));
    critical_section::with(|cs| WATCHDOG.borrow(cs).replace(Some(watchdog)));
}

/// Feeds the watchdog (nothing before [`start`]).
pub fn feed() {
    critical_section::with(|cs| {
        if let Some(w) = WATCHDOG.borrow(cs).borrow().as_ref() {
            w.feed();
        }
    });
}

/// Logs why the board last reset, when the watchdog did it (its REASON register, read before
/// the watchdog is set up again: TIMER after its own timeout, FORCE after a forced reset).
pub fn reset_reason(watchdog: &hal::pac::WATCHDOG) {
    let reason = watchdog.reason().read().bits();
    if reason & 1 != 0 {
        defmt::warn!(
            "the watchdog reset the board: core 0 did not feed it for {} ms (a core stopped making progress)",
            TIMEOUT_MS
        );
    } else if reason & 2 != 0 {
        defmt::warn!("the board was reset by its watchdog on request");
    }
}
