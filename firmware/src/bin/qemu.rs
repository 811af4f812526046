//! The render loop on QEMU's mps2-an385 (Cortex-M3, runs the thumbv6m build) or mps2-an386
//! (Cortex-M4F, thumbv7em-none-eabihf). Each frame goes out over semihosting as hex rows with
//! its statistics; the exit code says whether every scene rendered.
//!
//! Also the Cortex-M33 build (thumbv8m.main-none-eabihf, the Pico 2's core) on mps2-an505.
//!
//! Run with `-icount shift=0`: every instruction then takes 1 ns of virtual time, and SysTick,
//! clocked at the board's rate, ticks once per so many instructions; the `CALIBRATE` line gives
//! that rate (ticks over a loop of known length), so the reported tick counts convert to
//! deterministic instruction counts.
#![no_std]
#![no_main]

use core::cell::Cell;
use core::fmt;
use cortex_m::interrupt::{free, Mutex};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};
use firmware::app::{render_embedded_at, Board, OneCore, Scalar, SceneMemory, ShareMemory, Shot, EMBEDDED, FRAME};
use firmware::stack;
use lattice_rt::{BitFrame, NoHooks};

static WRAPS: Mutex<Cell<u32>> = Mutex::new(Cell::new(0));
const RELOAD: u32 = 0x00FF_FFFF;

#[exception]
fn SysTick() {
    free(|cs| WRAPS.borrow(cs).set(WRAPS.borrow(cs).get() + 1));
}

/// SysTick ticks since start (wraps counted by the exception).
fn ticks() -> u64 {
    loop {
        let w0 = free(|cs| WRAPS.borrow(cs).get());
        let cur = cortex_m::peripheral::SYST::get_current();
        let w1 = free(|cs| WRAPS.borrow(cs).get());
        if w0 == w1 && !cortex_m::peripheral::SCB::is_pendst_pending() {
            return w0 as u64 * (RELOAD as u64 + 1) + (RELOAD - cur) as u64;
        }
    }
}

struct Hex<'a>(&'a [u8]);
impl fmt::Display for Hex<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|b| write!(f, "{b:02x}"))
    }
}

/// Instructions in the calibration loop.
const CALIBRATE_INSTRUCTIONS: u32 = 4_000_000;

/// Runs `n` iterations of a two-instruction loop (`subs`, `bne`): 2n instructions.
fn spin(n: u32) {
    // SAFETY: the loop only counts r0 down to zero; it touches no memory and no stack.
    #[allow(unsafe_code)]
    unsafe {
        core::arch::asm!("2:", "subs r0, #1", "bne 2b", inout("r0") n => _, options(nomem, nostack))
    };
}

#[entry]
fn main() -> ! {
    let mut cp = cortex_m::Peripherals::take().unwrap();
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(RELOAD);
    cp.SYST.clear_current();
    cp.SYST.enable_interrupt();
    cp.SYST.enable_counter();
    let board = env!("FIRMWARE_CORE");
    hprintln!("BOARD {} scalar {} size {}x{}", board, <Scalar as lattice_rt::Real>::NAME, FRAME.width, FRAME.height);
    // SysTick's clock differs between the machines (25 MHz on the an385/an386, 20 MHz on the
    // an505): a loop of exactly CALIBRATE_INSTRUCTIONS instructions tells the host the rate.
    let t0 = ticks();
    spin(CALIBRATE_INSTRUCTIONS / 2);
    hprintln!("CALIBRATE instructions {} ticks {}", CALIBRATE_INSTRUCTIONS, ticks() - t0);
    let mut st = SceneMemory::new();
    let mut second = ShareMemory::new();
    let mut bits = [0u8; BitFrame::bytes(FRAME.width as u32, FRAME.height as u32)];
    let mut failed = false;
    for (name, scene) in EMBEDDED.iter().copied() {
        let mut frame = BitFrame::new(FRAME.width as u32, FRAME.height as u32, &mut bits).unwrap();
        let t0 = ticks();
        let shot = Shot::default();
        let board = Board { cores: &mut OneCore, second: &mut second, now: &ticks, shown: &mut |_| {} };
        match render_embedded_at(scene, &mut st, &mut frame, &mut NoHooks, &shot, board) {
            Ok(r) => {
                let t = ticks() - t0;
                let s = r.stats;
                hprintln!(
                    "SCENE {} ticks {} tiles {} rays {} primary {} shadow {} reflection {} refraction {} tests {} cells {} objects {} lattice_bytes {} stack_so_far {}",
                    name, t, r.share_us[0] + r.share_us[1], s.total_rays(), s.rays[0], s.rays[1], s.rays[2], s.rays[3], s.object_tests,
                    s.cells_visited, r.objects, r.lattice_bytes, stack::high_water()
                );
                for row in frame.raster().chunks(FRAME.width as usize / 8) {
                    hprintln!("ROW {}", Hex(row));
                }
            }
            Err(e) => {
                hprintln!("ERROR {}: {}", name, e);
                failed = true;
            }
        }
    }
    hprintln!("RAM stack_high_water {} static {}", stack::high_water(), stack::static_bytes());
    debug::exit(if failed { debug::EXIT_FAILURE } else { debug::EXIT_SUCCESS });
    loop {
        cortex_m::asm::wfi();
    }
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    hprintln!("HARDFAULT at pc {:#010x}", ef.pc());
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("PANIC {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}
