//! Objects, composite objects, materials, lights and camera: the validated scene.
//!
//! A [`SceneBuilder`] takes raw descriptions in `f64` (from the text parser or from code),
//! validates each one (finite numbers, invertible transforms, coordinates within the
//! scalar's range, capacities) and converts it to the tracer's scalar. The resulting
//! [`Scene`] is what the accelerators and the tracer trust. Object storage is a caller-provided
//! slice, so the capacity is the caller's choice and running out is an ordinary error.
//!
//! Rooms: [`model`] (what a validated scene is), [`builder`] (how one is validated),
//! [`error`] (why one is refused), [`effects`] (what the scene calls for), [`region`] (where
//! on the image and across the light each object can appear, built by `windows` through the
//! eye's `projection` and, with the `eye-hulls` feature, `hull`), and the formats: [`text`]
//! (the plain-text format, one function per statement) and `nff` (with `polygon`). The camera
//! is [`crate::camera`]'s.

pub mod builder;
pub mod effects;
pub mod error;
#[cfg(feature = "eye-hulls")]
pub(crate) mod hull;
pub mod model;
#[cfg(feature = "nff")]
pub mod nff;
#[cfg(feature = "nff")]
pub mod polygon;
mod projection;
pub mod region;
pub mod text;
mod windows;

pub use crate::camera::{lowest_terms, Camera, CameraDesc, FieldOfView, DEFAULT_FRAME, VIEW_MARGIN};
pub use builder::{check_value, SceneBuilder, IOR};
pub use effects::{Effects, MAX_DEPTH};
pub use error::SceneError;
pub use model::{
    axis_normal, Composite, Light, Material, Object, Parts, Scene, Smooth, BOARD_LIGHTS, BOARD_MATERIALS,
    MAX_COMPOSITES, MAX_LIGHTS, MAX_MATERIALS, MAX_SMOOTH, NO_COMPOSITE,
};
pub use region::{
    Culled, EyeHull, EyeWindow, HullEdge, Region, ShadowWindow, EYE_MARGIN, HULL_EDGES, NO_HULL, WHOLE_PLANE,
};

use crate::scalar::Real;
use text::ParseError;

/// The scene formats read: our own text ([`text`]) and NFF ([`nff`]), told apart by the first
/// word ([`Format::of`]), so every reader of scene text takes both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// The plain-text scene format (`docs/scene-format.md`).
    Text,
    /// Eric Haines' Neutral File Format, the SPD's.
    Nff,
}

/// NFF's entity words: text whose first word (after `#` comments) is one of them is NFF.
pub const NFF_ENTITIES: [&str; 8] = ["v", "b", "l", "f", "c", "s", "p", "pp"];

impl Format {
    /// The format of `text`: NFF when its first word is one of [`NFF_ENTITIES`] (a build
    /// without the `nff` feature tells them apart too, to refuse NFF by name).
    pub fn of(text: &str) -> Self {
        let first =
            without_bom(text).lines().map(|l| l.split('#').next().unwrap_or("")).flat_map(str::split_whitespace).next();
        if first.is_some_and(|w| NFF_ENTITIES.contains(&w)) {
            Format::Nff
        } else {
            Format::Text
        }
    }
}

/// `text` without the UTF-8 byte-order mark some editors put first: no word of either format.
fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// The object storage `text` (either [`Format`]) needs.
pub fn object_count(text: &str) -> usize {
    let text = without_bom(text);
    match Format::of(text) {
        #[cfg(feature = "nff")]
        Format::Nff => nff::object_count(text),
        _ => text::object_count(text),
    }
}

/// Where `text` (either [`Format`]) describes its view: the `camera` statement or NFF's last
/// `v`, as line, column and word; what a view refused outside the parser is blamed on.
pub fn camera_statement(text: &str) -> Option<(u32, u32, &str)> {
    let text = without_bom(text);
    match Format::of(text) {
        #[cfg(feature = "nff")]
        Format::Nff => nff::view_entity(text),
        _ => text::camera_statement(text),
    }
}

/// Parses `text` (either [`Format`]) into a [`Scene`], storing objects in `storage` (at least
/// [`object_count`] long) and the composites, materials and lights in `parts`: [`text::parse`]
/// or NFF's reader.
pub fn parse<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
) -> Result<Scene<'a, R>, ParseError<'t>> {
    parse_with(text, storage, parts, |_| {})
}

/// Parses `text` (either [`Format`]) into a [`Scene`], the camera changed by `camera` before
/// the scene is validated ([`text::parse_with`], [`nff::parse_with`]).
pub fn parse_with<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
    camera: impl FnOnce(&mut CameraDesc),
) -> Result<Scene<'a, R>, ParseError<'t>> {
    let text = without_bom(text);
    match Format::of(text) {
        #[cfg(feature = "nff")]
        Format::Nff => nff::parse_with(text, storage, parts, camera),
        #[cfg(not(feature = "nff"))]
        Format::Nff => Err(ParseError { line: 1, col: 1, token: "", kind: text::ParseErrorKind::NffLeftOut }),
        Format::Text => text::parse_with(text, storage, parts, camera),
    }
}
