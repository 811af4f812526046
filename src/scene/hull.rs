//! Eye hulls: where on the image an object can appear, more tightly than its eye window.
//!
//! An [`EyeWindow`](super::EyeWindow) is the rectangle around an object's padded box as the eye
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
//!
//! [`behind`] answers the other half of two-level sampling's question, whether a block of
//! pixels whose corners hit one object may be filled: which of the objects that can appear
//! there that object hides all over the block.

#[cfg(feature = "eye-hulls")]
use super::model::Object;
use super::model::{any_object, Camera, Scene};
use crate::math::Aabb;
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
#[cfg(feature = "eye-hulls")]
use crate::shape::Shape;

/// Edges an [`EyeHull`] keeps: the image of a box seen from outside has at most six.
pub const HULL_EDGES: usize = 6;

/// Where on the image an object can appear: up to [`HULL_EDGES`] half-planes `a u + b v <= c`,
/// each `[a, b, c]`, in units of 2^-10 of the camera's window coordinates `u` and `v` (each
/// running -1..1 across the image), `a` and `b` at most 2^14 in size. Their intersection holds
/// the image of the object's padded box widened by 2^-10 (a 16th of a pixel of a 128-pixel-wide
/// image, 32 times the rounding of a fixed-point eye ray's direction; an eye window is widened
/// 16 times more, [`EYE_MARGIN`](super::EYE_MARGIN)); an edge that culls nothing is
/// `[0, 0, i32::MAX]` ([`NO_HULL`]).
pub type EyeHull = [[i32; 3]; HULL_EDGES];

/// The hull that culls nothing: for an object whose box is not wholly in front of the eye.
pub const NO_HULL: EyeHull = [[0, 0, i32::MAX]; HULL_EDGES];

/// Largest size of an edge's `a` and `b`: with window coordinates within 2^15 units, each of
/// `a u` and `b v` stays within 2^29 and their sum within `i32`.
#[cfg(feature = "eye-hulls")]
const NORMAL: f64 = (1 << 14) as f64;
/// Window coordinates are taken within 2^15 units of 2^-10 (32 times the image's half-width):
/// every tile's and pixel's lies well within.
const REACH: i32 = 1 << 21;
/// 2^-16 units (an [`EyeWindow`](super::EyeWindow)'s) per unit of the hull's 2^-10.
const SHIFT: u32 = 6;
/// How far (in the hull's units, along each edge's normal of size 1) a hull is widened beyond
/// the image of the padded box ([`EyeHull`]).
#[cfg(feature = "eye-hulls")]
const MARGIN: f64 = 1.0;

/// Whether the window rectangle `u` x `v` (2^-16 units, inclusive bounds, as an
/// [`EyeWindow`](super::EyeWindow) takes it) meets the hull: no edge has the whole rectangle
/// outside. The rectangle is rounded outwards to the hull's units.
#[inline]
pub fn hull_meets(hull: &EyeHull, u: [i32; 2], v: [i32; 2]) -> bool {
    let below = |x: i32| x.clamp(-REACH, REACH) >> SHIFT;
    let above = |x: i32| (x.clamp(-REACH, REACH) + (1 << SHIFT) - 1) >> SHIFT;
    let (u0, u1, v0, v1) = (below(u[0]), above(u[1]), below(v[0]), above(v[1]));
    // Each edge's smallest `a u + b v` over the rectangle is at the corner its normal points
    // away from.
    hull.iter().all(|&[a, b, c]| a * if a > 0 { u0 } else { u1 } + b * if b > 0 { v0 } else { v1 } <= c)
}

/// Depth-key steps (about 0.05 % each in fixed point, 1 % in floats) by which an object's
/// nearest possible hit must lie beyond the farthest of a block's corner hits for [`behind`] to
/// count it hidden: far more than the rounding of either.
const BEHIND_SLACK: u16 = 4;

/// The objects of `among` (bit `i`: object `i`, of the first 64) that no eye ray of a block of
/// pixels can see, because object `front` lies in front of them all over the block: the rays
/// through the block's corner pixels hit `front`, the farthest at depth key `far`
/// ([`Real::depth_key`]), and every ray of the block has a direction whose component `k` lies
/// in `dirs[k]` (the smallest and the largest). `front` is convex and the eye lies outside it,
/// so every ray between the corners hits it too, at most as far as the farthest corner (along
/// the ray through `(u, v)` the reciprocal of the entry parameter is concave in `(u, v)`); an
/// object whose box none of those rays can reach before that is hidden. None when the eye lies
/// in `front`'s box, or `front` is no object.
pub fn behind<R: Real>(scene: &Scene<'_, R>, among: u64, front: usize, far: u16, dirs: &[[R; 2]; 3]) -> u64 {
    let eye = scene.camera.eye;
    let Some(f) = scene.objects.get(front) else { return 0 };
    let inside = |lo: R, x: R, hi: R| lo <= x && x <= hi;
    if inside(f.bounds.min.x, eye.x, f.bounds.max.x)
        && inside(f.bounds.min.y, eye.y, f.bounds.max.y)
        && inside(f.bounds.min.z, eye.z, f.bounds.max.z)
    {
        return 0;
    }
    // Beyond every parameter whose key is within the slack of the farthest corner's.
    let beyond = R::key_bound(far.saturating_add(BEHIND_SLACK));
    let mut hidden = 0;
    any_object(among, scene.objects.len(), |i| {
        if scene.objects.get(i).is_some_and(|o| beyond_reach(&o.bounds, eye, dirs, beyond)) {
            hidden |= 1 << i;
        }
        false
    });
    hidden
}

/// Per component, the smallest and the largest direction `forward + right u + up v` of the eye
/// rays with `u` and `v` between the given ones (as [`Camera::ray_through`] sums them: at the
/// corners, since each product rounds monotonically), for [`behind`].
pub fn block_directions<R: Real>(cam: &Camera<R>, u: [R; 2], v: [R; 2]) -> [[R; 2]; 3] {
    let span = |f: R, r: R, up: R| {
        let (a, b, c, d) = (r * u[0], r * u[1], up * v[0], up * v[1]);
        [f + a.min(b) + c.min(d), f + a.max(b) + c.max(d)]
    };
    [
        span(cam.forward.x, cam.right.x, cam.up.x),
        span(cam.forward.y, cam.right.y, cam.up.y),
        span(cam.forward.z, cam.right.z, cam.up.z),
    ]
}

/// Whether no eye ray from `eye` whose direction's components lie in `dirs` meets box `b` at a
/// parameter below `t`: on some axis whose slab the eye lies outside, the gap to the slab is at
/// least `t` times the largest step towards it (or no ray heads towards it).
fn beyond_reach<R: Real>(b: &Aabb<R>, eye: Vec3<R>, dirs: &[[R; 2]; 3], t: R) -> bool {
    (0..3).any(|k| {
        let (e, lo, hi) = (eye.axis(k), b.min.axis(k), b.max.axis(k));
        let (gap, step) = if e > hi {
            (e - hi, -dirs[k][0])
        } else if e < lo {
            (lo - e, dirs[k][1])
        } else {
            return false;
        };
        step <= R::ZERO || gap >= t * step
    })
}

/// The window position `(u, v)` of world points as eye rays reach them, in `f64`: a point `p`
/// lies on the eye ray `eye + s (forward + u right + v up)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Projection {
    eye: Vec3<f64>,
    from_eye: Affine<f64>,
    /// Per row of `from_eye`, the sum of its entries' magnitudes.
    #[cfg(feature = "eye-hulls")]
    rows: [f64; 3],
}

impl Projection {
    /// The projection of `cam` (from its vectors as the scalar holds them), or `None` if they
    /// span no volume.
    pub(crate) fn new<R: Real>(cam: &Camera<R>) -> Option<Self> {
        let (f, r, u) = (cam.forward.cast::<f64>(), cam.right.cast::<f64>(), cam.up.cast::<f64>());
        // Columns forward, right, up: a direction's coordinates (s, s u, s v) along them.
        let to_window = Affine { m: [[f.x, r.x, u.x, 0.0], [f.y, r.y, u.y, 0.0], [f.z, r.z, u.z, 0.0]] };
        let from_eye = to_window.inverse()?;
        Some(Projection {
            eye: cam.eye.cast(),
            from_eye,
            #[cfg(feature = "eye-hulls")]
            rows: from_eye.m.map(|r| r[0].abs() + r[1].abs() + r[2].abs()),
        })
    }

    /// `p`'s window position, or `None` for a point on or behind the eye's plane (whose
    /// image is unbounded).
    pub(crate) fn window(&self, p: Vec3<f64>) -> Option<[f64; 2]> {
        let k = self.from_eye.vector(p - self.eye);
        (k.x > 1e-6 * (p - self.eye).max_abs()).then(|| [k.y / k.x, k.z / k.x])
    }

    /// The window-space image `F (p - eye)` of a point `p` (`F` the map to the window's
    /// coordinates: a point's image `k` lies on the eye ray through `(k.y / k.x, k.z / k.x)`).
    #[cfg(feature = "eye-hulls")]
    fn image(&self, p: Vec3<f64>) -> Vec3<f64> {
        self.from_eye.vector(p - self.eye)
    }

    /// The window position `(u, v)` of a point whose image is `k` ([`Projection::image`]),
    /// and how far from it along `u` and `v` the window position of any point within `pad` of
    /// it on every axis can lie; `None` if such a point can lie on or behind the eye's plane. A
    /// move `d` of the point moves `k` by `F d`, each part at most `pad` times its row's sum of
    /// magnitudes, and `u = k.y / k.x` by at most `(|F d|.y + |u| |F d|.x) / (k.x - |F d|.x)`;
    /// likewise `v`.
    #[cfg(feature = "eye-hulls")]
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

/// The [`EyeHull`] of an object seen through `projection`: the hull of its box's eight corners'
/// images gives the edges' directions, and each edge's bound is the largest it takes over the
/// images of the box padded by `pad` on every side (the padded box is the hull of the cubes of
/// side `2 pad` around its corners, and each cube's image lies within a rectangle around its
/// corner's, [`Projection::window_within`]), widened by [`MARGIN`]. [`NO_HULL`] if a padded
/// corner can lie on or behind the eye's plane.
#[cfg(feature = "eye-hulls")]
pub(crate) fn eye_hull<R: Real>(o: &Object<R>, projection: &Projection, pad: f64) -> EyeHull {
    // The box's corners' images, by linearity: the image of its lowest corner plus, per axis
    // where a corner lies high, the image of that edge (no point mapped eight times over).
    let place = o.to_world.cast::<f64>();
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
            [a as i32, b as i32, c.max(-((1u32 << 30) as f64)) as i32]
        } else {
            NO_HULL[0]
        };
    }
    hull
}

/// A disc (filled ellipse) in window space: the images ([`Projection::image`]) of its centre
/// and of two of its radii at right angles, `k(t) = centre + p cos t + q sin t` on its rim.
#[cfg(feature = "eye-hulls")]
type Disc = [Vec3<f64>; 3];

/// The discs whose hull holds a round shape, as the eye sees it: a cylinder's or cone's two
/// caps (the cone's top a point when it is pointed), a sphere's outline (where the eye's rays
/// graze it: a circle, in object space, about the line from its centre to the eye); none for a
/// box, or an eye inside the sphere.
#[cfg(feature = "eye-hulls")]
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
        Shape::Box => [None, None],
        Shape::Cylinder => [disc(Vec3::new(0.0, 0.0, 0.0), x, z), disc(Vec3::new(0.0, 1.0, 0.0), x, z)],
        Shape::Cone { top } => {
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
#[cfg(feature = "eye-hulls")]
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
#[cfg(feature = "eye-hulls")]
fn convex_hull(mut points: [[f64; 2]; 8]) -> ([[f64; 2]; 16], usize) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Object, Parts, SceneBuilder};

    /// `each` over the paper's five scenes in scalar `R`, with the scene's name: the sum of what
    /// it counted.
    fn over_paper<R: Real>(mut each: impl FnMut(&Scene<'_, R>, &str) -> usize) -> usize {
        let mut sum = 0;
        for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
            let text =
                std::fs::read_to_string(std::format!("{}/scenes/{name}.scene", env!("CARGO_MANIFEST_DIR"))).unwrap();
            let (mut storage, mut parts) = (std::vec![Object::<R>::default(); 64], Parts::default());
            let scene = crate::parse::<R>(&text, &mut storage, &mut parts).unwrap();
            sum += each(&scene, name);
        }
        sum
    }

    /// `each` over generated scenes of turned, sheared and scaled objects (eight seeds) in fixed
    /// point, seen from far off and from among them, with what names each: how many scenes were
    /// built, and the sum of what `each` counted.
    fn over_generated(mut each: impl FnMut(&Scene<'_, crate::Fx>, &str) -> usize) -> (usize, usize) {
        let (mut built, mut sum) = (0, 0);
        for seed in 0..8u64 {
            for (eye, look) in [((0.0, 2.0, -30.0), (0.0, 0.0, 0.0)), ((3.0, 4.0, 3.0), (6.0, 5.0, 9.0))] {
                let (mut storage, mut parts) = (std::vec![Object::<crate::Fx>::default(); 24], Parts::default());
                let mut b = SceneBuilder::new(&mut storage, &mut parts);
                crate::generate::random_scene(
                    &mut b,
                    &crate::generate::RandomScene { objects: 24, composite_size: 3, spread: 12.0, seed },
                )
                .unwrap();
                b.camera.eye = Vec3::new(eye.0, eye.1, eye.2);
                b.camera.look = Vec3::new(look.0, look.1, look.2);
                b.camera.fov = crate::scene::FieldOfView::Within(70.0, 50.0);
                let Ok(scene) = b.finish() else { continue };
                built += 1;
                sum += each(&scene, &std::format!("seed {seed}, eye {eye:?}"));
            }
        }
        (built, sum)
    }

    /// A square's hull test: rectangles inside, across an edge, and wholly outside one edge.
    #[test]
    fn a_rectangle_outside_an_edge_is_culled() {
        // The diamond |u| + |v| <= 1 (units of 2^-10: 1024), as four edges with a, b = 2^14.
        let n = 1 << 14;
        let mut hull = NO_HULL;
        for (k, (a, b)) in [(n, n), (-n, n), (-n, -n), (n, -n)].into_iter().enumerate() {
            hull[k] = [a, b, n * 1024];
        }
        let unit = 1 << 16;
        assert!(hull_meets(&hull, [0, 0], [0, 0]));
        assert!(hull_meets(&hull, [unit / 4, unit], [unit / 4, unit]));
        // The corner square beyond the edge u + v = 1.
        assert!(!hull_meets(&hull, [unit * 3 / 5, unit], [unit * 3 / 5, unit]));
        assert!(!hull_meets(&hull, [-unit, -unit * 3 / 5], [-unit, -unit * 3 / 5]));
        assert!(hull_meets(&NO_HULL, [i32::MIN, i32::MIN], [i32::MAX, i32::MAX]));
    }

    /// Just outside each edge of every object's hull (one unit of 2^-10 beyond it, all along
    /// the edge within the object's eye window) no eye ray hits the object, in every scalar:
    /// on the paper's scenes, and on generated scenes of turned, sheared and scaled objects
    /// seen from far off and from among them.
    #[cfg(feature = "eye-hulls")]
    #[test]
    fn no_eye_ray_just_outside_a_hull_edge_hits_the_object() {
        fn along_edges<R: Real>(objects: &[Object<R>], cam: &Camera<R>, what: &str, every_object: bool) -> usize {
            let mut rays = 0;
            for (i, o) in objects.iter().enumerate() {
                let w = o.eye_window;
                // A hull's edges touch the padded object's image, which lies in its window: the
                // walks along them find points there (an edge may pass outside the window
                // where the window is the tighter bound; for an object seen well in front of
                // the eye, as in the paper's scenes, not every edge).
                let before = rays;
                let edges = o.eye_hull.iter().filter(|e| e[2] != i32::MAX).count();
                for &[a, b, c] in o.eye_hull.iter().filter(|e| e[2] != i32::MAX) {
                    let (a, b) = (f64::from(a), f64::from(b));
                    let n2 = a * a + b * b;
                    // The foot of the line a U + b V = c + 1 (units of 2^-10), and its direction.
                    let foot = [a * (f64::from(c) + 1.0) / n2, b * (f64::from(c) + 1.0) / n2];
                    let along = [-b / n2.sqrt(), a / n2.sqrt()];
                    for k in -4000..=4000 {
                        let s = f64::from(k) * 2.0;
                        let (u, v) = ((foot[0] + s * along[0]) / 1024.0, (foot[1] + s * along[1]) / 1024.0);
                        let inside =
                            |x: f64, lo: i32, hi: i32| x * 65536.0 >= f64::from(lo) && x * 65536.0 <= f64::from(hi);
                        if !(inside(u, w[0], w[1]) && inside(v, w[2], w[3])) {
                            continue;
                        }
                        rays += 1;
                        let ray = cam.ray_through(R::from_f64(u), R::from_f64(v));
                        assert!(
                            o.intersect(&ray, R::ZERO, R::MAX).is_none(),
                            "{what}, {}: object {i} hit at ({u}, {v}), outside its hull edge {a} u + {b} v <= {c}",
                            R::NAME
                        );
                    }
                }
                assert!(
                    !every_object || edges == 0 || rays > before,
                    "{what}, {}: object {i}'s hull edges all miss its window {w:?}: {:?}",
                    R::NAME,
                    o.eye_hull
                );
            }
            rays
        }
        // On the paper's scenes, objects seen well in front of the eye: every object's hull is checked
        // to meet its window.
        fn paper<R: Real>(scene: &Scene<'_, R>, name: &str) -> usize {
            along_edges(scene.objects(), scene.camera(), name, true)
        }
        for rays in [over_paper::<f64>(paper), over_paper::<f32>(paper), over_paper::<crate::Fx>(paper)] {
            assert!(rays > 10_000, "{rays} rays along the hulls' edges");
        }
        let (built, _) = over_generated(|s, what| along_edges(s.objects(), s.camera(), what, false));
        assert!(built >= 10, "{built} generated scenes");
    }

    /// Over every block of pixels whose corner rays hit one object, no pixel's eye ray sees an
    /// object [`behind`] counts hidden there, in every scalar, on the paper's scenes and on
    /// generated ones; and some objects are counted hidden, so the check is not empty.
    #[test]
    fn objects_behind_a_block_s_object_show_in_none_of_its_pixels() {
        use crate::{BruteForce, Query, Tracer};
        fn blocks<R: Real>(scene: &Scene<'_, R>, what: &str) -> usize {
            let (w, h) = (64usize, 32usize);
            let (w4, h4) = (4 * w as i32, 4 * h as i32);
            let tracer = Tracer::new(scene, &BruteForce);
            let mut mailbox = std::vec![0; Query::mailbox_len(scene)];
            let mut q = Query::new(&mut mailbox);
            let centre = |p: usize| 4 * p as i32 + 2;
            let mut hit = |x: usize, y: usize| {
                let ray = scene.camera().ray(centre(x), centre(y), w4, h4);
                q.set_eye_ray(None);
                let (id, t) = tracer.eye_hit(ray, &mut q);
                (id, if id == crate::trace::NO_OBJECT { u16::MAX } else { t.depth_key() })
            };
            let pixels: std::vec::Vec<(u32, u16)> =
                (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| hit(x, y)).collect();
            let all = if scene.objects().len() >= 64 { u64::MAX } else { (1u64 << scene.objects().len()) - 1 };
            let mut counted = 0;
            for size in [2usize, 4] {
                for y0 in 0..h - size {
                    for x0 in 0..w - size {
                        let (xs, ys) = ([x0, x0 + size], [y0, y0 + size]);
                        let corners = [(xs[0], ys[0]), (xs[1], ys[0]), (xs[0], ys[1]), (xs[1], ys[1])]
                            .map(|(x, y)| pixels[y * w + x]);
                        let id = corners[0].0;
                        if id == crate::trace::NO_OBJECT || corners.iter().any(|c| c.0 != id) {
                            continue;
                        }
                        let far = corners.iter().map(|c| c.1).max().unwrap();
                        let us = [Camera::<R>::ray_u(centre(xs[0]), w4), Camera::<R>::ray_u(centre(xs[1]), w4)];
                        let vs = [Camera::<R>::ray_v(centre(ys[0]), h4), Camera::<R>::ray_v(centre(ys[1]), h4)];
                        let hidden = behind(
                            scene,
                            all & !(1 << id),
                            id as usize,
                            far,
                            &block_directions(scene.camera(), us, vs),
                        );
                        counted += hidden.count_ones() as usize;
                        for y in ys[0]..=ys[1] {
                            for x in xs[0]..=xs[1] {
                                let seen = pixels[y * w + x].0;
                                assert!(seen == crate::trace::NO_OBJECT || hidden & (1 << seen) == 0, "{what}, {}: object {seen} counted hidden behind {id} over ({x0}, {y0}) + {size} shows at ({x}, {y})", R::NAME);
                            }
                        }
                    }
                }
            }
            counted
        }
        for counted in [over_paper::<f64>(blocks), over_paper::<f32>(blocks), over_paper::<crate::Fx>(blocks)] {
            assert!(counted > 1000, "{counted} objects counted hidden");
        }
        let (_, counted) = over_generated(blocks);
        assert!(counted > 0, "no object counted hidden in the generated scenes");
    }

    /// The hull of a square's corners and four points inside is the square, counter-clockwise.
    #[cfg(feature = "eye-hulls")]
    #[test]
    fn the_hull_of_eight_points_is_their_outer_ring() {
        let pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [0.2, 0.7], [0.9, 0.1], [0.5, 0.0]];
        let (ring, n) = convex_hull(pts);
        assert_eq!(&ring[..n], &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    }
}
