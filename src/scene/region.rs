//! Regions: where an object can appear, as each kind of ray sees it. An eye ray's window
//! position is tested against the object's [`EyeWindow`] (a rectangle) and [`EyeHull`] (a
//! convex polygon); a shadow ray towards a directional first light is tested by its position
//! across the light against the object's [`ShadowWindow`]. A ray outside cannot hit the object,
//! so its exact test is skipped. An object holds its three as one [`Region`].

use crate::scalar::Real;

/// Where on the image an object can appear: `[u_lo, u_hi, v_lo, v_hi]` in units of 2^-16 of
/// the camera's window coordinates `u` and `v` (each running -1..1 across the image, as in
/// [`crate::camera::Camera::ray`]), from its padded box's corners projected through the eye and widened by
/// [`EYE_MARGIN`]. An eye ray whose `(u, v)` lies outside cannot hit the object, so its exact
/// test is skipped: the picture is the same, the work less. A box not wholly in front of the
/// eye gets the whole plane.
pub type EyeWindow = [i32; 4];

/// The window that culls nothing.
pub const WHOLE_PLANE: EyeWindow = [i32::MIN, i32::MAX, i32::MIN, i32::MAX];

/// How far (in 2^-16 units of `u`, `v`) an eye window is widened beyond the projected box:
/// 2^-6, about one pixel of a 128-pixel-wide image and hundreds of times the rounding of any
/// scalar's eye-ray direction.
pub const EYE_MARGIN: i32 = 1 << 10;

/// An eye ray passes outside an object's [`EyeWindow`]: it cannot hit the object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Culled;

/// Where shadow rays towards the scene's first light (when it is directional, so its rays are
/// parallel) can meet an object: `[a_lo, a_hi, b_lo, b_hi]`, the object's padded box projected
/// along the light onto the plane of `Scene::shadow_basis`, widened by the rounding of that
/// projection. A shadow ray whose origin projects outside cannot hit the object.
pub type ShadowWindow<R> = [R; 4];

/// The shadow window that culls nothing.
pub fn shadow_whole_plane<R: Real>() -> ShadowWindow<R> {
    [-R::MAX, R::MAX, -R::MAX, R::MAX]
}

/// Edges an [`EyeHull`] keeps: the image of a box seen from outside has at most six.
pub const HULL_EDGES: usize = 6;

/// Where on the image an object can appear: up to [`HULL_EDGES`] half-planes ([`HullEdge`]s)
/// in units of 2^-10 of the camera's window coordinates `u` and `v` (each running -1..1 across
/// the image). Their intersection holds the image of the object's padded box widened by 2^-10
/// (a 16th of a pixel of a 128-pixel-wide image, 32 times the rounding of a fixed-point eye
/// ray's direction; an eye window is widened 16 times more, [`EYE_MARGIN`]); an edge that culls
/// nothing is [`HullEdge::EVERYWHERE`] ([`NO_HULL`]).
pub type EyeHull = [HullEdge; HULL_EDGES];

/// One edge of an [`EyeHull`]: the half-plane `a u + b v <= c`. Its normal `(a, b)` is scaled
/// so its larger part is 2^14, so it is kept in 16 bits (8 bytes an edge instead of 12: a
/// baked scene of thousands of objects keeps 24 bytes less per object in flash).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HullEdge {
    /// The normal's `u` part, at most 2^14 in size.
    pub a: i16,
    /// The normal's `v` part, at most 2^14 in size.
    pub b: i16,
    /// The bound.
    pub c: i32,
}

impl HullEdge {
    /// The edge that culls nothing.
    pub const EVERYWHERE: HullEdge = HullEdge::new(0, 0, i32::MAX);

    /// The half-plane `a u + b v <= c` (as baked tables write it).
    pub const fn new(a: i16, b: i16, c: i32) -> Self {
        HullEdge { a, b, c }
    }

    /// Whether the edge culls nothing.
    pub fn is_everywhere(&self) -> bool {
        self.c == i32::MAX
    }
}

/// The hull that culls nothing: for an object whose box is not wholly in front of the eye.
pub const NO_HULL: EyeHull = [HullEdge::EVERYWHERE; HULL_EDGES];

/// Window coordinates are taken within 2^15 units of 2^-10 (32 times the image's half-width):
/// every tile's and pixel's lies well within.
const REACH: i32 = 1 << 21;

/// 2^-16 units (an [`EyeWindow`]'s) per unit of the hull's 2^-10.
const SHIFT: u32 = 6;

/// Whether the window rectangle `u` x `v` (2^-16 units, inclusive bounds, as an
/// [`EyeWindow`] takes it) meets the hull: no edge has the whole rectangle
/// outside. The rectangle is rounded outwards to the hull's units.
#[inline]
pub fn hull_meets(hull: &EyeHull, u: [i32; 2], v: [i32; 2]) -> bool {
    let below = |x: i32| x.clamp(-REACH, REACH) >> SHIFT;
    let above = |x: i32| (x.clamp(-REACH, REACH) + (1 << SHIFT) - 1) >> SHIFT;
    let (u0, u1, v0, v1) = (below(u[0]), above(u[1]), below(v[0]), above(v[1]));
    // Each edge's smallest `a u + b v` over the rectangle is at the corner its normal points
    // away from.
    hull.iter().all(|e| {
        let (a, b) = (i32::from(e.a), i32::from(e.b));
        a * if a > 0 { u0 } else { u1 } + b * if b > 0 { v0 } else { v1 } <= e.c
    })
}

/// An object's regions, one per kind of ray that culling tests: it can be hit only by an eye
/// ray through its eye window (and, with the `eye-hulls` feature, its eye hull), and only by a
/// shadow ray towards a directional first light through its shadow window (not kept with
/// `lean-objects`, whose records leave out what serves only the eye's and a directional first
/// light's rays: such a shadow ray then takes the exact test, with the same answer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region<R> {
    /// The part of the image the object can appear in, as an [`EyeWindow`].
    pub(crate) eye_window: EyeWindow,
    /// The same part more tightly, as an [`EyeHull`] (with the `eye-hulls` feature).
    #[cfg(feature = "eye-hulls")]
    pub(crate) eye_hull: EyeHull,
    /// Where a shadow ray towards the scene's first light can meet it, as a [`ShadowWindow`].
    #[cfg(not(feature = "lean-objects"))]
    pub(crate) shadow_window: ShadowWindow<R>,
    /// Without the shadow window, the scalar the region is in.
    #[cfg(feature = "lean-objects")]
    pub(crate) scalar: core::marker::PhantomData<R>,
}

impl<R> Region<R> {
    /// A region from its parts, as [`bake::source`](crate::bake) writes them (a build without
    /// the `eye-hulls` feature drops the hull, one with `lean-objects` the shadow window).
    pub const fn from_tables(eye_window: EyeWindow, eye_hull: EyeHull, shadow_window: ShadowWindow<R>) -> Self {
        #[cfg(not(feature = "eye-hulls"))]
        let _ = eye_hull;
        // Not kept (a const fn cannot drop a generic value: it forgets it).
        #[cfg(feature = "lean-objects")]
        core::mem::forget(shadow_window);
        Region {
            eye_window,
            #[cfg(feature = "eye-hulls")]
            eye_hull,
            #[cfg(not(feature = "lean-objects"))]
            shadow_window,
            #[cfg(feature = "lean-objects")]
            scalar: core::marker::PhantomData,
        }
    }
    /// The eye window.
    pub fn eye_window(&self) -> &EyeWindow {
        &self.eye_window
    }
    /// The eye hull ([`NO_HULL`] in a build without the `eye-hulls` feature).
    pub fn eye_hull(&self) -> &EyeHull {
        #[cfg(feature = "eye-hulls")]
        return &self.eye_hull;
        #[cfg(not(feature = "eye-hulls"))]
        return &NO_HULL;
    }
    /// Whether the eye window meets the window rectangle `u` x `v` (2^-16 units, inclusive
    /// bounds, see [`EyeWindow`]).
    #[inline]
    pub fn eye_window_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        let w = &self.eye_window;
        w[0] <= u[1] && u[0] <= w[1] && w[2] <= v[1] && v[0] <= w[3]
    }
    /// Whether the object can appear in the window rectangle `u` x `v`: its eye window meets
    /// it, and so does its eye hull where the build keeps one.
    #[inline]
    pub fn eye_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        #[cfg(feature = "eye-hulls")]
        return self.eye_window_meets(u, v) && hull_meets(&self.eye_hull, u, v);
        #[cfg(not(feature = "eye-hulls"))]
        return self.eye_window_meets(u, v);
    }
}

impl<R: Real> Region<R> {
    /// The region that culls nothing.
    pub fn everywhere() -> Self {
        Region::from_tables(WHOLE_PLANE, NO_HULL, shadow_whole_plane())
    }
    /// The shadow window ([`shadow_whole_plane`] with `lean-objects`, which keeps none).
    pub fn shadow_window(&self) -> ShadowWindow<R> {
        #[cfg(not(feature = "lean-objects"))]
        return self.shadow_window;
        #[cfg(feature = "lean-objects")]
        return shadow_whole_plane();
    }
    /// Whether a shadow ray towards the first light at position `w` across the light can meet
    /// the object: `w` lies in its shadow window (always, with `lean-objects`).
    #[inline]
    pub fn shadow_holds(&self, w: [R; 2]) -> bool {
        #[cfg(not(feature = "lean-objects"))]
        {
            let sw = &self.shadow_window;
            w[0] >= sw[0] && w[0] <= sw[1] && w[1] >= sw[2] && w[1] <= sw[3]
        }
        #[cfg(feature = "lean-objects")]
        {
            let _ = w;
            true
        }
    }
}

/// Calls `f` with each object of a mask (bit `i`: object `i`, of the first 64) that a scene of
/// `n` objects has, lowest first, until `f` answers true; returns whether it did. The mask is
/// taken by halves of 32 bits (a Cortex-M0+ counts and shifts 64-bit values in library calls),
/// each cut to the objects there are; two plain loops, which the tracer's eye rays run faster
/// than an iterator's state.
#[inline(always)]
pub(crate) fn any_object(mask: u64, n: usize, mut f: impl FnMut(usize) -> bool) -> bool {
    let below = |n: usize| if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    for (half, base) in [(mask as u32, 0), ((mask >> 32) as u32, 32)] {
        let mut left = half & below(n.saturating_sub(base));
        while left != 0 {
            let i = base + left.trailing_zeros() as usize;
            left &= left - 1;
            if f(i) {
                return true;
            }
        }
    }
    false
}
