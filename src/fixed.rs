//! Fixed point: [`Fx`], Q16.16 on `i32` with `i64` intermediates.
//!
//! No float instruction is used per ray: products and quotients round to nearest, every
//! operation saturates instead of wrapping, and the square root is an integer one. Saturation
//! is what keeps "far away" answers right (a huge squared distance stays huge, so the ray
//! misses); the scene validation (`Real::LIMIT`) keeps every value that must be exact well
//! inside the range: coordinates, and object-space coordinates, below 8192.

use crate::scalar::Real;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Fractional bits.
pub const FRAC: u32 = 16;
const ONE_RAW: i32 = 1 << FRAC;

/// A Q16.16 fixed-point number: value = raw / 65536.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Fx(pub i32);

#[inline]
fn sat(v: i64) -> Fx {
    Fx(v.clamp(-(i32::MAX as i64), i32::MAX as i64) as i32)
}

impl Add for Fx {
    type Output = Fx;
    #[inline]
    fn add(self, o: Fx) -> Fx {
        sat(self.0 as i64 + o.0 as i64)
    }
}
impl Sub for Fx {
    type Output = Fx;
    #[inline]
    fn sub(self, o: Fx) -> Fx {
        sat(self.0 as i64 - o.0 as i64)
    }
}
impl Mul for Fx {
    type Output = Fx;
    #[inline]
    fn mul(self, o: Fx) -> Fx {
        let p = self.0 as i64 * o.0 as i64;
        sat((p + (1 << (FRAC - 1))) >> FRAC)
    }
}
impl Div for Fx {
    type Output = Fx;
    #[inline]
    fn div(self, o: Fx) -> Fx {
        if o.0 == 0 {
            return match self.0.cmp(&0) {
                core::cmp::Ordering::Less => Fx(-i32::MAX),
                core::cmp::Ordering::Equal => Fx(0),
                core::cmp::Ordering::Greater => Fx(i32::MAX),
            };
        }
        let n = (self.0 as i64) << FRAC;
        let d = o.0 as i64;
        let (q, r) = (n / d, n % d);
        // Round half away from zero.
        let q = if 2 * r.abs() >= d.abs() { q + if (n < 0) == (d < 0) { 1 } else { -1 } } else { q };
        sat(q)
    }
}
impl Neg for Fx {
    type Output = Fx;
    #[inline]
    fn neg(self) -> Fx {
        Fx(-self.0.max(-i32::MAX))
    }
}
impl AddAssign for Fx {
    fn add_assign(&mut self, o: Fx) {
        *self = *self + o;
    }
}
impl SubAssign for Fx {
    fn sub_assign(&mut self, o: Fx) {
        *self = *self - o;
    }
}
impl MulAssign for Fx {
    fn mul_assign(&mut self, o: Fx) {
        *self = *self * o;
    }
}

/// Integer square root (floor) of a `u64`, bit by bit.
fn isqrt(mut n: u64) -> u64 {
    let mut res = 0u64;
    let mut bit = 1u64 << 62;
    while bit > n {
        bit >>= 2;
    }
    while bit != 0 {
        if n >= res + bit {
            n -= res + bit;
            res = (res >> 1) + bit;
        } else {
            res >>= 1;
        }
        bit >>= 2;
    }
    res
}

impl Real for Fx {
    const ZERO: Self = Fx(0);
    const ONE: Self = Fx(ONE_RAW);
    const HALF: Self = Fx(ONE_RAW / 2);
    const MAX: Self = Fx(i32::MAX);
    const NAME: &'static str = "fixed";
    const LIMIT: f64 = 8192.0;
    fn from_f64(v: f64) -> Self {
        if v.is_nan() {
            return Fx(0);
        }
        sat(libm::round(v * ONE_RAW as f64).clamp(-(i32::MAX as f64), i32::MAX as f64) as i64)
    }
    fn from_i32(v: i32) -> Self {
        sat((v as i64) << FRAC)
    }
    fn to_f64(self) -> f64 {
        self.0 as f64 / ONE_RAW as f64
    }
    fn sqrt(self) -> Self {
        if self.0 <= 0 {
            return Fx(0);
        }
        // sqrt(raw / 2^16) * 2^16 = sqrt(raw * 2^16), rounded to nearest.
        let n = (self.0 as u64) << FRAC;
        let r = isqrt(n);
        let r = if n - r * r > r { r + 1 } else { r };
        Fx(r as i32)
    }
    fn offset_eps() -> Self {
        Fx(1 << 6) // 2^-10
    }
    fn pad_eps() -> Self {
        Fx(1 << 6)
    }
    fn is_finite(self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fx(v: f64) -> Fx {
        Fx::from_f64(v)
    }

    #[test]
    fn arithmetic_rounds_to_nearest() {
        assert_eq!((fx(1.5) * fx(2.25)).to_f64(), 3.375);
        assert_eq!((fx(1.0) / fx(3.0)).0, 21845); // 0.333328..., nearest to 1/3
        assert_eq!((fx(-1.0) / fx(3.0)).0, -21845);
        assert_eq!((fx(2.0) / fx(3.0)).0, 43691);
        assert_eq!(fx(2.0).sqrt().0, 92682); // sqrt(2) * 65536 = 92681.9
        assert_eq!(fx(0.0).sqrt(), Fx(0));
        assert_eq!(fx(-4.0).sqrt(), Fx(0));
    }

    #[test]
    fn overflow_saturates_instead_of_wrapping() {
        let big = fx(30000.0);
        assert_eq!(big * big, Fx::MAX);
        assert_eq!(-big * big, -Fx::MAX);
        assert_eq!(big + big, Fx::MAX);
        assert_eq!(fx(1.0) / Fx(0), Fx::MAX);
        assert_eq!(fx(-1.0) / Fx(0), -Fx::MAX);
        assert_eq!(-Fx(i32::MIN), Fx::MAX);
    }

    #[test]
    fn conversions_round_trip_on_the_grid() {
        for v in [0.0, 1.0, -1.0, 0.5, 1234.5678, -8191.99] {
            assert!((fx(v).to_f64() - v).abs() <= 0.5 / 65536.0, "{v}");
        }
        assert_eq!(Fx::from_i32(-3), fx(-3.0));
        assert_eq!(Fx::from_f64(f64::NAN), Fx(0));
        assert_eq!(Fx::from_f64(1e12), Fx::MAX);
    }

    #[test]
    fn isqrt_is_exact_floor() {
        for n in [0u64, 1, 2, 3, 4, 15, 16, 17, 1 << 40, (1 << 47) - 1, u32::MAX as u64 * 7] {
            let r = isqrt(n);
            assert!(r * r <= n && (r + 1) * (r + 1) > n, "{n}");
        }
    }
}
