//! Objects, composite objects, materials, lights and camera: the validated scene.
//!
//! A [`SceneBuilder`] takes raw descriptions in `f64` (from the text parser or from code),
//! validates each one (finite numbers, invertible transforms, coordinates within the
//! scalar's range, capacities) and converts it to the tracer's scalar. The resulting
//! [`Scene`] is what the accelerators and the tracer trust. Object storage is a caller-provided
//! slice, so the capacity is the caller's choice and running out is an ordinary error.
//!
//! Rooms: [`model`] (what a validated scene is), [`builder`] (how one is validated),
//! [`error`] (why one is refused) and [`text`] (the plain-text format, one function per
//! statement). Where on the image an object can appear is [`crate::cull`]'s; the camera is
//! [`crate::camera`]'s.

pub mod builder;
pub mod error;
pub mod model;
pub mod text;

pub use crate::camera::{lowest_terms, Camera, CameraDesc, FieldOfView, DEFAULT_FRAME, VIEW_MARGIN};
pub use crate::cull::{Culled, EyeHull, EyeWindow, ShadowWindow, EYE_MARGIN, HULL_EDGES, NO_HULL, WHOLE_PLANE};
pub use builder::{check_value, SceneBuilder, IOR};
pub use error::SceneError;
pub use model::{
    axis_normal, Composite, Light, Material, Object, Parts, Scene, MAX_COMPOSITES, MAX_LIGHTS, MAX_MATERIALS,
    NO_COMPOSITE,
};
