//! The firmware's `compact` helpers (`firmware/src/builtins.rs`: the ARM EABI's memory copies
//! and fills that images built for size link in place of compiler-builtins'), run on the host
//! against Rust's own slice copies.

#[allow(dead_code, clippy::missing_safety_doc)]
mod builtins {
    include!("../../firmware/src/builtins.rs");
}
use builtins::*;

#[test]
fn copies_and_fills_touch_exactly_their_bytes() {
    let src: Vec<u8> = (1..=80).collect();
    for n in 0..48 {
        // Byte copies at every offset.
        for off in 0..4 {
            let mut buf = [0u8; 64];
            // SAFETY: both regions hold n bytes.
            unsafe { __aeabi_memcpy(buf.as_mut_ptr().add(off), src.as_ptr(), n) };
            assert_eq!(&buf[off..off + n], &src[..n]);
            assert!(buf[..off].iter().chain(&buf[off + n..]).all(|&b| b == 0), "memcpy of {n} at {off} wrote outside");
        }
        // Word-aligned copies, fills and clears.
        let words: [u32; 16] = core::array::from_fn(|i| 0x0102_0304u32.wrapping_mul(i as u32 + 1));
        let bytes = |w: &[u32; 16]| w.iter().flat_map(|v| v.to_ne_bytes()).collect::<Vec<u8>>();
        let mut out = [0u32; 16];
        // SAFETY: both are aligned arrays of 64 bytes.
        unsafe { __aeabi_memcpy4(out.as_mut_ptr().cast(), words.as_ptr().cast(), n) };
        assert_eq!(&bytes(&out)[..n], &bytes(&words)[..n]);
        assert!(bytes(&out)[n..].iter().all(|&b| b == 0), "memcpy4 of {n} wrote past its end");
        for (fill, value) in [(0x5au8, 0x5a), (0, 0)] {
            let mut out = [u32::MAX; 16];
            // SAFETY: an aligned array of 64 bytes.
            unsafe {
                if fill == 0 {
                    __aeabi_memclr4(out.as_mut_ptr().cast(), n)
                } else {
                    __aeabi_memset4(out.as_mut_ptr().cast(), n, value)
                }
            };
            assert!(bytes(&out)[..n].iter().all(|&b| b == fill));
            assert!(bytes(&out)[n..].iter().all(|&b| b == 0xff), "fill of {n} wrote past its end");
        }
    }
}
