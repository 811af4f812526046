//! The builder: raw descriptions in `f64` in, validated objects in the tracer's scalar out.

use super::effects::{Effects, MAX_DEPTH};
use super::error::SceneError;
use super::model::{Composite, Light, Material, Object, Parts, Scene, Smooth, NO_COMPOSITE};
use super::region::Region;
use super::windows::{shadow_basis, Regions};
use crate::camera::{lowest_terms, resolvable_pixels, Camera, CameraDesc};
use crate::math::{Aabb, Affine, Linear, Vec3};
use crate::scalar::{log2_of_pow2, Real};
use crate::shape::Shape;

/// Builds and validates a [`Scene`] into caller-provided object storage.
#[derive(Debug)]
pub struct SceneBuilder<'a, R> {
    storage: &'a mut [Object<R>],
    len: usize,
    /// The composites, materials and lights, as the scene will hold them.
    parts: &'a mut Parts<R>,
    open_composite: Option<(usize, Affine<f64>, Aabb<f64>)>,
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
/// refraction the smaller of its square root (refraction squares the ratio of indices) and
/// [`IOR_SPREAD`] over the scalar's resolution. A ray leaving glass of index `eta` near the
/// normal has its direction's part along the surface multiplied by `eta`, and that part is only
/// known to the resolution: past the bound, the refracted rays of f32 scatter by more than a
/// thousandth of a radian (an index of 40,000 put 8 % of a picture's pixels off f64's).
fn value_limit<R: Real>(what: &'static str) -> f64 {
    if what == IOR {
        libm::sqrt(R::LIMIT).min(IOR_SPREAD / R::RESOLUTION)
    } else {
        R::LIMIT
    }
}

/// The largest error (radians) a refracted ray's direction may carry from the rounding of the
/// incoming one, times the index: 2^-10, about a tenth of a pixel at 128 pixels across a
/// 60-degree view.
pub const IOR_SPREAD: f64 = 1.0 / 1024.0;

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
    /// A builder storing objects in `storage` (its length is the object capacity) and the
    /// composites, materials and lights in `parts` (emptied first).
    pub fn new(storage: &'a mut [Object<R>], parts: &'a mut Parts<R>) -> Self {
        *parts = Parts::new();
        SceneBuilder {
            storage,
            len: 0,
            parts,
            open_composite: None,
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
        let conv = Material { ka: f(m.ka), kd: f(m.kd), ks: f(m.ks), kt: f(m.kt), ior: f(m.ior), shine: m.shine };
        self.parts.materials.push(conv).map_err(|_| SceneError::TooManyMaterials)?;
        Ok((self.parts.materials.len() - 1) as u8)
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
        self.parts.lights.push(conv).map_err(|_| SceneError::TooManyLights)
    }

    /// Adds the triangle `a`, `b`, `c` (world or composite coordinates, as
    /// [`SceneBuilder::add_object`] places objects): [`Shape::Triangle`] placed by the map whose
    /// x and z columns are its sides `b - a` and `c - a` and whose y column is its unit normal
    /// times the square root of its sides' cross product (about the triangle's size, so the map
    /// is as well conditioned as the triangle). A triangle of no area is refused.
    pub fn add_triangle(&mut self, [a, b, c]: [Vec3<f64>; 3], material: u8) -> Result<(), SceneError> {
        check_range::<R>(a)?;
        check_range::<R>(b)?;
        check_range::<R>(c)?;
        let (e1, e2) = (b - a, c - a);
        let cross = e1.cross(e2);
        let area2 = cross.length();
        if !(area2 > 0.0)
            || !area2.is_finite()
            || area2
                < 1e-12 * {
                    let l = e1.length().max(e2.length());
                    l * l
                }
        {
            return Err(SceneError::DegenerateTriangle);
        }
        // y = n * sqrt(|e1 x e2|) with n the unit normal: `cross / sqrt(|cross|)`.
        let y = cross * (1.0 / libm::sqrt(area2));
        let place = Affine::from_columns(e1, y, e2, a);
        self.add_object(Shape::Triangle, place, material)
    }

    /// Adds a smooth triangle: [`SceneBuilder::add_triangle`] with a normal at each corner
    /// (NFF's `pp`), interpolated across it for shading ([`Smooth`]). A corner's normal of no
    /// length (or not finite) takes the flat one; any other, however long or short, is taken
    /// as its direction; normals need not face the triangle's side.
    pub fn add_smooth_triangle(
        &mut self,
        corners: [Vec3<f64>; 3],
        normals: [Vec3<f64>; 3],
        material: u8,
    ) -> Result<(), SceneError> {
        if crate::scene::MAX_SMOOTH == 0 {
            return Err(SceneError::SmoothLeftOut);
        }
        self.add_triangle(corners, material)?;
        let [a, b, c] = corners;
        let flat = (b - a).cross(c - a).normalize();
        // Divided by its largest component first, so a normal of any finite length (1e300,
        // 1e-300) keeps its direction: its square would overflow or vanish.
        let unit = |n: Vec3<f64>| {
            let m = n.max_abs();
            if m > 0.0 && m.is_finite() {
                let v = Vec3::new(n.x / m, n.y / m, n.z / m);
                v * (1.0 / v.length())
            } else {
                flat
            }
        };
        // Inside a composite the corners are the group's: its normals map by the inverse
        // transpose of the group's transform.
        let group = match &self.open_composite {
            Some((_, g, _)) => Some(checked_inverse(g)?),
            None => None,
        };
        let to_world = |n: Vec3<f64>| match &group {
            Some(inv) => {
                let m = &inv.m;
                Vec3::new(
                    m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
                    m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
                    m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z,
                )
            }
            None => n,
        };
        let object = (self.len - 1) as u32;
        self.push_smooth(Smooth { object, normals: normals.map(|n| unit(to_world(unit(n))).cast()) })
    }

    #[cfg(feature = "alloc")]
    fn push_smooth(&mut self, s: Smooth<R>) -> Result<(), SceneError> {
        self.parts.smooth.push(s);
        Ok(())
    }

    #[cfg(not(feature = "alloc"))]
    fn push_smooth(&mut self, s: Smooth<R>) -> Result<(), SceneError> {
        self.parts.smooth.push(s).map_err(|_| SceneError::SmoothLeftOut)
    }

    /// Opens a composite object placed by `t`; objects until [`SceneBuilder::end_composite`] belong to it.
    pub fn begin_composite(&mut self, t: Affine<f64>) -> Result<(), SceneError> {
        if self.open_composite.is_some() {
            return Err(SceneError::NestedComposite);
        }
        if self.parts.composites.is_full() {
            return Err(SceneError::TooManyComposites);
        }
        checked_inverse(&t)?;
        self.open_composite = Some((self.len, t, Aabb::empty()));
        Ok(())
    }

    /// Closes the open composite object.
    pub fn end_composite(&mut self) -> Result<(), SceneError> {
        let (first, _, bounds) = self.open_composite.take().ok_or(SceneError::EndWithoutComposite)?;
        if self.len == first {
            return Err(SceneError::EmptyComposite);
        }
        // Object indices are below 2^31 (checked in `add_object`), so both fit in u32.
        let g = Composite { first: first as u32, len: (self.len - first) as u32, bounds: bounds.cast_padded() };
        self.parts.composites.push(g).map_err(|_| SceneError::TooManyComposites)
    }

    /// Adds a primitive placed by `to_world` (inside an open composite, the composite's
    /// transform is applied after it).
    pub fn add_object(&mut self, shape: Shape<f64>, to_world: Affine<f64>, material: u8) -> Result<(), SceneError> {
        // Lattice references keep the top bit for sub-lattices, so 2^31 objects at most.
        if self.len >= self.storage.len() || self.len >= 1 << 31 {
            return Err(SceneError::TooManyObjects { capacity: self.storage.len(), needed: self.len + 1 });
        }
        if let Some(feature) = shape.left_out() {
            return Err(SceneError::ShapeLeftOut { feature });
        }
        let place = match &self.open_composite {
            Some((_, g, _)) => g.after(&to_world),
            None => to_world,
        };
        // `place` is `to_world` after an invertible group transform: checking it covers both.
        let inv = checked_inverse(&place)?;
        let (shape, place, inv) = upright(shape, place, inv)?;
        let bounds = world_bounds(&shape, &place);
        // The padded box is what the lattice registers: it must be in range too.
        let padded = bounds.padded_for::<R>();
        check_range::<R>(padded.min)?;
        check_range::<R>(padded.max)?;
        let material = material.min(self.parts.materials.len().saturating_sub(1) as u8);
        if self.parts.materials.is_empty() {
            self.add_material(Material::DEFAULT)?;
        }
        let composite = match &mut self.open_composite {
            Some((_, _, gb)) => {
                *gb = gb.union(&bounds);
                self.parts.composites.len() as u16
            }
            None => NO_COMPOSITE,
        };
        let shape = match shape {
            Shape::Sphere => Shape::Sphere,
            Shape::Cylinder => Shape::Cylinder,
            Shape::Cone { top } => Shape::Cone { top: R::from_f64(top) },
            Shape::Box => Shape::Box,
            Shape::Open { top } => Shape::Open { top: R::from_f64(top) },
            Shape::Triangle => Shape::Triangle,
        };
        let (dir_scale, unscale) = scales::<R>(&inv, self.len)?;
        let mut scaled = inv;
        scaled.m.iter_mut().flatten().for_each(|v| *v /= unscale);
        scaled.m.iter_mut().for_each(|row| row[3] = 0.0);
        let to_object: Linear<R> = scaled.linear().cast();
        let m = &to_object.m;
        let uniform = (0..3).all(|i| (0..3).all(|j| if i == j { m[i][j] == m[0][0] } else { m[i][j] == R::ZERO }));
        self.storage[self.len] = Object {
            shape,
            origin: Vec3::new(place.m[0][3], place.m[1][3], place.m[2][3]).cast(),
            unscale: R::pow2(log2_of_pow2(unscale)),
            dir_factor: R::pow2(log2_of_pow2(unscale * dir_scale)),
            dir_scale: R::pow2(log2_of_pow2(dir_scale)),
            inv_dir_scale: R::pow2(log2_of_pow2(1.0 / dir_scale)),
            material,
            // Distant is known once the world box is, at `finish`.
            flags: if uniform { Object::<R>::UNIFORM } else { 0 },
            composite,
            to_object,
            to_world: place.linear().cast(),
            bounds: bounds.cast_padded(),
            // The camera is known at `finish`, which sets both.
            #[cfg(not(feature = "lean-objects"))]
            eye_local: Vec3::new(R::ZERO, R::ZERO, R::ZERO),
            #[cfg(not(feature = "lean-objects"))]
            light_local: Vec3::new(R::ZERO, R::ZERO, R::ZERO),
            region: Region::everywhere(),
        };
        self.len += 1;
        Ok(())
    }

    /// Validates the whole and returns the scene.
    pub fn finish(mut self) -> Result<Scene<'a, R>, SceneError> {
        if self.open_composite.is_some() {
            return Err(SceneError::UnclosedComposite);
        }
        if self.len == 0 {
            return Err(SceneError::NoObjects);
        }
        if self.parts.materials.is_empty() {
            self.add_material(Material::DEFAULT)?;
        }
        let c = &self.camera;
        check_range::<R>(c.eye)?;
        check_range::<R>(c.look)?;
        check_finite(&[c.up.x, c.up.y, c.up.z, c.fov.angles()[0], c.fov.angles()[1]])?;
        check_value::<R>("ambient", self.ambient)?;
        check_value::<R>("background", self.background)?;
        let camera = camera::<R>(c)?;
        let mut world = Aabb { min: camera.eye, max: camera.eye };
        for o in &self.storage[..self.len] {
            world = world.union(&o.bounds);
        }
        let shadow_basis = shadow_basis(&self.parts.lights);
        let regions = Regions::new(&camera, shadow_basis, &world);
        for o in self.storage[..self.len].iter_mut() {
            #[cfg(not(feature = "lean-objects"))]
            {
                (o.eye_local, o.light_local) = o.local_eye_and_light(camera.eye, &self.parts.lights);
            }
            o.region = regions.of(o);
        }
        let bound = brightness_bound(&self.parts.materials, &self.parts.lights, self.ambient, self.background);
        check_range::<R>(world.min.cast())?;
        check_range::<R>(world.max.cast())?;
        check_objects(&mut self.storage[..self.len], &world)?;
        let (len, ambient, background, max_depth) = (self.len, self.ambient, self.background, self.max_depth);
        let objects: &'a [Object<R>] = &self.storage[..len];
        let parts: &'a Parts<R> = self.parts;
        if !(bound < R::LIMIT) {
            return Err(SceneError::TooBright { bound, limit: R::LIMIT, scalar: R::NAME });
        }
        let mut scene = Scene {
            objects,
            composites: &parts.composites,
            materials: &parts.materials,
            lights: &parts.lights,
            ambient: R::from_f64(ambient),
            background: R::from_f64(background),
            camera,
            max_depth,
            world,
            shadow_basis,
            effects: Effects::NONE,
            smooth: &parts.smooth,
        };
        scene.effects = Effects::called_for(&scene);
        Ok(scene)
    }
}

/// The camera of `c` (its numbers checked finite and in range): a field of view between 0 and
/// 180 degrees, a frame of some size, and directions that span a view.
fn camera<R: Real>(c: &CameraDesc) -> Result<Camera<R>, SceneError> {
    let angles = c.fov.angles();
    if !angles.iter().all(|a| *a > 0.0 && *a < 180.0) || c.frame.contains(&0) {
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
    let (tx, ty) = c.fov.half_tangents(c.frame);
    Ok(Camera {
        eye: c.eye.cast(),
        forward: forward.cast(),
        right: (right * tx).cast(),
        up: (up * ty).cast(),
        resolves: [resolvable_pixels::<R>(tx), resolvable_pixels::<R>(ty)],
        shape: lowest_terms(c.frame),
    })
}

/// Checks each object against what the scalar can hold, and marks those it holds only near
/// them ([`Object::distant`]): its own coordinates of the world box's corners within the
/// scalar's range, or else of the points a ray is moved to near it, and thick enough for the
/// scalar to resolve.
// Out of line, and its boxes' corners mapped one at a time: built into a board's image that
// parses its scenes, its frame would otherwise add to the set-up's deepest stack.
#[inline(never)]
fn check_objects<R: Real>(objects: &mut [Object<R>], world: &Aabb<R>) -> Result<(), SceneError> {
    // Every ray the tracer casts stays in the world box (or leaves it), so an object's own
    // coordinates never exceed those of the world box's corners in its space; a distant
    // object's test maps only points within `Object::near` of its box's centre on every
    // axis.
    for (i, o) in objects.iter_mut().enumerate() {
        let reach = own_reach(o, world);
        if reach < R::LIMIT {
            continue;
        }
        if !Object::<R>::TRACES_DISTANT {
            return Err(SceneError::ObjectOutOfRange { object: i, reach, limit: R::LIMIT, scalar: R::NAME });
        }
        // As the test computes them, in `R`.
        let (centre, r) = o.near();
        let r = Vec3::new(r, r, r);
        let reach = own_reach(o, &Aabb { min: centre - r, max: centre + r });
        if reach >= R::LIMIT {
            return Err(SceneError::ObjectOutOfRange { object: i, reach, limit: R::LIMIT, scalar: R::NAME });
        }
        o.flags |= Object::<R>::DISTANT;
    }
    // A triangle has no inside for a secondary ray to start in (every ray off it leaves it):
    // the rule is for solids.
    for (i, o) in objects.iter().enumerate().filter(|(_, o)| o.shape.is_solid()) {
        let (size, smallest) = thickness(o);
        if size < smallest {
            return Err(SceneError::ObjectTooThin { object: i, size, smallest, scalar: R::NAME });
        }
    }
    Ok(())
}

/// The largest of the object's own coordinates of the corners of the box `b`, in `f64`.
fn own_reach<R: Real>(o: &Object<R>, b: &Aabb<R>) -> f64 {
    let inv = o.to_object.cast::<f64>();
    let unscale = R::pow2_value(o.unscale);
    b.corners().into_iter().map(|p| (inv.vector(p.cast() - o.origin().cast()) * unscale).max_abs()).fold(0.0, f64::max)
}

/// A shape, its placement and the placement's inverse.
type Placed = (Shape<f64>, Affine<f64>, Affine<f64>);

/// A shape placed by `place` (inverse `inv`) as the canonical shapes take it: a cone's top
/// radius checked, and a cone wider at its top than at its base turned over onto its top.
fn upright(shape: Shape<f64>, place: Affine<f64>, inv: Affine<f64>) -> Result<Placed, SceneError> {
    let top = match shape {
        Shape::Cone { top } | Shape::Open { top } => top,
        _ => 0.0,
    };
    check_finite(&[top])?;
    if top < 0.0 {
        return Err(SceneError::NonPositiveSize);
    }
    // The canonical cone narrows from radius 1 at its base (the sides of its box lie at 1):
    // one wider at its top is the cone of the top's radius turned over onto it.
    Ok(if top > 1.0 {
        let over = Affine::translate(Vec3::new(0.0, 1.0, 0.0))
            .after(&Affine::rotate(0, 180.0))
            .after(&Affine::scale(Vec3::new(top, 1.0, top)));
        let place = place.after(&over);
        let turned = if let Shape::Open { .. } = shape {
            Shape::Open { top: 1.0 / top }
        } else {
            Shape::Cone { top: 1.0 / top }
        };
        (turned, place, checked_inverse(&place)?)
    } else {
        (shape, place, inv)
    })
}

/// For the object `object` whose world-to-object map is `inv`: the power of two its object-space
/// directions are multiplied by (to about unit length) and the one its map is divided by (its
/// largest entry into `(0.5, 1]`); an object so small or large that the map leaves `f64`'s
/// comfortable range is refused.
fn scales<R: Real>(inv: &Affine<f64>, object: usize) -> Result<(f64, f64), SceneError> {
    // Largest stretch of a direction into object space, rounded up to a power of two.
    let m = &inv.m;
    let stretch =
        (0..3).map(|i| libm::sqrt(m[i][0] * m[i][0] + m[i][1] * m[i][1] + m[i][2] * m[i][2])).fold(0.0, f64::max);
    let largest = m.iter().flat_map(|r| r[..3].iter()).fold(0.0f64, |a, v| a.max(v.abs()));
    // An object so small that its inverse transform leaves f64's comfortable range is too
    // small for any scene (its own coordinates would overflow).
    if !(stretch < 1e200 && largest > 1e-200) {
        return Err(SceneError::ObjectOutOfRange { object, reach: f64::INFINITY, limit: R::LIMIT, scalar: R::NAME });
    }
    Ok((1.0 / pow2_at_least(stretch), pow2_at_least(largest)))
}

/// Whether `v` is finite and of length 1 (to rounding).
fn is_unit(v: Vec3<f64>) -> bool {
    (v.length() - 1.0).abs() < 1e-6
}

/// The inverse of a transform, refusing one whose entries overflowed (composition of huge
/// factors) or that is singular.
fn checked_inverse(t: &Affine<f64>) -> Result<Affine<f64>, SceneError> {
    if t.m.iter().flatten().any(|v| !v.is_finite()) || !t.det().is_finite() {
        return Err(SceneError::TransformOverflow);
    }
    t.inverse().ok_or(SceneError::SingularTransform)
}

/// An object's smallest width (its canonical primitive's narrowest width divided by the
/// largest stretch of its world-to-object map), and the smallest width the scalar can trace
/// there: twice the offset of secondary rays at the object's farthest point (a ray entering
/// the object starts that far inside it, so it must stay in the inner half). The offset is
/// the object's own ([`Real::offset`]), so nothing else in the scene changes the answer.
fn thickness<R: Real>(o: &Object<R>) -> (f64, f64) {
    let m = o.to_object.cast::<f64>();
    let unscale = R::pow2_value(o.unscale);
    let stretch = (0..3)
        .map(|i| libm::sqrt(m.m[i][0] * m.m[i][0] + m.m[i][1] * m.m[i][1] + m.m[i][2] * m.m[i][2]))
        .fold(0.0, f64::max)
        * unscale;
    // Narrowest width of the canonical primitive: sphere 2 (diameter), the others 1.
    let width = if let Shape::Sphere = o.shape { 2.0 } else { 1.0 };
    let far = o.bounds.min.max_abs().max(o.bounds.max.max_abs());
    (width / stretch, 2.0 * R::offset(far, o.size()).to_f64())
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
    // A highlight adds at most `Ks * Ip` per light.
    let local = |m: &Material<R>| {
        let highlight = if m.shine > 0 { m.ks.to_f64() } else { 0.0 };
        ambient.abs() * m.ka.to_f64() + (m.kd.to_f64() + highlight) * ip
    };
    let mut below = materials.iter().map(local).fold(bg, f64::max);
    for _ in 0..MAX_DEPTH {
        below = materials.iter().map(|m| local(m) + (m.ks.to_f64() + m.kt.to_f64()) * below).fold(bg, f64::max);
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

/// World box of a placed primitive: exact for spheres (an ellipsoid's extent along axis `i`
/// is the length of row `i` of the linear part), the transformed corners otherwise.
fn world_bounds(shape: &Shape<f64>, place: &Affine<f64>) -> Aabb<f64> {
    let m = &place.m;
    if let Shape::Triangle = shape {
        let mut b = Aabb::empty();
        for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)] {
            b.include(place.point(p));
        }
        return b;
    }
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
