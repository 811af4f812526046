//! The firmware's `compact` helpers (`firmware/src/builtins.rs`: the ARM EABI's division and
//! memory copies and fills that images built for size link in place of compiler-builtins'),
//! run on the host against Rust's own division and slice copies.

#[allow(dead_code, clippy::missing_safety_doc)]
mod builtins {
    include!("../firmware/src/builtins.rs");
}
use builtins::*;

/// A xorshift generator: the same numbers on every run.
fn numbers() -> impl FnMut() -> u32 {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x as u32
    }
}

#[test]
fn division_is_rusts_quotient() {
    let mut next = numbers();
    for i in 0..500_000u32 {
        // Numerators and divisors of every length, from 1 bit to 32.
        let n = next() >> (i % 32);
        let d = (next() >> (next() % 32)).max(1);
        assert_eq!(__aeabi_uidiv(n, d), n / d, "{n} / {d}");
        let (a, b) = (n as i32, d as i32);
        if !(a == i32::MIN && b == -1) {
            assert_eq!(__aeabi_idiv(a, b), a / b, "{a} / {b}");
        }
    }
    for (n, d) in [(u32::MAX, 1), (u32::MAX, u32::MAX), (u32::MAX, 1 << 31), (1 << 31, (1 << 31) + 1), (0, 5), (7, 7), (u32::MAX, 3), (1 << 16, 3)] {
        assert_eq!(__aeabi_uidiv(n, d), n / d, "{n} / {d}");
    }
    for (a, b) in [(i32::MIN, 1), (i32::MIN, 2), (i32::MAX, -1), (-7, 2), (7, -2), (-7, -2), (i32::MIN, i32::MAX)] {
        assert_eq!(__aeabi_idiv(a, b), a / b, "{a} / {b}");
    }
}

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
