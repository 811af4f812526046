//! The eye's projection in `f64`: where on the camera's window a world point's eye ray passes,
//! the one map every eye window and eye hull is built with.

use crate::camera::Camera;
use crate::math::{Affine, Vec3};
use crate::scalar::Real;

/// The window position `(u, v)` of world points as eye rays reach them, in `f64`: a point `p`
/// lies on the eye ray `eye + s (forward + u right + v up)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Projection {
    pub(super) eye: Vec3<f64>,
    pub(super) from_eye: Affine<f64>,
    /// Per row of `from_eye`, the sum of its entries' magnitudes.
    #[cfg(feature = "eye-hulls")]
    pub(super) rows: [f64; 3],
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
}
