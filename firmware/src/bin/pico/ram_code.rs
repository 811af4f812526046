//! The hot code that runs from SRAM (`firmware/pico/ram-code.x`): copied there from flash once,
//! before anything calls it. On silicon a miss in the 16 KiB XIP cache stalls a core for a
//! QSPI line fill (56 cycles at 125 MHz); the tracer's code is several times the cache, so in
//! flash it misses all the time (`cargo xtask board` measures both).

/// Copies the hot code from its flash image to SRAM. Called first thing in `main`, before any
/// of that code runs, and on core 0 alone (core 1 starts later).
#[cfg(ram_code)]
pub fn load() {
    extern "C" {
        static mut __sram_code: u32;
        static mut __eram_code: u32;
        static __siram_code: u32;
    }
    // SAFETY: the linker script places `.ram_code` at [__sram_code, __eram_code) in RAM, with
    // its image at __siram_code in flash, both word-aligned and the same length; nothing in RAM
    // there is in use yet (no code in it has run, no static lives there). Volatile word copies,
    // so the compiler cannot turn the loop into a call to `memcpy`, which may itself be there.
    #[allow(unsafe_code)]
    unsafe {
        let mut to = core::ptr::addr_of_mut!(__sram_code);
        let end = core::ptr::addr_of_mut!(__eram_code);
        let mut from = core::ptr::addr_of!(__siram_code);
        while to < end {
            to.write_volatile(from.read_volatile());
            to = to.add(1);
            from = from.add(1);
        }
    }
}

/// Built with `code-in-flash` (or for the Pico 2): the code runs where it is.
#[cfg(not(ram_code))]
pub fn load() {}
