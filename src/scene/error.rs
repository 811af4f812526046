//! Why a scene was refused: every error says what, and where a capacity is involved, how much
//! was available and how much was needed.

use super::model::{MAX_COMPOSITES, MAX_LIGHTS, MAX_MATERIALS};
use core::fmt;

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
    /// More than [`MAX_COMPOSITES`] composite objects.
    TooManyComposites,
    /// A composite inside a composite.
    NestedComposite,
    /// `end` with no open composite.
    EndWithoutComposite,
    /// The file ended inside a composite.
    UnclosedComposite,
    /// A composite with no objects.
    EmptyComposite,
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
    /// A shape this build leaves out ([`Shape::left_out`](crate::Shape::left_out)).
    ShapeLeftOut {
        /// The Cargo feature that has it (`spheres`, `cones`).
        feature: &'static str,
    },
    /// A material coefficient below zero, or an index of refraction below 1.
    BadCoefficient,
    /// A camera whose view direction is zero or parallel to its up vector.
    DegenerateCamera,
    /// A field of view outside `(0, 180)` degrees.
    BadFieldOfView,
    /// A light with a zero direction.
    DegenerateLight,
    /// A `triangle` statement without one of its corners `a`, `b`, `c`.
    MissingCorner,
    /// A triangle (or polygon) whose corners lie on one line: it has no area and no normal.
    DegenerateTriangle,
    /// A smooth triangle (vertex normals, NFF's `pp`) in a build without `alloc`, whose parts
    /// keep no room for their normals.
    SmoothLeftOut,
    /// The scene has no objects.
    NoObjects,
    /// Where rays meet the object (within twice its box's extent of the box's centre, where a
    /// ray is moved before its test when the world box is beyond the scalar's range in the
    /// object's own space; the world box in a build without `distant-objects`), its own
    /// coordinates grow beyond what the scalar holds: the object is too thin for its length, or
    /// without `distant-objects` too small for the scene.
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
            SceneError::TooManyComposites => write!(f, "too many composite objects (at most {MAX_COMPOSITES})"),
            SceneError::NestedComposite => write!(f, "a group cannot be opened inside another group"),
            SceneError::EndWithoutComposite => write!(f, "`end` without an open group"),
            SceneError::UnclosedComposite => write!(f, "group not closed with `end`"),
            SceneError::EmptyComposite => write!(f, "group has no objects"),
            SceneError::SingularTransform => write!(f, "transform is singular (zero or near-zero scale)"),
            SceneError::NotFinite => write!(f, "number is not finite"),
            SceneError::OutOfRange { limit, scalar } => {
                write!(f, "coordinate out of range for {scalar}: magnitude must stay below {}", Round(*limit))
            }
            SceneError::ValueOutOfRange { what, limit, scalar } => {
                write!(f, "{what} out of range for {scalar}: magnitude must stay below {}", Round(*limit))
            }
            SceneError::TransformOverflow => {
                write!(f, "transform out of range: its entries, composed or multiplied, overflow (more than 1e308)")
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
            SceneError::ShapeLeftOut { feature } => {
                write!(f, "this build leaves out {feature} (lattice-rt's Cargo feature `{feature}`, a default one)")
            }
            SceneError::BadCoefficient => {
                write!(f, "coefficients must be >= 0 and the index of refraction >= 1")
            }
            SceneError::DegenerateCamera => {
                write!(f, "camera looks nowhere or straight along its up vector")
            }
            SceneError::BadFieldOfView => write!(f, "field of view must be between 0 and 180 degrees"),
            SceneError::DegenerateLight => write!(f, "light direction is zero"),
            SceneError::MissingCorner => write!(f, "a triangle needs its three corners: a X Y Z b X Y Z c X Y Z"),
            SceneError::DegenerateTriangle => write!(f, "the polygon's corners lie on one line: it has no area"),
            SceneError::SmoothLeftOut => {
                write!(f, "vertex normals (a smooth patch) need lattice-rt's Cargo feature `alloc`, which this build leaves out")
            }
            SceneError::NoObjects => write!(f, "scene has no objects"),
            SceneError::ObjectOutOfRange { object, reach, limit, scalar } => write!(
                f,
                "object {object} is too small for this scene in {scalar}: its own coordinates reach \
                 {} where rays meet it, the limit is {} (make it thicker)",
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
