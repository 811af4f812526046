//! The board's two buttons, read between scenes at every probe of the pause ([`crate::modes`]):
//! [`Wiring::NEXT`] shows the next scene, [`Wiring::TURN`] the same scene with the camera turned
//! a step further around it. A press (the button going down after it was up) ends the pause;
//! holding a button down counts once, not at every probe.

use crate::hal;
use crate::wiring::Wiring;
use core::sync::atomic::{AtomicU32, Ordering};

/// A button pressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Press {
    /// The next scene ([`Wiring::NEXT`]).
    Next,
    /// The camera turned ([`Wiring::TURN`]).
    Turn,
}

/// The buttons' pins, in the order [`pressed`] reports them.
const BUTTONS: [(u8, Press); 2] = [(Wiring::NEXT, Press::Next), (Wiring::TURN, Press::Turn)];

/// The buttons down at the last read, as GPIO bits (a press is a change from up to down).
static DOWN: AtomicU32 = AtomicU32::new(0);

/// Presses read and not yet reported, as GPIO bits: of two buttons pressed between two reads,
/// the second is reported by the next call.
static PENDING: AtomicU32 = AtomicU32::new(0);

/// The button pressed since the last call, if any: down now and up then. Of both pressed, the
/// next-scene button first and the camera-turn button at the next call (the next scene, then
/// that scene turned), so no press is lost.
pub fn pressed() -> Option<Press> {
    // SAFETY: a read of SIO's GPIO_IN, which has no side effects.
    #[allow(unsafe_code)]
    let levels = unsafe { (*hal::pac::SIO::ptr()).gpio_in().read().bits() };
    let mask = BUTTONS.iter().fold(0, |m, &(pin, _)| m | 1 << pin);
    // A button pressed takes its pin to the level of the rail it closes to.
    let down = if Wiring::BUTTONS_ACTIVE_HIGH { levels } else { !levels } & mask;
    // A load and a store (the M0 has no atomic swap): only core 0 reads the buttons.
    let was_down = DOWN.load(Ordering::Relaxed);
    DOWN.store(down, Ordering::Relaxed);
    let pending = PENDING.load(Ordering::Relaxed) | (down & !was_down);
    let first = BUTTONS.iter().find(|&&(pin, _)| pending & 1 << pin != 0);
    PENDING.store(first.map_or(pending, |&(pin, _)| pending & !(1 << pin)), Ordering::Relaxed);
    first.map(|&(_, press)| press)
}
