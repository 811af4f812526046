//! Scenes, capacities and the render loop.

use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::pixelcolor::BinaryColor;
use lattice_rt::lattice::LatticeError;
use lattice_rt::scene::text::ParseError;
use lattice_rt::render::{Hooks, RenderError};
use lattice_rt::storage::{LoadError, Loaded};
use lattice_rt::trace::MissingEffects;
use lattice_rt::{render, Effects, LatticeConfig, Real, Stats, Tracer};

pub use crate::frame::{FRAME, HEIGHT, ORBIT_FRAMES, WIDTH};

/// The frame the firmware renders: [`FRAME`], or with the `exact-sampling` feature one eye ray
/// per pixel.
pub const RENDERED: lattice_rt::Frame = if cfg!(feature = "exact-sampling") {
    lattice_rt::Frame { sampling: lattice_rt::Sampling::Center, ..FRAME }
} else {
    FRAME
};

/// The scalar the firmware traces in, chosen by a `scalar-*` feature (default f32 with libm).
#[cfg(feature = "scalar-fixed")]
pub type Scalar = lattice_rt::Fx;
/// The scalar the firmware traces in.
#[cfg(feature = "scalar-micromath")]
pub type Scalar = lattice_rt::F32Micro;
/// The scalar the firmware traces in.
#[cfg(feature = "scalar-micromath-newton")]
pub type Scalar = lattice_rt::F32MicroNewton;
/// The scalar the firmware traces in.
#[cfg(not(any(feature = "scalar-fixed", feature = "scalar-micromath", feature = "scalar-micromath-newton")))]
pub type Scalar = f32;

// SCENES and the capacities, computed by build.rs from the scenes chosen for this build.
include!(concat!(env!("OUT_DIR"), "/capacities.rs"));

/// All memory a frame of any embedded scene needs, with the capacities build.rs computed.
pub type Storage<R> = lattice_rt::Storage<R, MAX_OBJECTS, MAX_LATTICES, MAX_COORDS, MAX_WORDS, MAX_ROWS>;

/// Why a scene could not be shown.
#[derive(Debug)]
pub enum AppError<'t, E> {
    /// The scene text is invalid or exceeds the object capacity.
    Parse(ParseError<'t>),
    /// The lattice exceeds a compiled capacity.
    Lattice(LatticeError),
    /// The scene needs an effect this build leaves out.
    Effects(MissingEffects),
    /// The display failed or the render was cancelled.
    Render(RenderError<E>),
}

impl<E: fmt::Debug> fmt::Display for AppError<'_, E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AppError::Parse(e) => write!(f, "scene: {e}"),
            AppError::Lattice(e) => write!(f, "{e}"),
            AppError::Effects(e) => write!(f, "{e}"),
            AppError::Render(e) => write!(f, "{e}"),
        }
    }
}

/// Logged by defmt without `core::fmt`: the core's errors derive `defmt::Format` (its `defmt`
/// feature); only the display's own error goes through `Debug`.
#[cfg(feature = "pico")]
impl<E: fmt::Debug> defmt::Format for AppError<'_, E> {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            AppError::Parse(e) => defmt::write!(f, "scene: {}", e),
            AppError::Lattice(e) => defmt::write!(f, "{}", e),
            AppError::Effects(e) => defmt::write!(f, "{}", e),
            AppError::Render(RenderError::Draw(e)) => defmt::write!(f, "display: {}", defmt::Debug2Format(e)),
            AppError::Render(RenderError::Cancelled) => defmt::write!(f, "render cancelled"),
            AppError::Render(RenderError::BadTile) => defmt::write!(f, "bad tile size"),
            AppError::Render(RenderError::EdgesNotCompiled) => defmt::write!(f, "edge sampling not compiled in"),
            AppError::Render(RenderError::ScratchTooSmall { needed }) => {
                defmt::write!(f, "scratch storage too small: {} entries needed", needed)
            }
        }
    }
}

/// What a finished frame reports.
#[derive(Clone, Copy, Debug)]
pub struct Report {
    /// Work counted by the core.
    pub stats: Stats,
    /// Primitives in the scene.
    pub objects: usize,
    /// Bytes of the built lattice.
    pub lattice_bytes: usize,
}

/// Parses `text`, builds its lattice and renders [`RENDERED`] into `target`, tile by tile.
pub fn render_scene<'t, R: Real, D: DrawTarget<Color = BinaryColor>>(
    text: &'t str,
    st: &mut Storage<R>,
    target: &mut D,
    hooks: &mut impl Hooks,
) -> Result<Report, AppError<'t, D::Error>> {
    render_scene_at(text, st, target, hooks, 0.0)
}

/// [`render_scene`] with the camera moved `turn` of a circle around the point it looks at
/// (`CameraDesc::orbit`; 0 is the scene's own camera).
pub fn render_scene_at<'t, R: Real, D: DrawTarget<Color = BinaryColor>>(
    text: &'t str,
    st: &mut Storage<R>,
    target: &mut D,
    hooks: &mut impl Hooks,
    turn: f64,
) -> Result<Report, AppError<'t, D::Error>> {
    let at = |c: &mut lattice_rt::scene::CameraDesc| *c = c.orbit(turn);
    let Loaded { scene, lattice, mut scratch } = st.view().load_with(text, &LatticeConfig::default(), at)?;
    let mut tracer = Tracer::<_, _, EFFECTS>::compiled(&scene, &lattice).map_err(AppError::Effects)?;
    if cfg!(feature = "effects-all") {
        tracer.set_effects(Effects::ALL);
    }
    let stats = render(&tracer, &RENDERED, target, &mut scratch, hooks).map_err(AppError::Render)?;
    Ok(Report { stats, objects: scene.objects().len(), lattice_bytes: lattice.bytes() })
}

impl<'t, E> From<LoadError<'t>> for AppError<'t, E> {
    fn from(e: LoadError<'t>) -> Self {
        match e {
            LoadError::Parse(e) => AppError::Parse(e),
            LoadError::Lattice(e) => AppError::Lattice(e),
        }
    }
}
