//! Eye hulls: where on the image an object can appear, more tightly than its eye window.
//!
//! An [`EyeWindow`](super::region::EyeWindow) is the rectangle around an object's padded box as the eye
//! sees it. A box turned about an axis, a thin leg seen at a slant, or a floor whose far edge
//! runs across the image shows in only part of that rectangle, so a tile or a block of pixels
//! inside the rectangle may lie wholly outside the object's image. The [`EyeHull`] is the
//! convex hull of the object's own box (its canonical shape's box through its placement, padded
//! as its world box is) projected through the eye: the image of a convex body is the convex
//! hull of its corners' images, and the object lies in that box, so an eye ray that meets the
//! object passes inside the hull. It is kept as half-planes in integers, so a tile or a block
//! of pixels is tested against it without a division or a float. A sphere's, cylinder's or
//! cone's hull is drawn in further, to its outline (the images of its caps, or of the circle
//! where the eye's rays graze the sphere).

use super::model::Object;
use super::projection::Projection;
use super::region::{EyeHull, HullEdge, NO_HULL};
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::shape::Shape;

impl Projection {
    /// The window-space image `F (p - eye)` of a point `p` (`F` the map to the window's
    /// coordinates: a point's image `k` lies on the eye ray through `(k.y / k.x, k.z / k.x)`).
    fn image(&self, p: Vec3<f64>) -> Vec3<f64> {
        self.from_eye.vector(p - self.eye)
    }

    /// The window position `(u, v)` of a point whose image is `k` ([`Projection::image`]),
    /// and how far from it along `u` and `v` the window position of any point within `pad` of
    /// it on every axis can lie; `None` if such a point can lie on or behind the eye's plane. A
    /// move `d` of the point moves `k` by `F d`, each part at most `pad` times its row's sum of
    /// magnitudes, and `u = k.y / k.x` by at most `(|F d|.y + |u| |F d|.x) / (k.x - |F d|.x)`;
    /// likewise `v`.
    fn window_within(&self, k: Vec3<f64>, pad: f64) -> Option<([f64; 2], [f64; 2])> {
        let [dx, dy, dz] = self.rows.map(|r| pad * r);
        let near = k.x - dx;
        if !(near > 1e-6 * k.max_abs()) {
            return None;
        }
        let (u, v) = (k.y / k.x, k.z / k.x);
        Some(([u, v], [(dy + u.abs() * dx) / near, (dz + v.abs() * dx) / near]))
    }
}

/// Largest size of an edge's `a` and `b`: with window coordinates within 2^15 units, each of
/// `a u` and `b v` stays within 2^29 and their sum within `i32`.
const NORMAL: f64 = (1 << 14) as f64;
/// How far (in the hull's units, along each edge's normal of size 1) a hull is widened beyond
/// the image of the padded box ([`EyeHull`]).
const MARGIN: f64 = 1.0;

/// The [`EyeHull`] of an object seen through `projection`: the hull of its box's eight corners'
/// images gives the edges' directions, and each edge's bound is the largest it takes over the
/// images of the box padded by `pad` on every side (the padded box is the hull of the cubes of
/// side `2 pad` around its corners, and each cube's image lies within a rectangle around its
/// corner's, [`Projection::window_within`]), widened by [`MARGIN`]. [`NO_HULL`] if a padded
/// corner can lie on or behind the eye's plane.
pub(crate) fn eye_hull<R: Real>(o: &Object<R>, projection: &Projection, pad: f64) -> EyeHull {
    // The box's corners' images, by linearity: the image of its lowest corner plus, per axis
    // where a corner lies high, the image of that edge (no point mapped eight times over).
    let place = o.to_world().cast::<f64>();
    let (lo, hi) = o.shape.bounds();
    let (lo, hi) = (lo.cast::<f64>(), hi.cast::<f64>());
    let base = projection.image(place.point(lo));
    let m = &place.m;
    let edge = |i: usize, len: f64| projection.from_eye.vector(Vec3::new(m[0][i], m[1][i], m[2][i]) * len);
    let edges = [edge(0, hi.x - lo.x), edge(1, hi.y - lo.y), edge(2, hi.z - lo.z)];
    // Each corner's window position, and the rectangle (in the hull's units) that the
    // positions of the points within `pad` of the corner on every axis lie in.
    let mut images = [[0.0; 2]; 8];
    let mut spans = [[[0.0; 2]; 2]; 8];
    let scale = f64::from(1u32 << 10);
    // The largest `|u|` and `|v|` and the smallest `k.x` of the corners: bounds for every
    // point of the box, for the padding of a curved shape's outline.
    let (mut wide, mut nearest) = ([0.0f64; 2], f64::MAX);
    for c in 0..8 {
        let k = (0..3).filter(|&i| c & (1 << i) != 0).fold(base, |k, i| k + edges[i]);
        let Some((w, d)) = projection.window_within(k, pad) else { return NO_HULL };
        images[c] = w;
        spans[c] = [[(w[0] - d[0]) * scale, (w[0] + d[0]) * scale], [(w[1] - d[1]) * scale, (w[1] + d[1]) * scale]];
        (wide, nearest) = ([wide[0].max(w[0].abs()), wide[1].max(w[1].abs())], nearest.min(k.x));
    }
    // A sphere, cylinder or cone shows within its outline's discs' images, tighter than its
    // box's; a point within `pad` of one moves its image by at most `moves` along `u` and `v`.
    let discs = outline_discs(o, &place, projection);
    let [dx, dy, dz] = projection.rows.map(|r| pad * r);
    let moves = [(dy + wide[0] * dx) / (nearest - dx), (dz + wide[1] * dx) / (nearest - dx)];
    let mut hull = NO_HULL;
    let (ring, n) = convex_hull(images);
    // Past [`HULL_EDGES`] edges (only rounding makes more) the further ones are left out,
    // which only culls less.
    for (k, edge) in hull.iter_mut().enumerate().take(n) {
        let (p, q) = (ring[k], ring[(k + 1) % n]);
        // Outward normal of a counter-clockwise ring's edge, scaled so its larger part is 2^14.
        let (nx, ny) = (q[1] - p[1], p[0] - q[0]);
        let size = nx.abs().max(ny.abs());
        if !(size > 0.0) {
            continue;
        }
        let (a, b) = (libm::round(nx / size * NORMAL), libm::round(ny / size * NORMAL));
        // Over each corner's rectangle the edge's `a u + b v` is largest at the corner its
        // normal points to.
        let (i, j) = (usize::from(a > 0.0), usize::from(b > 0.0));
        let mut far = spans.iter().map(|s| a * s[0][i] + b * s[1][j]).fold(f64::MIN, f64::max);
        // The discs' largest support, if each disc has one (a box has no discs: none).
        let mut round = None;
        for d in discs.iter().flatten() {
            round = match disc_support(d, a, b) {
                Some(h) => Some(round.map_or(h, |m: f64| m.max(h))),
                None => {
                    round = None;
                    break;
                }
            };
        }
        if let Some(h) = round {
            far = far.min((h + a.abs() * moves[0] + b.abs() * moves[1]) * scale);
        }
        let c = libm::ceil(far + MARGIN * (a.abs() + b.abs())) + 1.0;
        // An edge whose bound leaves `i32` culls nothing; one far below only widens to -2^30.
        *edge = if c < (1u32 << 30) as f64 {
            HullEdge { a: a as i16, b: b as i16, c: c.max(-((1u32 << 30) as f64)) as i32 }
        } else {
            HullEdge::EVERYWHERE
        };
    }
    hull
}

/// A disc (filled ellipse) in window space: the images ([`Projection::image`]) of its centre
/// and of two of its radii at right angles, `k(t) = centre + p cos t + q sin t` on its rim.
type Disc = [Vec3<f64>; 3];

/// The discs whose hull holds a round shape, as the eye sees it: a cylinder's or cone's two
/// caps (the cone's top a point when it is pointed), a sphere's outline (where the eye's rays
/// graze it: a circle, in object space, about the line from its centre to the eye); none for a
/// box, or an eye inside the sphere.
fn outline_discs<R: Real>(o: &Object<R>, place: &Affine<f64>, projection: &Projection) -> [Option<Disc>; 2] {
    let disc = |c: Vec3<f64>, p: Vec3<f64>, q: Vec3<f64>| {
        let at = place.point(c);
        Some([
            projection.image(at),
            projection.from_eye.vector(place.point(c + p) - at),
            projection.from_eye.vector(place.point(c + q) - at),
        ])
    };
    let (x, z) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
    match o.shape {
        Shape::Box | Shape::Triangle => [None, None],
        Shape::Cylinder => [disc(Vec3::new(0.0, 0.0, 0.0), x, z), disc(Vec3::new(0.0, 1.0, 0.0), x, z)],
        Shape::Cone { top } | Shape::Open { top } => {
            let top = top.to_f64();
            [disc(Vec3::new(0.0, 0.0, 0.0), x, z), disc(Vec3::new(0.0, 1.0, 0.0), x * top, z * top)]
        }
        Shape::Sphere => {
            let Some(eye) = place.inverse().map(|inv| inv.point(projection.eye)) else { return [None, None] };
            let d2 = eye.dot(eye);
            if !(d2 > 1.0 + 1e-6) {
                return [None, None];
            }
            // Two unit vectors at right angles to the eye's direction, and the circle's radius.
            let helper = if eye.x.abs() < 0.6 * libm::sqrt(d2) { x } else { Vec3::new(0.0, 1.0, 0.0) };
            let p = eye.cross(helper).normalize();
            let q = eye.cross(p).normalize();
            let r = libm::sqrt(1.0 - 1.0 / d2);
            [disc(eye * (1.0 / d2), p * r, q * r), None]
        }
    }
}

/// The largest `a u + b v` over a disc's image (`u`, `v` its points' window positions), or
/// `None` if the disc comes near the eye's plane. Along its rim the value is a ratio of two
/// sinusoids, `(α0 + α1 cos t + α2 sin t) / (β0 + β1 cos t + β2 sin t)`; it reaches `h` where
/// `α - h β` just touches 0: `(α0 - h β0)^2 = (α1 - h β1)^2 + (α2 - h β2)^2`, a quadratic in `h`
/// whose larger root is the largest value.
fn disc_support(d: &Disc, a: f64, b: f64) -> Option<f64> {
    let al = d.map(|k| a * k.y + b * k.z);
    let be = d.map(|k| k.x);
    let qa = be[0] * be[0] - be[1] * be[1] - be[2] * be[2];
    if !(be[0] > 0.0 && qa > 1e-6 * be[0] * be[0]) {
        return None;
    }
    let qb = -2.0 * (al[0] * be[0] - al[1] * be[1] - al[2] * be[2]);
    let qc = al[0] * al[0] - al[1] * al[1] - al[2] * al[2];
    let h = (-qb + libm::sqrt((qb * qb - 4.0 * qa * qc).max(0.0))) / (2.0 * qa);
    // The rounding of these sums, far inside the hull's margin, added all the same.
    h.is_finite().then(|| h + 1e-9 * (h.abs() + a.abs() + b.abs()))
}

/// The convex hull of eight points: its corners counter-clockwise, and how many there are.
pub(crate) fn convex_hull(mut points: [[f64; 2]; 8]) -> ([[f64; 2]; 16], usize) {
    points.sort_unstable_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    // Andrew's monotone chain: the lower hull left to right, then the upper right to left.
    let (mut ring, mut n) = ([[0.0; 2]; 16], 0);
    for pass in 0..2 {
        let start = n;
        for i in 0..8 {
            let p = points[if pass == 0 { i } else { 7 - i }];
            while n >= start + 2 && cross(ring[n - 2], ring[n - 1], p) <= 0.0 {
                n -= 1;
            }
            ring[n] = p;
            n += 1;
        }
        // The last point of each chain is the first of the other.
        n -= 1;
    }
    (ring, n)
}
