//! Vectors, rays, axis-aligned boxes and affine transforms.
//!
//! Transforms are the paper's homogeneous matrices reduced to 3x4 (the last row is always
//! `0 0 0 1`). They are composed and inverted in `f64` while a scene is built and then
//! converted to the tracer's scalar, so no scalar needs trigonometry or a matrix inverse.

use crate::scalar::Real;
use core::ops::{Add, Mul, Neg, Sub};

/// A 3-vector (point, direction or normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3<R> {
    /// x component.
    pub x: R,
    /// y component.
    pub y: R,
    /// z component.
    pub z: R,
}

impl<R: Real> Vec3<R> {
    /// Builds a vector from its components.
    pub const fn new(x: R, y: R, z: R) -> Self {
        Vec3 { x, y, z }
    }
    /// The zero vector.
    pub const fn zero() -> Self {
        Vec3::new(R::ZERO, R::ZERO, R::ZERO)
    }
    /// Component by axis index 0, 1, 2.
    #[inline]
    pub fn axis(&self, a: usize) -> R {
        match a {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }
    /// Dot product.
    #[inline]
    pub fn dot(self, o: Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Cross product.
    pub fn cross(self, o: Self) -> Self {
        Vec3::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }
    /// Euclidean length.
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }
    /// Unit vector in the same direction (the zero vector stays zero). The vector is first
    /// divided by its largest component, so the squares never exceed 3 (no overflow in fixed
    /// point, no underflow in floats).
    pub fn normalize(self) -> Self {
        let m = self.max_abs();
        if m == R::ZERO {
            return self;
        }
        let v = self * m.recip();
        v * v.length().recip()
    }
    /// Every component times the power of two `p` ([`Real::mul_pow2`]).
    #[inline]
    pub fn mul_pow2(self, p: crate::scalar::Pow2<R>) -> Self {
        Vec3::new(self.x.mul_pow2(p), self.y.mul_pow2(p), self.z.mul_pow2(p))
    }
    /// Largest absolute component.
    pub fn max_abs(self) -> R {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }
    /// Converts every component to another scalar.
    pub fn cast<S: Real>(self) -> Vec3<S> {
        Vec3::new(S::from_f64(self.x.to_f64()), S::from_f64(self.y.to_f64()), S::from_f64(self.z.to_f64()))
    }
}

impl<R: Real> Add for Vec3<R> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl<R: Real> Sub for Vec3<R> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl<R: Real> Mul<R> for Vec3<R> {
    type Output = Self;
    #[inline]
    fn mul(self, s: R) -> Self {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl<R: Real> Neg for Vec3<R> {
    type Output = Self;
    fn neg(self) -> Self {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// A ray `P = origin + t * dir` (the paper's `P = V + A t`); `dir` need not be unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray<R> {
    /// Start point `V`.
    pub origin: Vec3<R>,
    /// Direction `A`.
    pub dir: Vec3<R>,
}

impl<R: Real> Ray<R> {
    /// Builds a ray.
    pub fn new(origin: Vec3<R>, dir: Vec3<R>) -> Self {
        Ray { origin, dir }
    }
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: R) -> Vec3<R> {
        self.origin + self.dir * t
    }
}

/// An axis-aligned box through its min and max corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb<R> {
    /// Minimum corner.
    pub min: Vec3<R>,
    /// Maximum corner.
    pub max: Vec3<R>,
}

impl<R: Real> Aabb<R> {
    /// The eight corners (corner `c` takes `max` on axis `a` where bit `a` of `c` is set).
    pub fn corners(&self) -> [Vec3<R>; 8] {
        let (lo, hi) = (self.min, self.max);
        core::array::from_fn(|c| {
            Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            )
        })
    }
    /// Whether `p` lies strictly inside the box: off its sides on every axis.
    #[inline]
    pub fn strictly_holds(&self, p: Vec3<R>) -> bool {
        (0..3).all(|a| self.min.axis(a) < p.axis(a) && p.axis(a) < self.max.axis(a))
    }
    /// The empty box (min above max), the identity of [`Aabb::union`].
    pub fn empty() -> Self {
        Aabb { min: Vec3::new(R::MAX, R::MAX, R::MAX), max: Vec3::new(-R::MAX, -R::MAX, -R::MAX) }
    }
    /// Grows the box to hold a point.
    pub fn include(&mut self, p: Vec3<R>) {
        self.min = Vec3::new(self.min.x.min(p.x), self.min.y.min(p.y), self.min.z.min(p.z));
        self.max = Vec3::new(self.max.x.max(p.x), self.max.y.max(p.y), self.max.z.max(p.z));
    }
    /// The smallest box holding both.
    pub fn union(mut self, o: &Self) -> Self {
        self.include(o.min);
        self.include(o.max);
        self
    }
    /// The box grown by `pad` on every side.
    pub fn padded(&self, pad: R) -> Self {
        let p = Vec3::new(pad, pad, pad);
        Aabb { min: self.min - p, max: self.max + p }
    }
    /// Largest extent along any axis.
    pub fn extent(&self) -> R {
        (self.max.x - self.min.x).max(self.max.y - self.min.y).max(self.max.z - self.min.z)
    }
    /// Clips the ray's parameter range `[t0, t1]` to the box (slab method). A zero direction
    /// component (+0.0 or -0.0 alike) keeps the whole range if the origin lies within that slab.
    pub fn clip(&self, ray: &Ray<R>, t0: R, t1: R) -> Option<(R, R)> {
        // The three slabs written out: no axis chosen by index at run time.
        let (o, d) = (ray.origin, ray.dir);
        let (t0, t1) = slab(o.x, d.x, self.min.x, self.max.x, t0, t1)?;
        let (t0, t1) = slab(o.y, d.y, self.min.y, self.max.y, t0, t1)?;
        slab(o.z, d.z, self.min.z, self.max.z, t0, t1)
    }
    /// [`Aabb::clip`] of a ray from `origin` whose direction's reciprocal `inv` is known (per
    /// axis `1 / d`, zero where `d` is zero): three slabs at two products each, no division.
    #[inline]
    pub fn clip_by_inverse(&self, origin: Vec3<R>, inv: Vec3<R>, t0: R, t1: R) -> Option<(R, R)> {
        self.clip_grown_by_inverse((origin, origin), inv, t0, t1)
    }
    /// [`Aabb::clip_by_inverse`] of this box grown by `pad` on every side, with the growth moved
    /// onto the ray's origin, given as `(o + pad, o - pad)`: the crossings of the sides are
    /// taken as `(min - (o + pad)) / d` and `(max - (o - pad)) / d`, from origins a caller makes
    /// once per ray, not as `((min - pad) - o) / d` from a box grown at every test. The same
    /// value in fixed point (its sums are exact); in floats within a rounding of it. Always
    /// inlined: a walk's box test is this, in its loop.
    #[inline(always)]
    pub fn clip_grown_by_inverse(&self, (near, far): (Vec3<R>, Vec3<R>), inv: Vec3<R>, t0: R, t1: R) -> Option<(R, R)> {
        let i = inv;
        let (t0, t1) = slab_by((near.x, far.x), i.x, self.min.x, self.max.x, t0, t1)?;
        let (t0, t1) = slab_by((near.y, far.y), i.y, self.min.y, self.max.y, t0, t1)?;
        slab_by((near.z, far.z), i.z, self.min.z, self.max.z, t0, t1)
    }
    /// Converts to another scalar, rounding outwards by the target's padding so the box stays
    /// conservative.
    pub fn cast_padded<S: Real>(&self) -> Aabb<S> {
        let p = self.padded_for::<S>();
        Aabb { min: p.min.cast(), max: p.max.cast() }
    }
    /// The padding (in `f64`, on every side) [`Aabb::cast_padded`] gives the box in `S`: the
    /// scalar's padding at the box's farthest coordinate.
    pub fn pad_for<S: Real>(&self) -> f64 {
        S::pad_eps().to_f64() * (1.0 + self.min.max_abs().max(self.max.max_abs()).to_f64())
    }
    /// The box grown (in `f64`) by the padding [`Aabb::cast_padded`] gives it in `S`.
    pub fn padded_for<S: Real>(&self) -> Aabb<f64> {
        let pad = self.pad_for::<S>();
        let grow =
            |v: Vec3<R>, s: f64| Vec3::new(v.x.to_f64() + s * pad, v.y.to_f64() + s * pad, v.z.to_f64() + s * pad);
        Aabb { min: grow(self.min, -1.0), max: grow(self.max, 1.0) }
    }
}

/// [`Aabb::clip`] on one axis: the range `[t0, t1]` of a ray with origin `o` and direction `d`
/// on that axis, cut to the slab `lo..=hi`.
#[inline(always)]
fn slab<R: Real>(o: R, d: R, lo: R, hi: R, t0: R, t1: R) -> Option<(R, R)> {
    // A nonzero direction's reciprocal is never zero (it saturates in fixed point).
    slab_by((o, o), if d == R::ZERO { R::ZERO } else { d.recip() }, lo, hi, t0, t1)
}

/// [`slab`] given the direction's reciprocal `inv` (zero for a zero direction), the origin
/// taken as `near` against the side `lo` and as `far` against `hi` (both the origin for the
/// slab itself; [`Aabb::clip_grown_by_inverse`] for a grown one).
#[inline(always)]
fn slab_by<R: Real>((near, far): (R, R), inv: R, lo: R, hi: R, t0: R, t1: R) -> Option<(R, R)> {
    if inv == R::ZERO {
        return if near < lo || far > hi { None } else { Some((t0, t1)) };
    }
    cut((lo - near) * inv, (hi - far) * inv, t0, t1)
}

/// The range `[t0, t1]` cut to a slab the ray crosses at `ta` and `tb` (either order), or
/// `None` if nothing is left.
#[inline(always)]
pub(crate) fn cut<R: Real>(ta: R, tb: R, t0: R, t1: R) -> Option<(R, R)> {
    let (ta, tb) = if ta > tb { (tb, ta) } else { (ta, tb) };
    let (t0, t1) = (t0.max(ta), t1.min(tb));
    if t0 > t1 {
        None
    } else {
        Some((t0, t1))
    }
}

/// `a * b` for a matrix entry `a`; where products are dear ([`Real::DEAR_PRODUCTS`]), zero
/// without multiplying when `a` is zero: an object placed along the axes, or turned about one,
/// has four to six zero entries. The same value either way (a fixed-point sum adds the zero as
/// nothing).
#[inline(always)]
fn entry_times<R: Real>(a: R, b: R) -> R {
    if R::DEAR_PRODUCTS && a == R::ZERO {
        R::ZERO
    } else {
        a * b
    }
}

/// A linear map as a 3x3 matrix: an [`Affine`] transform without its translation (what maps
/// directions, and points taken relative to an origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear<R> {
    /// Rows of `A`.
    pub m: [[R; 3]; 3],
}

impl<R: Real> Linear<R> {
    /// Applies the affine map `[A | t]` to a point: `A p + t`, each row's products summed
    /// before `t` is added.
    #[inline]
    pub fn point_plus(&self, p: Vec3<R>, t: Vec3<R>) -> Vec3<R> {
        let (m, e) = (&self.m, entry_times);
        Vec3::new(
            e(m[0][0], p.x) + e(m[0][1], p.y) + e(m[0][2], p.z) + t.x,
            e(m[1][0], p.x) + e(m[1][1], p.y) + e(m[1][2], p.z) + t.y,
            e(m[2][0], p.x) + e(m[2][1], p.y) + e(m[2][2], p.z) + t.z,
        )
    }
    /// Applies the map to a direction.
    #[inline]
    pub fn vector(&self, v: Vec3<R>) -> Vec3<R> {
        let (m, t) = (&self.m, entry_times);
        Vec3::new(
            t(m[0][0], v.x) + t(m[0][1], v.y) + t(m[0][2], v.z),
            t(m[1][0], v.x) + t(m[1][1], v.y) + t(m[1][2], v.z),
            t(m[2][0], v.x) + t(m[2][1], v.y) + t(m[2][2], v.z),
        )
    }
    /// Applies the transpose: with `self` the world-to-object map this maps an object-space
    /// normal to world space (the inverse transpose rule).
    #[inline]
    pub fn transpose_vector(&self, v: Vec3<R>) -> Vec3<R> {
        let (m, t) = (&self.m, entry_times);
        Vec3::new(
            t(m[0][0], v.x) + t(m[1][0], v.y) + t(m[2][0], v.z),
            t(m[0][1], v.x) + t(m[1][1], v.y) + t(m[2][1], v.z),
            t(m[0][2], v.x) + t(m[1][2], v.y) + t(m[2][2], v.z),
        )
    }
    /// Converts to another scalar.
    pub fn cast<S: Real>(&self) -> Linear<S> {
        Linear { m: self.m.map(|row| row.map(|v| S::from_f64(v.to_f64()))) }
    }
    /// The affine transform with this linear part and no translation.
    pub fn affine(&self) -> Affine<R> {
        let (m, z) = (&self.m, R::ZERO);
        Affine { m: [[m[0][0], m[0][1], m[0][2], z], [m[1][0], m[1][1], m[1][2], z], [m[2][0], m[2][1], m[2][2], z]] }
    }
}

/// An affine transform as a 3x4 matrix `[A | b]`: `p' = A p + b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine<R> {
    /// Rows of `[A | b]`.
    pub m: [[R; 4]; 3],
}

impl<R: Real> Affine<R> {
    /// The identity transform.
    pub fn identity() -> Self {
        let (o, z) = (R::ONE, R::ZERO);
        Affine { m: [[o, z, z, z], [z, o, z, z], [z, z, o, z]] }
    }
    /// Applies to a point.
    #[inline]
    pub fn point(&self, p: Vec3<R>) -> Vec3<R> {
        let m = &self.m;
        self.linear().point_plus(p, Vec3::new(m[0][3], m[1][3], m[2][3]))
    }
    /// Applies the linear part to a direction.
    #[inline]
    pub fn vector(&self, v: Vec3<R>) -> Vec3<R> {
        self.linear().vector(v)
    }
    /// The linear part `A`, without the translation.
    #[inline]
    pub fn linear(&self) -> Linear<R> {
        let m = &self.m;
        Linear { m: [[m[0][0], m[0][1], m[0][2]], [m[1][0], m[1][1], m[1][2]], [m[2][0], m[2][1], m[2][2]]] }
    }
    /// Maps a ray (the parameter `t` is preserved because the direction is not renormalised).
    #[inline]
    pub fn ray(&self, r: &Ray<R>) -> Ray<R> {
        Ray::new(self.point(r.origin), self.vector(r.dir))
    }
    /// `self` after `first`: the transform that applies `first`, then `self`.
    pub fn after(&self, first: &Self) -> Self {
        let (a, b) = (&self.m, &first.m);
        let mut m = [[R::ZERO; 4]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                let mut s = if j == 3 { a[i][3] } else { R::ZERO };
                for k in 0..3 {
                    s += a[i][k] * b[k][j];
                }
                *cell = s;
            }
        }
        Affine { m }
    }
    /// Converts to another scalar.
    pub fn cast<S: Real>(&self) -> Affine<S> {
        let mut m = [[S::ZERO; 4]; 3];
        for i in 0..3 {
            for j in 0..4 {
                m[i][j] = S::from_f64(self.m[i][j].to_f64());
            }
        }
        Affine { m }
    }
}

impl Affine<f64> {
    /// The map taking the unit axes to `x`, `y`, `z` and the origin to `at`.
    pub fn from_columns(x: Vec3<f64>, y: Vec3<f64>, z: Vec3<f64>, at: Vec3<f64>) -> Self {
        Affine { m: [[x.x, y.x, z.x, at.x], [x.y, y.y, z.y, at.y], [x.z, y.z, z.z, at.z]] }
    }
    /// Translation by `v`.
    pub fn translate(v: Vec3<f64>) -> Self {
        let mut t = Self::identity();
        t.m[0][3] = v.x;
        t.m[1][3] = v.y;
        t.m[2][3] = v.z;
        t
    }
    /// Non-uniform scale.
    pub fn scale(v: Vec3<f64>) -> Self {
        let mut t = Self::identity();
        t.m[0][0] = v.x;
        t.m[1][1] = v.y;
        t.m[2][2] = v.z;
        t
    }
    /// Rotation by `deg` degrees about axis 0 (x), 1 (y) or 2 (z), right-handed.
    pub fn rotate(axis: usize, deg: f64) -> Self {
        let r = deg * core::f64::consts::PI / 180.0;
        let (s, c) = (libm::sin(r), libm::cos(r));
        let mut t = Self::identity();
        let (i, j) = match axis {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        t.m[i][i] = c;
        t.m[i][j] = -s;
        t.m[j][i] = s;
        t.m[j][j] = c;
        t
    }
    /// Shear: coordinate `i` gains `k` times coordinate `j`.
    pub fn shear(i: usize, j: usize, k: f64) -> Self {
        let mut t = Self::identity();
        t.m[i][j] = k;
        t
    }
    /// Determinant of the linear part.
    pub fn det(&self) -> f64 {
        let m = &self.m;
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }
    /// The inverse transform, or `None` when the linear part is singular (or nearly so).
    ///
    /// Singular means the computed inverse does not undo the transform: `inverse * self` is
    /// off the identity by more than `1e-9` in some entry. A large but exact inverse (a shear by
    /// `1e12`, whose determinant is 1) is not singular; a determinant that is zero, or tiny
    /// against the entries so that rounding dominates, is.
    pub fn inverse(&self) -> Option<Self> {
        let d = self.det();
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let m = &self.m;
        let mut inv = [[0.0; 4]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let (a, b) = ((j + 1) % 3, (j + 2) % 3);
                let (c, e) = ((i + 1) % 3, (i + 2) % 3);
                inv[i][j] = (m[a][c] * m[b][e] - m[a][e] * m[b][c]) / d;
            }
        }
        for i in 0..3 {
            inv[i][3] = -(inv[i][0] * m[0][3] + inv[i][1] * m[1][3] + inv[i][2] * m[2][3]);
        }
        for i in 0..3 {
            for j in 0..3 {
                let p = inv[i][0] * m[0][j] + inv[i][1] * m[1][j] + inv[i][2] * m[2][j];
                let want = if i == j { 1.0 } else { 0.0 };
                if !((p - want).abs() <= 1e-9) {
                    return None;
                }
            }
        }
        Some(Affine { m: inv })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_undoes_a_compound_transform() {
        let t = Affine::translate(Vec3::new(1.0, -2.0, 3.0))
            .after(&Affine::rotate(1, 30.0))
            .after(&Affine::scale(Vec3::new(2.0, 0.5, 3.0)))
            .after(&Affine::shear(0, 1, 0.7));
        let inv = t.inverse().unwrap();
        let p = Vec3::new(0.3, -1.2, 4.5);
        let q = inv.point(t.point(p));
        assert!((q - p).max_abs() < 1e-12, "{q:?}");
    }

    #[test]
    fn singular_transform_has_no_inverse() {
        assert!(Affine::scale(Vec3::new(1.0, 0.0, 1.0)).inverse().is_none());
    }

    #[test]
    fn rotation_about_y_turns_z_into_x() {
        let p = Affine::rotate(1, 90.0).point(Vec3::new(0.0, 0.0, 1.0));
        assert!((p - Vec3::new(1.0, 0.0, 0.0)).max_abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn clip_keeps_whole_range_for_signed_zero_inside_slab() {
        let b = Aabb { min: Vec3::new(0.0, 0.0, 0.0), max: Vec3::new(1.0, 1.0, 1.0) };
        for dz in [0.0, -0.0] {
            let r = Ray::new(Vec3::new(-1.0, 0.5, 1.0), Vec3::new(1.0, 0.0, dz));
            assert_eq!(b.clip(&r, 0.0, 10.0), Some((1.0, 2.0)));
        }
    }
}
