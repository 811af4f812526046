//! The board's one button: a push button from [`Wiring::NEXT`] to ground shows the next scene.
//! It is read between scenes, every probe of the pause ([`crate::modes`]): a press (the pin
//! going low after it was high) ends the pause. Holding it down skips one scene, not all.

use crate::hal;
use crate::wiring::Wiring;
use core::sync::atomic::{AtomicBool, Ordering};

/// The button was up at the last read (a press is a change from up to down).
static UP: AtomicBool = AtomicBool::new(true);

/// Whether the button has been pressed since the last call: it is down now and was up then.
pub fn pressed() -> bool {
    // SAFETY: a read of SIO's GPIO_IN, which has no side effects.
    #[allow(unsafe_code)]
    let up = unsafe { (*hal::pac::SIO::ptr()).gpio_in().read().bits() } & (1 << Wiring::NEXT) != 0;
    let was_up = UP.load(Ordering::Relaxed);
    UP.store(up, Ordering::Relaxed);
    was_up && !up
}
