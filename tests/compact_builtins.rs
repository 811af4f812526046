//! The firmware's `compact` helpers (`firmware/src/builtins.rs`: the ARM EABI's memory copies
//! and fills that images built for size link in place of compiler-builtins'), run on the host
//! against Rust's own slice copies.

#[allow(dead_code, clippy::missing_safety_doc)]
mod builtins {
    include!("../firmware/src/builtins.rs");
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

/// Dividends and divisors at the edges (0, 1, powers of two and their neighbours, the
/// extremes) and a spread of others.
fn edges() -> Vec<u32> {
    let mut v = vec![0, 1, 2, 3, 7, 10, 255, 256, 65535, 65536, u32::MAX - 1, u32::MAX];
    for s in 0..32 {
        v.extend([(1u32 << s).wrapping_sub(1), 1 << s, (1u32 << s) + 1, 0x8000_0000 | (1 << s)]);
    }
    let mut x = 0x1234_5678u32;
    for _ in 0..200 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        v.extend([x, x >> (x % 29)]);
    }
    v
}

#[test]
fn division_and_leading_zeros_agree_with_rust() {
    let values = edges();
    for &n in &values {
        assert_eq!(__clzsi2(n), n.leading_zeros() as i32, "clz of {n:#x}");
        for &d in values.iter().filter(|&&d| d != 0) {
            assert_eq!(divide(n, d), (n / d, n % d), "{n} / {d}");
            assert_eq!(__aeabi_uidivmod(n, d), u64::from(n / d) | u64::from(n % d) << 32);
            let (a, b) = (n as i32, d as i32);
            if !(a == i32::MIN && b == -1) {
                assert_eq!(__aeabi_idiv(a, b), a / b, "{a} / {b}");
                assert_eq!(__aeabi_idivmod(a, b), u64::from((a / b) as u32) | u64::from((a % b) as u32) << 32);
            }
        }
    }
}
