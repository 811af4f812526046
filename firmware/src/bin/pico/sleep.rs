//! The board's timer: frames are timed with it, and the firmware sleeps between scenes on one
//! of its alarms (`wfi`), whose interrupt is here too.

use crate::hal;
use embedded_hal::digital::OutputPin;
use hal::pac;
use hal::pac::interrupt;

/// The 1 MHz timer.
#[cfg(feature = "pico")]
pub type Timer = hal::Timer;
/// The 1 MHz timer.
#[cfg(feature = "pico2")]
pub type Timer = hal::Timer<hal::timer::CopyableTimer0>;
/// The timer's registers.
#[cfg(feature = "pico")]
pub type TimerBlock = pac::TIMER;
/// The timer's registers.
#[cfg(feature = "pico2")]
pub type TimerBlock = pac::TIMER0;

/// Starts the timer and takes the alarm the firmware sleeps on.
pub fn start(block: TimerBlock, resets: &mut pac::RESETS, clocks: &hal::clocks::ClocksManager) -> (Timer, Alarm0) {
    #[cfg(feature = "pico")]
    let mut timer = hal::Timer::new(block, resets, clocks);
    #[cfg(feature = "pico2")]
    let mut timer = hal::Timer::new_timer0(block, resets, clocks);
    let Some(alarm) = timer.alarm_0() else {
        defmt::panic!("timer alarm 0 is taken");
    };
    (timer, alarm)
}

/// Blinks `led` quickly `times` times (a second in all): the sign that no display answers.
pub fn blink(led: &mut impl OutputPin, alarm: &mut Alarm0, times: u32) {
    for _ in 0..times {
        let _ = led.set_high();
        sleep_ms(alarm, 100);
        let _ = led.set_low();
        sleep_ms(alarm, 100);
    }
}

/// The timer alarm the firmware sleeps on.
#[cfg(feature = "pico")]
pub type Alarm0 = hal::timer::Alarm0;
/// Its interrupt.
#[cfg(feature = "pico")]
const ALARM_IRQ: pac::Interrupt = pac::Interrupt::TIMER_IRQ_0;
/// The timer alarm the firmware sleeps on.
#[cfg(feature = "pico2")]
pub type Alarm0 = hal::timer::Alarm0<hal::timer::CopyableTimer0>;
/// Its interrupt.
#[cfg(feature = "pico2")]
const ALARM_IRQ: pac::Interrupt = pac::Interrupt::TIMER0_IRQ_0;

/// The timer's microseconds (its raw low word: it wraps every 71 minutes, so take differences
/// with `wrapping_sub`), for waits that must not outlast a deadline (the I2C queue's) and the
/// Sharp LCD's VCOM.
#[cfg(any(not(feature = "spi"), feature = "sharp"))]
pub fn micros() -> u32 {
    // SAFETY: a read of TIMERAWL, which has no side effects (unlike TIMELR, which latches TIMEHR).
    #[allow(unsafe_code)]
    unsafe {
        (*TimerBlock::ptr()).timerawl().read().bits()
    }
}

/// Sleeps (`wfi`) until `alarm` has run `ms` milliseconds, instead of spinning: the core draws
/// less power, and an emulator skips the idle time. The check and the `wfi` run with interrupts
/// masked, so an alarm that fires between them still ends the `wfi` (a pending interrupt wakes
/// the core whatever PRIMASK says); the alarm's interrupt handler then clears it.
pub fn sleep_ms(alarm: &mut Alarm0, ms: u32) {
    use hal::timer::Alarm;
    if alarm.schedule(hal::fugit::MicrosDurationU32::millis(ms)).is_err() {
        return;
    }
    alarm.enable_interrupt();
    // SAFETY: the alarm's handler touches nothing but the alarm's own interrupt flag, so
    // enabling it cannot break any critical section or data the main loop holds.
    #[allow(unsafe_code)]
    unsafe {
        cortex_m::peripheral::NVIC::unmask(ALARM_IRQ)
    };
    while !cortex_m::interrupt::free(|_| {
        let done = alarm.finished();
        if !done {
            cortex_m::asm::wfi();
        }
        done
    }) {}
    cortex_m::peripheral::NVIC::mask(ALARM_IRQ);
    alarm.disable_interrupt();
}

/// Alarm 0 has fired: clear its interrupt (the main loop only needed to wake up).
#[cfg(feature = "pico")]
#[interrupt]
fn TIMER_IRQ_0() {
    // SAFETY: a write-1-to-clear of alarm 0's bit in TIMER.INTR; no other code writes INTR
    // while this alarm is armed, and the write is a single atomic store.
    #[allow(unsafe_code)]
    unsafe {
        (*pac::TIMER::ptr()).intr().write(|w| w.alarm_0().clear_bit_by_one())
    };
}

/// Alarm 0 of TIMER0 has fired: clear its interrupt (the main loop only needed to wake up).
#[cfg(feature = "pico2")]
#[interrupt]
fn TIMER0_IRQ_0() {
    // SAFETY: as for the Pico's handler, on TIMER0.INTR.
    #[allow(unsafe_code)]
    unsafe {
        (*pac::TIMER0::ptr()).intr().write(|w| w.alarm_0().clear_bit_by_one())
    };
}
