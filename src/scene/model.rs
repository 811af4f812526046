//! The validated scene: objects, composites, materials, lights and the camera.

use super::effects::Effects;
use super::region::{any_object, Culled, EyeHull, EyeWindow, Region, ShadowWindow};
use crate::bounds::at;
use crate::camera::Camera;
use crate::math::{Aabb, Affine, Linear, Ray, Vec3};
use crate::scalar::{Pow2, Real};
use crate::shape::{Shape, ShapeHit};
use heapless::Vec;

/// Most materials a scene may define in a build without `alloc`: a board's ([`MAX_MATERIALS`]
/// there; a host that checks a scene for a board, as `host-sim uf2 --scene` does, holds it to
/// this).
pub const BOARD_MATERIALS: usize = 16;
/// Most lights a scene may define in a build without `alloc`: a board's ([`MAX_LIGHTS`] there).
pub const BOARD_LIGHTS: usize = 4;
/// Most materials a scene may define: 16 in a build without `alloc` (a microcontroller's),
/// 256 with it (the host's, where NFF scenes give objects dozens of colours; a material index
/// is a byte).
#[cfg(not(feature = "alloc"))]
pub const MAX_MATERIALS: usize = BOARD_MATERIALS;
/// Most materials a scene may define: 16 in a build without `alloc` (a microcontroller's),
/// 256 with it (the host's, where NFF scenes give objects dozens of colours; a material index
/// is a byte).
#[cfg(feature = "alloc")]
pub const MAX_MATERIALS: usize = 256;
/// Most lights a scene may define: 4 in a build without `alloc`, 16 with it (the SPD's `tree`
/// has 7). Each core's work remembers an occluder per light, for at most this many lights.
#[cfg(not(feature = "alloc"))]
pub const MAX_LIGHTS: usize = BOARD_LIGHTS;
/// Most lights a scene may define: 4 in a build without `alloc`, 16 with it (the SPD's `tree`
/// has 7). Each core's work remembers an occluder per light, for at most this many lights.
#[cfg(feature = "alloc")]
pub const MAX_LIGHTS: usize = 16;
/// Most smooth triangles (NFF's `pp` patches, [`Smooth`]): none in a build without `alloc`
/// (whose parts keep no room for them), as many as there are objects with it.
pub const MAX_SMOOTH: usize = if cfg!(feature = "alloc") { usize::MAX } else { 0 };
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
    /// The Phong power of a highlight of weight `Ks` at each light (NFF's `Shine`), as a whole
    /// number (raised by squaring in every scalar: no `pow` table in the firmware); 0 for none.
    pub shine: u16,
}

impl Material<f64> {
    /// A Phong power as [`Material::shine`] holds it: `p >= 0` rounded to the nearest whole
    /// number, at most 65,535 (a cosine below 1 raised that far is as good as 0 beside 1).
    pub fn power(p: f64) -> u16 {
        if p >= 65_535.0 {
            u16::MAX
        } else {
            (p + 0.5) as u16
        }
    }
}

impl Material<f64> {
    /// The material objects get when none is named: matte gray.
    pub const DEFAULT: Self = Material { ka: 0.2, kd: 0.8, ks: 0.0, kt: 0.0, ior: 1.0, shine: 0 };
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

/// One primitive placed in the world.
///
/// Laid out as declared and aligned to 8 bytes (`repr(C, align(8))`), as the flash's cache lines
/// are, in the order a ray test reads it: in a baked table of them, read through the XIP cache,
/// an exact test reads the first 76 bytes (10 lines), a sphere or other object placed by a
/// uniform scale and a translation alone only the first 44 (6 lines: [`Object::UNIFORM`]); the
/// bounds a walk's box test reads start on a line (offset 112) and take three lines, never
/// four; the placement's linear part, read at a hit, lies between them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(8))]
pub struct Object<R> {
    /// The canonical primitive.
    pub(crate) shape: Shape<R>,
    /// The placement's translation: the object's origin in the world. Rays are taken relative
    /// to it before `to_object` (whose translation is then zero), so a scene far from the
    /// world's origin loses no precision to cancellation.
    pub(crate) origin: Vec3<R>,
    /// The power of two `to_object`'s results are multiplied by to get object space
    /// ([`Real::mul_pow2`]: a shift in fixed point, not a multiply).
    pub(crate) unscale: Pow2<R>,
    /// `unscale * dir_scale`: what `to_object`'s direction results are multiplied by.
    pub(crate) dir_factor: Pow2<R>,
    /// A power of two that object-space directions are multiplied by, so that they stay near
    /// unit length however small or large the object is (exact in floating point).
    pub(crate) dir_scale: Pow2<R>,
    /// `1 / dir_scale`.
    pub(crate) inv_dir_scale: Pow2<R>,
    /// Index into the scene's materials.
    pub(crate) material: u8,
    /// [`Object::DISTANT`] and [`Object::UNIFORM`], or neither.
    pub(crate) flags: u8,
    /// Composite object it belongs to, or [`NO_COMPOSITE`].
    pub(crate) composite: u16,
    /// World-to-object transform (the inverse of the placement) multiplied by the power of two
    /// `2^-unscale` that brings its largest linear entry into `(0.5, 1]`, so fixed point keeps
    /// full precision however large or small the object is (exact in floating point).
    pub(crate) to_object: Linear<R>,
    /// The placement's linear part, from canonical object space to the world (with
    /// [`Object::origin`], [`Object::to_world`]): hit points are mapped back through it
    /// ([`Object::surface_point`]).
    pub(crate) to_world: Linear<R>,
    /// World-space bounding box, padded for the scalar's rounding.
    pub(crate) bounds: Aabb<R>,
    /// The camera's eye in object space, `to_object.vector(eye - origin) * unscale`: the same
    /// for every eye ray, so it is computed once per scene instead of once per eye-ray test
    /// (not kept with `lean-objects`).
    #[cfg(not(feature = "lean-objects"))]
    pub(crate) eye_local: Vec3<R>,
    /// The direction towards the scene's first light, when it is directional, in object space
    /// as [`Object::intersect`] maps a ray's direction (zero otherwise): the same for every
    /// shadow ray towards that light, so it is mapped once per scene instead of once per test
    /// (not kept with `lean-objects`).
    #[cfg(not(feature = "lean-objects"))]
    pub(crate) light_local: Vec3<R>,
    /// Where it can appear, to each kind of ray that culling tests ([`crate::scene::region`]).
    pub(crate) region: Region<R>,
}

impl<R: Real> Default for Object<R> {
    /// A placeholder (unit sphere at the origin) for filling storage arrays.
    fn default() -> Self {
        let z = Vec3::new(R::ZERO, R::ZERO, R::ZERO);
        Object {
            shape: Shape::Sphere,
            origin: z,
            unscale: R::pow2(0),
            dir_factor: R::pow2(0),
            dir_scale: R::pow2(0),
            inv_dir_scale: R::pow2(0),
            material: 0,
            flags: Object::<R>::UNIFORM,
            composite: NO_COMPOSITE,
            to_object: Affine::identity().linear(),
            to_world: Affine::identity().linear(),
            bounds: Aabb { min: z, max: z },
            #[cfg(not(feature = "lean-objects"))]
            eye_local: z,
            #[cfg(not(feature = "lean-objects"))]
            light_local: z,
            region: Region::everywhere(),
        }
    }
}

impl<R> Object<R> {
    /// An object flag: it is small in a large scene, in fixed point: its world box,
    /// in the object's own space, reaches past the scalar's range, so a ray is first moved along
    /// itself to near the object ([`Object::intersect`]), and only points near it are mapped
    /// into its space.
    pub const DISTANT: u8 = 1;
    /// An object flag: its `to_object` is a multiple of the identity (a sphere or box placed by
    /// a uniform scale and a translation, as most of the SPD's are): a point or direction is
    /// mapped into object space by its first entry alone, the same products the whole matrix
    /// gives (its other entries are zero) without reading the rest of it.
    pub const UNIFORM: u8 = 2;

    /// An object from its parts, as [`bake::source`](crate::bake) writes them: for baked
    /// tables only, which hold objects of a validated scene (with `lean-objects`, `eye_local`
    /// and `light_local` are not kept).
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    pub const fn from_tables(
        shape: Shape<R>,
        origin: Vec3<R>,
        unscale: Pow2<R>,
        dir_factor: Pow2<R>,
        dir_scale: Pow2<R>,
        inv_dir_scale: Pow2<R>,
        material: u8,
        flags: u8,
        composite: u16,
        to_object: Linear<R>,
        to_world: Linear<R>,
        bounds: Aabb<R>,
        eye_local: Vec3<R>,
        light_local: Vec3<R>,
        eye_window: EyeWindow,
        eye_hull: EyeHull,
        shadow_window: ShadowWindow<R>,
    ) -> Self {
        // Not kept (a const fn cannot drop a generic value: it forgets them).
        #[cfg(feature = "lean-objects")]
        core::mem::forget((eye_local, light_local));
        Object {
            shape,
            origin,
            unscale,
            dir_factor,
            dir_scale,
            inv_dir_scale,
            material,
            flags,
            composite,
            to_object,
            to_world,
            bounds,
            #[cfg(not(feature = "lean-objects"))]
            eye_local,
            #[cfg(not(feature = "lean-objects"))]
            light_local,
            region: Region::from_tables(eye_window, eye_hull, shadow_window),
        }
    }
}

impl<R: Real> Object<R> {
    /// The camera's eye `eye` in the object's space, and the direction towards the first of
    /// `lights` when it is directional (zero otherwise) as a test maps a ray's direction: what
    /// the object keeps (without `lean-objects`) for eye rays and first-light shadow rays.
    #[cfg_attr(all(feature = "lean-objects", not(feature = "bake")), allow(dead_code))]
    pub(crate) fn local_eye_and_light(&self, eye: Vec3<R>, lights: &[Light<R>]) -> (Vec3<R>, Vec3<R>) {
        let light = match lights.first() {
            Some(Light::Directional { to_light, .. }) => self.direction_local(*to_light),
            _ => Vec3::new(R::ZERO, R::ZERO, R::ZERO),
        };
        (self.point_local(eye), light)
    }

    /// Nearest hit of a world ray with `tmin < t <= tmax`: `t` (the world ray's parameter) and
    /// the object-space normal and point.
    #[inline]
    pub fn intersect(&self, ray: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        if Self::TRACES_DISTANT && self.is_distant() {
            return self.intersect_near(ray, self.direction_local(ray.dir), tmin, tmax);
        }
        self.intersect_local(self.point_local(ray.origin), self.direction_local(ray.dir), tmin, tmax)
    }

    /// The test of a [distant](Object::DISTANT) object, its direction `dir` already in object
    /// space: the ray's origin moved along the ray to where it crosses the plane through the
    /// centre of the object's box across the axis the ray runs most along, `t0` along it, and
    /// the test made from there with the range shifted by `t0` (exact in fixed point, whose
    /// sums do not round). `t0` is one quotient of a difference of coordinates, so fixed point
    /// finds that point to a unit or two of its last place however far the ray came (a closest
    /// approach, through `dir . dir`, would carry its relative rounding times the distance).
    /// A ray that meets the box passes within its half diagonal of the centre, and crosses the
    /// plane within three halves of the box's extent of it: one whose crossing lies farther on
    /// some axis than twice the extent (and the scalar's offset) misses at once, and any other's
    /// moved origin lies within that distance, which the scene's validation checks the object's
    /// own coordinates hold there ([`crate::scene::SceneBuilder::finish`]).
    #[inline(never)]
    fn intersect_near(&self, ray: &Ray<R>, dir: Vec3<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        let (centre, reach) = self.near();
        let (o, d) = (ray.origin, ray.dir);
        let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
        let t0 = if ax >= ay && ax >= az {
            (centre.x - o.x) / d.x
        } else if ay >= az {
            (centre.y - o.y) / d.y
        } else {
            (centre.z - o.z) / d.z
        };
        let near = ray.at(t0);
        if (near - centre).max_abs() > reach {
            return None;
        }
        let tmax = if tmax == R::MAX { R::MAX } else { tmax - t0 };
        let hit = self.intersect_local(self.point_local(near), dir, tmin - t0, tmax)?;
        Some(ShapeHit { t: hit.t + t0, ..hit })
    }

    /// The centre of the object's box, and how far from it on any axis a distant object's test
    /// may map a point into its space ([`Object::intersect_near`]): twice the box's largest
    /// extent and the scalar's offset.
    #[inline]
    pub(crate) fn near(&self) -> (Vec3<R>, R) {
        let b = &self.bounds;
        let extent = b.extent();
        (b.min + (b.max - b.min) * R::HALF, extent + extent + R::offset_eps())
    }

    /// Whether this build traces [distant](Object::DISTANT) objects in `R`: with the
    /// `distant-objects` feature, in a scalar of narrow range (fixed point, whose own
    /// coordinates stop at 8,192). A float's range holds any scene's coordinates, so its images
    /// carry no distant branch.
    pub(crate) const TRACES_DISTANT: bool = cfg!(feature = "distant-objects") && R::LIMIT < 1e6;

    /// Whether the object's eye window meets the window rectangle `u` x `v` (2^-16 units,
    /// inclusive bounds, see [`EyeWindow`]).
    #[inline]
    pub fn eye_window_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        self.region.eye_window_meets(u, v)
    }

    /// Whether the object can appear in the window rectangle `u` x `v` (as
    /// [`Object::eye_window_meets`] takes it): its eye window meets it, and so does its
    /// [`EyeHull`] where the build keeps one (the `eye-hulls` feature).
    #[inline]
    pub fn eye_region_meets(&self, u: [i32; 2], v: [i32; 2]) -> bool {
        self.region.eye_meets(u, v)
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
        if Self::TRACES_DISTANT && self.is_distant() {
            return Ok(self.intersect_near(ray, self.direction_local(ray.dir), tmin, tmax));
        }
        #[cfg(not(feature = "lean-objects"))]
        let eye = self.eye_local;
        // The ray's origin is the camera's eye, which the scene's set-up mapped the same way.
        #[cfg(feature = "lean-objects")]
        let eye = self.point_local(ray.origin);
        Ok(self.intersect_local(eye, self.direction_local(ray.dir), tmin, tmax))
    }

    /// [`Object::intersect`] for a shadow ray towards the scene's first light when that light
    /// is directional (the ray's direction is the light's `to_light`): the same answer, with
    /// the direction's object-space image taken from the scene instead of transformed again.
    #[inline]
    pub fn intersect_first_light_ray(&self, ray: &Ray<R>, tmin: R, tmax: R) -> Option<ShapeHit<R>> {
        #[cfg(not(feature = "lean-objects"))]
        let towards = self.light_local;
        // The ray's direction is the light's, which the scene's set-up mapped the same way.
        #[cfg(feature = "lean-objects")]
        let towards = self.direction_local(ray.dir);
        if Self::TRACES_DISTANT && self.is_distant() {
            return self.intersect_near(ray, towards, tmin, tmax);
        }
        self.intersect_local(self.point_local(ray.origin), towards, tmin, tmax)
    }

    /// Whether a shadow ray towards the scene's first light (directional) at position `w` across
    /// the light can meet the object: `w` lies in its [`ShadowWindow`].
    #[inline]
    pub fn shadow_window_holds(&self, w: [R; 2]) -> bool {
        self.region.shadow_holds(w)
    }

    /// Where the object can appear ([`crate::scene::region`]).
    pub fn region(&self) -> &Region<R> {
        &self.region
    }

    /// A world point in object space, as the ray tests take it: relative to the object's
    /// origin, then through `to_object` and its scale.
    #[inline]
    pub(crate) fn point_local(&self, p: Vec3<R>) -> Vec3<R> {
        self.linear_local(p - self.origin).mul_pow2(self.unscale)
    }

    /// A world direction in object space, scaled to about unit length ([`Object::dir_scale`]).
    #[inline]
    pub(crate) fn direction_local(&self, d: Vec3<R>) -> Vec3<R> {
        self.linear_local(d).mul_pow2(self.dir_factor)
    }

    /// `to_object.vector(v)`; for a [uniform](Object::UNIFORM) object by its first entry alone.
    /// In fixed point the same bits (a product by zero is zero, a sum with zero exact); in
    /// floating point the same value (but for the sign of a zero sum).
    #[inline(always)]
    fn linear_local(&self, v: Vec3<R>) -> Vec3<R> {
        if self.flags & Self::UNIFORM != 0 {
            let s = self.to_object.m[0][0];
            Vec3::new(s * v.x, s * v.y, s * v.z)
        } else {
            self.to_object.vector(v)
        }
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
        self.origin
    }
    /// The placement, from canonical object space to the world.
    pub fn to_world(&self) -> Affine<R> {
        let mut a = self.to_world.affine();
        for (row, t) in a.m.iter_mut().zip([self.origin.x, self.origin.y, self.origin.z]) {
            row[3] = t;
        }
        a
    }
    /// Whether the object is [distant](Object::DISTANT).
    #[inline]
    pub fn is_distant(&self) -> bool {
        self.flags & Self::DISTANT != 0
    }
    /// The world point of a hit found with [`Object::intersect`]: the object-space point put
    /// on the surface ([`Shape::on_surface`]) and mapped through the placement. Its error is a
    /// few units of the last place of the point and of the object's own size, wherever the ray
    /// came from: `ray.at(t)` would carry the rounding of the ray's origin, which for an eye
    /// 10^14 units away is more than a thin object is thick.
    #[inline]
    pub fn surface_point(&self, point: Vec3<R>, normal: Vec3<R>) -> Vec3<R> {
        self.to_world.point_plus(self.shape.on_surface(point, normal), self.origin)
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

/// The vertex normals of a smooth triangle (an NFF `pp` patch): its shading normal at a hit is
/// theirs interpolated by the hit's barycentric weights, as Phong shading does, while its
/// intersection, its offsets and the side a ray meets stay the flat triangle's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Smooth<R> {
    /// The triangle's index among the scene's objects.
    pub object: u32,
    /// Unit world normals at its corners `a`, `b`, `c` (as given to
    /// [`SceneBuilder::add_smooth_triangle`](crate::SceneBuilder::add_smooth_triangle)).
    pub normals: [Vec3<R>; 3],
}

impl<R: Real> Smooth<R> {
    /// The shading normal at the canonical point `p` of the triangle ((0,0,0), (1,0,0), (0,0,1)
    /// in y = 0: `p.x` and `p.z` are the weights of `b` and `c`), unit, turned to the side of
    /// `face` (the flat normal the ray meets).
    pub fn normal(&self, p: Vec3<R>, face: Vec3<R>) -> Vec3<R> {
        let [a, b, c] = self.normals;
        let (u, w) = (p.x.max(R::ZERO).min(R::ONE), p.z.max(R::ZERO).min(R::ONE));
        let n = (a * (R::ONE - u - w).max(R::ZERO) + b * u + c * w).normalize();
        if !(n.dot(n) > R::ZERO) {
            face
        } else if n.dot(face) < R::ZERO {
            -n
        } else {
            n
        }
    }
}

/// The smooth triangles' normals a [`Parts`] holds: on the heap with `alloc`, none without.
#[cfg(feature = "alloc")]
pub(crate) type SmoothList<R> = alloc::vec::Vec<Smooth<R>>;
/// The smooth triangles' normals a [`Parts`] holds: on the heap with `alloc`, none without.
#[cfg(not(feature = "alloc"))]
pub(crate) type SmoothList<R> = Vec<Smooth<R>, 0>;

/// Where a parsed scene's composites, materials and lights are kept, beside the object storage
/// (lists of fixed capacity; a [`Scene`] holds exact slices of them, as a baked scene holds
/// slices of its tables, so that neither carries the unused capacity).
#[derive(Clone, Debug)]
pub struct Parts<R> {
    pub(crate) composites: Vec<Composite<R>, MAX_COMPOSITES>,
    pub(crate) materials: Vec<Material<R>, MAX_MATERIALS>,
    pub(crate) lights: Vec<Light<R>, MAX_LIGHTS>,
    pub(crate) smooth: SmoothList<R>,
}

impl<R> Parts<R> {
    /// Empty lists.
    pub const fn new() -> Self {
        Parts { composites: Vec::new(), materials: Vec::new(), lights: Vec::new(), smooth: SmoothList::new() }
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
    /// The effects the scene calls for ([`Effects::of`]).
    pub(crate) effects: Effects,
    /// The smooth triangles' vertex normals, by object index.
    pub(crate) smooth: &'a [Smooth<R>],
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
        effects: Effects,
        smooth: &'a [Smooth<R>],
    ) -> Self {
        Scene {
            objects,
            composites,
            materials,
            lights,
            ambient,
            background,
            camera,
            max_depth,
            world,
            shadow_basis,
            effects,
            smooth,
        }
    }
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
    /// The smooth triangles' vertex normals, in object order.
    pub fn smooth(&self) -> &'a [Smooth<R>] {
        self.smooth
    }
    /// The vertex normals of object `i`, when it is a smooth triangle.
    #[inline]
    pub fn smooth_of(&self, i: u32) -> Option<&'a Smooth<R>> {
        let k = self.smooth.binary_search_by_key(&i, |s| s.object).ok()?;
        self.smooth.get(k)
    }
}

/// What a scene calls for is read from its model: the set is worked out once, when the scene is
/// validated, and kept in it.
impl Effects {
    /// The effects a scene calls for. Shadows need a light and at least two objects (a lone
    /// convex solid never shadows itself; a lone open side can); reflection needs a
    /// material with `Ks > 0` on some object, refraction one with `Kt > 0`, highlights one with
    /// `Ks > 0` and a `shine` power.
    pub fn of<R: Real>(scene: &Scene<'_, R>) -> Self {
        scene.effects
    }

    /// [`Effects::of`] worked out from the scene's objects, materials and lights (when the scene
    /// is validated, so a baked scene carries it as a literal).
    pub(crate) fn called_for<R: Real>(scene: &Scene<'_, R>) -> Self {
        let used = |f: fn(&Material<R>) -> R| {
            scene.objects.iter().any(|o| f(at(scene.materials, o.material as usize)) > R::ZERO)
        };
        let mut e = Self::NONE;
        let self_shadowing = || scene.objects.iter().any(|o| !o.shape.is_solid());
        if !scene.lights.is_empty() && (scene.objects.len() > 1 || self_shadowing()) {
            e = e | Self::SHADOWS;
        }
        if used(|m| if m.shine > 0 { m.ks } else { R::ZERO }) {
            e = e | Self::HIGHLIGHTS;
        }
        if used(|m| m.ks) {
            e = e | Self::REFLECTION;
        }
        if used(|m| m.kt) {
            e = e | Self::REFRACTION;
        }
        if scene.lights.iter().any(|l| matches!(l, Light::Point { .. })) {
            e = e | Self::POINT_LIGHTS;
        }
        if !scene.composites.is_empty() {
            e = e | Self::COMPOSITES;
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::Object;
    use crate::fixed::Fx;
    use core::mem::{align_of, offset_of, size_of};

    /// What a baked table of objects in flash relies on (8-byte XIP cache lines): every record
    /// starts on a line and its bounds, what a walk's box test reads, do too. In fixed point and
    /// f32, the boards' scalars, the record is 240 bytes (200 with `lean-objects`: without the
    /// eye and light in object space and the shadow window), the bounds at 112.
    #[test]
    fn an_objects_bounds_start_on_a_flash_line() {
        fn check<R>() {
            let lean = cfg!(feature = "lean-objects");
            assert_eq!(align_of::<Object<R>>(), 8);
            assert_eq!(size_of::<Object<R>>(), if lean { 200 } else { 240 });
            assert_eq!(offset_of!(Object<R>, bounds), 112);
            // What an exact test reads: 76 bytes, a uniform object's 44 (to_object's first
            // entry at 40).
            assert_eq!(offset_of!(Object<R>, to_object), 40);
            assert_eq!(offset_of!(Object<R>, to_world), 76);
        }
        check::<Fx>();
        check::<f32>();
        assert_eq!(offset_of!(Object<f64>, bounds) % 8, 0);
    }

    /// A uniform object maps points and directions into its space by `to_object`'s first
    /// entry alone: in fixed point the bits the whole matrix gives, over scales and vectors of
    /// every size.
    #[test]
    fn a_uniform_objects_map_is_the_whole_matrixs() {
        use crate::math::{Linear, Vec3};
        use crate::scalar::Real;
        let mut rng = crate::generate::Rng::new(7);
        for _ in 0..2000 {
            let s = Fx::from_f64(rng.range(-1.0, 1.0));
            let z = Fx::ZERO;
            let o = Object::<Fx> { to_object: Linear { m: [[s, z, z], [z, s, z], [z, z, s]] }, ..Default::default() };
            assert!(o.flags & Object::<Fx>::UNIFORM != 0);
            let size = rng.range(-6.0, 12.0).exp2();
            let v = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let v = Vec3::new(Fx::from_f64(v.x * size), Fx::from_f64(v.y * size), Fx::from_f64(v.z * size));
            assert_eq!(o.linear_local(v), o.to_object.vector(v), "{s:?} {v:?}");
        }
    }
}
