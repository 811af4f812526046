//! Scenes, capacities and the render loop.

use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::pixelcolor::BinaryColor;
use lattice_rt::lattice::LatticeError;
use lattice_rt::scene::text::ParseError;
use lattice_rt::render::{Hooks, RenderError};
use lattice_rt::storage::{LoadError, Loaded};
use lattice_rt::trace::MissingEffects;
use lattice_rt::{render_share, Effects, Frame, LatticeConfig, Real, Share, Stats, Tracer};

pub use crate::frame::{Tuning, FRAME, HEIGHT, LADDER, ORBIT_FRAMES, SHARES, TUNING, WIDTH};

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
            AppError::Render(RenderError::BadShare) => defmt::write!(f, "bad tile share"),
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
    render_scene_at(text, st, target, hooks, &Shot::default(), |_| {})
}

/// What one frame shows and how it is traced.
#[derive(Clone, Copy, Debug)]
pub struct Shot {
    /// The camera moved this much of a circle around the point it looks at
    /// (`CameraDesc::orbit`; 0 is the scene's own camera).
    pub turn: f64,
    /// The levers switched on ([`TUNING`]: all; the `ladder` image steps through [`LADDER`]).
    pub tuning: Tuning,
}

impl Default for Shot {
    fn default() -> Self {
        Shot { turn: 0.0, tuning: Tuning { sampling: RENDERED.sampling, ..TUNING } }
    }
}

/// [`render_scene`] for a [`Shot`]: the frame is rendered in [`SHARES`] tile shares, one after
/// the other; `mark(i)` is called as share `i` starts, and `mark(SHARES)` when the last is done
/// (to time each core's share where one core renders them all).
pub fn render_scene_at<'t, R: Real, D: DrawTarget<Color = BinaryColor>>(
    text: &'t str,
    st: &mut Storage<R>,
    target: &mut D,
    hooks: &mut impl Hooks,
    shot: &Shot,
    mut mark: impl FnMut(u8),
) -> Result<Report, AppError<'t, D::Error>> {
    let at = |c: &mut lattice_rt::scene::CameraDesc| *c = c.orbit(shot.turn);
    let Loaded { scene, lattice, mut scratch } = st.view().load_with(text, &LatticeConfig::default(), at)?;
    let mut tracer = Tracer::<_, _, EFFECTS>::compiled(&scene, &lattice).map_err(AppError::Effects)?;
    if cfg!(feature = "effects-all") {
        tracer.set_effects(Effects::ALL);
    }
    if let Some(how) = shot.tuning.eye_rays {
        tracer.set_eye_rays(how);
    }
    tracer.set_shadow_coherence(shot.tuning.shadow_coherence);
    let tuned = Frame { sampling: shot.tuning.sampling, ..RENDERED };
    // Every image but the ladder renders the constant RENDERED, whose sizes the compiler folds
    // into the render loop (a division by the window's size becomes a shift).
    let frame = if cfg!(feature = "ladder") { &tuned } else { &RENDERED };
    let mut stats = Stats::default();
    for index in 0..SHARES {
        mark(index);
        let share = Share { index, of: SHARES };
        stats.add(&render_share(&tracer, frame, share, target, &mut scratch, hooks).map_err(AppError::Render)?);
    }
    mark(SHARES);
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
