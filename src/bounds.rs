//! Index bounds checks whose panic formats nothing.
//!
//! Core's own checks (`slice[i]`, `&slice[a..b]`) put the index and the length in their panic
//! message, and that links core's integer formatting (about 1.2 KB on a Cortex-M0) into every
//! image that indexes, though no firmware panic handler prints the message. The render path
//! indexes through these instead. With a validated scene and the tile loop's own sizes none of
//! them fails; if one did, the panic says where, as core's does (in code built for size, the
//! `compact` feature, it names this file instead: each caller's place is a file name and 16
//! bytes of flash).

use core::ops::Range;

/// `s[i]`.
#[inline(always)]
#[cfg_attr(not(feature = "compact"), track_caller)]
pub(crate) fn at<T>(s: &[T], i: usize) -> &T {
    match s.get(i) {
        Some(v) => v,
        None => out_of_bounds(),
    }
}

/// `&mut s[i]`.
#[inline(always)]
#[cfg_attr(not(feature = "compact"), track_caller)]
pub(crate) fn at_mut<T>(s: &mut [T], i: usize) -> &mut T {
    match s.get_mut(i) {
        Some(v) => v,
        None => out_of_bounds(),
    }
}

/// `&mut s[r]`.
#[inline(always)]
#[cfg_attr(not(feature = "compact"), track_caller)]
pub(crate) fn span_mut<T>(s: &mut [T], r: Range<usize>) -> &mut [T] {
    match s.get_mut(r) {
        Some(v) => v,
        None => out_of_bounds(),
    }
}

#[cold]
#[inline(never)]
#[cfg_attr(not(feature = "compact"), track_caller)]
fn out_of_bounds() -> ! {
    panic!("index out of bounds")
}
