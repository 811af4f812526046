//! Fixed point: [`Fx`], Q16.16 on `i32` with `i64` intermediates.
//!
//! No float instruction is used per ray: products and quotients round to nearest, every
//! operation saturates instead of wrapping, and the square root is an integer one. Saturation
//! is what keeps "far away" answers right (a huge squared distance stays huge, so the ray
//! misses); the scene validation (`Real::LIMIT`) keeps every value that must be exact well
//! inside the range: coordinates, and object-space coordinates, below 8192.

use crate::scalar::{pow2_f64, Pow2, Real};
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

// Saturating sums and differences are a dozen bytes each on a Cortex-M0 and the tracer has
// hundreds: code built for size (`compact`) calls one copy of each.
impl Add for Fx {
    type Output = Fx;
    #[cfg_attr(not(feature = "compact"), inline)]
    #[cfg_attr(feature = "compact", inline(never))]
    fn add(self, o: Fx) -> Fx {
        Fx(self.0.saturating_add(o.0).max(-i32::MAX))
    }
}
impl Sub for Fx {
    type Output = Fx;
    #[cfg_attr(not(feature = "compact"), inline)]
    #[cfg_attr(feature = "compact", inline(never))]
    fn sub(self, o: Fx) -> Fx {
        Fx(self.0.saturating_sub(o.0).max(-i32::MAX))
    }
}
impl Mul for Fx {
    type Output = Fx;
    /// `|a| * |b|` rounded half away from zero, then signed; saturates. Both factors below 1
    /// (the common case: unit vectors and normals, the objects' scaled matrices) take one
    /// 32-bit product inline; the rest goes to `product`.
    #[inline]
    fn mul(self, o: Fx) -> Fx {
        let neg = (self.0 ^ o.0) < 0;
        let (a, b) = (self.0.unsigned_abs(), o.0.unsigned_abs());
        let m = if (a | b) >> 16 == 0 {
            // Both below 1 (unit vectors and normals, the objects' scaled matrices): the one
            // product of the low halves is the whole, (a * b + 2^15) >> 16 < 2^16.
            ((a * b + 0x8000) >> 16) as i32
        } else {
            product(a, b)
        };
        Fx(if neg { -m } else { m })
    }
}

/// `(a * b + 2^15) >> 16` for magnitudes `a`, `b` not both below 2^16, saturated to
/// `i32::MAX`, from 16-bit halves with 32-bit multiplies only (a Cortex-M0+ has no 32x32->64
/// multiply). Out of line: inlined at every product, its paths made the tracer's deepest frames
/// larger (the chair's baked M0 build, 488 B more stack) and the image 5 KB larger, for 0.7 %
/// fewer instructions.
#[inline(never)]
fn product(a: u32, b: u32) -> i32 {
    if a >> 16 == 0 || b >> 16 == 0 {
        // One factor below 1: two products, the high half's by it and the rounded low half's,
        // whose sum is below 2^31 + 2^16 (saturated all the same).
        let (big, small) = if a >> 16 == 0 { (b, a) } else { (a, b) };
        return ((big >> 16) * small + (((big & 0xFFFF) * small + 0x8000) >> 16)).min(i32::MAX as u32) as i32;
    }
    // Built for size (`compact`: the tiny image has no room for the second path), every
    // product of factors 1 or more takes the wide one.
    if cfg!(feature = "compact") || (a | b) >> 23 != 0 {
        return wide_product(a, b);
    }
    // (a * b + 2^15) >> 16 = ah*bh << 16 + ah*bl + al*bh + (al*bl + 2^15) >> 16, whose first
    // two terms are ah * b. Both factors below 128 (ah, bh < 2^7): ah * b < 2^30 and al * bh <
    // 2^23, so the sum stays below 2^31 in 32 bits: three multiplies, no 64-bit sum and no
    // saturation check.
    let (ah, al, bh, bl) = (a >> 16, a & 0xFFFF, b >> 16, b & 0xFFFF);
    (ah * b + al * bh + ((al * bl + 0x8000) >> 16)) as i32
}

/// `product` of factors both 1 or more, one of them 128 or more: the partial products summed
/// in 64 bits (two instructions an add on a Cortex-M0+), so no step needs an overflow check.
/// Out of line and cold: rare in a frame, and its registers would make every product save more
/// (inlined into it where built for size, as one function is smaller).
#[cfg_attr(not(feature = "compact"), cold, inline(never))]
#[cfg_attr(feature = "compact", inline(always))]
fn wide_product(a: u32, b: u32) -> i32 {
    let (ah, al, bh, bl) = (a >> 16, a & 0xFFFF, b >> 16, b & 0xFFFF);
    // Each product fits 32 bits (ah, bh <= 2^15), and al*bl + 2^15 < 2^32.
    let m = (u64::from(ah * bh) << 16) + u64::from(ah * bl) + u64::from(al * bh) + u64::from((al * bl + 0x8000) >> 16);
    if m > i32::MAX as u64 {
        i32::MAX
    } else {
        m as i32
    }
}

/// `(a << 16) / b` for `b > 0` as a quotient and remainder, by restoring long division in base
/// 2 in 32 bits (the remainder stays below `b < 2^32`, and below 2^31 doubling it fits), not a
/// 64-bit division: its sixteen fraction bits after the integer quotient `a / b`, which must be
/// below 2^16 for the quotient to fit.
pub(crate) fn shifted_quotient(a: u32, b: u32) -> (u32, u32) {
    let (mut q, mut r) = (a / b, a % b);
    for _ in 0..FRAC {
        r <<= 1;
        q <<= 1;
        if r >= b {
            r -= b;
            q |= 1;
        }
    }
    (q, r)
}

impl Div for Fx {
    type Output = Fx;
    /// `(a << 16) / b` rounded half away from zero; saturates, and `x / 0` is the largest value
    /// of the sign of `x`. A Cortex-M0+ has no divide instruction, and a 64-bit division is
    /// several times dearer than a 32-bit one, so a divisor of at most 1 (a unit direction's
    /// component) is done as long division in base 2^16 with two 32-bit steps, and one below 128
    /// (nearly every other one the tracer uses) in base 256 with three.
    #[inline]
    fn div(self, o: Fx) -> Fx {
        if o.0 == 0 {
            return match self.0.cmp(&0) {
                core::cmp::Ordering::Less => Fx(-i32::MAX),
                core::cmp::Ordering::Equal => Fx(0),
                core::cmp::Ordering::Greater => Fx(i32::MAX),
            };
        }
        let neg = (self.0 < 0) != (o.0 < 0);
        let (a, b) = (self.0.unsigned_abs(), o.0.unsigned_abs());
        let q = if a < 1 << FRAC {
            // A numerator below 1: `a << 16` fits 32 bits, so one division gives the quotient
            // and remainder the long division below finds in three.
            let (q, r) = ((a << FRAC) / b, (a << FRAC) % b);
            if r >= b - r {
                q + 1
            } else {
                q
            }
        } else if !cfg!(feature = "compact") && b <= 1 << FRAC {
            // A divisor of at most 1 (a unit direction's component, the walk's every crossing):
            // the remainder stays below 2^16, so the long division is in base 2^16, two steps
            // (not built for size: the next path gives the same quotient).
            let (q0, r) = (a / b, a % b);
            if q0 >= 1 << 15 {
                i32::MAX as u32
            } else {
                let (q1, r) = ((r << FRAC) / b, (r << FRAC) % b);
                let q = (q0 << FRAC) | q1;
                if r >= b - r {
                    q + 1
                } else {
                    q
                }
            }
        } else if b < 1 << 23 {
            let (q0, r) = (a / b, a % b);
            if q0 >= 1 << 15 {
                i32::MAX as u32
            } else {
                let (q1, r) = ((r << 8) / b, (r << 8) % b);
                let (q2, r) = ((r << 8) / b, (r << 8) % b);
                let q = (q0 << 16) | (q1 << 8) | q2;
                // Round half away from zero; q < 2^31 - 1 here, so no overflow.
                if r >= b - r {
                    q + 1
                } else {
                    q
                }
            }
        } else if b.is_power_of_two() {
            // A power of two (an eye ray's window size): a rounded shift, the same quotient.
            let s = b.trailing_zeros() - FRAC;
            (a >> s) + ((a >> (s - 1)) & 1)
        } else {
            // A divisor of 2^23 or more: the quotient is below 2^24 and its 16 fraction bits
            // come by restoring long division in base 2, in 32 bits (the remainder stays
            // below the divisor, at most 2^31, so doubling it fits), not a 64-bit division.
            let (q, r) = shifted_quotient(a, b);
            if r >= b - r {
                q + 1
            } else {
                q
            }
        };
        let q = q.min(i32::MAX as u32) as i32;
        Fx(if neg { -q } else { q })
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

/// Square root of `raw * 2^16` for a non-negative `raw`, rounded to nearest: the root of a
/// Q16.16 number, in Q16.16. Digit by digit, two bits of the radicand per step, in 32-bit
/// arithmetic only (the remainder stays below `8 * root + 4 < 2^27`): a Cortex-M0+ has no
/// 64-bit operations, and this is several times faster than the same method on a `u64`.
/// `raw`'s digit pairs are taken from the top of a copy shifted left (leading zero pairs
/// leave root and remainder at zero, so they are skipped), then the 8 zero pairs of `<< 16`:
/// no shift by a variable amount and no test of which pair comes next, in the loop.
fn sqrt_q16(raw: u32) -> u32 {
    let (mut root, mut rem) = (0u32, 0u32);
    let pairs = (32 - raw.leading_zeros()).div_ceil(2);
    let mut digits = raw.checked_shl(32 - 2 * pairs).unwrap_or(0);
    for _ in 0..pairs {
        rem = (rem << 2) | (digits >> 30);
        digits <<= 2;
        sqrt_step(&mut root, &mut rem);
    }
    for _ in 0..8 {
        rem <<= 2;
        sqrt_step(&mut root, &mut rem);
    }
    // `rem = n - root^2`; the nearest integer is `root + 1` when `n > root^2 + root`.
    if rem > root {
        root + 1
    } else {
        root
    }
}

/// One digit of [`sqrt_q16`]: the root's next bit, given the remainder with the next digit
/// pair brought down.
#[inline(always)]
fn sqrt_step(root: &mut u32, rem: &mut u32) {
    let trial = (*root << 2) | 1;
    *root <<= 1;
    if *rem >= trial {
        *rem -= trial;
        *root |= 1;
    }
}

impl Real for Fx {
    const ZERO: Self = Fx(0);
    const ONE: Self = Fx(ONE_RAW);
    const HALF: Self = Fx(ONE_RAW / 2);
    const MAX: Self = Fx(i32::MAX);
    const NAME: &'static str = "fixed";
    const DEAR_PRODUCTS: bool = true;
    const LIMIT: f64 = 8192.0;
    const RESOLUTION: f64 = 1.0 / 65536.0;
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
    fn to_raw(self) -> u64 {
        u64::from(self.0 as u32)
    }
    fn from_raw(bits: u64) -> Self {
        Fx(bits as u32 as i32)
    }
    fn depth_key(self) -> u16 {
        // A float of the raw value, integers only: 5 bits of exponent (the leading one's
        // place), 11 of mantissa.
        if self.0 <= 0 {
            return 0;
        }
        let raw = self.0 as u32;
        let lz = raw.leading_zeros();
        let mantissa = ((raw << lz) >> 20) & 0x7ff;
        (((31 - lz) << 11) | mantissa) as u16
    }
    /// The smallest raw value whose key is above `key`: its leading one at bit `(key + 1) >> 11`,
    /// then the eleven mantissa bits of `key + 1` (below bit 11, the fewest bits the leading
    /// one leaves them, rounded up: that may carry into the next power of two).
    fn key_bound(key: u16) -> Self {
        let Some(next) = key.checked_add(1) else { return Fx::MAX };
        let (lead, mantissa) = (u32::from(next >> 11), u32::from(next & 0x7ff));
        if lead > 30 {
            return Fx::MAX;
        }
        let raw = if lead >= 11 {
            (1 << lead) | (mantissa << (lead - 11))
        } else {
            (1 << lead) + mantissa.div_ceil(1 << (11 - lead))
        };
        Fx(raw as i32)
    }
    #[inline]
    fn recip(self) -> Self {
        // 2^32 / |b| rounded half away from zero, as `ONE / self` divides: the floor of
        // (2^32 + |b| / 2) / |b| (an odd |b|'s half rounded down changes no floor), one
        // division of 2^32 - |b| + |b| / 2, which fits 32 bits, plus one. |b| <= 2 saturates
        // (and 1 / 0 is the largest value).
        let b = self.0.unsigned_abs();
        if b <= 2 {
            return Fx::ONE / self;
        }
        let q = ((b >> 1).wrapping_sub(b) / b + 1) as i32;
        Fx(if self.0 < 0 { -q } else { q })
    }
    /// The exponent `k` itself, as the raw bits.
    fn pow2(k: i16) -> Pow2<Self> {
        Pow2(Fx(i32::from(k)))
    }
    /// A shift of the magnitude, rounded as [`Mul`] rounds the product with `2^k` (half away
    /// from zero, saturating); powers of two outside fixed point's range multiply by the value
    /// `from_f64` gives them, as the default does.
    #[inline]
    fn mul_pow2(self, p: Pow2<Self>) -> Self {
        let k = p.0 .0;
        if !(-16..=14).contains(&k) {
            // What `from_f64(2^k)` is there, in integers (no float code in the renderer): the
            // largest value above, 2^-16 for 2^-17 (a half rounded away from zero), else 0.
            let v = match k {
                15.. => Fx::MAX,
                -17 => Fx(1),
                _ => Fx(0),
            };
            return self * v;
        }
        let a = self.0.unsigned_abs();
        let m = if k >= 0 {
            if a > (i32::MAX as u32) >> k {
                i32::MAX as u32
            } else {
                a << k
            }
        } else {
            let s = (-k) as u32;
            (a >> s) + ((a >> (s - 1)) & 1)
        };
        let m = m as i32;
        Fx(if self.0 < 0 { -m } else { m })
    }
    fn pow2_value(p: Pow2<Self>) -> f64 {
        pow2_f64(p.0 .0 as i16)
    }
    fn div_pow2(self, k: u32) -> Self {
        // Division rounds half away from zero: a rounded shift of the magnitude.
        let k = k.min(14);
        if k == 0 {
            return self;
        }
        let a = self.0.unsigned_abs();
        let q = ((a >> k) + ((a >> (k - 1)) & 1)) as i32;
        Fx(if self.0 < 0 { -q } else { q })
    }
    fn sqrt(self) -> Self {
        if self.0 <= 0 {
            return Fx(0);
        }
        // sqrt(raw / 2^16) * 2^16 = sqrt(raw * 2^16), rounded to nearest.
        Fx(sqrt_q16(self.0 as u32) as i32)
    }
    fn offset_eps() -> Self {
        Fx(1 << 3) // 2^-13
    }
    fn pad_eps() -> Self {
        Fx(1 << 6)
    }
    /// `pad_eps` is 2^-10: the product with it is that shift, rounded as [`Mul`] rounds.
    #[inline]
    fn padding(self) -> Self {
        self.mul_pow2(Self::pow2(-10))
    }
    fn point_eps() -> Self {
        Fx(0)
    }
    /// Fixed point has the same absolute precision everywhere, so the offset depends on the
    /// size of the object only, not on where the point lies: a few units of the last place,
    /// and as many of the object's own (unit-sized) coordinates scaled to its size.
    /// `offset_eps` is 2^-13: the product with it is that shift, rounded as [`Mul`] rounds.
    #[inline]
    fn offset(_p_max: Self, size: Self) -> Self {
        (Self::ONE + size).mul_pow2(Self::pow2(-13))
    }
    fn is_finite(self) -> bool {
        true
    }
    fn floor_clamped(self, max: u8) -> u8 {
        // `from_i32(k)` is exactly `k << FRAC`, so the bisection's answer is the integer part.
        if self.0 < 0 {
            0
        } else {
            (self.0 >> FRAC).min(i32::from(max)) as u8
        }
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
        assert_eq!((fx(-1.5) * fx(2.25)).to_f64(), -3.375);
        assert_eq!((Fx(3) * Fx(32768)).0, 2); // 1.5 LSB rounds away from zero
        assert_eq!((Fx(-3) * Fx(32768)).0, -2);
        assert_eq!((fx(1.0) / fx(3.0)).0, 21845); // 0.333328..., nearest to 1/3
        assert_eq!((fx(-1.0) / fx(3.0)).0, -21845);
        assert_eq!((fx(2.0) / fx(3.0)).0, 43691);
        assert_eq!(fx(2.0).sqrt().0, 92682); // sqrt(2) * 65536 = 92681.9
        assert_eq!(fx(0.0).sqrt(), Fx(0));
        assert_eq!(fx(-4.0).sqrt(), Fx(0));
    }

    /// Every key's bound is the first raw value past it: its own key is later, the value
    /// before it has a key no later than the one asked for.
    #[test]
    fn key_bound_is_the_first_value_of_a_later_key() {
        for key in 0..=u16::MAX {
            let b = Fx::key_bound(key);
            if b == Fx::MAX {
                assert!(key >= (31 << 11) - 1, "{key}");
                continue;
            }
            assert!(b.depth_key() > key && Fx(b.0 - 1).depth_key() <= key, "{key}: {}", b.0);
        }
    }

    #[test]
    fn product_is_the_rounded_wide_product() {
        // Every path of `product` (a factor below 1, both below 128, the rest) against the
        // 64-bit product, on magnitudes of every size and at the paths' edges.
        let want = |a: u32, b: u32| ((u64::from(a) * u64::from(b) + 0x8000) >> 16).min(i32::MAX as u64) as i32;
        let edges =
            [0u32, 1, 0xFFFF, 0x1_0000, 0x1_0001, 0x7F_FFFF, 0x80_0000, 0x80_0001, 0xFF_FFFF, 0x7FFF_FFFF, 0x8000_0000];
        for &a in &edges {
            for &b in &edges {
                if a >> 16 != 0 || b >> 16 != 0 {
                    assert_eq!(product(a, b), want(a, b), "{a:#x} * {b:#x}");
                }
            }
        }
        let mut x = 0x5DEE_CE66_D1CE_4E5Bu64;
        for _ in 0..200_000 {
            xorshift(&mut x);
            let (a, b) = ((x as u32) >> (x % 17) as u32, ((x >> 32) as u32) >> ((x >> 8) % 17) as u32);
            if a >> 16 != 0 || b >> 16 != 0 {
                assert_eq!(product(a, b), want(a, b), "{a:#x} * {b:#x}");
            }
        }
    }

    #[test]
    fn mul_is_the_rounded_signed_product() {
        // Every path of `Fx * Fx` against the 64-bit product: |a| |b| rounded half away from
        // zero, saturated, then signed.
        let want = |a: i32, b: i32| {
            let m = ((u64::from(a.unsigned_abs()) * u64::from(b.unsigned_abs()) + 0x8000) >> 16).min(i32::MAX as u64)
                as i32;
            if (a ^ b) < 0 {
                -m
            } else {
                m
            }
        };
        let edges = [
            0,
            1,
            -1,
            0x7FFF,
            0x8000,
            -0x8000,
            46_340,
            -46_341,
            0xFFFF,
            -0xFFFF,
            0x1_0000,
            -0x1_0000,
            i32::MAX,
            -i32::MAX,
        ];
        for &a in &edges {
            for &b in &edges {
                assert_eq!((Fx(a) * Fx(b)).0, want(a, b), "{a} * {b}");
            }
        }
        let mut x = 0x0123_4567_89AB_CDEFu64;
        for _ in 0..200_000 {
            xorshift(&mut x);
            let (a, b) = (
                ((x as i32) >> (x % 31) as i32).max(-i32::MAX),
                (((x >> 32) as i32) >> ((x >> 8) % 31) as i32).max(-i32::MAX),
            );
            assert_eq!((Fx(a) * Fx(b)).0, want(a, b), "{a} * {b}");
        }
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
    fn power_of_two_shifts_give_the_products() {
        // Every exponent in and around fixed point's range, on edge and random operands: the
        // shift equals the product with `from_f64(2^k)`, rounding and saturation included.
        let edges = [0, 1, -1, 2, 3, -3, 0x8000, 0x18000, -0x18000, i32::MAX, -i32::MAX, i32::MIN, 1 << 30, -(1 << 30)];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let random = core::iter::repeat_with(|| {
            xorshift(&mut x);
            (x >> 32) as i32 >> (x & 31)
        });
        for a in edges.into_iter().chain(random.take(2000)) {
            for k in -20i16..=20 {
                assert_eq!(Fx(a).mul_pow2(Fx::pow2(k)), Fx(a) * Fx::from_f64(pow2_f64(k)), "{a} * 2^{k}");
            }
        }
    }

    /// One step of the 64-bit xorshift generator the randomised tests draw their operands from.
    fn xorshift(x: &mut u64) {
        *x ^= *x << 13;
        *x ^= *x >> 7;
        *x ^= *x << 17;
    }

    #[test]
    fn padding_is_the_product_with_pad_eps() {
        let mut x = 0x9e37_79b9u64;
        let check = |a: i32| assert_eq!(Fx(a).padding(), Fx(a) * Fx::pad_eps(), "{a}");
        for a in [0, 1, -1, 511, 512, 513, -512, 1023, 1024, 0xFFFF, 0x1_0000, i32::MAX, -i32::MAX] {
            check(a);
        }
        for _ in 0..100_000 {
            xorshift(&mut x);
            check(((x as i32) >> (x % 23) as i32).max(-i32::MAX));
            // The offset's product with offset_eps (2^-13) is a shift too.
            let size = Fx(((x >> 32) as i32 >> (x % 19) as i32).max(-i32::MAX));
            assert_eq!(Fx::offset(Fx::ONE, size), Fx::offset_eps() * (Fx::ONE + size), "{size:?}");
        }
    }

    #[test]
    fn multiply_matches_the_wide_product_everywhere() {
        let check = |a: i32, b: i32| {
            let p = a as i64 * b as i64;
            let r = (p.abs() + (1 << 15)) >> 16;
            let want = (if p < 0 { -r } else { r }).clamp(-(i32::MAX as i64), i32::MAX as i64) as i32;
            assert_eq!((Fx(a) * Fx(b)).0, want, "{a} * {b}");
        };
        let mut x = 0x1234_5678u64;
        for _ in 0..100_000 {
            xorshift(&mut x);
            let (a, b) = ((x as i32) >> (x % 17) as i32, ((x >> 32) as i32) >> ((x >> 40) % 19) as i32);
            check(a.max(-i32::MAX), b.max(-i32::MAX));
            // One factor or both below 1, as the short paths take them.
            let small = ((x >> 48) as i32) - 0x8000;
            check(small, a.max(-i32::MAX));
            check(b.max(-i32::MAX), small);
            check(small, small >> (x % 5));
        }
        // Around the products that just fit and just saturate, and the halves' extremes.
        let edges: [i32; 13] = [
            0,
            1,
            0x7FFF,
            0x8000,
            0xFFFF,
            0x1_0000,
            0x1_FFFF,
            0x00B5_04F3,
            0x00B5_0500,
            0x7FFF_0000,
            0x7FFF_FFFF,
            0x00FF_FFFF,
            0x0100_0000,
        ];
        for &a in &edges {
            for &b in &edges {
                for (da, db) in [(0, 0), (-1, 1), (1, -1), (2, 3)] {
                    let (a, b) = (a.saturating_add(da).max(0), b.saturating_add(db).max(0));
                    for (sa, sb) in [(1, 1), (-1, 1), (1, -1), (-1, -1)] {
                        check(a * sa, b * sb);
                    }
                }
            }
        }
    }

    #[test]
    fn divide_matches_the_wide_quotient_everywhere() {
        let mut x = 0x9876_5432u64;
        for _ in 0..100_000 {
            xorshift(&mut x);
            let (a, b) = ((x as i32) >> (x % 23) as i32, ((x >> 32) as i32) >> ((x >> 40) % 29) as i32);
            let (a, b) = (a.max(-i32::MAX), b.max(-i32::MAX));
            if b == 0 {
                continue;
            }
            assert_eq!((Fx(a) / Fx(b)).0, wide_quotient(a, b), "{a} / {b}");
        }
        // Each path's edges: divisors at and around 1 (the base 2^16 steps' last) and 2^23,
        // quotients at and just below saturation.
        for b in [1, 2, 65_535, 65_536, 65_537, (1 << 23) - 1, 1 << 23, i32::MAX] {
            for a in [1, 65_535, 65_536, 65_537, b / 2, b, (b >> 1) << 15, ((b >> 1) << 15) + 1, i32::MAX] {
                for (a, b) in [(a, b), (-a, b), (a, -b)] {
                    assert_eq!((Fx(a) / Fx(b)).0, wide_quotient(a, b), "{a} / {b}");
                }
            }
        }
    }

    /// `(a << 16) / b` in 64 bits, rounded half away from zero and saturated: what `Fx`'s
    /// division must give.
    fn wide_quotient(a: i32, b: i32) -> i32 {
        let (n, d) = ((a as i64).abs() << 16, (b as i64).abs());
        // Half away from zero (magnitudes here, the sign comes after).
        let q = if (n % d) * 2 >= d { n / d + 1 } else { n / d };
        let q = q.min(i32::MAX as i64);
        (if (a < 0) != (b < 0) { -q } else { q }) as i32
    }

    #[test]
    fn recip_is_one_divided_by() {
        let mut x = 0x2468_ace1u64;
        for _ in 0..200_000 {
            xorshift(&mut x);
            let b = ((x as i32) >> (x % 31) as i32).max(-i32::MAX);
            assert_eq!(Fx(b).recip(), Fx::ONE / Fx(b), "1 / {b}");
        }
        for b in (-70_000..=70_000).chain([i32::MAX, -i32::MAX, i32::MAX - 1, 1 << 30, -(1 << 30), 3 << 20, 65_537 * 3])
        {
            assert_eq!(Fx(b).recip(), Fx::ONE / Fx(b), "1 / {b}");
        }
    }

    #[test]
    fn div_pow2_is_the_division_by_the_power_of_two() {
        let mut x = 0x1234_5678u64;
        for _ in 0..20_000 {
            xorshift(&mut x);
            let a = ((x as i32) >> (x % 31) as i32).max(-i32::MAX);
            for k in 0..=14 {
                assert_eq!(Fx(a).div_pow2(k), Fx(a) / Fx::from_i32(1 << k), "{a} / 2^{k}");
            }
        }
        for a in [0, 1, -1, 0x7fff_ffff, -0x7fff_ffff, 0x8000, -0x8000, 0x4000, -0x4000, 0xc000, -0xc000] {
            for k in 0..=14 {
                assert_eq!(Fx(a).div_pow2(k), Fx(a) / Fx::from_i32(1 << k), "{a} / 2^{k}");
            }
        }
    }

    #[test]
    fn divide_by_large_powers_of_two_matches_the_wide_quotient() {
        for k in 23..31 {
            for a in
                [0, 1, 3, 0x7f, 0x80, 0x81, 0xffff, 0x1_0000, 0x12_3456, 0x7fff_ffff, -1, -0x80, -0x81, -0x7fff_ffff]
            {
                for b in [1i32 << k, -(1i32 << k)] {
                    let (n, d) = ((a as i64).abs() << 16, (b as i64).abs());
                    let q = if (n % d) * 2 >= d { n / d + 1 } else { n / d };
                    let want = if (a < 0) != (b < 0) { -q } else { q } as i32;
                    assert_eq!((Fx(a) / Fx(b)).0, want, "{a} / {b}");
                }
            }
        }
    }

    #[test]
    fn sqrt_is_the_nearest_root_everywhere() {
        // The reference: floor root of the 64-bit radicand by f64 estimate and correction,
        // then rounded to nearest.
        let want = |raw: u32| {
            let n = (raw as u64) << FRAC;
            let mut r = libm::sqrt(n as f64) as u64;
            while r * r > n {
                r -= 1;
            }
            while (r + 1) * (r + 1) <= n {
                r += 1;
            }
            if n - r * r > r {
                r + 1
            } else {
                r
            }
        };
        let mut x = 0x9E37_79B9u32;
        let edges = [0u32, 1, 2, 3, 4, 255, 256, 65535, 65536, 65537, i32::MAX as u32 - 1, i32::MAX as u32];
        // Every radicand below 2^18, each power of two and its neighbours, and a random spread.
        let powers = (0..31).flat_map(|k| [(1u32 << k) - 1, 1 << k, (1 << k) + 1]);
        for raw in edges.into_iter().chain(0..1 << 18).chain(powers).chain((0..200_000).map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x & 0x7FFF_FFFF) >> (x % 31)
        })) {
            assert_eq!(sqrt_q16(raw) as u64, want(raw), "{raw}");
        }
    }
}
