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
    /// The largest finite value, used as "no hit yet".
    const MAX: Self;
    /// Short name for reports ("f64", "f32", ...).
    const NAME: &'static str;
    /// Converts from `f64` (scene set-up only); values out of range saturate.
    fn from_f64(v: f64) -> Self;
    /// Largest coordinate magnitude a scene may use with this scalar (checked by validation).
    const LIMIT: f64;
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
    /// Relative epsilon for offsetting secondary-ray origins off a surface: the offset is
    /// `OFFSET * (1 + |p|_max)` along the normal (see `trace`).
    fn offset_eps() -> Self;
    /// Relative padding of bounding boxes registered in lattice cells, so that rounding in
    /// an object test can never put a hit outside the cells the object is listed in.
    fn pad_eps() -> Self;
    /// Whether the value is finite (always true for fixed point).
    fn is_finite(self) -> bool;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const MAX: Self = f64::MAX;
    const NAME: &'static str = "f64";
    const LIMIT: f64 = 1e150;
    fn from_f64(v: f64) -> Self {
        v
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    fn offset_eps() -> Self {
        1e-9
    }
    fn pad_eps() -> Self {
        1e-9
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const MAX: Self = f32::MAX;
    const NAME: &'static str = "f32";
    const LIMIT: f64 = 1e15;
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn sqrt(self) -> Self {
        libm::sqrtf(self)
    }
    fn offset_eps() -> Self {
        1e-4
    }
    fn pad_eps() -> Self {
        2e-5
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

#[cfg(test)]
mod tests {
    use super::Real;

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
