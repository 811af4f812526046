//! Scenes, capacities and the render loop.

use crate::schedule::{Schedule, Take, TraceTile, Traced1};
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
#[cfg(not(feature = "gray"))]
use embedded_graphics_core::pixelcolor::BinaryColor;
#[cfg(feature = "gray")]
use embedded_graphics_core::pixelcolor::Gray2;
use lattice_rt::dither::Shade;
use lattice_rt::dither::{Carry, Ditherer};
#[cfg(not(baked_scenes))]
use lattice_rt::lattice::LatticeError;
#[cfg(not(baked_scenes))]
use lattice_rt::load::{LoadError, Loaded};
use lattice_rt::render::{Hooks, RenderError};
#[cfg(not(baked_scenes))]
use lattice_rt::scene::text::ParseError;
use lattice_rt::trace::MissingEffects;
use lattice_rt::{
    dither_tiles, render_pass, render_share, trace_pass, trace_share, Accelerator, Effects, Frame, KeptTile, Real,
    Share, Stats, Traced, Tracer,
};

pub use board_records::frame::{
    rendered, Build, Glass, Tuning, FRAME, LADDER, ORBIT_FRAMES, SHARES, TUNING, TURN_STEPS,
};

/// What this build asks of its frame (its features; `board_records::frame::Build::of` reads
/// the same names for build.rs and the checks).
pub const BUILD: Build = Build {
    panel: cfg!(any(feature = "rp", feature = "panel-frame")),
    orbit: cfg!(feature = "orbit"),
    progressive: cfg!(feature = "progressive"),
    lines: if cfg!(feature = "outline") {
        Some(true)
    } else if cfg!(feature = "no-outline") {
        Some(false)
    } else {
        None
    },
    exact_sampling: cfg!(feature = "exact-sampling"),
    glass: if cfg!(feature = "ssd1306-128x32") {
        Glass::Oled128x32
    } else if cfg!(feature = "ssd1306-72x40") {
        Glass::Oled72x40
    } else if cfg!(feature = "sharp-400x240") {
        Glass::Sharp400x240
    } else if cfg!(feature = "sharp-128x128") {
        Glass::Sharp128x128
    } else if cfg!(feature = "uc8151") {
        Glass::Epaper296x128
    } else {
        Glass::Oled128x64
    },
    gray: cfg!(feature = "gray"),
};

/// The frame the firmware renders ([`rendered`]): on the Raspberry Pi boards' panel a still in
/// Floyd-Steinberg with silhouette lines, orbit and progressive frames in blue noise with lines;
/// elsewhere [`FRAME`].
pub const RENDERED: lattice_rt::Frame = rendered(BUILD);

/// The pixel the panel shows: one bit, or with the `gray` feature one of four shades (shown as
/// three subframes: the display's `gray` module).
#[cfg(not(feature = "gray"))]
pub type Shown = BinaryColor;
/// The pixel the panel shows: one bit, or with the `gray` feature one of four shades (shown as
/// three subframes: the display's `gray` module).
#[cfg(feature = "gray")]
pub type Shown = Gray2;

/// The frame's width in pixels: the panel's glass ([`Glass`]), or 128 without a panel.
pub const WIDTH: u16 = RENDERED.width;
/// The frame's height in pixels.
pub const HEIGHT: u16 = RENDERED.height;

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

/// The embedded scenes baked into flash (the `baked` feature, and the Raspberry Pi boards'
/// default): tables `build.rs` wrote.
#[cfg(baked_scenes)]
pub mod baked {
    use lattice_rt::bake::prelude::*;
    /// The scalar of the tables.
    pub type S = super::Scalar;
    include!(concat!(env!("OUT_DIR"), "/baked.rs"));
}

#[cfg(all(baked_scenes, feature = "orbit"))]
compile_error!("the `baked` scenes are shown from their own cameras: `orbit` needs run-time set-up");

/// All memory a frame of any embedded scene needs, with the capacities build.rs computed.
pub type Storage<R> = lattice_rt::Storage<R, MAX_OBJECTS, MAX_LATTICES, MAX_COORDS, MAX_WORDS, MAX_ROWS>;

/// Why a scene could not be shown.
#[derive(Debug)]
pub enum AppError<'t, E> {
    /// The scene text is invalid or exceeds the object capacity (not in a `baked` build, which
    /// parses nothing: the variant and its messages stay out of its flash).
    #[cfg(not(baked_scenes))]
    Parse(ParseError<'t>),
    /// The lattice exceeds a compiled capacity.
    #[cfg(not(baked_scenes))]
    Lattice(LatticeError),
    /// The scene needs an effect this build leaves out.
    Effects(MissingEffects),
    /// Only a `baked` build borrows the scene text: the lifetime `'t` of the other builds.
    #[cfg(baked_scenes)]
    #[doc(hidden)]
    Text(core::marker::PhantomData<&'t str>),
    /// A baked scene is shown from its own camera only.
    BakedCamera,
    /// The display failed or the render was cancelled.
    Render(RenderError<E>),
}

impl<E: fmt::Debug> fmt::Display for AppError<'_, E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            #[cfg(not(baked_scenes))]
            AppError::Parse(e) => write!(f, "scene: {e}"),
            #[cfg(not(baked_scenes))]
            AppError::Lattice(e) => write!(f, "{e}"),
            #[cfg(baked_scenes)]
            AppError::Text(_) => Ok(()),
            AppError::Effects(e) => write!(f, "{e}"),
            AppError::BakedCamera => write!(f, "a baked scene is shown from its own camera only"),
            AppError::Render(e) => write!(f, "{e}"),
        }
    }
}

/// Logged by defmt without `core::fmt`: the core's errors derive `defmt::Format` (its `defmt`
/// feature); only the display's own error goes through `Debug`.
#[cfg(feature = "rp")]
impl<E: fmt::Debug> defmt::Format for AppError<'_, E> {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            #[cfg(not(baked_scenes))]
            AppError::Parse(e) => defmt::write!(f, "scene: {}", e),
            #[cfg(not(baked_scenes))]
            AppError::Lattice(e) => defmt::write!(f, "{}", e),
            #[cfg(baked_scenes)]
            AppError::Text(_) => {}
            AppError::Effects(e) => defmt::write!(f, "{}", e),
            AppError::BakedCamera => defmt::write!(f, "a baked scene is shown from its own camera only"),
            AppError::Render(RenderError::Draw(e)) => defmt::write!(f, "display: {}", defmt::Debug2Format(e)),
            AppError::Render(RenderError::Cancelled) => defmt::write!(f, "render cancelled"),
            AppError::Render(RenderError::BadTile) => defmt::write!(f, "bad tile size"),
            AppError::Render(RenderError::EdgesNotCompiled) => defmt::write!(f, "edge sampling not compiled in"),
            AppError::Render(RenderError::CoarseNotCompiled) => defmt::write!(f, "two-level sampling not compiled in"),
            AppError::Render(RenderError::DiffusionNotCompiled) => defmt::write!(f, "error diffusion not compiled in"),
            AppError::Render(RenderError::BadShare) => defmt::write!(f, "bad tile share"),
            AppError::Render(RenderError::NotProgressive) => defmt::write!(f, "frame cannot be rendered progressively"),
            AppError::Render(RenderError::ViewTooNarrow { most, .. }) => {
                defmt::write!(f, "view too narrow for the scalar: at most {}x{} pixels", most[0], most[1])
            }
            AppError::Render(RenderError::FrameShape { fitted, frame }) => {
                defmt::write!(f, "the view was fitted to {}:{}, not {}x{}", fitted[0], fitted[1], frame[0], frame[1])
            }
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
    /// Time each tile share took, all passes together (in the units of the clock given to
    /// [`render_scene_at`]).
    pub share_us: [u64; 2],
    /// The clock (as [`Board::now`] read it) when the tile shares started: what the frame did
    /// before is its set-up.
    pub tiles_at: u64,
}

/// The passes a frame is shown in: with the `progressive` feature 8, 4, 2 and 1 (`render_pass`:
/// one ray per 8x8 block first, the finished frame last, no ray traced twice); otherwise one,
/// `0`, the frame drawn at once (`render_share`).
pub const PASSES: &[u8] = if cfg!(feature = "progressive") { &[8, 4, 2, 1] } else { &[0] };

/// Entries of [`Traced`] storage each tile share keeps between passes on a one-core board
/// (`render_pass`; none without the `progressive` feature, and none on a two-core board, whose
/// tiles each keep their own: [`TILE_RAYS`]).
pub const TRACED: usize = if cfg!(feature = "progressive") && !SECOND_CORE {
    let (a, b) =
        (RENDERED.traced_len(Share { index: 0, of: SHARES }), RENDERED.traced_len(Share { index: 1, of: SHARES }));
    if a > b {
        a
    } else {
        b
    }
} else {
    0
};

/// Parses `text`, builds its lattice and renders [`RENDERED`] into `target`, tile by tile.
#[cfg(not(baked_scenes))]
pub fn render_scene<'t, R: Real, D: DrawTarget<Color = Shown, Error: Send> + Send>(
    text: &'t str,
    st: &mut Storage<R>,
    target: &mut D,
    hooks: &mut impl Hooks,
) -> Result<Report, AppError<'t, D::Error>> {
    let mut second = ShareMemory::new();
    let board = Board { cores: &mut OneCore, second: &mut second, now: &|| 0, shown: &mut |_| {}, alive: &|| {} };
    render_scene_at(text, st, target, hooks, &Shot::default(), board)
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

impl Shot {
    /// The scene's own frame with the camera turned `step` of [`TURN_STEPS`] around it (the
    /// camera-turn button's frames).
    pub fn turned(step: u32) -> Self {
        Shot { turn: f64::from(step % TURN_STEPS) / f64::from(TURN_STEPS), ..Shot::default() }
    }
}

/// Runs two pieces of work, on two cores where there are two.
pub trait Cores {
    /// Runs `there` on the other core while `here` runs on this one and returns when both are
    /// done; with one core, `here` and then `there`.
    fn join(&mut self, there: &mut (dyn FnMut() + Send), here: &mut dyn FnMut());
}

/// One core does all the work: [`Cores::join`] runs both pieces in turn.
#[derive(Clone, Copy, Debug, Default)]
pub struct OneCore;

impl Cores for OneCore {
    fn join(&mut self, there: &mut (dyn FnMut() + Send), here: &mut dyn FnMut()) {
        here();
        there();
    }
}

/// The board's side of a frame: how the two tile shares run, the second share's memory, a
/// clock and what to do once a pass is on the display.
pub struct Board<'a, C: Cores> {
    /// Runs the two tile shares (on two cores where there are two).
    pub cores: &'a mut C,
    /// The second share's memory.
    pub second: &'a mut ShareMemory,
    /// Reads a clock (from either core) to time each share.
    pub now: &'a (dyn Fn() -> u64 + Sync),
    /// Called with each pass once it is on the display.
    pub shown: &'a mut dyn FnMut(u8),
    /// Called after each eye sample core 1 traces (or, on one core rendering trace then
    /// dither, the second share's), as core 0's hooks are ([`Hooks::sampled`]): a sign that it
    /// makes progress, for a watchdog.
    pub alive: &'a (dyn Fn() + Sync),
}

/// Core 1's hooks in [`trace_then_dither`]: each eye sample it traces reported to the board's
/// `alive`.
struct Alive<'a>(&'a (dyn Fn() + Sync));

impl Hooks for Alive<'_> {
    #[inline(always)]
    fn sampled(&mut self) {
        (self.0)();
    }
}

/// The render's hooks behind one type in [`trace_then_dither`], whichever core they serve
/// (core 0's own, or [`Alive`]), so the tracer's code is built once for both, not once per type of hooks
/// (core 1's own type took 27 KB more of the Pico 2 image's flash). A call through it costs an
/// indirect branch: once a tile, and once an eye sample for [`Hooks::sampled`].
struct AnyHooks<'h>(&'h mut dyn Hooks);

impl Hooks for AnyHooks<'_> {
    fn gray_tile(&mut self, x: u16, y: u16, w: u16, h: u16, levels: &[u8]) {
        self.0.gray_tile(x, y, w, h, levels);
    }
    #[inline(always)]
    fn sampled(&mut self) {
        self.0.sampled();
    }
    fn progress(&mut self, done: u32, total: u32) -> bool {
        self.0.progress(done, total)
    }
}

/// Whether the board has a second core to trace share 1 (the `rp` boards): it then needs its own
/// query scratch in [`ShareMemory`]. A one-core board draws both shares one after the other, and
/// the memory is empty.
const SECOND_CORE: bool = cfg!(feature = "rp");
/// Entries of [`ShareMemory`]'s arrays when [`SECOND_CORE`] (else none).
const fn second(n: usize) -> usize {
    if SECOND_CORE {
        n
    } else {
        0
    }
}

/// Whether a two-core board renders trace, then dither ([`trace_then_dither`]): every frame,
/// and every pass of a progressive one. Error diffusion carries error from tile to tile, so the
/// cores cannot each draw their own tiles; silhouette lines then need no apron rays; and a band
/// goes to the display in one transfer (a progressive pass's 128 tiles sent one by one took
/// twice the bytes). A one-core board rendering a panel's frame (`panel-frame`) takes the same
/// path: its core traces every tile and dithers the bands in order.
const TRACE_THEN_DITHER: bool = SECOND_CORE || cfg!(feature = "panel-frame");
/// Rays each tile keeps between the passes of a progressive frame on a two-core board (the
/// cores take tiles one at a time, so each has its own: one per pixel of its 2x2 grid); none
/// otherwise.
const TILE_RAYS: usize = if cfg!(feature = "progressive") && SECOND_CORE {
    (RENDERED.tile as usize / 2) * (RENDERED.tile as usize / 2)
} else {
    0
};
/// Entries of [`ShareMemory`]'s arrays when [`TRACE_THEN_DITHER`] (else none).
const fn dithered(n: usize) -> usize {
    if TRACE_THEN_DITHER {
        n
    } else {
        0
    }
}
/// Tiles across the frame.
const TILES_X: usize = (WIDTH as usize).div_ceil(RENDERED.tile as usize);
/// Tiles of the frame.
const TILES: usize = TILES_X * (HEIGHT as usize).div_ceil(RENDERED.tile as usize);
/// Tiles whose storage trace, then dither keeps at once (`schedule`'s ring of bands): every
/// tile of a frame as small as the 128x64 panel's (32) and of a progressive one (its tiles keep
/// rays between passes); of a larger frame three bands, so core 1 traces up to two bands ahead
/// of core 0's dithering (a 400x240 frame keeps 75 tiles of its 375).
const RING: usize = if cfg!(feature = "progressive") || TILES <= 32 { TILES } else { TILES_X * 3 };

/// The memory of the second tile share: on a board with two cores its own query scratch; and
/// the rays both shares keep between progressive passes ([`TRACED`] each) on one core. Where
/// the two cores trace, then dither: what every tile keeps between its trace and its dithering
/// (24 KiB) and between progressive passes ([`TILE_RAYS`]), the bottom row's hits of the band
/// last dithered, the band's pixels and the dither's carries.
pub struct ShareMemory {
    mailbox: [u32; second(MAX_OBJECTS + MAX_LATTICES)],
    rows: [i16; second(MAX_ROWS)],
    traced: [[Traced; TRACED]; 2],
    kept: [KeptTile; dithered(RING)],
    rays: [[Traced; TILE_RAYS]; TILES],
    above: [(u16, u16); dithered(WIDTH as usize)],
    band: [Shown; dithered(WIDTH as usize * RENDERED.tile as usize)],
    carries: [i16; dithered(Carry::len(WIDTH as usize))],
}

impl ShareMemory {
    /// Zeroed memory.
    pub const fn new() -> Self {
        const NONE: Traced = Traced { level: 0, object: 0, depth: 0 };
        ShareMemory {
            mailbox: [0; second(MAX_OBJECTS + MAX_LATTICES)],
            rows: [0; second(MAX_ROWS)],
            traced: [[NONE; TRACED]; 2],
            kept: [KeptTile::EMPTY; dithered(RING)],
            rays: [[NONE; TILE_RAYS]; TILES],
            above: [(0, 0); dithered(WIDTH as usize)],
            band: [Shown::DARK; dithered(WIDTH as usize * RENDERED.tile as usize)],
            carries: [0; dithered(Carry::len(WIDTH as usize))],
        }
    }
}

impl Default for ShareMemory {
    fn default() -> Self {
        Self::new()
    }
}

/// [`render_scene`] for a [`Shot`], on the board's cores: with two, both trace the tiles and
/// this one dithers and draws each finished band ([`trace_then_dither`]); a one-core board
/// draws [`SHARES`] tile shares straight to `target`, one after the other. The board's clock
/// times each core's work. The frame is shown in [`PASSES`]; the board's `shown` is called with
/// each pass once it is on `target`.
#[cfg(not(baked_scenes))]
pub fn render_scene_at<'t, R: Real, D: DrawTarget<Color = Shown, Error: Send> + Send>(
    text: &'t str,
    st: &mut Storage<R>,
    target: &mut D,
    hooks: &mut impl Hooks,
    shot: &Shot,
    board: Board<'_, impl Cores>,
) -> Result<Report, AppError<'t, D::Error>> {
    // The view fitted to the frame's shape (square pixels on any glass), then turned.
    let at = |c: &mut lattice_rt::scene::CameraDesc| {
        *c = lattice_rt::scene::CameraDesc { frame: RENDERED.size(), ..c.orbit(shot.turn) }
    };
    let Loaded { scene, lattice, scratch } = st.view().load_with(text, &lattice_rt::LatticeConfig::default(), at)?;
    render_loaded(&scene, (&lattice, lattice.bytes()), scratch, target, hooks, shot, board)
}

/// Memory a baked scene's frame needs besides the tables in flash: the render's query scratch
/// (mailbox and rows).
#[derive(Debug)]
pub struct BakedMemory {
    mailbox: [u32; MAX_OBJECTS + MAX_LATTICES],
    rows: [i16; MAX_ROWS],
}

impl BakedMemory {
    /// Zeroed memory.
    pub const fn new() -> Self {
        BakedMemory { mailbox: [0; MAX_OBJECTS + MAX_LATTICES], rows: [0; MAX_ROWS] }
    }
}

impl Default for BakedMemory {
    fn default() -> Self {
        Self::new()
    }
}

/// [`render_scene_at`] for a scene baked into flash (the `baked` feature: `build.rs` wrote it
/// and its lattice as tables), which is neither parsed nor built. Its camera is the scene's
/// own: `shot.turn` must be 0 (an orbit needs the camera set up at run time).
pub fn render_baked_at<'t, R: Real, D: DrawTarget<Color = Shown, Error: Send> + Send>(
    baked: &lattice_rt::Baked<R>,
    memory: &mut BakedMemory,
    target: &mut D,
    hooks: &mut impl Hooks,
    shot: &Shot,
    board: Board<'_, impl Cores>,
) -> Result<Report, AppError<'t, D::Error>> {
    if shot.turn != 0.0 {
        return Err(AppError::BakedCamera);
    }
    let scratch = lattice_rt::Scratch::new(&mut memory.mailbox[..], &mut memory.rows[..]);
    // Where the windows answer every ray of every embedded scene (`windows_only`, which
    // `build.rs` finds with `EyeRays::serve_every_ray`), the tracer never asks its accelerator:
    // brute force stands in for the lattice, and the walk's code is not linked.
    #[cfg(windows_only)]
    let accel = &lattice_rt::BruteForce;
    #[cfg(not(windows_only))]
    let accel = &baked.lattice;
    render_loaded(&baked.scene, (accel, baked.lattice.bytes()), scratch, target, hooks, shot, board)
}

/// An embedded scene as this build holds it: its text, parsed and set up for every frame.
#[cfg(not(baked_scenes))]
pub type Embedded = &'static str;
/// An embedded scene as this build holds it: its tables baked into flash.
#[cfg(baked_scenes)]
pub type Embedded = &'static lattice_rt::Baked<Scalar>;

/// The memory a frame of an [`Embedded`] scene needs: the storage a scene is parsed and its
/// lattice built in.
#[cfg(not(baked_scenes))]
pub type SceneMemory = Storage<Scalar>;
/// The memory a frame of an [`Embedded`] scene needs: the render's query scratch.
#[cfg(baked_scenes)]
pub type SceneMemory = BakedMemory;

/// Whether this build can turn the camera around its scenes: not when it bakes them, whose eye
/// windows and hulls were computed at build time for the scene's own camera.
pub const CAMERA_TURNS: bool = cfg!(not(baked_scenes));

/// The embedded scenes by name, as this build holds them.
#[cfg(not(baked_scenes))]
pub const EMBEDDED: [(&str, Embedded); SCENES.len()] = SCENES;
/// The embedded scenes by name, as this build holds them.
#[cfg(baked_scenes)]
pub static EMBEDDED: [(&str, Embedded); SCENES.len()] = baked::BAKED;

/// A frame of an embedded scene: [`render_scene_at`] for its text, or [`render_baked_at`] for
/// its tables.
pub fn render_embedded_at<D: DrawTarget<Color = Shown, Error: Send> + Send>(
    scene: Embedded,
    memory: &mut SceneMemory,
    target: &mut D,
    hooks: &mut impl Hooks,
    shot: &Shot,
    board: Board<'_, impl Cores>,
) -> Result<Report, AppError<'static, D::Error>> {
    #[cfg(not(baked_scenes))]
    return render_scene_at(scene, memory, target, hooks, shot, board);
    #[cfg(baked_scenes)]
    return render_baked_at(scene, memory, target, hooks, shot, board);
}

/// The frame of a scene loaded or baked: its tracer (over `accel`, with `lattice_bytes` of
/// lattice), then every pass of both tile shares.
fn render_loaded<'t, R: Real, A: Accelerator<R> + Sync + ?Sized, D: DrawTarget<Color = Shown, Error: Send> + Send>(
    scene: &lattice_rt::Scene<'_, R>,
    (accel, lattice_bytes): (&A, usize),
    mut scratch: lattice_rt::Scratch<'_>,
    target: &mut D,
    hooks: &mut impl Hooks,
    shot: &Shot,
    board: Board<'_, impl Cores>,
) -> Result<Report, AppError<'t, D::Error>> {
    let mut tracer = Tracer::<_, _, EFFECTS>::compiled(scene, accel).map_err(AppError::Effects)?;
    if cfg!(feature = "effects-all") {
        tracer.set_effects(Effects::ALL);
    }
    if let Some(how) = shot.tuning.eye_rays {
        tracer.set_eye_rays(how);
    }
    tracer.set_shadow_coherence(shot.tuning.shadow_coherence);
    tracer.set_box_tests(shot.tuning.box_tests);
    let tuned = Frame { sampling: shot.tuning.sampling, ..RENDERED };
    // Every image but the ladder renders the constant RENDERED, whose sizes the compiler folds
    // into the render loop (a division by the window's size becomes a shift); named in each
    // closure below, so that no call passes it through a closure's captures.
    let pick = |tuned| if cfg!(feature = "ladder") { tuned } else { &RENDERED };
    let (first, other) = (Share { index: 0, of: SHARES }, Share { index: 1, of: SHARES });
    let tracer = &tracer;
    let Board { cores, second, now, shown, alive } = board;
    let ShareMemory { mailbox, rows, traced, kept, rays, above, band, carries } = second;
    let [traced_here, traced_there] = traced;
    let mut stats = Stats::default();
    let mut times = [0u64; 2];
    let tiles_at = now();
    if TRACE_THEN_DITHER {
        let memory = DitherMemory { mailbox, rows, kept, rays, above, band, carries };
        let (s, [there, mine]) = trace_then_dither(
            tracer,
            pick(&tuned),
            cores,
            memory,
            (&mut scratch, &mut AnyHooks(hooks), now, shown, alive),
            target,
        )?;
        return Ok(Report {
            stats: s,
            objects: scene.objects().len(),
            lattice_bytes,
            share_us: [mine, there],
            tiles_at,
        });
    }
    for &pass in PASSES {
        // One core: both shares straight to the display, one after the other.
        let [there_us, here_us] = &mut times;
        let t0 = now();
        stats.add(
            &draw(tracer, pick(&tuned), first, pass, &mut traced_here[..], target, &mut scratch, hooks)
                .map_err(AppError::Render)?,
        );
        let t1 = now();
        let more = draw(
            tracer,
            pick(&tuned),
            other,
            pass,
            &mut traced_there[..],
            target,
            &mut scratch,
            &mut lattice_rt::NoHooks,
        );
        stats.add(&more.map_err(AppError::Render)?);
        (*here_us, *there_us) = (*here_us + t1 - t0, *there_us + now() - t1);
        shown(pass);
    }
    Ok(Report { stats, objects: scene.objects().len(), lattice_bytes, share_us: [times[1], times[0]], tiles_at })
}

/// Where [`trace_then_dither`] works: core 1's query scratch, what every tile keeps, the
/// bottom row's hits of the band last dithered, the band's pixels and the dither's carries.
struct DitherMemory<'m> {
    mailbox: &'m mut [u32],
    rows: &'m mut [i16],
    kept: &'m mut [KeptTile],
    rays: &'m mut [[Traced; TILE_RAYS]],
    above: &'m mut [(u16, u16)],
    band: &'m mut [Shown],
    carries: &'m mut [i16],
}

/// A frame on two cores, trace then dither: the cores take the frame's tiles one at a time as
/// they come free (`Share::single`), in raster order, and trace each into its levels
/// (`trace_share`); core 0, between its tiles, dithers each band whose tiles are all traced,
/// in order (`dither_band`), and sends it to `target`. Neither core waits for the other but at
/// the frame's end, and core 0's time on the bus is made up by core 1 taking more tiles. The
/// frame is bit for bit what `render` draws, error diffusion included. A progressive frame's
/// passes ([`PASSES`]) run in the same way without a pause between them: a tile of the next
/// pass is free to trace as soon as its band of the last has been dithered (`trace_pass`, each
/// tile's rays kept in `memory` from pass to pass), so neither core waits at a pass's end; each
/// pass is bit for bit what `render_pass` draws. `here` is core 0's side: its query scratch,
/// the render's hooks, the board's clock, what to do once each pass is on the display, and
/// what core 1 calls after each eye sample it traces.
/// Returns both cores' statistics and their times, core 1's first.
#[allow(clippy::type_complexity)]
fn trace_then_dither<
    't,
    R: Real,
    A: Accelerator<R> + Sync + ?Sized,
    D: DrawTarget<Color = Shown, Error: Send> + Send,
>(
    tracer: &Tracer<'_, '_, R, A, EFFECTS>,
    frame: &Frame,
    cores: &mut impl Cores,
    memory: DitherMemory<'_>,
    (scratch, hooks, now, shown, alive): (
        &mut lattice_rt::Scratch<'_>,
        &mut impl Hooks,
        &(dyn Fn() -> u64 + Sync),
        &mut dyn FnMut(u8),
        &(dyn Fn() + Sync),
    ),
    target: &mut D,
) -> Result<(Stats, [u64; 2]), AppError<'t, D::Error>> {
    let DitherMemory { mailbox, rows, kept, rays, above, band, carries } = memory;
    let Some(schedule) = FrameSchedule::new(frame, PASSES.len(), kept, rays) else {
        return Err(AppError::Render(RenderError::ScratchTooSmall { needed: TILES }));
    };
    let mut there = (Stats::default(), None, 0);
    let mut here: (Stats, Result<(), AppError<'t, D::Error>>, u64) = (Stats::default(), Ok(()), 0);
    cores.join(
        // Core 1 traces tiles until every tile of every pass is taken.
        &mut || {
            let t0 = now();
            let mut scratch = lattice_rt::Scratch::new(&mut mailbox[..], &mut rows[..]);
            let mut alive = Alive(alive);
            let mut hooks = AnyHooks(&mut alive);
            let mut trace = tile_tracer(tracer, &mut hooks);
            loop {
                match schedule.take(&mut scratch, &mut trace) {
                    Take::Tile(Ok(s)) => there.0.add(&s),
                    Take::Tile(Err(e)) => there.1 = there.1.or(Some(e)),
                    Take::Wait => core::hint::spin_loop(),
                    Take::Finished => break,
                }
            }
            there.2 = now() - t0;
        },
        // Core 0 dithers and sends each band once its tiles are traced, and traces in between.
        &mut || {
            let t0 = now();
            let mut trace = tile_tracer(tracer, &mut *hooks);
            let mut dither = BandDither { frame, above: &mut *above, band: &mut *band, carries: &mut *carries };
            here.1 = PASSES.iter().try_for_each(|&pass| {
                dither.pass(&schedule, pass, (&mut *scratch, &mut trace, &mut here.0), &mut *target)?;
                shown(pass);
                Ok(())
            });
            if here.1.is_err() {
                schedule.stop();
            }
            here.2 = now() - t0;
        },
    );
    here.1?;
    if let Some(e) = there.1 {
        return Err(AppError::Render(e.widen()));
    }
    here.0.add(&there.0);
    Ok((here.0, [there.2, here.2]))
}

/// The scheduler of [`trace_then_dither`] for this build's frame.
type FrameSchedule<'l> = Schedule<'l, RING, TILES_X, TILE_RAYS>;

/// The one way a core traces a tile in trace, then dither: [`trace_tile`] of pass `PASSES[p]`,
/// with `hooks` (core 0's report progress; core 1 has none).
fn tile_tracer<'h, R: Real, A: Accelerator<R> + ?Sized>(
    tracer: &'h Tracer<'_, '_, R, A, EFFECTS>,
    hooks: &'h mut impl Hooks,
) -> impl FnMut(&mut lattice_rt::Scratch<'_>, usize, Frame, Share, &mut [KeptTile], &mut [Traced]) -> Traced1 + 'h {
    move |scratch, p, band, share, l, r| trace_tile(tracer, &band, share, PASSES[p], (l, r), scratch, hooks)
}

/// Core 0's side of trace, then dither: the bottom row's hits of the band last dithered, the
/// band's pixels and the dither's carries.
struct BandDither<'f, 'm> {
    frame: &'f Frame,
    above: &'m mut [(u16, u16)],
    band: &'m mut [Shown],
    carries: &'m mut [i16],
}

impl BandDither<'_, '_> {
    /// One pass of the frame: each band dithered and sent once its tiles are traced (the
    /// frame's last band in parts, as its tiles come), its tiles freed for the next pass; while
    /// no band is ready, core 0 traces the next tile (`work`: its scratch, its trace and its
    /// statistics).
    fn pass<'t, D: DrawTarget<Color = Shown>>(
        &mut self,
        schedule: &FrameSchedule<'_>,
        pass: u8,
        (scratch, trace, stats): (&mut lattice_rt::Scratch<'_>, &mut TraceTile<'_>, &mut Stats),
        target: &mut D,
    ) -> Result<(), AppError<'t, D::Error>> {
        let (w, tiles_x) = (self.frame.width as usize, schedule.tiles_x());
        // Only a finished frame (a progressive one's last pass) has silhouette lines.
        let shows = Frame { outline: self.frame.outline && pass <= 1, ..*self.frame };
        let mut ditherer = Ditherer::new(self.frame.dither, w, &mut *self.carries)
            .ok_or(AppError::Render(RenderError::ScratchTooSmall { needed: Carry::len(w) }))?;
        let (mut band, mut from) = (0, 0);
        // The right column's hits of the last tile dithered (`dither_tiles`).
        let mut left = [(0, 0); lattice_rt::dither::MAX_TILE];
        while band < schedule.bands() {
            // The frame's last band goes in parts: once the last tile is traced, what is left on
            // the bus is its part, not the whole band (parts of every band cost more addressing
            // bytes than the bus had time for in a progressive frame).
            let parts = band + 1 == schedule.bands() && Some(&pass) == PASSES.last();
            let Some(mut part) = schedule.ready(band, from, parts) else {
                match schedule.take(scratch, trace) {
                    Take::Tile(traced) => stats.add(&traced.map_err(|e| AppError::Render(e.widen()))?),
                    Take::Wait | Take::Finished => core::hint::spin_loop(),
                }
                continue;
            };
            let tile = |tx: usize| part.get(tx.wrapping_sub(from)).and_then(|l| l.as_ref()).map(|l| l.kept());
            let rows = (&mut *self.above, &mut *self.band, &mut left);
            let next =
                dither_tiles(&shows, (band, from), tile, rows, &mut ditherer, target).map_err(AppError::Render)?;
            schedule.free(band, from, &mut part);
            (band, from) = if next >= tiles_x { (band + 1, 0) } else { (band, next) };
        }
        Ok(())
    }
}

/// One tile traced for trace, then dither: pass `pass` of a progressive frame (`trace_pass`,
/// its rays kept in the tile's own storage), or, in a build without the `progressive` feature,
/// the whole frame's tile (`trace_share`).
fn trace_tile<R: Real, A: Accelerator<R> + ?Sized>(
    tracer: &Tracer<'_, '_, R, A, EFFECTS>,
    band: &Frame,
    share: Share,
    pass: u8,
    (kept, rays): (&mut [KeptTile], &mut [Traced]),
    scratch: &mut lattice_rt::Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<core::convert::Infallible>> {
    if cfg!(feature = "progressive") {
        trace_pass(tracer, band, share, pass, rays, kept, scratch, hooks)
    } else {
        trace_share(tracer, band, share, kept, scratch, hooks)
    }
}

/// One share of a frame: pass `pass` of a progressive frame (`render_pass`), or, in a build
/// without the `progressive` feature (whose only pass is 0), the whole frame at once
/// (`render_share`).
#[allow(clippy::too_many_arguments)]
fn draw<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = Shown>>(
    tracer: &Tracer<'_, '_, R, A, EFFECTS>,
    frame: &Frame,
    share: Share,
    pass: u8,
    traced: &mut [Traced],
    target: &mut D,
    scratch: &mut lattice_rt::Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    // A build without the `progressive` feature links no pass code at all, and one with it
    // renders through `render_pass` alone (one caller of the tile loop, so the compiler still
    // folds the constant frame's sizes into it).
    if cfg!(feature = "progressive") {
        render_pass(tracer, frame, share, pass, traced, target, scratch, hooks)
    } else {
        render_share(tracer, frame, share, target, scratch, hooks)
    }
}

#[cfg(not(baked_scenes))]
impl<'t, E> From<LoadError<'t>> for AppError<'t, E> {
    fn from(e: LoadError<'t>) -> Self {
        match e {
            LoadError::Parse(e) => AppError::Parse(e),
            LoadError::Lattice(e) => AppError::Lattice(e),
        }
    }
}
