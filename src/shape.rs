//! The paper's four primitives in their canonical object space: intersection and normal.
//!
//! * sphere: unit sphere at the origin;
//! * cylinder: radius 1 about the y axis, `0 <= y <= 1`, capped;
//! * cone: radius 1 at `y = 0`, radius `top` at `y = 1` (`top = 0` is a pointed cone), capped;
//! * box: the unit cube `[0,1]^3`;
//! * open: the side of the cone (or cylinder, `top = 1`) above, without its caps: NFF's `c`;
//! * triangle: corners `(0,0,0)`, `(1,0,0)` and `(0,0,1)` in the plane `y = 0`, normal `+y`.
//!
//! The open side and the triangle are not solids: a ray can meet an open side twice from
//! within, and a triangle has no inside. [`Shape::is_solid`] says which are; the tracer's
//! rules that rest on convex solids (a ray leaving a surface cannot meet it again, a ray
//! inside is refracted out) ask it (see `docs/scene-format.md`, *Open shapes and triangles*).
//!
//! A scene object places one of these with an affine transform. This module knows nothing of
//! transforms, materials or lattices: it answers "where does this object-space ray first meet
//! the surface in `(tmin, tmax]`", with the outward object-space normal.

use crate::math::{Ray, Vec3};
use crate::scalar::Real;

/// A canonical primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape<R> {
    /// Unit sphere at the origin.
    Sphere,
    /// Capped unit cylinder along y from 0 to 1.
    Cylinder,
    /// Capped cone (or frustum) along y from radius 1 at y=0 to radius `top` at y=1.
    Cone {
        /// Radius at y = 1, relative to the base radius (0 for a pointed cone).
        top: R,
    },
    /// The unit cube `[0,1]^3`.
    Box,
    /// The side of [`Shape::Cone`] (a cylinder's for `top = 1`) without its caps.
    Open {
        /// Radius at y = 1, relative to the base radius.
        top: R,
    },
    /// The triangle `(0,0,0)`, `(1,0,0)`, `(0,0,1)` in the plane `y = 0`, a surface of no
    /// thickness; its object-space normal is `+y`.
    Triangle,
}

/// Where a ray meets a primitive, in object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit<R> {
    /// The ray parameter.
    pub t: R,
    /// The outward normal (not normalised).
    pub normal: Vec3<R>,
    /// The point, as the ray reached it: along the ray it is as far off as the ray's origin
    /// is rounded, so [`Shape::on_surface`] puts it back on the surface before it is used.
    pub point: Vec3<R>,
}

/// Which primitive a shape is, without parameters (for names and statistics).
pub const SHAPE_NAMES: [&str; 6] = ["sphere", "cylinder", "cone", "box", "open side", "triangle"];

impl<R: Real> Shape<R> {
    /// Index into [`SHAPE_NAMES`].
    pub fn kind(&self) -> usize {
        match self {
            Shape::Sphere => 0,
            Shape::Cylinder => 1,
            Shape::Cone { .. } => 2,
            Shape::Box => 3,
            Shape::Open { .. } => 4,
            Shape::Triangle => 5,
        }
    }

    /// Whether the shape bounds a convex solid (sphere, capped cylinder and cone, box): a ray
    /// leaving its surface cannot meet it again, and a ray inside it is refracted out. The open
    /// side (seen from within) and the triangle (no inside) are not.
    pub fn is_solid(&self) -> bool {
        // A build without cones and triangles holds only solids (scenes with others are refused).
        !(cfg!(any(feature = "cones", feature = "triangles")) && matches!(self, Shape::Open { .. } | Shape::Triangle))
    }

    /// The Cargo feature that has the shape's intersection code (`spheres`, `cones`); `None`
    /// for boxes and cylinders, which every build has.
    pub fn feature(&self) -> Option<&'static str> {
        match self {
            Shape::Sphere => Some("spheres"),
            Shape::Cone { .. } | Shape::Open { .. } => Some("cones"),
            Shape::Triangle => Some("triangles"),
            _ => None,
        }
    }

    /// [`Shape::feature`] if this build lacks it.
    pub fn left_out(&self) -> Option<&'static str> {
        match self {
            Shape::Sphere if !cfg!(feature = "spheres") => self.feature(),
            Shape::Cone { .. } | Shape::Open { .. } if !cfg!(feature = "cones") => self.feature(),
            Shape::Triangle if !cfg!(feature = "triangles") => self.feature(),
            _ => None,
        }
    }

    /// Nearest intersection with `tmin < t <= tmax`: the parameter, the outward normal
    /// (not normalised) and the point, in object space.
    ///
    /// The ray is first clipped to the shape's object-space box (a slab test needs no squares),
    /// and the quadratic is solved from the entry point: every square then involves numbers of
    /// about the shape's own size, however far away the ray started. That keeps fixed point
    /// from overflowing and floats from cancelling.
    // On x86-64 inlined into its callers, and the shapes' own tests into it: a hit comes back
    // through memory otherwise, written field by field and read in wider moves, which wait for
    // the stores to retire.
    #[cfg_attr(target_arch = "x86_64", inline(always))]
    pub fn intersect(&self, r: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        if let (true, Shape::Triangle) = (cfg!(feature = "triangles"), self) {
            // A plane and three sides: no square to keep small, so no clip first. (A build
            // without triangles holds none: the scene was refused.)
            return triangle(r, tmin, tmax);
        }
        let (t0, t1) = self.clip(r, tmin, tmax)?;
        if let Shape::Box = self {
            // The clip is the whole box test.
            return unit_box(r, tmin, t0, t1);
        }
        let local = Ray::new(r.at(t0), r.dir);
        let mut best = Closest { t: tmax - t0, hit: None, tmin: tmin - t0 };
        match *self {
            // A shape a build leaves out is refused when the scene is built.
            Shape::Sphere if cfg!(feature = "spheres") => sphere(&local, &mut best),
            Shape::Cylinder => cone_side_and_caps(&local, R::ONE, true, &mut best),
            Shape::Cone { top } if cfg!(feature = "cones") => cone_side_and_caps(&local, top, true, &mut best),
            Shape::Open { top } if cfg!(feature = "cones") => cone_side_and_caps(&local, top, false, &mut best),
            _ => {}
        }
        best.hit.map(|(normal, point)| ShapeHit { t: best.t + t0, normal, point })
    }

    /// [`Aabb::clip`](crate::math::Aabb::clip) of the ray to the shape's box ([`Shape::bounds`]), whose sides lie at -1
    /// or 0 and at 1 on every axis: per axis one product, `o * (1 / d)`, instead of one per
    /// side, since the crossing `(side - o) / d` of side 0 is `-o / d` and of side 1 or -1 that
    /// plus or minus `1 / d`. A product that saturates (an origin far off and a ray nearly
    /// parallel to the side) is left for `clip`'s own two products, which saturate apart.
    #[inline]
    fn clip(&self, r: &Ray<R>, tmin: R, tmax: R) -> Option<(R, R)> {
        let ((o, d), (round, flat)) = ((r.origin, r.dir), self.sides_below());
        let (t0, t1) = unit_slab(o.x, d.x, round, tmin, tmax)?;
        let (t0, t1) = unit_slab(o.y, d.y, flat, t0, t1)?;
        unit_slab(o.z, d.z, round, t0, t1)
    }

    /// `p`, a point [`Shape::intersect`] found with outward normal `n`, on the surface to the
    /// rounding of the shape's own (unit-sized) coordinates.
    ///
    /// A hit is only as exact along the ray as the ray's origin: from an eye 10^14 units away
    /// the slab clip's entry point is many units of the last place of the object's coordinates
    /// off, and a secondary ray from such a point would start inside the object. The sphere,
    /// cylinder and cone solve their quadratic from that entry point, so their hit lies on the
    /// surface (of a ray beside the true one, which only moves it along the surface); the box's
    /// hit is the entry point itself, so the coordinate of its face is set to 0 or 1.
    #[inline]
    pub fn on_surface(&self, p: Vec3<R>, n: Vec3<R>) -> Vec3<R> {
        match self {
            Shape::Box => Vec3::new(onto_face(p.x, n.x), onto_face(p.y, n.y), onto_face(p.z, n.z)),
            Shape::Triangle => Vec3::new(p.x, R::ZERO, p.z),
            _ => p,
        }
    }

    /// Corners of an object-space box that holds the shape (a triangle's is flat in y).
    pub fn bounds(&self) -> (Vec3<R>, Vec3<R>) {
        if let Shape::Triangle = self {
            let z = R::ZERO;
            return (Vec3::new(z, z, z), Vec3::new(R::ONE, z, R::ONE));
        }
        let (round, flat) = self.sides_below();
        let side = |below: bool| if below { -R::ONE } else { R::ZERO };
        (Vec3::new(side(round), side(flat), side(round)), Vec3::new(R::ONE, R::ONE, R::ONE))
    }

    /// Which sides of the shape's box ([`Shape::bounds`]) lie at -1 rather than 0: those of the
    /// x and z axes, and that of the y axis. Every upper side lies at 1.
    #[inline]
    fn sides_below(&self) -> (bool, bool) {
        match self {
            Shape::Sphere => (true, true),
            Shape::Cylinder | Shape::Cone { .. } | Shape::Open { .. } => (true, false),
            Shape::Box | Shape::Triangle => (false, false),
        }
    }
}

/// [`Shape::clip`] on one axis: the range `[t0, t1]` of a ray with origin `o` and direction `d`
/// on that axis, cut to the slab from -1 (`below`) or 0 to 1. A zero direction keeps the whole
/// range if the origin lies within the slab, as [`Aabb::clip`](crate::math::Aabb::clip) does.
#[inline(always)]
fn unit_slab<R: Real>(o: R, d: R, below: bool, t0: R, t1: R) -> Option<(R, R)> {
    let lo = if below { -R::ONE } else { R::ZERO };
    if d == R::ZERO {
        return if o < lo || o > R::ONE { None } else { Some((t0, t1)) };
    }
    let inv = d.recip();
    let m = o * inv;
    let (ta, tb) =
        if m.abs() < R::MAX { (if below { -m - inv } else { -m }, inv - m) } else { sides_apart(o, inv, lo) };
    crate::math::cut(ta, tb, t0, t1)
}

/// The crossings of the sides `lo` and 1 as [`Aabb::clip`](crate::math::Aabb::clip) finds them,
/// one product each: for [`unit_slab`]'s rare saturated case, out of line.
#[cold]
#[inline(never)]
fn sides_apart<R: Real>(o: R, inv: R, lo: R) -> (R, R) {
    ((lo - o) * inv, (R::ONE - o) * inv)
}

/// A unit cube's coordinate `c` of a hit whose normal has component `n` along it: 0 or 1 on
/// the face the normal leaves (the other coordinates are kept).
fn onto_face<R: Real>(c: R, n: R) -> R {
    if n > R::ZERO {
        R::ONE
    } else if n < R::ZERO {
        R::ZERO
    } else {
        c
    }
}

/// The running nearest root of one shape test: its parameter, and its normal and point.
struct Closest<R> {
    t: R,
    hit: Option<(Vec3<R>, Vec3<R>)>,
    tmin: R,
}

impl<R: Real> Closest<R> {
    #[inline]
    fn offer(&mut self, t: R, hit: impl FnOnce() -> (Vec3<R>, Vec3<R>)) {
        if t > self.tmin && t <= self.t {
            self.t = t;
            self.hit = Some(hit());
        }
    }
}

/// Roots of `a t^2 + 2 b t + c = 0` given the discriminant `disc = b^2 - a c >= 0`, in the
/// cancellation-free form (Press et al.): `q = -(b + sign(b) sqrt(disc))`, roots `q/a`, `c/q`.
/// A root whose denominator is zero is left out, so `a = 0` gives the one linear root.
fn roots<R: Real>(a: R, b: R, c: R, disc: R) -> [Option<R>; 2] {
    let s = disc.sqrt();
    let q = if b < R::ZERO { s - b } else { -(b + s) };
    let r1 = if a != R::ZERO { Some(q / a) } else { None };
    let r2 = if q != R::ZERO { Some(c / q) } else { None };
    [r1, r2]
}

#[cfg_attr(target_arch = "x86_64", inline(always))]
fn sphere<R: Real>(r: &Ray<R>, best: &mut Closest<R>) {
    let (o, d) = (r.origin, r.dir);
    let a = d.dot(d);
    if a == R::ZERO {
        return;
    }
    let b = o.dot(d);
    let c = o.dot(o) - R::ONE;
    // Hearn-Baker: b^2 - a c = a (1 - |o - d b/a|^2), with the closest-approach vector computed
    // first, so a far small sphere is not lost to cancellation between b^2 and a c.
    let v = o - d * (b / a);
    let disc = a * (R::ONE - v.dot(v));
    if disc < R::ZERO {
        return;
    }
    for t in roots(a, b, c, disc).into_iter().flatten() {
        best.offer(t, || {
            let p = r.at(t);
            (p, p)
        });
    }
}

/// Side of the cone `x^2 + z^2 = (1 + k y)^2` with `k = top - 1` (k = 0 is the cylinder) for
/// `0 <= y <= 1`, plus the caps when `capped`. The mirror cone beyond a pointed apex has
/// `y > 1` and is rejected by the same `y` range test.
#[cfg_attr(target_arch = "x86_64", inline(always))]
fn cone_side_and_caps<R: Real>(r: &Ray<R>, top: R, capped: bool, best: &mut Closest<R>) {
    let (o, d) = (r.origin, r.dir);
    let k = top - R::ONE;
    let w = R::ONE + k * o.y;
    let e = k * d.y;
    let a = d.x * d.x + d.z * d.z - e * e;
    let b = o.x * d.x + o.z * d.z - w * e;
    let c = o.x * o.x + o.z * o.z - w * w;
    let disc = if k == R::ZERO && a != R::ZERO {
        // Cylinder: the same Hearn-Baker form as the sphere, in the xz plane.
        let (vx, vz) = (o.x - d.x * (b / a), o.z - d.z * (b / a));
        a * (R::ONE - (vx * vx + vz * vz))
    } else {
        b * b - a * c
    };
    if disc >= R::ZERO && (a != R::ZERO || b != R::ZERO) {
        for t in roots(a, b, c, disc).into_iter().flatten() {
            let p = r.at(t);
            if p.y >= R::ZERO && p.y <= R::ONE {
                best.offer(t, || {
                    let n = Vec3::new(p.x, -k * (R::ONE + k * p.y), p.z);
                    if n.x == R::ZERO && n.z == R::ZERO && n.y == R::ZERO {
                        (Vec3::new(R::ZERO, R::ONE, R::ZERO), p) // the apex itself
                    } else {
                        (n, p)
                    }
                });
            }
        }
    }
    if capped && d.y != R::ZERO {
        for (y, radius, ny) in [(R::ZERO, R::ONE, -R::ONE), (R::ONE, top, R::ONE)] {
            if radius <= R::ZERO {
                continue;
            }
            let t = (y - o.y) / d.y;
            let (px, pz) = (o.x + d.x * t, o.z + d.z * t);
            if px * px + pz * pz <= radius * radius {
                best.offer(t, || (Vec3::new(R::ZERO, ny, R::ZERO), Vec3::new(px, y, pz)));
            }
        }
    }
}

/// The triangle `(0,0,0)`, `(1,0,0)`, `(0,0,1)` in `y = 0`: where the ray crosses the plane
/// in `(tmin, tmax]`, if that point's `x` and `z` lie in the triangle. The three side tests
/// are widened by the scalar's box padding ([`Real::pad_eps`]), so the triangles a polygon is
/// cut into overlap by a rounding's width along their shared sides and no ray slips
/// between them.
#[cfg_attr(target_arch = "x86_64", inline(always))]
fn triangle<R: Real>(r: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
    let (o, d) = (r.origin, r.dir);
    if d.y == R::ZERO {
        return None;
    }
    let t = -o.y / d.y;
    if !(t > tmin && t <= tmax) {
        return None;
    }
    let (u, v) = (o.x + d.x * t, o.z + d.z * t);
    let slack = R::pad_eps();
    if u < -slack || v < -slack || u + v > R::ONE + slack {
        return None;
    }
    let z = R::ZERO;
    Some(ShapeHit { t, normal: Vec3::new(z, R::ONE, z), point: Vec3::new(u, z, v) })
}

/// The unit cube, given the ray's parameter range inside it `[t0, t1]` from the slab clip:
/// the first of entry and exit after `tmin`, with the normal of the face it crosses.
#[cfg_attr(target_arch = "x86_64", inline(always))]
fn unit_box<R: Real>(r: &Ray<R>, tmin: R, t0: R, t1: R) -> Option<ShapeHit<R>> {
    let t = if t0 > tmin {
        t0
    } else if t1 > tmin {
        t1
    } else {
        return None;
    };
    // The face is the one the point lies on: the axis whose coordinate is nearest 0 or 1.
    let p = r.at(t);
    let (mut axis, mut dist, mut sign) = (0, R::MAX, R::ZERO);
    for a in 0..3 {
        let c = p.axis(a);
        for (d, s) in [(c.abs(), -R::ONE), ((R::ONE - c).abs(), R::ONE)] {
            if d < dist {
                (axis, dist, sign) = (a, d, s);
            }
        }
    }
    // Component by component, not through an array indexed by `axis`: a store at a computed
    // index read back whole straight after stalls the load on x86 (store forwarding).
    let on = |a: usize| if axis == a { sign } else { R::ZERO };
    Some(ShapeHit { t, normal: Vec3::new(on(0), on(1), on(2)), point: p })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f64; 3], d: [f64; 3]) -> Ray<f64> {
        Ray::new(Vec3::new(o[0], o[1], o[2]), Vec3::new(d[0], d[1], d[2]))
    }

    #[test]
    fn sphere_front_hit_and_inside_exit() {
        let s = Shape::<f64>::Sphere;
        let ShapeHit { t, normal: n, .. } = s.intersect(&ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]), 0.0, 100.0).unwrap();
        assert_eq!(t, 4.0);
        assert_eq!(n, Vec3::new(0.0, 0.0, -1.0));
        let ShapeHit { t, .. } = s.intersect(&ray([0.0, 0.0, 0.0], [0.0, 0.0, 2.0]), 0.0, 100.0).unwrap();
        assert_eq!(t, 0.5);
    }

    #[test]
    fn cylinder_parallel_to_axis_hits_the_cap() {
        let s = Shape::<f64>::Cylinder;
        let ShapeHit { t, normal: n, .. } = s.intersect(&ray([0.5, -1.0, 0.0], [0.0, 1.0, 0.0]), 0.0, 100.0).unwrap();
        assert_eq!((t, n), (1.0, Vec3::new(0.0, -1.0, 0.0)));
        assert!(s.intersect(&ray([1.5, -1.0, 0.0], [0.0, 1.0, 0.0]), 0.0, 100.0).is_none());
    }

    #[test]
    fn cone_mirror_nappe_is_never_hit() {
        let s = Shape::Cone { top: 0.0 };
        // A horizontal ray at y = 1.5 crosses the mirror cone above the apex only.
        assert!(s.intersect(&ray([-5.0, 1.5, 0.0], [1.0, 0.0, 0.0]), 0.0, 100.0).is_none());
        // At y = 0.5 the radius is 0.5.
        let ShapeHit { t, .. } = s.intersect(&ray([-5.0, 0.5, 0.0], [1.0, 0.0, 0.0]), 0.0, 100.0).unwrap();
        assert!((t - 4.5).abs() < 1e-12);
    }

    #[test]
    fn an_open_side_has_no_caps_and_is_met_from_within() {
        let s = Shape::<f64>::Open { top: 1.0 };
        // Along the axis: through both open ends, nothing.
        assert!(s.intersect(&ray([0.5, -1.0, 0.0], [0.0, 1.0, 0.0]), 0.0, 100.0).is_none());
        // From the axis outwards: the inside of the side, its outward normal pointing away.
        let ShapeHit { t, normal: n, .. } = s.intersect(&ray([0.0, 0.5, 0.0], [1.0, 0.0, 0.0]), 0.0, 100.0).unwrap();
        assert_eq!(t, 1.0);
        assert!(n.x > 0.0);
        // A slanted ray into the open end meets the far inner wall.
        let ShapeHit { t, .. } = s.intersect(&ray([0.0, 2.0, 0.0], [1.0, -2.0, 0.0]), 0.0, 100.0).unwrap();
        assert!((t - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_triangle_is_hit_inside_its_three_sides_from_either_side() {
        let s = Shape::<f64>::Triangle;
        let ShapeHit { t, normal: n, point: p } =
            s.intersect(&ray([0.25, 2.0, 0.25], [0.0, -1.0, 0.0]), 0.0, 100.0).unwrap();
        assert_eq!((t, n, p), (2.0, Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.25, 0.0, 0.25)));
        assert!(s.intersect(&ray([0.25, -2.0, 0.25], [0.0, 1.0, 0.0]), 0.0, 100.0).is_some());
        // Past the hypotenuse, behind the start, and parallel to the plane: no hit.
        assert!(s.intersect(&ray([0.6, 2.0, 0.6], [0.0, -1.0, 0.0]), 0.0, 100.0).is_none());
        assert!(s.intersect(&ray([0.25, 2.0, 0.25], [0.0, 1.0, 0.0]), 0.0, 100.0).is_none());
        assert!(s.intersect(&ray([0.25, 0.0, 0.25], [1.0, 0.0, 0.0]), 0.0, 100.0).is_none());
    }

    #[test]
    fn box_entering_and_leaving_faces() {
        let s = Shape::<f64>::Box;
        let ShapeHit { t, normal: n, .. } = s.intersect(&ray([0.5, 0.5, -1.0], [0.0, 0.0, 1.0]), 0.0, 100.0).unwrap();
        assert_eq!((t, n), (1.0, Vec3::new(0.0, 0.0, -1.0)));
        let ShapeHit { t, normal: n, .. } = s.intersect(&ray([0.5, 0.5, 0.5], [0.0, 0.0, -1.0]), 0.0, 100.0).unwrap();
        assert_eq!((t, n), (0.5, Vec3::new(0.0, 0.0, -1.0)));
    }
}
