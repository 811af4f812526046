//! The validated scene: objects, composites, materials, lights and the camera.

use super::hull::EyeHull;
#[cfg(feature = "eye-hulls")]
use super::hull::NO_HULL;
use crate::math::{Aabb, Affine, Linear, Ray, Vec3};
use crate::scalar::{Pow2, Real};
use crate::shape::{Shape, ShapeHit};
use heapless::Vec;

/// Most materials a scene may define.
pub const MAX_MATERIALS: usize = 16;
/// Most lights a scene may define.
pub const MAX_LIGHTS: usize = 4;
/// Most composite objects (each gets a sub-lattice).
pub const MAX_COMPOSITES: usize = 16;
/// The composite index of an object that belongs to no composite.
pub const NO_COMPOSITE: u16 = u16::MAX;

/// A gray, wavelength-independent surface in the paper's terms (eq. 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material<R> {
    /// Ambient coefficient `Ka` (multiplies the scene's `Ia`).
    pub ka: R,
    /// Diffuse coefficient `Kd`.
    pub kd: R,
    /// Mirror-reflection coefficient `Ks` (weight of `S`).
    pub ks: R,
    /// Transmission coefficient `Kt` (weight of `T`).
    pub kt: R,
    /// Index of refraction of the inside.
    pub ior: R,
}

impl Material<f64> {
    /// The material objects get when none is named: matte gray.
    pub const DEFAULT: Self = Material { ka: 0.2, kd: 0.8, ks: 0.0, kt: 0.0, ior: 1.0 };
}

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light<R> {
    /// The paper's planar light at infinite distance.
    Directional {
        /// Unit vector from the surface towards the light.
        to_light: Vec3<R>,
        /// Intensity `Ip`.
        intensity: R,
    },
    /// A point light.
    Point {
        /// Position.
        pos: Vec3<R>,
        /// Intensity `Ip`.
        intensity: R,
    },
}

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
    /// in integers (to within one unit), for [`Object::intersect_eye_ray`].
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

/// One primitive placed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object<R> {
    /// The canonical primitive.
    pub(crate) shape: Shape<R>,
    /// World-to-object transform (the inverse of the placement) multiplied by the power of two
    /// `2^-unscale` that brings its largest linear entry into `(0.5, 1]`, so fixed point keeps
    /// full precision however large or small the object is (exact in floating point).
    pub(crate) to_object: Linear<R>,
    /// The placement, from canonical object space to the world: hit points are mapped back
    /// through it ([`Object::surface_point`]). Its translation is the object's origin: rays are
    /// taken relative to it before `to_object` (whose translation is then zero), so a scene far
    /// from the world's origin loses no precision to cancellation.
    pub(crate) to_world: Affine<R>,
    /// The power of two `to_object`'s results are multiplied by to get object space
    /// ([`Real::mul_pow2`]: a shift in fixed point, not a multiply).
    pub(crate) unscale: Pow2<R>,
    /// `unscale * dir_scale`: what `to_object`'s direction results are multiplied by.
    pub(crate) dir_factor: Pow2<R>,
    /// Index into the scene's materials.
    pub(crate) material: u8,
    /// Composite object it belongs to, or [`NO_COMPOSITE`].
    pub(crate) composite: u16,
    /// World-space bounding box, padded for the scalar's rounding.
    pub(crate) bounds: Aabb<R>,
    /// A power of two that object-space directions are multiplied by, so that they stay near
    /// unit length however small or large the object is (exact in floating point).
    pub(crate) dir_scale: Pow2<R>,
    /// `1 / dir_scale`.
    pub(crate) inv_dir_scale: Pow2<R>,
    /// The camera's eye in object space, `to_object.vector(eye - origin) * unscale`: the same
    /// for every eye ray, so it is computed once per scene instead of once per eye-ray test.
    pub(crate) eye_local: Vec3<R>,
    /// The direction towards the scene's first light, when it is directional, in object space
    /// as [`Object::intersect`] maps a ray's direction (zero otherwise): the same for every
    /// shadow ray towards that light, so it is mapped once per scene instead of once per test.
    pub(crate) light_local: Vec3<R>,
    /// The part of the image the object can appear in, as an [`EyeWindow`].
    pub(crate) eye_window: EyeWindow,
    /// The same part more tightly, as an [`EyeHull`] (with the `eye-hulls` feature).
    #[cfg(feature = "eye-hulls")]
    pub(crate) eye_hull: EyeHull,
    /// Where a shadow ray towards the scene's first light can meet it, as a [`ShadowWindow`].
    pub(crate) shadow_window: ShadowWindow<R>,
}

/// Where shadow rays towards the scene's first light (when it is directional, so its rays are
/// parallel) can meet an object: `[a_lo, a_hi, b_lo, b_hi]`, the object's padded box projected
/// along the light onto the plane of [`Scene::shadow_basis`], widened by the rounding of that
/// projection. A shadow ray whose origin projects outside cannot hit the object.
pub type ShadowWindow<R> = [R; 4];

/// The shadow window that culls nothing.
pub fn shadow_whole_plane<R: Real>() -> ShadowWindow<R> {
    [-R::MAX, R::MAX, -R::MAX, R::MAX]
}

/// Where on the image an object can appear: `[u_lo, u_hi, v_lo, v_hi]` in units of 2^-16 of
/// the camera's window coordinates `u` and `v` (each running -1..1 across the image, as in
/// [`Camera::ray`]), from its padded box's corners projected through the eye and widened by
/// [`EYE_MARGIN`]. An eye ray whose `(u, v)` lies outside cannot hit the object, so its exact
/// test is skipped: the picture is the same, the work less. A box not wholly in front of the
/// eye gets the whole plane.
pub type EyeWindow = [i32; 4];

/// An eye ray passes outside an object's [`EyeWindow`]: it cannot hit the object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Culled;

/// The window that culls nothing.
pub const WHOLE_PLANE: EyeWindow = [i32::MIN, i32::MAX, i32::MIN, i32::MAX];

/// How far (in 2^-16 units of `u`, `v`) an eye window is widened beyond the projected box:
/// 2^-6, about one pixel of a 128-pixel-wide image and hundreds of times the rounding of any
/// scalar's eye-ray direction.
pub const EYE_MARGIN: i32 = 1 << 10;

impl<R: Real> Default for Object<R> {
    /// A placeholder (unit sphere at the origin) for filling storage arrays.
    fn default() -> Self {
        let z = Vec3::new(R::ZERO, R::ZERO, R::ZERO);
        Object {
            shape: Shape::Sphere,
            to_object: Affine::identity().linear(),
            to_world: Affine::identity(),
            unscale: R::pow2(0),
            dir_factor: R::pow2(0),
            material: 0,
            composite: NO_COMPOSITE,
            bounds: Aabb { min: z, max: z },
            dir_scale: R::pow2(0),
            inv_dir_scale: R::pow2(0),
            eye_local: z,
            light_local: z,
            eye_window: WHOLE_PLANE,
            #[cfg(feature = "eye-hulls")]
            eye_hull: NO_HULL,
            shadow_window: shadow_whole_plane(),
        }
    }
}

impl<R> Object<R> {
    /// An object from its parts, as [`bake::source`](crate::bake) writes them: for baked
    /// tables only, which hold objects of a validated scene.
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    pub const fn from_tables(
        shape: Shape<R>,
        to_object: Linear<R>,
        to_world: Affine<R>,
        unscale: Pow2<R>,
        dir_factor: Pow2<R>,
        material: u8,
        composite: u16,
        bounds: Aabb<R>,
        dir_scale: Pow2<R>,
        inv_dir_scale: Pow2<R>,
        eye_local: Vec3<R>,
        light_local: Vec3<R>,
        eye_window: EyeWindow,
        eye_hull: EyeHull,
        shadow_window: ShadowWindow<R>,
    ) -> Self {
        // A build without the feature keeps no hull (a baked table's is dropped here).
        #[cfg(not(feature = "eye-hulls"))]
        let _ = eye_hull;
        Object {
            shape,
            to_object,
            to_world,
            unscale,
            dir_factor,
            material,
            composite,
            bounds,
            dir_scale,
            inv_dir_scale,
            eye_local,
            light_local,
            eye_window,
            #[cfg(feature = "eye-hulls")]
            eye_hull,
            shadow_window,
        }
    }
}

impl<R: Real> Object<R> {
    /// Nearest hit of a world ray with `tmin < t <= tmax`: `t` (the world ray's parameter) and
    /// the object-space normal and point.
    #[inline]
    pub fn intersect(&self, ray: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        self.intersect_local(self.point_local(ray.origin), self.direction_local(ray.dir), tmin, tmax)
    }

    /// Whether the object's eye window meets the window rectangle `u` x `v` (2^-16 units,
    /// inclusive bounds, see [`EyeWindow`]).
    #[inline]
    pub fn eye_window_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        let w = &self.eye_window;
        w[0] <= u[1] && u[0] <= w[1] && w[2] <= v[1] && v[0] <= w[3]
    }

    /// Whether the object can appear in the window rectangle `u` x `v` (as
    /// [`Object::eye_window_meets`] takes it): its eye window meets it, and so does its
    /// [`EyeHull`] where the build keeps one (the `eye-hulls` feature).
    #[inline]
    pub fn eye_region_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        #[cfg(feature = "eye-hulls")]
        return self.eye_window_meets(u, v) && super::hull::hull_meets(&self.eye_hull, u, v);
        #[cfg(not(feature = "eye-hulls"))]
        return self.eye_window_meets(u, v);
    }

    /// [`Object::intersect`] for an eye ray (its origin the camera's eye) through window
    /// position `uv` (2^-16 units, see [`EyeWindow`]): `Err(Culled)` without a test when `uv` lies
    /// outside the object's window, else the same answer as `intersect`, with the eye's
    /// object-space position taken from the scene instead of transformed again.
    #[inline]
    pub fn intersect_eye_ray(
        &self,
        ray: &Ray<R>,
        uv: [i32; 2],
        tmin: R,
        tmax: R,
    ) -> Result<Option<ShapeHit<R>>, Culled> {
        if !self.eye_window_meets([uv[0]; 2], [uv[1]; 2]) {
            return Err(Culled);
        }
        Ok(self.intersect_local(self.eye_local, self.direction_local(ray.dir), tmin, tmax))
    }

    /// [`Object::intersect`] for a shadow ray towards the scene's first light when that light
    /// is directional (the ray's direction is the light's `to_light`): the same answer, with
    /// the direction's object-space image taken from the scene instead of transformed again.
    #[inline]
    pub fn intersect_first_light_ray(&self, ray: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        self.intersect_local(self.point_local(ray.origin), self.light_local, tmin, tmax)
    }

    /// Whether a shadow ray towards the scene's first light (directional) at position `w` across
    /// the light can meet the object: `w` lies in its [`ShadowWindow`].
    #[inline]
    pub fn shadow_window_holds(&self, w: [R; 2]) -> bool {
        let sw = &self.shadow_window;
        w[0] >= sw[0] && w[0] <= sw[1] && w[1] >= sw[2] && w[1] <= sw[3]
    }

    /// A world point in object space, as the ray tests take it: relative to the object's
    /// origin, then through `to_object` and its scale.
    #[inline]
    pub(crate) fn point_local(&self, p: Vec3<R>) -> Vec3<R> {
        self.to_object.vector(p - self.origin()).mul_pow2(self.unscale)
    }

    /// A world direction in object space, scaled to about unit length ([`Object::dir_scale`]).
    #[inline]
    pub(crate) fn direction_local(&self, d: Vec3<R>) -> Vec3<R> {
        self.to_object.vector(d).mul_pow2(self.dir_factor)
    }

    /// The intersection, given the ray's origin and direction already in object space.
    #[inline(always)]
    fn intersect_local(&self, origin: Vec3<R>, dir: Vec3<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        let r = Ray::new(origin, dir);
        // With the direction scaled by k, the object-space parameter is t / k. Multiplying by
        // a power of two is exact in floating point but rounds in fixed point, so the range is
        // checked on the world parameter: a hit exactly at `tmax` (a tie with the best hit so
        // far) is then found whichever scalar runs.
        // The object-space limit is widened by the scalar's padding so rounding cannot exclude a
        // hit at exactly `tmax`, yet still prunes hits well beyond it.
        let far = if tmax == R::MAX {
            R::MAX
        } else {
            let f = tmax.mul_pow2(self.inv_dir_scale);
            f + (f.abs() + R::ONE).padding()
        };
        let hit = self.shape.intersect(&r, tmin.mul_pow2(self.inv_dir_scale), far)?;
        let t = hit.t.mul_pow2(self.dir_scale);
        (t > tmin && t <= tmax).then_some(ShapeHit { t, ..hit })
    }
    /// The canonical primitive.
    pub fn shape(&self) -> Shape<R> {
        self.shape
    }
    /// Index into the scene's materials.
    pub fn material(&self) -> u8 {
        self.material
    }
    /// Composite object it belongs to, or [`NO_COMPOSITE`].
    pub fn composite(&self) -> u16 {
        self.composite
    }
    /// World-space bounding box, padded for the scalar's rounding.
    pub fn bounds(&self) -> Aabb<R> {
        self.bounds
    }
    /// The world point at the object's origin.
    #[inline]
    pub fn origin(&self) -> Vec3<R> {
        let m = &self.to_world.m;
        Vec3::new(m[0][3], m[1][3], m[2][3])
    }
    /// The world point of a hit found with [`Object::intersect`]: the object-space point put
    /// on the surface ([`Shape::on_surface`]) and mapped through the placement. Its error is a
    /// few units of the last place of the point and of the object's own size, wherever the ray
    /// came from: `ray.at(t)` would carry the rounding of the ray's origin, which for an eye
    /// 10^14 units away is more than a thin object is thick.
    #[inline]
    pub fn surface_point(&self, point: Vec3<R>, normal: Vec3<R>) -> Vec3<R> {
        self.to_world.point(self.shape.on_surface(point, normal))
    }
    /// The largest side of the object's (padded) box: the size term of the offset of the
    /// secondary rays that leave it ([`Real::offset`]).
    #[inline]
    pub fn size(&self) -> R {
        self.bounds.extent()
    }
    /// The map from a world offset relative to [`Object::origin`] to object space (the
    /// inverse of the placement), without the scaling the stored copy carries for precision.
    pub fn world_to_object(&self) -> Affine<R> {
        let mut t = self.to_object.affine();
        for row in t.m.iter_mut() {
            for v in row.iter_mut() {
                *v = v.mul_pow2(self.unscale);
            }
        }
        t
    }
    /// Unit world-space normal from an object-space normal (inverse-transpose rule). A unit
    /// axis (one component 1 or -1, the others 0: a box's faces, the caps) maps to a row of
    /// `to_object`, which is taken as it is: the same value without the products by 0 and 1.
    pub fn world_normal(&self, n_obj: Vec3<R>) -> Vec3<R> {
        match axis_normal(n_obj) {
            Some(k) => self.axis_world_normal(k),
            None => self.to_object.transpose_vector(n_obj).normalize(),
        }
    }
    /// [`Object::world_normal`] of the unit axis `k` ([`axis_normal`]'s numbering).
    pub(crate) fn axis_world_normal(&self, k: u8) -> Vec3<R> {
        let row = &self.to_object.m[usize::from(k / 2)];
        let v = Vec3::new(row[0], row[1], row[2]);
        if k % 2 == 1 { -v } else { v }.normalize()
    }
}

/// Which unit axis `n` is, if it is one (one component 1 or -1, the others 0): `2 * axis`, plus
/// 1 for -1. Every face of a box and every cap has such a normal, and its world normal is then
/// the object's alone (see [`Object::world_normal`]).
#[inline]
pub fn axis_normal<R: Real>(n: Vec3<R>) -> Option<u8> {
    let (o, z) = (R::ONE, R::ZERO);
    let axis = match (n.x, n.y, n.z) {
        (x, y, z0) if y == z && z0 == z && x.abs() == o => 0,
        (x, y, z0) if x == z && z0 == z && y.abs() == o => 1,
        (x, y, z0) if x == z && y == z && z0.abs() == o => 2,
        _ => return None,
    };
    Some(2 * axis + u8::from(n.axis(usize::from(axis)) < z))
}

/// A composite object: a contiguous run of objects with a common box (gets a sub-lattice).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Composite<R> {
    /// Index of its first object (as wide as object indices: a composite may start anywhere).
    pub first: u32,
    /// Number of objects (as wide as object indices: a composite may hold any number).
    pub len: u32,
    /// Union of its objects' boxes.
    pub bounds: Aabb<R>,
}

/// Where a parsed scene's composites, materials and lights are kept, beside the object storage
/// (lists of fixed capacity; a [`Scene`] holds exact slices of them, as a baked scene holds
/// slices of its tables, so that neither carries the unused capacity).
#[derive(Clone, Debug)]
pub struct Parts<R> {
    pub(crate) composites: Vec<Composite<R>, MAX_COMPOSITES>,
    pub(crate) materials: Vec<Material<R>, MAX_MATERIALS>,
    pub(crate) lights: Vec<Light<R>, MAX_LIGHTS>,
}

impl<R> Parts<R> {
    /// Empty lists.
    pub const fn new() -> Self {
        Parts { composites: Vec::new(), materials: Vec::new(), lights: Vec::new() }
    }
}

impl<R> Default for Parts<R> {
    fn default() -> Self {
        Self::new()
    }
}

/// A validated scene, ready to trace.
#[derive(Debug)]
pub struct Scene<'a, R> {
    /// All primitives; the objects of a composite are contiguous.
    pub(crate) objects: &'a [Object<R>],
    /// Composite objects.
    pub(crate) composites: &'a [Composite<R>],
    /// Materials.
    pub(crate) materials: &'a [Material<R>],
    /// Lights.
    pub(crate) lights: &'a [Light<R>],
    /// Ambient intensity `Ia`.
    pub(crate) ambient: R,
    /// Gray of rays that hit nothing (0 black .. 1 white).
    pub(crate) background: R,
    /// Camera.
    pub(crate) camera: Camera<R>,
    /// Maximum depth of the intersection tree (0: eye rays only).
    pub(crate) max_depth: u8,
    /// Box holding the viewpoint and every object (the paper's world range).
    pub(crate) world: Aabb<R>,
    /// Two unit vectors across the first light, when it is directional (see [`ShadowWindow`]).
    pub(crate) shadow_basis: Option<(Vec3<R>, Vec3<R>)>,
}

impl<'a, R> Scene<'a, R> {
    /// A scene from its parts, as [`bake::source`](crate::bake) writes them: for baked tables
    /// only, which hold a validated scene.
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    pub const fn from_tables(
        objects: &'a [Object<R>],
        composites: &'a [Composite<R>],
        materials: &'a [Material<R>],
        lights: &'a [Light<R>],
        ambient: R,
        background: R,
        camera: Camera<R>,
        max_depth: u8,
        world: Aabb<R>,
        shadow_basis: Option<(Vec3<R>, Vec3<R>)>,
    ) -> Self {
        Scene { objects, composites, materials, lights, ambient, background, camera, max_depth, world, shadow_basis }
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

impl<'a, R: Real> Scene<'a, R> {
    /// The objects (bit `i`: object `i`, for the first 64) that can appear in the window
    /// rectangle `u` x `v` (2^-16 units, inclusive bounds, see [`EyeWindow`];
    /// [`Object::eye_region_meets`]): an eye ray through that rectangle can hit no other.
    /// Objects past the 64th are always included.
    pub fn eye_candidates(&self, u: [i32; 2], v: [i32; 2]) -> u64 {
        let mut mask = 0u64;
        for (i, o) in self.objects.iter().enumerate().take(64) {
            if o.eye_region_meets(u, v) {
                mask |= 1 << i;
            }
        }
        if self.objects.len() > 64 {
            u64::MAX
        } else {
            mask
        }
    }
    /// Whether any of the objects in `among` (bit `i`: object `i`, of the first 64) can appear
    /// in the window rectangle `u` x `v`, as [`Scene::eye_candidates`] finds them.
    pub fn eye_region_among_meets(&self, among: u64, u: [i32; 2], v: [i32; 2]) -> bool {
        any_object(among, self.objects.len(), |i| self.objects.get(i).is_some_and(|o| o.eye_region_meets(u, v)))
    }
    /// All primitives; the objects of a composite are contiguous.
    pub fn objects(&self) -> &'a [Object<R>] {
        self.objects
    }
    /// Composite objects.
    pub fn composites(&self) -> &'a [Composite<R>] {
        self.composites
    }
    /// Materials.
    pub fn materials(&self) -> &'a [Material<R>] {
        self.materials
    }
    /// Lights.
    pub fn lights(&self) -> &'a [Light<R>] {
        self.lights
    }
    /// Ambient intensity `Ia`.
    pub fn ambient(&self) -> R {
        self.ambient
    }
    /// Gray of rays that hit nothing (0 black .. 1 white).
    pub fn background(&self) -> R {
        self.background
    }
    /// Camera.
    pub fn camera(&self) -> &Camera<R> {
        &self.camera
    }
    /// Maximum depth of the intersection tree the scene asks for (0: eye rays only).
    pub fn max_depth(&self) -> u8 {
        self.max_depth
    }
    /// Box holding the viewpoint and every object (the paper's world range).
    pub fn world(&self) -> Aabb<R> {
        self.world
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
