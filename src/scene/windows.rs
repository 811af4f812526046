//! Building an object's [`Region`]: its padded box's corners projected through the eye (the
//! eye window), along the first light (the shadow window) and, with the `eye-hulls` feature,
//! the convex hull of its box's image ([`super::hull`]).

use super::model::{Light, Object};
use super::projection::Projection;
use super::region::{shadow_whole_plane, EyeWindow, Region, ShadowWindow, EYE_MARGIN, WHOLE_PLANE};
use crate::camera::Camera;
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;

/// The [`EyeWindow`] of a box: its eight corners projected through the camera's eye onto the
/// window plane (`projection`: in `f64`, from the camera's vectors as the scalar holds them),
/// widened by [`EYE_MARGIN`]. The image of a box wholly in front of the eye is the convex hull
/// of its corners' images, so every eye ray that meets the box passes inside.
fn eye_window<R: Real>(b: &Aabb<R>, projection: &Projection) -> EyeWindow {
    let (min, max) = (b.min.cast::<f64>(), b.max.cast::<f64>());
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in (Aabb { min, max }).corners() {
        // A corner on or behind the eye plane: the box's image is unbounded.
        let Some(image) = projection.window(p) else { return WHOLE_PLANE };
        for (a, w) in image.into_iter().enumerate() {
            lo[a] = lo[a].min(w);
            hi[a] = hi[a].max(w);
        }
    }
    // Rounded outwards; `as` saturates, so a window beyond the i32 range only widens.
    let (below, above) = (|w: f64| libm::floor(w * 65536.0) as i32, |w: f64| libm::ceil(w * 65536.0) as i32);
    [
        below(lo[0]).saturating_sub(EYE_MARGIN),
        above(hi[0]).saturating_add(EYE_MARGIN),
        below(lo[1]).saturating_sub(EYE_MARGIN),
        above(hi[1]).saturating_add(EYE_MARGIN),
    ]
}

/// Two unit vectors across the first light when it is directional (in the scalar, as the
/// tracer projects with them): shadow rays towards it are parallel, so each object's shadow
/// window is a rectangle in their plane.
pub(crate) fn shadow_basis<R: Real>(lights: &[Light<R>]) -> Option<(Vec3<R>, Vec3<R>)> {
    let Some(Light::Directional { to_light, .. }) = lights.first() else { return None };
    let l = to_light.cast::<f64>().normalize();
    let helper = if l.x.abs() < 0.9 { Vec3::new(1.0, 0.0, 0.0) } else { Vec3::new(0.0, 1.0, 0.0) };
    let a = l.cross(helper).normalize();
    let b = l.cross(a).normalize();
    Some((a.cast(), b.cast()))
}

/// The [`ShadowWindow`] of a box: its corners' coordinates along `a` and `b` (the basis as
/// the scalar holds it, in `f64`), widened by `margin`.
fn shadow_window<R: Real>(b: &Aabb<R>, x: Vec3<f64>, y: Vec3<f64>, margin: f64) -> ShadowWindow<R> {
    let (min, max) = (b.min.cast::<f64>(), b.max.cast::<f64>());
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in (Aabb { min, max }).corners() {
        for (k, w) in [p.dot(x), p.dot(y)].into_iter().enumerate() {
            lo[k] = lo[k].min(w);
            hi[k] = hi[k].max(w);
        }
    }
    // Rounded outwards into the scalar (beyond its range the window is unbounded there).
    let down = |w: f64| R::from_f64(w - margin - (w.abs() + 1.0) * R::pad_eps().to_f64());
    let up = |w: f64| R::from_f64(w + margin + (w.abs() + 1.0) * R::pad_eps().to_f64());
    [down(lo[0]), up(hi[0]), down(lo[1]), up(hi[1])]
}

/// What every object's [`Region`] is built from: the eye's projection, the first light's basis
/// (when it is directional) and the margin the rounding of a light-window position needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Regions {
    projection: Option<Projection>,
    shadow_basis: Option<(Vec3<f64>, Vec3<f64>)>,
    margin: f64,
}

impl Regions {
    /// For a scene seen by `camera`, lit first along `shadow_basis` (from [`shadow_basis`]),
    /// whose objects and eye lie in `world`.
    pub(crate) fn new<R: Real>(camera: &Camera<R>, shadow_basis: Option<(Vec3<R>, Vec3<R>)>, world: &Aabb<R>) -> Self {
        Regions {
            projection: Projection::new(camera),
            shadow_basis: shadow_basis.map(|(a, b)| (a.cast(), b.cast())),
            // A point's light-window position is two dot products in R: widen every window by
            // what their rounding can reach anywhere in the world (the scalar's padding at its
            // corners).
            margin: world.pad_for::<R>(),
        }
    }

    /// The region of object `o`, placed and bounded.
    pub(crate) fn of<R: Real>(&self, o: &Object<R>) -> Region<R> {
        let p = self.projection.as_ref();
        Region::from_tables(
            p.map_or(WHOLE_PLANE, |p| eye_window(&o.bounds, p)),
            // The padding the object's world box got (`Aabb::pad_for`), on its own box (not
            // kept without the `eye-hulls` feature).
            #[cfg(feature = "eye-hulls")]
            p.map_or(super::NO_HULL, |p| super::hull::eye_hull(o, p, o.bounds.pad_for::<R>())),
            #[cfg(not(feature = "eye-hulls"))]
            super::NO_HULL,
            // Not kept with `lean-objects`.
            match self.shadow_basis {
                Some((a, b)) => shadow_window(&o.bounds, a, b, self.margin),
                None => shadow_whole_plane(),
            },
        )
    }
}
