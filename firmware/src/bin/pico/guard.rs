//! What brings a board back by itself. The watchdog: started in every board image once the
//! display is set up, and fed only where the firmware makes progress: by core 0 after each tile
//! it traces, between frames and while it waits for a panel that does not answer, and by either
//! core every [`SAMPLES_PER_FEED`] eye samples traced ([`alive`]: one tile of a heavy scene can
//! take seconds). A core that stops making progress stops feeding it, and the other runs out
//! of tiles and waits for it without feeding, so the board resets within [`TIMEOUT_MS`] of
//! that; the next boot logs why ([`reset_reason`]). The panic
//! handler of the images without a probe: the reason kept in RAM across a reset, reported by
//! the next boot ([`last_panic`]); `cargo pico` (feature `probe`) keeps panic-probe's
//! breakpoint for the debugger.

use crate::hal;
use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};
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

/// Eye samples traced (by both cores, so some counts may be lost to a race: it only paces
/// [`alive`]'s feeding).
static SAMPLES: AtomicU32 = AtomicU32::new(0);

/// How many eye samples [`alive`] counts between feeds: at most a few million cycles even in a
/// scene of thousands of objects, far below [`TIMEOUT_MS`], and the watchdog's critical
/// section taken once in 32 samples, not at each.
pub const SAMPLES_PER_FEED: u32 = 32;

/// An eye sample traced, on either core: the watchdog fed every [`SAMPLES_PER_FEED`]. Out of
/// line and in flash: the tracer's code in SRAM (`ram_code`) carries one call for it, not its
/// body at every place the sampler traces.
#[inline(never)]
pub fn alive() {
    // Load and store: a Cortex-M0+ has no atomic read-modify-write.
    let n = SAMPLES.load(Ordering::Relaxed).wrapping_add(1);
    SAMPLES.store(n, Ordering::Relaxed);
    if n.is_multiple_of(SAMPLES_PER_FEED) {
        feed();
    }
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

/// Bytes of a panic's reason kept for the next boot.
const NOTE_BYTES: usize = 120;

/// A panic's reason for the next boot, in RAM the runtime leaves as it is at boot (`.uninit`),
/// which a reset keeps: valid when `magic` is [`NOTE_MAGIC`].
#[repr(C)]
struct Note {
    magic: u32,
    len: u32,
    text: [u8; NOTE_BYTES],
}

/// "PANC".
const NOTE_MAGIC: u32 = 0x434e_4150;

/// The note a panic leaves.
#[link_section = ".uninit.PANIC_NOTE"]
static mut NOTE: core::mem::MaybeUninit<Note> = core::mem::MaybeUninit::uninit();

/// Why the last boot panicked (the note's text).
pub struct PanicNote {
    text: [u8; NOTE_BYTES],
    len: usize,
}

impl PanicNote {
    /// The reason and where.
    pub fn as_str(&self) -> &str {
        core::str::from_utf8(self.text.get(..self.len).unwrap_or(&[])).unwrap_or("(no reason kept)")
    }
}

/// The reason the last boot panicked, if it did (read once: the note is cleared).
pub fn last_panic() -> Option<PanicNote> {
    // SAFETY: read and cleared on core 0 at boot, before core 1 or any interrupt runs; every
    // bit pattern is a valid `Note` (plain integers), and its length is bounded below.
    #[allow(unsafe_code)]
    let note = unsafe { &mut *core::ptr::addr_of_mut!(NOTE) };
    #[allow(unsafe_code)]
    let n = unsafe { note.assume_init_mut() };
    if n.magic != NOTE_MAGIC {
        return None;
    }
    n.magic = 0;
    Some(PanicNote { text: n.text, len: (n.len as usize).min(NOTE_BYTES) })
}

/// Set (to anything but 0) by the test harness (`run.mjs --panic-at`) to have core 0 panic at its
/// next check between frames ([`check_requests`]): the way `cargo xtask board` reaches the
/// panic handler. Nothing on a board writes it.
#[no_mangle]
static PANIC_REQUEST: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// Panics when the test harness asked for it ([`PANIC_REQUEST`]).
pub fn check_requests() {
    if PANIC_REQUEST.load(core::sync::atomic::Ordering::Relaxed) != 0 {
        panic!("a panic the test harness asked for");
    }
}

/// Without a probe: a panic writes its reason and place into the note, and resets the board
/// through the watchdog (its REASON then says FORCE); the next boot reports the note.
#[cfg(not(feature = "probe"))]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    use core::fmt::Write as _;
    cortex_m::interrupt::disable();
    /// The note's text, cut at its size.
    struct Text([u8; NOTE_BYTES], usize);
    impl core::fmt::Write for Text {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            for &b in s.as_bytes() {
                if self.1 < NOTE_BYTES {
                    self.0[self.1] = b;
                    self.1 += 1;
                }
            }
            Ok(())
        }
    }
    let mut t = Text([0; NOTE_BYTES], 0);
    let _ = write!(t, "{}", info.message());
    if let Some(at) = info.location() {
        let _ = write!(t, " ({}:{})", at.file(), at.line());
    }
    // Cut on a character boundary.
    while t.1 > 0 && core::str::from_utf8(&t.0[..t.1]).is_err() {
        t.1 -= 1;
    }
    // SAFETY: interrupts are off and the other core is about to be reset with this one; the
    // note is plain data.
    #[allow(unsafe_code)]
    unsafe {
        core::ptr::addr_of_mut!(NOTE).write(core::mem::MaybeUninit::new(Note {
            magic: NOTE_MAGIC,
            len: t.1 as u32,
            text: t.0,
        }));
    }
    // SAFETY: writing TRIGGER to the watchdog's CTRL resets the chip (no other state is touched).
    #[allow(unsafe_code)]
    let watchdog = unsafe { &*hal::pac::WATCHDOG::ptr() };
    watchdog.ctrl().modify(|_, w| w.trigger().set_bit());
    cortex_m::peripheral::SCB::sys_reset()
}
