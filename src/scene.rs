//! Objects, composite objects, materials, lights and camera: the validated scene.
//!
//! A [`SceneBuilder`] takes raw descriptions in `f64` (from the text parser or from code),
//! validates each one (finite numbers, invertible transforms, coordinates within the
//! scalar's range, capacities) and converts it to the tracer's scalar. The resulting
//! [`Scene`] is what the accelerators and the tracer trust. Object storage is a caller-provided
//! slice, so the capacity is the caller's choice and running out is an ordinary error.

use crate::math::{Aabb, Affine, Ray, Vec3};
use crate::scalar::Real;
use crate::shape::Shape;
use core::fmt;
use heapless::Vec;

/// Most materials a scene may define.
pub const MAX_MATERIALS: usize = 16;
/// Most lights a scene may define.
pub const MAX_LIGHTS: usize = 4;
/// Most composite objects (each gets a sub-lattice).
pub const MAX_GROUPS: usize = 16;
/// The group index of an object that belongs to no composite.
pub const NO_GROUP: u16 = u16::MAX;

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

/// The camera as given in a scene (eye, look-at, up, field of view in degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    /// Viewpoint `V`.
    pub eye: Vec3<f64>,
    /// Point looked at.
    pub look: Vec3<f64>,
    /// Up direction.
    pub up: Vec3<f64>,
    /// Horizontal and vertical field of view in degrees (the paper: 40 x 25).
    pub fov: (f64, f64),
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            eye: Vec3::new(0.0, 0.0, -10.0),
            look: Vec3::zero(),
            up: Vec3::new(0.0, 1.0, 0.0),
            fov: (40.0, 25.0),
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
}

impl<R: Real> Camera<R> {
    /// The eye ray through the point `(sx, sy)` of a `w x h` window, in pixel units from the
    /// top-left corner (pixel centres are at `i + 0.5`).
    pub fn ray(&self, sx2: i32, sy2: i32, w2: i32, h2: i32) -> Ray<R> {
        // Arguments are doubled coordinates so that pixel centres stay integers.
        let u = R::from_i32(2 * sx2 - w2) / R::from_i32(w2);
        let v = R::from_i32(h2 - 2 * sy2) / R::from_i32(h2);
        Ray::new(self.eye, self.forward + self.right * u + self.up * v)
    }
}

/// One primitive placed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object<R> {
    /// The canonical primitive.
    pub(crate) shape: Shape<R>,
    /// World-to-object transform (the inverse of the placement) multiplied by the power of two
    /// `1 / unscale` that brings its largest linear entry into `(0.5, 1]`, so fixed point keeps
    /// full precision however large or small the object is (exact in floating point).
    pub(crate) to_object: Affine<R>,
    /// The world point at the object's origin: rays are taken relative to it before
    /// `to_object` (whose translation is then zero), so a scene far from the world's origin
    /// loses no precision to cancellation.
    pub(crate) origin: Vec3<R>,
    /// The power of two that `to_object`'s results are multiplied by to get object space.
    pub(crate) unscale: R,
    /// `unscale * dir_scale`: what `to_object`'s direction results are multiplied by.
    pub(crate) dir_factor: R,
    /// Index into the scene's materials.
    pub(crate) material: u8,
    /// Composite object it belongs to, or [`NO_GROUP`].
    pub(crate) group: u16,
    /// World-space bounding box, padded for the scalar's rounding.
    pub(crate) bounds: Aabb<R>,
    /// A power of two that object-space directions are multiplied by, so that they stay near
    /// unit length however small or large the object is (exact in floating point).
    pub(crate) dir_scale: R,
    /// `1 / dir_scale`.
    pub(crate) inv_dir_scale: R,
}

impl<R: Real> Default for Object<R> {
    /// A placeholder (unit sphere at the origin) for filling storage arrays.
    fn default() -> Self {
        let z = Vec3::new(R::ZERO, R::ZERO, R::ZERO);
        Object {
            shape: Shape::Sphere,
            to_object: Affine::identity(),
            origin: z,
            unscale: R::ONE,
            dir_factor: R::ONE,
            material: 0,
            group: NO_GROUP,
            bounds: Aabb { min: z, max: z },
            dir_scale: R::ONE,
            inv_dir_scale: R::ONE,
        }
    }
}

impl<R: Real> Object<R> {
    /// Nearest hit of a world ray with `tmin < t <= tmax`: `t` and the object-space normal.
    #[inline]
    pub fn intersect(&self, ray: &Ray<R>, tmin: R, tmax: R) -> Option<(R, Vec3<R>)> {
        let r = Ray::new(
            self.to_object.vector(ray.origin - self.origin) * self.unscale,
            self.to_object.vector(ray.dir) * self.dir_factor,
        );
        // With the direction scaled by k, the object-space parameter is t / k. Multiplying by
        // a power of two is exact in floating point but rounds in fixed point, so the range is
        // checked on the world parameter: a hit exactly at `tmax` (a tie with the best hit so
        // far) is then found whichever scalar runs.
        // The object-space limit is widened by the scalar's padding so rounding cannot exclude a
        // hit at exactly `tmax`, yet still prunes hits well beyond it.
        let far = if tmax == R::MAX {
            R::MAX
        } else {
            let f = tmax * self.inv_dir_scale;
            f + (f.abs() + R::ONE) * R::pad_eps()
        };
        let (t, n) = self.shape.intersect(&r, tmin * self.inv_dir_scale, far)?;
        let t = t * self.dir_scale;
        (t > tmin && t <= tmax).then_some((t, n))
    }
    /// The canonical primitive.
    pub fn shape(&self) -> Shape<R> {
        self.shape
    }
    /// Index into the scene's materials.
    pub fn material(&self) -> u8 {
        self.material
    }
    /// Composite object it belongs to, or [`NO_GROUP`].
    pub fn group(&self) -> u16 {
        self.group
    }
    /// World-space bounding box, padded for the scalar's rounding.
    pub fn bounds(&self) -> Aabb<R> {
        self.bounds
    }
    /// The world point at the object's origin.
    pub fn origin(&self) -> Vec3<R> {
        self.origin
    }
    /// The map from a world offset relative to [`Object::origin`] to object space (the
    /// inverse of the placement), without the scaling the stored copy carries for precision.
    pub fn world_to_object(&self) -> Affine<R> {
        let mut t = self.to_object;
        for row in t.m.iter_mut() {
            for v in row.iter_mut() {
                *v *= self.unscale;
            }
        }
        t
    }
    /// Unit world-space normal from an object-space normal (inverse-transpose rule).
    pub fn world_normal(&self, n_obj: Vec3<R>) -> Vec3<R> {
        self.to_object.transpose_vector(n_obj).normalize()
    }
}

/// A composite object: a contiguous run of objects with a common box (gets a sub-lattice).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Group<R> {
    /// Index of its first object (as wide as object indices: a group may start anywhere).
    pub first: u32,
    /// Number of objects (as wide as object indices: a group may hold any number).
    pub len: u32,
    /// Union of its objects' boxes.
    pub bounds: Aabb<R>,
}

/// Why a scene was refused.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneError {
    /// More objects than the storage holds.
    TooManyObjects {
        /// Objects the storage holds.
        capacity: usize,
        /// Objects the scene has (at least: the builder knows those added so far; the
        /// parser counts the whole text).
        needed: usize,
    },
    /// More than [`MAX_MATERIALS`] materials.
    TooManyMaterials,
    /// More than [`MAX_LIGHTS`] lights.
    TooManyLights,
    /// More than [`MAX_GROUPS`] composite objects.
    TooManyGroups,
    /// A composite inside a composite.
    NestedGroup,
    /// `end` with no open composite.
    EndWithoutGroup,
    /// The file ended inside a composite.
    UnclosedGroup,
    /// A composite with no objects.
    EmptyGroup,
    /// A transform that flattens space (zero or near-zero scale).
    SingularTransform,
    /// A NaN or infinite number.
    NotFinite,
    /// A coordinate beyond what the scalar can represent safely.
    OutOfRange {
        /// The largest magnitude allowed.
        limit: f64,
        /// The scalar's name.
        scalar: &'static str,
    },
    /// A number other than a coordinate (light intensity, ambient, background, material
    /// coefficient, index of refraction) beyond what the scalar holds.
    ValueOutOfRange {
        /// What the number is.
        what: &'static str,
        /// The largest magnitude allowed.
        limit: f64,
        /// The scalar's name.
        scalar: &'static str,
    },
    /// Transforms composed into one whose entries overflow `f64` (`scale 1e200 scale 1e200`).
    TransformOverflow,
    /// The brightness summed along one ray's intersection tree could exceed what the scalar
    /// holds (huge intensities, or reflection and transmission coefficients well above 1).
    TooBright {
        /// The largest sum the scene allows (at the deepest tree the tracer supports).
        bound: f64,
        /// The scalar's limit.
        limit: f64,
        /// The scalar's name.
        scalar: &'static str,
    },
    /// An object thinner than the distance secondary rays start off a surface in this scalar:
    /// a ray leaving one face would start beyond the other.
    ObjectTooThin {
        /// Index of the object (in the order it was added).
        object: usize,
        /// Its smallest width.
        size: f64,
        /// The smallest width the scalar can trace at the object's place in this scene.
        smallest: f64,
        /// The scalar's name.
        scalar: &'static str,
    },
    /// A size that must be positive is not (radius, height, box extent).
    NonPositiveSize,
    /// A material coefficient below zero, or an index of refraction below 1.
    BadCoefficient,
    /// A camera whose view direction is zero or parallel to its up vector.
    DegenerateCamera,
    /// A field of view outside `(0, 180)` degrees.
    BadFieldOfView,
    /// A light with a zero direction.
    DegenerateLight,
    /// The scene has no objects.
    NoObjects,
    /// Inside the world box, an object's own coordinates grow beyond what the scalar holds
    /// (the object is too small for the size of the scene).
    ObjectOutOfRange {
        /// Index of the object (in the order it was added).
        object: usize,
        /// The largest object-space coordinate reached.
        reach: f64,
        /// The scalar's limit.
        limit: f64,
        /// The scalar's name.
        scalar: &'static str,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::TooManyObjects { capacity, needed } => {
                write!(f, "too many objects: the scene needs storage for {needed}, it holds {capacity}")
            }
            SceneError::TooManyMaterials => write!(f, "too many materials (at most {MAX_MATERIALS})"),
            SceneError::TooManyLights => write!(f, "too many lights (at most {MAX_LIGHTS})"),
            SceneError::TooManyGroups => write!(f, "too many composite objects (at most {MAX_GROUPS})"),
            SceneError::NestedGroup => write!(f, "a group cannot be opened inside another group"),
            SceneError::EndWithoutGroup => write!(f, "`end` without an open group"),
            SceneError::UnclosedGroup => write!(f, "group not closed with `end`"),
            SceneError::EmptyGroup => write!(f, "group has no objects"),
            SceneError::SingularTransform => write!(f, "transform is singular (zero or near-zero scale)"),
            SceneError::NotFinite => write!(f, "number is not finite"),
            SceneError::OutOfRange { limit, scalar } => {
                write!(f, "coordinate out of range for {scalar}: magnitude must stay below {}", Round(*limit))
            }
            SceneError::ValueOutOfRange { what, limit, scalar } => {
                write!(f, "{what} out of range for {scalar}: magnitude must stay below {}", Round(*limit))
            }
            SceneError::TransformOverflow => {
                write!(f, "transform out of range: composed, its entries overflow (more than 1e308)")
            }
            SceneError::TooBright { bound, limit, scalar } => write!(
                f,
                "brightness out of range for {scalar}: lights, ambient, background and coefficients \
                 add up to {} along one ray, the limit is {} (lower the intensities, or keep ks + kt \
                 near 1 or below)",
                Round(*bound),
                Round(*limit)
            ),
            SceneError::ObjectTooThin { object, size, smallest, scalar } => write!(
                f,
                "object {object} is too thin for this scene in {scalar}: it is {} across, the \
                 smallest this scalar traces here is {} (secondary rays start that far off a \
                 surface; make it thicker or the scene smaller{})",
                Round(*size),
                Round(*smallest),
                if *scalar == "f64" { "" } else { ", or trace in f64" }
            ),
            SceneError::NonPositiveSize => write!(f, "size must be positive"),
            SceneError::BadCoefficient => {
                write!(f, "coefficients must be >= 0 and the index of refraction >= 1")
            }
            SceneError::DegenerateCamera => {
                write!(f, "camera looks nowhere or straight along its up vector")
            }
            SceneError::BadFieldOfView => write!(f, "field of view must be between 0 and 180 degrees"),
            SceneError::DegenerateLight => write!(f, "light direction is zero"),
            SceneError::NoObjects => write!(f, "scene has no objects"),
            SceneError::ObjectOutOfRange { object, reach, limit, scalar } => write!(
                f,
                "object {object} is too small for this scene in {scalar}: its own coordinates reach \
                 {} inside the world box, the limit is {} (make it larger or the scene smaller)",
                Round(*reach),
                Round(*limit)
            ),
        }
    }
}

impl core::error::Error for SceneError {}

/// A non-negative number shown rounded, with integer formatting only (`8192`, `1e15`,
/// `3e-5`): core's float formatting would add about 12 KB to every firmware image for a few
/// error messages.
struct Round(f64);

impl fmt::Display for Round {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut v = self.0.abs();
        if !v.is_finite() {
            return write!(f, "inf");
        }
        if v == 0.0 {
            return write!(f, "0");
        }
        if v < 0.5 {
            // One significant digit: 0.00012 is `1e-4`.
            let mut e = 0;
            while v < 0.95 {
                v *= 10.0;
                e += 1;
            }
            return write!(f, "{}e-{e}", ((v + 0.5) as u64).min(9));
        }
        if v < 1e6 {
            return write!(f, "{}", (v + 0.5) as u64);
        }
        let mut e = 0;
        while v >= 10.0 {
            v /= 10.0;
            e += 1;
        }
        write!(f, "{}e{e}", (v + 0.5) as u64)
    }
}

/// A validated scene, ready to trace.
#[derive(Debug)]
pub struct Scene<'a, R> {
    /// All primitives; the objects of a composite are contiguous.
    pub(crate) objects: &'a [Object<R>],
    /// Composite objects.
    pub(crate) groups: Vec<Group<R>, MAX_GROUPS>,
    /// Materials.
    pub(crate) materials: Vec<Material<R>, MAX_MATERIALS>,
    /// Lights.
    pub(crate) lights: Vec<Light<R>, MAX_LIGHTS>,
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
}

impl<'a, R: Real> Scene<'a, R> {
    /// All primitives; the objects of a composite are contiguous.
    pub fn objects(&self) -> &'a [Object<R>] {
        self.objects
    }
    /// Composite objects.
    pub fn groups(&self) -> &[Group<R>] {
        &self.groups
    }
    /// Materials.
    pub fn materials(&self) -> &[Material<R>] {
        &self.materials
    }
    /// Lights.
    pub fn lights(&self) -> &[Light<R>] {
        &self.lights
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

/// Builds and validates a [`Scene`] into caller-provided object storage.
#[derive(Debug)]
pub struct SceneBuilder<'a, R> {
    storage: &'a mut [Object<R>],
    len: usize,
    groups: Vec<Group<R>, MAX_GROUPS>,
    materials: Vec<Material<R>, MAX_MATERIALS>,
    lights: Vec<Light<R>, MAX_LIGHTS>,
    open_group: Option<(usize, Affine<f64>, Aabb<f64>)>,
    /// Ambient intensity `Ia`.
    pub ambient: f64,
    /// Background gray.
    pub background: f64,
    /// Camera description.
    pub camera: CameraDesc,
    /// Maximum depth of the intersection tree.
    pub max_depth: u8,
}

fn check_finite(vals: &[f64]) -> Result<(), SceneError> {
    if vals.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SceneError::NotFinite)
    }
}

/// Checks a number other than a coordinate against the scalar's range (`what` names it).
pub fn check_value<R: Real>(what: &'static str, v: f64) -> Result<(), SceneError> {
    check_finite(&[v])?;
    let limit = value_limit::<R>(what);
    if v.abs() < limit {
        Ok(())
    } else {
        Err(SceneError::ValueOutOfRange { what, limit, scalar: R::NAME })
    }
}

/// The largest magnitude of a shading number in `R`: coordinates' limit, or for the index of
/// refraction its square root (refraction squares the ratio of indices).
fn value_limit<R: Real>(what: &'static str) -> f64 {
    if what == IOR {
        libm::sqrt(R::LIMIT)
    } else {
        R::LIMIT
    }
}

/// The name [`check_value`] uses for the index of refraction.
pub const IOR: &str = "index of refraction";

fn check_range<R: Real>(v: Vec3<f64>) -> Result<(), SceneError> {
    check_finite(&[v.x, v.y, v.z])?;
    if v.max_abs() < R::LIMIT {
        Ok(())
    } else {
        Err(SceneError::OutOfRange { limit: R::LIMIT, scalar: R::NAME })
    }
}

impl<'a, R: Real> SceneBuilder<'a, R> {
    /// A builder storing objects in `storage` (its length is the object capacity).
    pub fn new(storage: &'a mut [Object<R>]) -> Self {
        SceneBuilder {
            storage,
            len: 0,
            groups: Vec::new(),
            materials: Vec::new(),
            lights: Vec::new(),
            open_group: None,
            ambient: 0.2,
            background: 0.0,
            camera: CameraDesc::default(),
            max_depth: 5,
        }
    }

    /// Number of objects so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no object was added yet.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds a material and returns its index.
    pub fn add_material(&mut self, m: Material<f64>) -> Result<u8, SceneError> {
        check_finite(&[m.ka, m.kd, m.ks, m.kt, m.ior])?;
        if m.ka < 0.0 || m.kd < 0.0 || m.ks < 0.0 || m.kt < 0.0 || m.ior < 1.0 {
            return Err(SceneError::BadCoefficient);
        }
        for v in [m.ka, m.kd, m.ks, m.kt] {
            check_value::<R>("coefficient", v)?;
        }
        check_value::<R>(IOR, m.ior)?;
        let f = R::from_f64;
        let conv = Material { ka: f(m.ka), kd: f(m.kd), ks: f(m.ks), kt: f(m.kt), ior: f(m.ior) };
        self.materials.push(conv).map_err(|_| SceneError::TooManyMaterials)?;
        Ok((self.materials.len() - 1) as u8)
    }

    /// Adds a light. A directional light's `dir` is the direction the light travels.
    pub fn add_light(&mut self, l: Light<f64>) -> Result<(), SceneError> {
        let conv = match l {
            Light::Directional { to_light, intensity } => {
                check_finite(&[to_light.x, to_light.y, to_light.z])?;
                check_value::<R>("light intensity", intensity)?;
                // A direction so short (subnormal) that normalising it overflows is as unusable
                // as a zero one.
                let unit = to_light.normalize();
                if to_light.max_abs() == 0.0 || !is_unit(unit) {
                    return Err(SceneError::DegenerateLight);
                }
                Light::Directional { to_light: unit.cast(), intensity: R::from_f64(intensity) }
            }
            Light::Point { pos, intensity } => {
                check_range::<R>(pos)?;
                check_value::<R>("light intensity", intensity)?;
                Light::Point { pos: pos.cast(), intensity: R::from_f64(intensity) }
            }
        };
        self.lights.push(conv).map_err(|_| SceneError::TooManyLights)
    }

    /// Opens a composite object placed by `t`; objects until [`SceneBuilder::end_group`] belong to it.
    pub fn begin_group(&mut self, t: Affine<f64>) -> Result<(), SceneError> {
        if self.open_group.is_some() {
            return Err(SceneError::NestedGroup);
        }
        if self.groups.is_full() {
            return Err(SceneError::TooManyGroups);
        }
        checked_inverse(&t)?;
        self.open_group = Some((self.len, t, Aabb::empty()));
        Ok(())
    }

    /// Closes the open composite object.
    pub fn end_group(&mut self) -> Result<(), SceneError> {
        let (first, _, bounds) = self.open_group.take().ok_or(SceneError::EndWithoutGroup)?;
        if self.len == first {
            return Err(SceneError::EmptyGroup);
        }
        // Object indices are below 2^31 (checked in `add_object`), so both fit in u32.
        let g = Group { first: first as u32, len: (self.len - first) as u32, bounds: bounds.cast_padded() };
        self.groups.push(g).map_err(|_| SceneError::TooManyGroups)
    }

    /// Adds a primitive placed by `to_world` (inside an open composite, the composite's
    /// transform is applied after it).
    pub fn add_object(&mut self, shape: Shape<f64>, to_world: Affine<f64>, material: u8) -> Result<(), SceneError> {
        // Lattice references keep the top bit for sub-lattices, so 2^31 objects at most.
        if self.len >= self.storage.len() || self.len >= 1 << 31 {
            return Err(SceneError::TooManyObjects { capacity: self.storage.len(), needed: self.len + 1 });
        }
        let place = match &self.open_group {
            Some((_, g, _)) => g.after(&to_world),
            None => to_world,
        };
        // `place` is `to_world` after an invertible group transform: checking it covers both.
        let inv = checked_inverse(&place)?;
        let top = match shape {
            Shape::Cone { top } => top,
            _ => 0.0,
        };
        check_finite(&[top])?;
        if top < 0.0 {
            return Err(SceneError::NonPositiveSize);
        }
        let bounds = world_bounds(&shape, &place);
        // The padded box is what the lattice registers: it must be in range too.
        let padded = bounds.padded_for::<R>();
        check_range::<R>(padded.min)?;
        check_range::<R>(padded.max)?;
        let material = material.min(self.materials.len().saturating_sub(1) as u8);
        if self.materials.is_empty() {
            self.add_material(Material::DEFAULT)?;
        }
        let group = match &mut self.open_group {
            Some((_, _, gb)) => {
                *gb = gb.union(&bounds);
                self.groups.len() as u16
            }
            None => NO_GROUP,
        };
        let shape = match shape {
            Shape::Sphere => Shape::Sphere,
            Shape::Cylinder => Shape::Cylinder,
            Shape::Cone { top } => Shape::Cone { top: R::from_f64(top) },
            Shape::Box => Shape::Box,
        };
        // Largest stretch of a direction into object space, rounded up to a power of two.
        let m = &inv.m;
        let stretch = (0..3).map(|i| libm::sqrt(m[i][0] * m[i][0] + m[i][1] * m[i][1] + m[i][2] * m[i][2])).fold(0.0, f64::max);
        let largest = m.iter().flat_map(|r| r[..3].iter()).fold(0.0f64, |a, v| a.max(v.abs()));
        // An object so small that its inverse transform leaves f64's comfortable range is too
        // small for any scene (its own coordinates would overflow).
        if !(stretch < 1e200 && largest > 1e-200) {
            return Err(SceneError::ObjectOutOfRange { object: self.len, reach: f64::INFINITY, limit: R::LIMIT, scalar: R::NAME });
        }
        let dir_scale = 1.0 / pow2_at_least(stretch);
        let unscale = pow2_at_least(largest);
        let mut scaled = inv;
        scaled.m.iter_mut().flatten().for_each(|v| *v /= unscale);
        scaled.m.iter_mut().for_each(|row| row[3] = 0.0);
        let origin = Vec3::new(place.m[0][3], place.m[1][3], place.m[2][3]);
        self.storage[self.len] = Object {
            shape,
            to_object: scaled.cast(),
            origin: origin.cast(),
            unscale: R::from_f64(unscale),
            dir_factor: R::from_f64(unscale * dir_scale),
            material,
            group,
            bounds: bounds.cast_padded(),
            dir_scale: R::from_f64(dir_scale),
            inv_dir_scale: R::from_f64(1.0 / dir_scale),
        };
        self.len += 1;
        Ok(())
    }

    /// Validates the whole and returns the scene.
    pub fn finish(mut self) -> Result<Scene<'a, R>, SceneError> {
        if self.open_group.is_some() {
            return Err(SceneError::UnclosedGroup);
        }
        if self.len == 0 {
            return Err(SceneError::NoObjects);
        }
        if self.materials.is_empty() {
            self.add_material(Material::DEFAULT)?;
        }
        let c = self.camera;
        check_range::<R>(c.eye)?;
        check_range::<R>(c.look)?;
        check_finite(&[c.up.x, c.up.y, c.up.z, c.fov.0, c.fov.1])?;
        check_value::<R>("ambient", self.ambient)?;
        check_value::<R>("background", self.background)?;
        if !(c.fov.0 > 0.0 && c.fov.0 < 180.0 && c.fov.1 > 0.0 && c.fov.1 < 180.0) {
            return Err(SceneError::BadFieldOfView);
        }
        let forward = (c.look - c.eye).normalize();
        let right = forward.cross(c.up);
        if forward.max_abs() == 0.0 || right.length() < 1e-9 * c.up.length() || c.up.max_abs() == 0.0 {
            return Err(SceneError::DegenerateCamera);
        }
        // Left-handed like POV-Ray: x right, y up, z into the screen, so right = up x forward.
        let right = -right.normalize();
        let up = forward.cross(right).normalize();
        if !(is_unit(forward) && is_unit(right) && is_unit(up)) {
            // Directions so short (subnormal) or long that normalising them overflowed.
            return Err(SceneError::DegenerateCamera);
        }
        let tx = libm::tan(c.fov.0.to_radians_core() / 2.0);
        let ty = libm::tan(c.fov.1.to_radians_core() / 2.0);
        let camera =
            Camera { eye: c.eye.cast(), forward: forward.cast(), right: (right * tx).cast(), up: (up * ty).cast() };
        let objects: &'a [Object<R>] = &self.storage[..self.len];
        let mut world = Aabb { min: camera.eye, max: camera.eye };
        for o in objects {
            world = world.union(&o.bounds);
        }
        check_range::<R>(world.min.cast())?;
        check_range::<R>(world.max.cast())?;
        // Every ray the tracer casts stays in the world box (or leaves it), so an object's own
        // coordinates never exceed those of the world box's corners in its space.
        for (i, o) in objects.iter().enumerate() {
            let inv = o.to_object.cast::<f64>();
            let unscale = o.unscale.to_f64();
            let reach = (0..8)
                .map(|c| {
                    let p = Vec3::new(
                        if c & 1 == 0 { world.min.x } else { world.max.x },
                        if c & 2 == 0 { world.min.y } else { world.max.y },
                        if c & 4 == 0 { world.min.z } else { world.max.z },
                    );
                    (inv.vector(p.cast() - o.origin.cast()) * unscale).max_abs()
                })
                .fold(0.0, f64::max);
            if reach >= R::LIMIT {
                return Err(SceneError::ObjectOutOfRange { object: i, reach, limit: R::LIMIT, scalar: R::NAME });
            }
        }
        let extent = world.extent();
        for (i, o) in objects.iter().enumerate() {
            let (size, smallest) = thickness(o, extent);
            if size < smallest {
                return Err(SceneError::ObjectTooThin { object: i, size, smallest, scalar: R::NAME });
            }
        }
        let bound = brightness_bound(&self.materials, &self.lights, self.ambient, self.background);
        if !(bound < R::LIMIT) {
            return Err(SceneError::TooBright { bound, limit: R::LIMIT, scalar: R::NAME });
        }
        Ok(Scene {
            objects,
            groups: self.groups,
            materials: self.materials,
            lights: self.lights,
            ambient: R::from_f64(self.ambient),
            background: R::from_f64(self.background),
            camera,
            max_depth: self.max_depth,
            world,
        })
    }
}

/// Whether `v` is finite and of length 1 (to rounding).
fn is_unit(v: Vec3<f64>) -> bool {
    (v.length() - 1.0).abs() < 1e-6
}

/// The inverse of a transform, refusing one whose entries overflowed (composition of huge
/// factors) or that is singular.
fn checked_inverse(t: &Affine<f64>) -> Result<Affine<f64>, SceneError> {
    if t.m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(SceneError::TransformOverflow);
    }
    t.inverse().ok_or(SceneError::SingularTransform)
}

/// An object's smallest width (its canonical primitive's narrowest width divided by the
/// largest stretch of its world-to-object map), and the smallest width the scalar can trace
/// there: twice the offset of secondary rays at the object's farthest point (a ray entering
/// the object starts that far inside it, so it must stay in the inner half).
fn thickness<R: Real>(o: &Object<R>, extent: R) -> (f64, f64) {
    let m = o.to_object.cast::<f64>();
    let unscale = o.unscale.to_f64();
    let stretch = (0..3)
        .map(|i| libm::sqrt(m.m[i][0] * m.m[i][0] + m.m[i][1] * m.m[i][1] + m.m[i][2] * m.m[i][2]))
        .fold(0.0, f64::max)
        * unscale;
    // Narrowest width of the canonical primitive: sphere 2 (diameter), the others 1.
    let width = if let Shape::Sphere = o.shape { 2.0 } else { 1.0 };
    let far = o.bounds.min.max_abs().max(o.bounds.max.max_abs());
    (width / stretch, 2.0 * R::offset(far, extent).to_f64())
}

/// The largest brightness one eye ray can sum in the intersection tree at the deepest depth
/// the tracer supports: each node adds `Ia*Ka + Kd * sum |Ip|` (or the background) and passes
/// `Ks + Kt` of its weight to its children (a ray that misses adds the background).
fn brightness_bound<R: Real>(materials: &[Material<R>], lights: &[Light<R>], ambient: f64, background: f64) -> f64 {
    let ip: f64 = lights
        .iter()
        .map(|l| match *l {
            Light::Directional { intensity, .. } | Light::Point { intensity, .. } => intensity.to_f64().abs(),
        })
        .sum();
    let bg = background.abs();
    let mut below = materials.iter().map(|m| ambient.abs() * m.ka.to_f64() + m.kd.to_f64() * ip).fold(bg, f64::max);
    for _ in 0..crate::trace::MAX_DEPTH {
        below = materials
            .iter()
            .map(|m| ambient.abs() * m.ka.to_f64() + m.kd.to_f64() * ip + (m.ks.to_f64() + m.kt.to_f64()) * below)
            .fold(bg, f64::max);
    }
    below
}

/// The smallest power of two at or above `x > 0` (without `log2`/`exp2`, which would bring
/// libm's 4 KB table into the firmware).
fn pow2_at_least(x: f64) -> f64 {
    let mut p = 1.0;
    while p < x && p < f64::MAX {
        p *= 2.0;
    }
    while p * 0.5 >= x {
        p *= 0.5;
    }
    p
}

trait ToRadians {
    fn to_radians_core(self) -> f64;
}
impl ToRadians for f64 {
    fn to_radians_core(self) -> f64 {
        self * core::f64::consts::PI / 180.0
    }
}

/// World box of a placed primitive: exact for spheres (an ellipsoid's extent along axis `i`
/// is the length of row `i` of the linear part), the transformed corners otherwise.
fn world_bounds(shape: &Shape<f64>, place: &Affine<f64>) -> Aabb<f64> {
    let m = &place.m;
    if let Shape::Sphere = shape {
        let c = Vec3::new(m[0][3], m[1][3], m[2][3]);
        let e = |i: usize| libm::sqrt(m[i][0] * m[i][0] + m[i][1] * m[i][1] + m[i][2] * m[i][2]);
        let h = Vec3::new(e(0), e(1), e(2));
        return Aabb { min: c - h, max: c + h };
    }
    let (lo, hi) = shape.bounds();
    let mut b = Aabb::empty();
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        b.include(place.point(p));
    }
    b
}
