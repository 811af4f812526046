//! The camera: the view as a scene gives it ([`CameraDesc`], fitted to a frame's shape with
//! square pixels), the camera reduced to what eye rays need ([`Camera`]), the pixel-position
//! conversions (a pixel's doubled or quarter-pixel coordinates to a window position in 2^-16
//! units and to a ray factor), and the per-column cache the tile loop makes its eye rays with
//! (`EyeRayCache`). Every eye ray of the tracer is made here.
//!
//! Words: the camera's *window* is the plane `forward + u right + v up` with `u` and `v` each
//! running -1..1 across the image; a *window position* is a point of it in integer units of
//! 2^-16 (what culling compares, [`crate::scene::region`]); a *ray factor* is the same point in the
//! scalar (what an eye ray's direction is made from).

use crate::dither::MAX_TILE;
use crate::math::{Ray, Vec3};
use crate::scalar::Real;

/// A scene's field of view, in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FieldOfView {
    /// The angle across the frame; the angle down follows from the frame's shape (square
    /// pixels).
    Across(f64),
    /// A view of at least this angle across and this angle down: the frame shows all of it,
    /// with square pixels, and more along the axis where its shape is wider than the view's
    /// (`fov 40 25`, the paper's 160x100 window, on a 128x64 panel shows 47.9 x 25 degrees).
    Within(f64, f64),
}

impl FieldOfView {
    /// The paper's view: 40 x 25 degrees.
    pub const PAPER: FieldOfView = FieldOfView::Within(40.0, 25.0);

    /// The tangents of half the angle across and down for a frame of `w x h` pixels (both at
    /// least 1): square pixels, and a [`FieldOfView::Within`] view fully inside.
    pub fn half_tangents(self, [w, h]: [u32; 2]) -> (f64, f64) {
        let aspect = f64::from(w.max(1)) / f64::from(h.max(1));
        let tan = |deg: f64| libm::tan(deg * core::f64::consts::PI / 180.0 / 2.0);
        match self {
            FieldOfView::Across(a) => (tan(a), tan(a) / aspect),
            FieldOfView::Within(a, d) => {
                let (tx, ty) = (tan(a), tan(d));
                if tx < ty * aspect {
                    (ty * aspect, ty)
                } else {
                    (tx, tx / aspect)
                }
            }
        }
    }

    /// The angles given, in degrees (the angle across twice for [`FieldOfView::Across`]).
    pub fn angles(self) -> [f64; 2] {
        match self {
            FieldOfView::Across(a) => [a, a],
            FieldOfView::Within(a, d) => [a, d],
        }
    }
}

/// The frame shape a camera is fitted to unless told otherwise: the boards' 128x64 panel.
pub const DEFAULT_FRAME: [u32; 2] = [128, 64];

/// The camera as given in a scene (eye, look-at, up, field of view in degrees), and the shape of
/// the frame it is fitted to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    /// Viewpoint `V`.
    pub eye: Vec3<f64>,
    /// Point looked at.
    pub look: Vec3<f64>,
    /// Up direction.
    pub up: Vec3<f64>,
    /// The field of view (the paper's: 40 x 25 degrees).
    pub fov: FieldOfView,
    /// Width and height of the frame the view is fitted to, in pixels (any multiple of them
    /// renders the same view): pixels are square, and the render refuses a frame of another
    /// shape ([`crate::render::RenderError::FrameShape`]).
    pub frame: [u32; 2],
}

impl CameraDesc {
    /// The camera moved `turn` of a full circle (0..1) around the vertical line through the
    /// point it looks at (the line along `up`): the eye keeps its height and distance, and still
    /// looks at `look`. Frames of an orbit.
    pub fn orbit(&self, turn: f64) -> CameraDesc {
        if turn == 0.0 {
            // Exactly the scene's camera (look + (eye - look) may round).
            return *self;
        }
        let (sin, cos) = libm::sincos(turn * 2.0 * core::f64::consts::PI);
        let axis = self.up.normalize();
        let v = self.eye - self.look;
        // Rodrigues' rotation of the eye's offset about the axis.
        let rotated = v * cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - cos));
        CameraDesc { eye: self.look + rotated, ..*self }
    }
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            eye: Vec3::new(0.0, 0.0, -10.0),
            look: Vec3::zero(),
            up: Vec3::new(0.0, 1.0, 0.0),
            fov: FieldOfView::PAPER,
            frame: DEFAULT_FRAME,
        }
    }
}

/// The camera reduced to what eye rays need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera<R> {
    /// Viewpoint.
    pub eye: Vec3<R>,
    /// Unit view direction.
    pub forward: Vec3<R>,
    /// Right vector scaled by `tan(fov_x / 2)`.
    pub right: Vec3<R>,
    /// Up vector scaled by `tan(fov_y / 2)`.
    pub up: Vec3<R>,
    /// The most pixels across and down the scalar resolves through this view: neighbouring
    /// pixels at least [`VIEW_MARGIN`] units of the scalar's last place apart (computed at
    /// set-up, so the render checks a frame against it with integers).
    pub resolves: [u32; 2],
    /// The frame shape the view was fitted to, in lowest terms (`[2, 1]` for 128x64).
    pub shape: [u32; 2],
}

/// `[w, h]` divided by their greatest common divisor (`[0, 0]` stays).
pub fn lowest_terms([w, h]: [u32; 2]) -> [u32; 2] {
    let (mut a, mut b) = (w, h);
    while b != 0 {
        (a, b) = (b, a % b);
    }
    match (w.checked_div(a), h.checked_div(a)) {
        (Some(w), Some(h)) => [w, h],
        _ => [w, h],
    }
}

/// How many times the scalar's resolution the angle between neighbouring pixels must be: an
/// eye ray's direction (and the eye itself, relative to its distance) is rounded to about one
/// unit of the last place, so edges then move by at most 1/32 of a pixel.
pub const VIEW_MARGIN: f64 = 32.0;

/// The most pixels a window side of half-width `tan_half` (the tangent of half the field of
/// view) may be divided into in `R` (see [`Camera::resolves`]).
pub fn resolvable_pixels<R: Real>(tan_half: f64) -> u32 {
    let n = 2.0 * tan_half / (VIEW_MARGIN * R::RESOLUTION);
    if n >= u32::MAX as f64 {
        u32::MAX
    } else {
        n as u32
    }
}

impl<R: Real> Camera<R> {
    /// The window position `(u, v)` of [`Camera::ray`]`(sx2, sy2, w2, h2)` in units of 2^-16,
    /// in integers (to within one unit), for [`crate::scene::Object::intersect_eye_ray`].
    pub fn window_uv(sx2: i32, sy2: i32, w2: i32, h2: i32) -> [i32; 2] {
        [Self::window_u(sx2, w2), Self::window_v(sy2, h2)]
    }

    /// The `u` of [`Camera::window_uv`] (it depends on the horizontal position alone).
    pub fn window_u(sx2: i32, w2: i32) -> i32 {
        window_coord(2 * sx2 - w2, w2)
    }

    /// The `v` of [`Camera::window_uv`] (it depends on the vertical position alone).
    pub fn window_v(sy2: i32, h2: i32) -> i32 {
        window_coord(h2 - 2 * sy2, h2)
    }

    /// The eye ray through the point `(sx, sy)` of a `w x h` window, in pixel units from the
    /// top-left corner (pixel centres are at `i + 0.5`).
    pub fn ray(&self, sx2: i32, sy2: i32, w2: i32, h2: i32) -> Ray<R> {
        self.ray_through(Self::ray_u(sx2, w2), Self::ray_v(sy2, h2))
    }

    /// The factor of `right` in the direction of [`Camera::ray`] (it depends on the horizontal
    /// position alone). Arguments are doubled coordinates so that pixel centres stay integers.
    #[inline]
    pub fn ray_u(sx2: i32, w2: i32) -> R {
        ratio::<R>(2 * sx2 - w2, w2)
    }

    /// The factor of `up` in the direction of [`Camera::ray`] (the vertical position's alone).
    #[inline]
    pub fn ray_v(sy2: i32, h2: i32) -> R {
        ratio::<R>(h2 - 2 * sy2, h2)
    }

    /// The eye ray with direction `forward + right * u + up * v`.
    #[inline]
    pub fn ray_through(&self, u: R, v: R) -> Ray<R> {
        self.ray_from(self.column(u), self.row(v))
    }

    /// The part of [`Camera::ray_through`]'s direction that a column of the window shares,
    /// `forward + right * u`: a renderer keeps it per column ([`Camera::ray_from`]).
    #[inline]
    pub fn column(&self, u: R) -> Vec3<R> {
        self.forward + self.right * u
    }

    /// The part of [`Camera::ray_through`]'s direction that a row of the window shares,
    /// `up * v`.
    #[inline]
    pub fn row(&self, v: R) -> Vec3<R> {
        self.up * v
    }

    /// The eye ray of a [`Camera::column`] and a [`Camera::row`]: the same ray as
    /// [`Camera::ray_through`], the same sums in the same order, without its six products.
    #[inline]
    pub fn ray_from(&self, column: Vec3<R>, row: Vec3<R>) -> Ray<R> {
        Ray::new(self.eye, column + row)
    }
}

/// `(n << 16) / d` (`d` at least 1) truncated towards zero, clamped to `i32`: one 32-bit
/// division while `n` is small (a microcontroller's divider does that in a few cycles), else
/// long division in 32 bits (no 64-bit division routine linked).
fn window_coord(n: i32, d: i32) -> i32 {
    let d = d.max(1);
    if n.unsigned_abs() < 1 << 15 {
        (n << 16) / d
    } else {
        window_coord_far(n, d)
    }
}

/// [`window_coord`] of a numerator of 2^15 or more (a window thousands of pixels wide), kept
/// out of the way of the common case.
#[cold]
#[inline(never)]
fn window_coord_far(n: i32, d: i32) -> i32 {
    let (a, b) = (n.unsigned_abs(), d as u32);
    // A whole quotient of 2^15 or more is past the clamp.
    let q = if a / b >= 1 << 15 { u32::MAX } else { crate::fixed::shifted_quotient(a, b).0 };
    if n < 0 {
        if q >= 1 << 31 {
            i32::MIN
        } else {
            -(q as i32)
        }
    } else {
        q.min(i32::MAX as u32) as i32
    }
}

/// `n / d` in `R`, as `from_i32(n) / from_i32(d)`; a window side that is a power of two (up to
/// 2^14, as every board's is) divides by [`Real::div_pow2`], the same value without a division.
#[inline]
fn ratio<R: Real>(n: i32, d: i32) -> R {
    if d > 0 && d <= 1 << 14 && d & (d - 1) == 0 {
        R::from_i32(n).div_pow2(d.trailing_zeros())
    } else {
        R::from_i32(n) / R::from_i32(d)
    }
}

/// Where a frame's eye rays pass the window: per quarter-pixel column its window coordinate
/// ([`Camera::window_u`]) and its part of the ray's direction ([`Camera::column`]), and of the
/// last row asked for its window coordinate and its part ([`Camera::row`]), each kept from the
/// last ray that needed it. Each depends on one position alone, so a tile's rays (row by row)
/// compute them, a division and three products, once per column and row instead of once per
/// ray; the rays are the same ([`Camera::ray_from`]). With 8x8 tiles (the `tile8` feature: the
/// 4 KiB boards) a column keeps its ray factor ([`Camera::ray_u`]) instead and each ray takes
/// the three products: its part would take 88 more bytes of stack, which those boards do not
/// have.
pub(crate) struct EyeRayCache<'c, R> {
    camera: &'c Camera<R>,
    size: (i32, i32),
    cols: [(i32, i32, ColumnPart<R>); MAX_TILE],
    row: (i32, i32, Vec3<R>),
}

/// What [`EyeRayCache`] keeps of a column for its rays: the ray factor ([`Camera::ray_u`]) with 8x8
/// tiles, else the column's part of the direction.
#[cfg(feature = "tile8")]
type ColumnPart<R> = R;

/// What [`EyeRayCache`] keeps of a column for its rays: the ray factor ([`Camera::ray_u`]) with 8x8
/// tiles, else the column's part of the direction.
#[cfg(not(feature = "tile8"))]
type ColumnPart<R> = Vec3<R>;

/// The [`ColumnPart`] of ray factor `u`.
#[cfg(feature = "tile8")]
fn column_part<R: Real>(_: &Camera<R>, u: R) -> ColumnPart<R> {
    u
}

/// The [`ColumnPart`] of ray factor `u`.
#[cfg(not(feature = "tile8"))]
fn column_part<R: Real>(camera: &Camera<R>, u: R) -> ColumnPart<R> {
    camera.column(u)
}

/// The column's part of the direction ([`Camera::column`]) from what the window kept of it.
#[cfg(feature = "tile8")]
fn column_of<R: Real>(camera: &Camera<R>, part: ColumnPart<R>) -> Vec3<R> {
    camera.column(part)
}

/// The column's part of the direction ([`Camera::column`]) from what the window kept of it.
#[cfg(not(feature = "tile8"))]
fn column_of<R: Real>(_: &Camera<R>, part: ColumnPart<R>) -> Vec3<R> {
    part
}

impl<'c, R: Real> EyeRayCache<'c, R> {
    /// A cache for the eye rays of an image of `w4 x h4` quarter pixels.
    pub(crate) fn new(camera: &'c Camera<R>, w4: i32, h4: i32) -> Self {
        let none = column_part(camera, R::ZERO);
        EyeRayCache {
            camera,
            size: (w4, h4),
            cols: [(-1, 0, none); MAX_TILE],
            row: (-1, 0, Vec3::new(R::ZERO, R::ZERO, R::ZERO)),
        }
    }

    /// The image's size in quarter pixels, as the cache was made for.
    pub(crate) fn size(&self) -> (i32, i32) {
        self.size
    }

    /// Window position (2^-16 units) and the eye ray through `(sx, sy)`.
    #[inline]
    pub(crate) fn at(&mut self, sx: i32, sy: i32) -> ([i32; 2], Ray<R>) {
        let (w4, h4) = self.size;
        let c = &mut self.cols[(sx as usize >> 2) % MAX_TILE];
        if c.0 != sx {
            *c = (sx, Camera::<R>::window_u(sx, w4), column_part(self.camera, Camera::<R>::ray_u(sx, w4)));
        }
        let r = &mut self.row;
        if r.0 != sy {
            *r = (sy, Camera::<R>::window_v(sy, h4), self.camera.row(Camera::<R>::ray_v(sy, h4)));
        }
        ([c.1, r.1], self.camera.ray_from(column_of(self.camera, c.2), r.2))
    }
}

#[cfg(test)]
mod tests {
    use super::window_coord;

    /// The window coordinate is the 64-bit quotient, truncated and clamped, for numerators
    /// small and large (long division past 2^15) and divisors from 1 up.
    #[test]
    fn window_coord_is_the_wide_quotient_clamped() {
        let wide = |n: i32, d: i32| {
            ((i64::from(n) << 16) / i64::from(d.max(1))).clamp(i32::MIN.into(), i32::MAX.into()) as i32
        };
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let n = (x as i32) >> (x % 31);
            let d = ((x >> 32) as i32 >> ((x >> 40) % 31)).max(-5);
            assert_eq!(window_coord(n, d), wide(n, d), "({n} << 16) / {d}");
        }
        for n in [i32::MIN, i32::MIN + 1, -(1 << 15), (1 << 15) - 1, 1 << 15, i32::MAX, 0, -1] {
            for d in [-1, 0, 1, 2, 3, 1 << 15, (1 << 16) + 1, i32::MAX] {
                assert_eq!(window_coord(n, d), wide(n, d), "({n} << 16) / {d}");
            }
        }
    }
}
