use core::ptr::{read_volatile, write_volatile};

/// Copies `n` bytes from `src` to `dest` (the regions do not overlap), a byte at a time.
///
/// # Safety
/// `dest` and `src` valid for `n` bytes, as the compiler guarantees where it calls it.
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memcpy(dest: *mut u8, src: *const u8, n: usize) {
    for i in 0..n {
        // SAFETY: both regions hold `n` bytes.
        unsafe { write_volatile(dest.add(i), read_volatile(src.add(i))) };
    }
}

/// [`__aeabi_memcpy`] of word-aligned regions: whole words, then the bytes left.
///
/// # Safety
/// As [`__aeabi_memcpy`], with `dest` and `src` aligned to 4 bytes.
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memcpy4(dest: *mut u8, src: *const u8, n: usize) {
    let words = n / 4;
    for i in 0..words {
        // SAFETY: both regions are aligned and hold `words` whole words.
        unsafe { write_volatile((dest as *mut u32).add(i), read_volatile((src as *const u32).add(i))) };
    }
    // SAFETY: the bytes after the words lie in both regions.
    unsafe { __aeabi_memcpy(dest.add(4 * words), src.add(4 * words), n % 4) };
}

/// [`__aeabi_memcpy4`] (8-byte alignment is 4-byte alignment too).
///
/// # Safety
/// As [`__aeabi_memcpy4`].
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memcpy8(dest: *mut u8, src: *const u8, n: usize) {
    // SAFETY: the caller's guarantees are the callee's.
    unsafe { __aeabi_memcpy4(dest, src, n) }
}

/// Sets `n` bytes at `dest` to the low byte of `c` (the EABI's argument order: `n` before `c`).
///
/// # Safety
/// `dest` valid for `n` bytes.
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memset(dest: *mut u8, n: usize, c: i32) {
    for i in 0..n {
        // SAFETY: the region holds `n` bytes.
        unsafe { write_volatile(dest.add(i), c as u8) };
    }
}

/// [`__aeabi_memset`] of a word-aligned region: whole words, then the bytes left.
///
/// # Safety
/// As [`__aeabi_memset`], with `dest` aligned to 4 bytes.
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memset4(dest: *mut u8, n: usize, c: i32) {
    let (words, word) = (n / 4, u32::from(c as u8) * 0x0101_0101);
    for i in 0..words {
        // SAFETY: the region is aligned and holds `words` whole words.
        unsafe { write_volatile((dest as *mut u32).add(i), word) };
    }
    // SAFETY: the bytes after the words lie in the region.
    unsafe { __aeabi_memset(dest.add(4 * words), n % 4, c) };
}

/// [`__aeabi_memset4`].
///
/// # Safety
/// As [`__aeabi_memset4`].
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memset8(dest: *mut u8, n: usize, c: i32) {
    // SAFETY: the caller's guarantees are the callee's.
    unsafe { __aeabi_memset4(dest, n, c) }
}

/// Zeroes `n` bytes at `dest`.
///
/// # Safety
/// As [`__aeabi_memset`].
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memclr(dest: *mut u8, n: usize) {
    // SAFETY: the caller's guarantees are the callee's.
    unsafe { __aeabi_memset(dest, n, 0) }
}

/// Zeroes a word-aligned region.
///
/// # Safety
/// As [`__aeabi_memset4`].
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memclr4(dest: *mut u8, n: usize) {
    // SAFETY: the caller's guarantees are the callee's.
    unsafe { __aeabi_memset4(dest, n, 0) }
}

/// [`__aeabi_memclr4`].
///
/// # Safety
/// As [`__aeabi_memset4`].
#[allow(unsafe_code)]
#[no_mangle]
pub unsafe extern "C" fn __aeabi_memclr8(dest: *mut u8, n: usize) {
    // SAFETY: the caller's guarantees are the callee's.
    unsafe { __aeabi_memset4(dest, n, 0) }
}

/// `n / d` and `n % d` by shifting and subtracting, one step per bit of the quotient: the
/// divisor is doubled until it reaches the dividend, then halved back, subtracted where it
/// fits. `d == 0` gives `(u32::MAX, n)` (Rust checks for zero before it divides).
pub fn divide(mut n: u32, d: u32) -> (u32, u32) {
    if d == 0 {
        return (u32::MAX, n);
    }
    let (mut step, mut bit, mut q) = (d, 1u32, 0u32);
    while step < n && step >> 31 == 0 {
        step <<= 1;
        bit <<= 1;
    }
    while bit != 0 {
        if n >= step {
            n -= step;
            q |= bit;
        }
        step >>= 1;
        bit >>= 1;
    }
    (q, n)
}

/// Unsigned division (the ARM EABI's name for it): [`divide`]'s quotient.
#[no_mangle]
pub extern "C" fn __aeabi_uidiv(n: u32, d: u32) -> u32 {
    divide(n, d).0
}

/// A quotient and remainder as the EABI returns them: the quotient in `r0`, the remainder in
/// `r1` (a 64-bit result's low and high words).
fn in_registers((q, r): (u32, u32)) -> u64 {
    u64::from(q) | u64::from(r) << 32
}

/// Unsigned quotient and remainder.
#[no_mangle]
pub extern "C" fn __aeabi_uidivmod(n: u32, d: u32) -> u64 {
    in_registers(divide(n, d))
}

/// Signed quotient and remainder, truncated towards zero (the remainder has the dividend's
/// sign), as the magnitudes' [`divide`].
fn signed(n: i32, d: i32) -> (i32, i32) {
    let (q, r) = divide(n.unsigned_abs(), d.unsigned_abs());
    let q = if (n ^ d) < 0 { (q as i32).wrapping_neg() } else { q as i32 };
    (q, if n < 0 { (r as i32).wrapping_neg() } else { r as i32 })
}

/// Signed division: [`signed`]'s quotient.
#[no_mangle]
pub extern "C" fn __aeabi_idiv(n: i32, d: i32) -> i32 {
    signed(n, d).0
}

/// Signed quotient and remainder.
#[no_mangle]
pub extern "C" fn __aeabi_idivmod(n: i32, d: i32) -> u64 {
    let (q, r) = signed(n, d);
    in_registers((q as u32, r as u32))
}

/// Leading zero bits of `x` (32 for zero), by halving the width searched five times.
#[no_mangle]
pub extern "C" fn __clzsi2(mut x: u32) -> i32 {
    if x == 0 {
        return 32;
    }
    let mut n = 0;
    for s in [16, 8, 4, 2, 1] {
        if x >> (32 - s) == 0 {
            x <<= s;
            n += s;
        }
    }
    n
}
