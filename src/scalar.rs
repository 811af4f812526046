//! The `Real` scalar trait and its implementations.
//!
//! The tracer is written once over [`Real`]; this module owns every place where the concrete
//! number type matters (square root, conversions, the self-intersection epsilon). It must not
//! know about rays, shapes or scenes.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real-number type the tracer can run on (f64, f32, fixed point).
///
/// Conversions from `f64` are used only while a scene is built, never per ray.
pub trait Real:
    Copy
    + Send
    + Sync
    + Debug
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Additive identity.
    const ZERO: Self;
    /// Multiplicative identity.
    const ONE: Self;
    /// One half.
    const HALF: Self;
    /// The largest finite value, used as "no hit yet".
    const MAX: Self;
    /// Short name for reports ("f64", "f32", ...).
    const NAME: &'static str;
    /// Converts from `f64` (scene set-up only); values out of range saturate.
    fn from_f64(v: f64) -> Self;
    /// Largest coordinate magnitude a scene may use with this scalar (checked by validation).
    const LIMIT: f64;
    /// The spacing of the scalar's numbers just above 1 (its machine epsilon; fixed point's
    /// last bit).
    const RESOLUTION: f64;
    /// Converts from a small integer (pixel coordinates).
    fn from_i32(v: i32) -> Self {
        Self::from_f64(v as f64)
    }
    /// Converts to `f64` (reports and tests).
    fn to_f64(self) -> f64;
    /// Square root; the argument must not be negative.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self {
        if self < Self::ZERO {
            -self
        } else {
            self
        }
    }
    /// The smaller of two values.
    fn min(self, o: Self) -> Self {
        if o < self {
            o
        } else {
            self
        }
    }
    /// The larger of two values.
    fn max(self, o: Self) -> Self {
        if o > self {
            o
        } else {
            self
        }
    }
    /// Relative epsilon of the size term of [`Real::offset`]: the rounding of an object's own
    /// arithmetic (the transform into its space, the quadratic), relative to its size.
    fn offset_eps() -> Self;
    /// Relative epsilon of the point term of [`Real::offset`]: eight units of the last place
    /// (the rounding of the hit point, of the offset point and of its map back into the
    /// object's space, each at most one unit of the last place per coordinate, with a margin of
    /// two). Zero for fixed point, whose absolute precision is the same everywhere.
    fn point_eps() -> Self;
    /// How far a secondary ray starts off the surface at a hit point whose largest coordinate
    /// is `p_max`, on an object whose largest side is `size`: `point_eps * p_max + offset_eps *
    /// size` (fixed point: `offset_eps * (1 + size)`). Local to the hit: what else the scene
    /// holds, and where the ray came from, do not change it.
    fn offset(p_max: Self, size: Self) -> Self {
        Self::point_eps() * p_max + Self::offset_eps() * size
    }
    /// Relative padding of bounding boxes registered in lattice cells, so that rounding in
    /// an object test can never put a hit outside the cells the object is listed in.
    fn pad_eps() -> Self;
    /// `self * pad_eps()`, the padding a size of `self` gets: the same value as the product,
    /// which is what the default does; fixed point's padding is a power of two, so it shifts.
    #[inline]
    fn padding(self) -> Self {
        self * Self::pad_eps()
    }
    /// Whether the value is finite (always true for fixed point).
    fn is_finite(self) -> bool;
    /// A 16-bit key that orders distances: `a <= b` gives `a.depth_key() <= b.depth_key()`
    /// (0 for zero, negatives and NaN). Coarse (about 1 % steps) but enough to tell which of
    /// two neighbouring pixels' hits is farther. The default goes through `f32`'s bits, whose
    /// order is the order of the non-negative values.
    fn depth_key(self) -> u16 {
        f32_key(self.to_f64() as f32)
    }
    /// A value above every value whose [`Real::depth_key`] is at most `key` (the smallest whose
    /// key is the next, or the largest value). The default inverts the `f32` key.
    fn key_bound(key: u16) -> Self {
        match key.checked_add(1) {
            Some(next) => Self::from_f64(f64::from(f32::from_bits(u32::from(next) << 16))),
            None => Self::MAX,
        }
    }
    /// `1 / self`: the same value as `Self::ONE / self`, which is what the default does; fixed
    /// point needs one 32-bit division for it instead of three.
    #[inline]
    fn recip(self) -> Self {
        Self::ONE / self
    }
    /// Whether a lattice walk finds where a ray crosses a cell plane by multiplying with the
    /// reciprocal of the direction component (made once per ray) instead of dividing at every
    /// step. Floats do: the product is within two roundings of the exact crossing, far inside
    /// the padding every box has. Fixed point divides: the reciprocal of a small component is
    /// coarse there.
    const WALK_BY_RECIPROCAL: bool = false;
    /// Whether a product is dear enough that the tracer skips the ones whose answer it knows: by
    /// a zero matrix entry (`math`'s transforms), by a weight of exactly one (an eye ray's):
    /// where a product costs a dozen instructions or a call (fixed point on a Cortex-M0+), not
    /// where it is one instruction and a branch would cost more (floats on an FPU). Either way
    /// the value is the same: fixed point's products by zero and one, and its sums with zero,
    /// are exact.
    const DEAR_PRODUCTS: bool = false;
    /// `self * x`, with `self` a weight that is often exactly one: where products are dear
    /// ([`Real::DEAR_PRODUCTS`]) `x` itself then. The same value.
    #[inline]
    fn weigh(self, x: Self) -> Self {
        if Self::DEAR_PRODUCTS && self == Self::ONE {
            x
        } else {
            self * x
        }
    }
    /// `self / 2^k` for `k` in `0..=14`: the same value as dividing by `from_i32(1 << k)`, which
    /// is what the default does; fixed point shifts instead of dividing.
    fn div_pow2(self, k: u32) -> Self {
        self / Self::from_i32(1 << k.min(14))
    }
    /// The value's bits, for scratch that keeps scalars of any kind ([`Real::from_raw`] gives
    /// the value back exactly).
    fn to_raw(self) -> u64;
    /// The value [`Real::to_raw`] gave these bits for.
    fn from_raw(bits: u64) -> Self;
    /// `2^k` as [`Real::mul_pow2`] applies it: the default keeps the value `from_f64(2^k)`.
    fn pow2(k: i16) -> Pow2<Self> {
        Pow2(Self::from_f64(pow2_f64(k)))
    }
    /// `self` times the power of two `p`: the same value as multiplying by `from_f64(2^k)`,
    /// which is what the default does (one multiply); fixed point shifts instead.
    #[inline]
    fn mul_pow2(self, p: Pow2<Self>) -> Self {
        self * p.0
    }
    /// The value of the power of two `p`, in `f64`.
    fn pow2_value(p: Pow2<Self>) -> f64 {
        p.0.to_f64()
    }
    /// The largest integer `k` in `0..=max` with `k <= self` (0 when there is none: below 0,
    /// or NaN). The default bisects with comparisons alone (no float-to-int conversion the
    /// scalar may not have); the built-in scalars convert directly, to the same answer.
    fn floor_clamped(self, max: u8) -> u8 {
        let (mut lo, mut hi) = (0u16, u16::from(max) + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if Self::from_i32(i32::from(mid)) <= self {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo as u8
    }
}

/// A power of two `2^k` as a scalar applies it ([`Real::pow2`] makes it, [`Real::mul_pow2`]
/// applies it): floating point keeps its value (one multiply), fixed point its exponent `k` in
/// the raw bits (a shift, not a multiply).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pow2<R>(pub R);

/// `2^k` in `f64` (0 below its smallest normal power, infinity above its largest): the powers
/// of two an object's scales are ([`Real::pow2`]).
pub fn pow2_f64(k: i16) -> f64 {
    match k {
        -1022..=1023 => f64::from_bits(((i64::from(k) + 1023) as u64) << 52),
        ..=-1023 => 0.0,
        _ => f64::INFINITY,
    }
}

/// The exponent `k` of a power of two `p = 2^k` (a normal `f64`): the inverse of [`pow2_f64`].
pub fn log2_of_pow2(p: f64) -> i16 {
    ((p.to_bits() >> 52) & 0x7ff) as i16 - 1023
}

/// [`Real::depth_key`] of an `f32`: its top 16 bits (sign, exponent, 7 mantissa bits).
fn f32_key(v: f32) -> u16 {
    if v > 0.0 {
        (v.to_bits() >> 16) as u16
    } else {
        0
    }
}

impl Real for f64 {
    const WALK_BY_RECIPROCAL: bool = true;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const MAX: Self = f64::MAX;
    const NAME: &'static str = "f64";
    const LIMIT: f64 = 1e150;
    const RESOLUTION: f64 = f64::EPSILON;
    fn from_f64(v: f64) -> Self {
        v
    }
    fn from_i32(v: i32) -> Self {
        v as f64
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn to_raw(self) -> u64 {
        self.to_bits()
    }
    /// The sign bit cleared: one instruction (`vabs`, `andpd`) where the default's comparison
    /// and negation take several. The same value but for -0, which becomes +0 (equal in every
    /// comparison the tracer makes).
    fn abs(self) -> Self {
        f64::abs(self)
    }
    fn from_raw(bits: u64) -> Self {
        f64::from_bits(bits)
    }
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    fn offset_eps() -> Self {
        1e-10
    }
    fn point_eps() -> Self {
        8.0 * f64::EPSILON / 2.0 // 2^-50
    }
    fn pad_eps() -> Self {
        1e-9
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    fn floor_clamped(self, max: u8) -> u8 {
        // `as` truncates towards zero, which is the floor from 0 up; NaN fails `>=`.
        if !(self >= 0.0) {
            0
        } else if self >= f64::from(max) {
            max
        } else {
            self as u8
        }
    }
}

/// Square root of an `f32`, correctly rounded (IEEE 754), so every way below gives the same bits:
/// on an Arm core with a hardware FPU (the `eabihf` targets: Cortex-M4F, M7, M33) the FPU's own
/// `vsqrt.f32`, one instruction instead of libm's software loop; elsewhere libm.
#[inline]
fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let r: u32;
        // Stable Rust cannot name FPU registers on these targets (its `vfp2` feature is not
        // seen as enabled), so the value goes through a core register and s0, which is saved
        // and restored around it.
        // SAFETY: the block leaves every register but `r` as it found it (s0 is pushed and
        // popped), touches no memory but the 4 bytes it pushes, and every eabihf target has the
        // single-precision FPU `vsqrt.f32` needs.
        #[allow(unsafe_code)]
        unsafe {
            core::arch::asm!(
                "vpush {{s0}}",
                "vmov s0, {x}",
                "vsqrt.f32 s0, s0",
                "vmov {r}, s0",
                "vpop {{s0}}",
                x = in(reg) x.to_bits(),
                r = lateout(reg) r,
                options(pure, nomem, preserves_flags)
            )
        };
        f32::from_bits(r)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

impl Real for f32 {
    const WALK_BY_RECIPROCAL: bool = true;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const MAX: Self = f32::MAX;
    const NAME: &'static str = "f32";
    const LIMIT: f64 = 1e15;
    const RESOLUTION: f64 = f32::EPSILON as f64;
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    fn from_i32(v: i32) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn to_raw(self) -> u64 {
        u64::from(self.to_bits())
    }
    /// The sign bit cleared: one instruction (`vabs`, `andpd`) where the default's comparison
    /// and negation take several. The same value but for -0, which becomes +0 (equal in every
    /// comparison the tracer makes).
    fn abs(self) -> Self {
        f32::abs(self)
    }
    fn from_raw(bits: u64) -> Self {
        f32::from_bits(bits as u32)
    }
    fn sqrt(self) -> Self {
        sqrt_f32(self)
    }
    fn depth_key(self) -> u16 {
        f32_key(self)
    }
    fn offset_eps() -> Self {
        3e-6
    }
    fn point_eps() -> Self {
        8.0 * f32::EPSILON / 2.0 // 2^-21
    }
    fn pad_eps() -> Self {
        2e-5
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    fn floor_clamped(self, max: u8) -> u8 {
        // As for f64.
        if !(self >= 0.0) {
            0
        } else if self >= f32::from(max) {
            max
        } else {
            self as u8
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Real;

    /// The comparison-only bisection the trait's default does, as the reference.
    fn bisect<R: Real>(x: R, max: u8) -> u8 {
        (0..=max).rev().find(|&k| R::from_i32(k as i32) <= x).unwrap_or(0)
    }

    fn floor_clamped_matches_bisection<R: Real>() {
        let mut values = std::vec![f64::NAN, f64::NEG_INFINITY, f64::INFINITY, -1e9, 1e9, -0.0, 0.0];
        for i in -300..=70 * 64 {
            let x = i as f64 / 64.0;
            values.extend([x, x - 1e-7, x + 1e-7, x - 1.0 / 65536.0]);
        }
        for v in values {
            let x = R::from_f64(v);
            for max in [0, 1, 64, 255] {
                assert_eq!(x.floor_clamped(max), bisect(x, max), "{} {v} (max {max})", R::NAME);
            }
        }
    }

    #[test]
    fn floor_clamped_is_the_bisection_in_every_scalar() {
        floor_clamped_matches_bisection::<f64>();
        floor_clamped_matches_bisection::<f32>();
        floor_clamped_matches_bisection::<crate::Fx>();
        floor_clamped_matches_bisection::<crate::F32Micro>();
    }

    fn depth_keys_keep_order<R: Real>() {
        let mut values: std::vec::Vec<f64> =
            (0..2000).map(|i| 1.013f64.powi(i) * 1e-3).filter(|v| *v < R::LIMIT).collect();
        values.extend([0.0, -1.0]);
        values.sort_by(f64::total_cmp);
        let keys: std::vec::Vec<u16> = values.iter().map(|&v| R::from_f64(v).depth_key()).collect();
        assert!(keys.windows(2).all(|k| k[0] <= k[1]), "{} keys out of order", R::NAME);
        // Distances 3 % apart get different keys from 1/100 to 100 units.
        let differ = |a: f64| R::from_f64(a).depth_key() < R::from_f64(a * 1.03).depth_key();
        assert!([0.01, 0.1, 1.0, 10.0, 100.0].into_iter().all(differ), "{}", R::NAME);
        assert!(R::MAX.depth_key() > R::from_f64(1000.0).depth_key());
        // A key's bound lies above every value of that key, and is the first value of a later one.
        for &v in &values {
            let key = R::from_f64(v).depth_key();
            let bound = R::key_bound(key);
            assert!(
                bound > R::from_f64(v) && bound.depth_key() > key,
                "{}: {v} has key {key}, bound {}",
                R::NAME,
                bound.to_f64()
            );
        }
    }

    #[test]
    fn depth_keys_order_distances_in_every_scalar() {
        depth_keys_keep_order::<f64>();
        depth_keys_keep_order::<f32>();
        depth_keys_keep_order::<crate::Fx>();
        depth_keys_keep_order::<crate::F32Micro>();
    }

    fn generic_min_max<R: Real>() {
        let two = R::from_f64(2.0);
        assert_eq!(Real::min(R::ONE, two), R::ONE);
        assert_eq!(Real::max(R::ONE, two), two);
        assert_eq!(Real::abs(-two), two);
        assert_eq!(Real::sqrt(R::from_f64(4.0)), two);
    }

    #[test]
    fn min_max_abs_sqrt_agree_in_every_float() {
        generic_min_max::<f64>();
        generic_min_max::<f32>();
    }
}

/// An `f32` newtype whose only difference from `f32` is its square root.
macro_rules! f32_with_sqrt {
    ($(#[$doc:meta])* $name:ident, $label:expr, $sqrt:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
        pub struct $name(pub f32);

        impl Add for $name {
            type Output = Self;
            #[inline]
            fn add(self, o: Self) -> Self {
                $name(self.0 + o.0)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline]
            fn sub(self, o: Self) -> Self {
                $name(self.0 - o.0)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline]
            fn mul(self, o: Self) -> Self {
                $name(self.0 * o.0)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline]
            fn div(self, o: Self) -> Self {
                $name(self.0 / o.0)
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                $name(-self.0)
            }
        }
        impl AddAssign for $name {
            fn add_assign(&mut self, o: Self) {
                self.0 += o.0;
            }
        }
        impl SubAssign for $name {
            fn sub_assign(&mut self, o: Self) {
                self.0 -= o.0;
            }
        }
        impl MulAssign for $name {
            fn mul_assign(&mut self, o: Self) {
                self.0 *= o.0;
            }
        }
        impl Real for $name {
            const WALK_BY_RECIPROCAL: bool = true;
            const ZERO: Self = $name(0.0);
            const ONE: Self = $name(1.0);
            const HALF: Self = $name(0.5);
            const MAX: Self = $name(f32::MAX);
            const NAME: &'static str = $label;
            const LIMIT: f64 = <f32 as Real>::LIMIT;
            const RESOLUTION: f64 = <f32 as Real>::RESOLUTION;
            fn from_f64(v: f64) -> Self {
                $name(v as f32)
            }
            fn from_i32(v: i32) -> Self {
                $name(v as f32)
            }
            fn to_raw(self) -> u64 {
                <f32 as Real>::to_raw(self.0)
            }
            fn from_raw(bits: u64) -> Self {
                $name(<f32 as Real>::from_raw(bits))
            }
            fn to_f64(self) -> f64 {
                self.0 as f64
            }
            fn sqrt(self) -> Self {
                $name(($sqrt)(self.0))
            }
            fn depth_key(self) -> u16 {
                f32_key(self.0)
            }
            fn offset_eps() -> Self {
                $name(<f32 as Real>::offset_eps())
            }
            fn point_eps() -> Self {
                $name(<f32 as Real>::point_eps())
            }
            fn pad_eps() -> Self {
                $name(<f32 as Real>::pad_eps())
            }

            fn is_finite(self) -> bool {
                self.0.is_finite()
            }
        }
    };
}

f32_with_sqrt!(
    /// `f32` with micromath's fast square root (an exponent trick, about 5 % off).
    F32Micro,
    "f32-micromath",
    |x: f32| micromath::F32Ext::sqrt(x)
);

f32_with_sqrt!(
    /// `f32` with micromath's square root refined by one Newton step (`(y + x / y) / 2`).
    F32MicroNewton,
    "f32-micromath-newton",
    |x: f32| {
        let y = micromath::F32Ext::sqrt(x);
        if y > 0.0 {
            0.5 * (y + x / y)
        } else {
            y
        }
    }
);

#[cfg(test)]
mod micromath_tests {
    use super::*;

    #[test]
    fn micromath_sqrt_is_rough_and_one_newton_step_fixes_it() {
        let (mut worst_fast, mut worst_refined) = (0.0f64, 0.0f64);
        for i in 1..2000 {
            let x = i as f64 * 0.37;
            let exact = libm::sqrt(x);
            let fast = F32Micro::from_f64(x).sqrt().to_f64();
            let refined = F32MicroNewton::from_f64(x).sqrt().to_f64();
            worst_fast = worst_fast.max((fast - exact).abs() / exact);
            worst_refined = worst_refined.max((refined - exact).abs() / exact);
        }
        assert!(worst_fast > 0.01 && worst_fast < 0.07, "fast sqrt error {worst_fast}");
        assert!(worst_refined < 2e-3, "refined sqrt error {worst_refined}");
    }
}
