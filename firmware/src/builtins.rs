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
