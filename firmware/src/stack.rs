//! Stack high-water mark by stack painting: cortex-m-rt (feature `paint-stack`) fills the
//! stack region with `0xCCCC_CCCC` at reset; the lowest word no longer holding the paint is
//! as deep as the stack ever reached.

extern "C" {
    static mut _stack_end: u32;
    static mut _stack_start: u32;
    static mut __sdata: u32;
    static mut __euninit: u32;
}

const PAINT: u32 = 0xCCCC_CCCC;

/// Bytes of RAM holding statics (`.data` + `.bss` + `.uninit`), from the linker symbols. They
/// are contiguous wherever the stack is: above them by default, below them with flip-link.
pub fn static_bytes() -> usize {
    // Only the addresses of the linker symbols are taken; nothing is read or written.
    let start = core::ptr::addr_of!(__sdata) as usize;
    let end = core::ptr::addr_of!(__euninit) as usize;
    end - start
}

/// Deepest stack use so far, in bytes.
pub fn high_water() -> usize {
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let mut p = bottom;
    while p < top {
        // SAFETY: `p` is word-aligned (cortex-m-rt aligns `_stack_end` to 4) and lies in
        // `[_stack_end, _stack_start)`, the RAM region the linker reserves for the stack,
        // which is always mapped; a volatile read of a u32 there has no side effects.
        #[allow(unsafe_code)]
        let v = unsafe { core::ptr::read_volatile(p as *const u32) };
        if v != PAINT {
            break;
        }
        p += 4;
    }
    top - p
}
