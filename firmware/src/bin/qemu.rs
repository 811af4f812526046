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
use cortex_m::interrupt::{free, Mutex};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hio};
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

/// A line the harness prints on the host's standard output over semihosting, built without
/// `core::fmt` (its formatting machinery is kilobytes of the flash the baked builds measure).
struct Line {
    bytes: [u8; 48],
    len: usize,
}

impl Line {
    fn new() -> Self {
        Line { bytes: [0; 48], len: 0 }
    }
    /// Appends bytes, sending the line so far when it is full.
    fn put(&mut self, bytes: &[u8]) -> &mut Self {
        for &b in bytes {
            if self.len >= self.bytes.len() {
                send(&self.bytes);
                self.len = 0;
            }
            self.bytes[self.len] = b;
            self.len += 1;
        }
        self
    }
    /// Appends text.
    fn text(&mut self, t: &str) -> &mut Self {
        self.put(t.as_bytes())
    }
    /// Appends a number in decimal, by subtracting powers of ten (no 64-bit division, whose
    /// library routine would be a kilobyte of the image for this alone).
    fn dec(&mut self, mut v: u64) -> &mut Self {
        // 10^19 down to 1.
        const POWERS: [u64; 20] = {
            let mut p = [1u64; 20];
            let mut i = 19;
            while i > 0 {
                p[i - 1] = p[i] * 10;
                i -= 1;
            }
            p
        };
        let mut started = false;
        for power in POWERS {
            let mut digit = b'0';
            while v >= power {
                v -= power;
                digit += 1;
            }
            started |= digit != b'0' || power == 1;
            if started {
                self.put(&[digit]);
            }
        }
        self
    }
    /// Appends bytes as lowercase hex, two digits each.
    fn hex(&mut self, bytes: &[u8]) -> &mut Self {
        const DIGITS: &[u8; 16] = b"0123456789abcdef";
        for &b in bytes {
            self.put(&[DIGITS[usize::from(b >> 4)], DIGITS[usize::from(b & 15)]]);
        }
        self
    }
    /// Appends ` key value`. Called, not inlined: a frame's line has a dozen.
    #[inline(never)]
    fn field(&mut self, key: &str, value: u64) -> &mut Self {
        self.text(" ").text(key).text(" ").dec(value)
    }
    /// Ends the line and sends it.
    fn end(&mut self) {
        self.put(b"\n");
        send(&self.bytes[..self.len.min(self.bytes.len())]);
        self.len = 0;
    }
}

/// Writes bytes to the host's standard output.
fn send(bytes: &[u8]) {
    if let Ok(mut out) = hio::hstdout() {
        let _ = out.write_all(bytes);
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
    Line::new()
        .text("BOARD ")
        .text(board)
        .text(" scalar ")
        .text(<Scalar as lattice_rt::Real>::NAME)
        .text(" size ")
        .dec(FRAME.width.into())
        .text("x")
        .dec(FRAME.height.into())
        .end();
    // SysTick's clock differs between the machines (25 MHz on the an385/an386, 20 MHz on the
    // an505): a loop of exactly CALIBRATE_INSTRUCTIONS instructions tells the host the rate.
    let t0 = ticks();
    spin(CALIBRATE_INSTRUCTIONS / 2);
    Line::new()
        .text("CALIBRATE instructions ")
        .dec(CALIBRATE_INSTRUCTIONS.into())
        .text(" ticks ")
        .dec(ticks() - t0)
        .end();
    let mut st = SceneMemory::new();
    let mut second = ShareMemory::new();
    let mut bits = [0u8; BitFrame::bytes(FRAME.width as u32, FRAME.height as u32)];
    let mut failed = false;
    for (name, scene) in EMBEDDED.iter().copied() {
        let mut frame = BitFrame::new(FRAME.width as u32, FRAME.height as u32, &mut bits).unwrap();
        let t0 = ticks();
        let shot = Shot::default();
        let board = Board { cores: &mut OneCore, second: &mut second, now: &ticks, shown: &mut |_| {}, alive: &|| {} };
        match render_embedded_at(scene, &mut st, &mut frame, &mut NoHooks, &shot, board) {
            Ok(r) => {
                let t = ticks() - t0;
                let s = r.stats;
                Line::new()
                    .text("SCENE ")
                    .text(name)
                    .field("ticks", t)
                    .field("tiles", r.share_us[0] + r.share_us[1])
                    .field("rays", s.total_rays())
                    .field("primary", s.rays[0])
                    .field("shadow", s.rays[1])
                    .field("reflection", s.rays[2])
                    .field("refraction", s.rays[3])
                    .field("tests", s.object_tests)
                    .field("cells", s.cells_visited)
                    .field("objects", r.objects as u64)
                    .field("lattice_bytes", r.lattice_bytes as u64)
                    .field("stack_so_far", stack::high_water() as u64)
                    .end();
                for row in frame.raster().chunks(FRAME.width as usize / 8) {
                    Line::new().text("ROW ").hex(row).end();
                }
            }
            Err(e) => {
                report_error(name, &e);
                failed = true;
            }
        }
    }
    Line::new()
        .text("RAM stack_high_water ")
        .dec(stack::high_water() as u64)
        .text(" static ")
        .dec(stack::static_bytes() as u64)
        .end();
    debug::exit(if failed { debug::EXIT_FAILURE } else { debug::EXIT_SUCCESS });
    loop {
        cortex_m::asm::wfi();
    }
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    Line::new().text("HARDFAULT at pc 0x").hex(&ef.pc().to_be_bytes()).end();
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // Where, not the message: formatting it would link `core::fmt` into every build.
    match info.location() {
        Some(at) => Line::new().text("PANIC at ").text(at.file()).text(":").dec(at.line().into()).end(),
        None => Line::new().text("PANIC").end(),
    }
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

/// The `ERROR` line of a scene that could not be shown: with the message where scenes are
/// parsed (the parser's messages are linked there anyway), the error's kind where they are baked.
fn report_error<E: core::fmt::Debug>(name: &str, e: &firmware::app::AppError<'_, E>) {
    #[cfg(not(baked_scenes))]
    {
        cortex_m_semihosting::hprintln!("ERROR {}: {}", name, e);
    }
    #[cfg(baked_scenes)]
    {
        use firmware::app::AppError;
        let kind = match e {
            AppError::Effects(_) => "the scene needs an effect this build leaves out",
            AppError::BakedCamera => "a baked scene is shown from its own camera only",
            AppError::Render(_) => "the render failed",
            AppError::Text(_) => "",
        };
        Line::new().text("ERROR ").text(name).text(": ").text(kind).end();
    }
}
