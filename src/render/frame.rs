//! The frame: what to render ([`Frame`]), which of its tiles a call renders ([`Share`]), the
//! grid of tiles every part of the render walks ([`TileGrid`]), and why a frame is refused
//! ([`RenderError`]).

use crate::camera::Camera;
use crate::dither::{Dither, Ditherer, Tone, MAX_TILE};
use crate::sample::{Sampler, Sampling};
use crate::scalar::Real;
use core::fmt;

/// What to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u16,
    /// Height in pixels.
    pub height: u16,
    /// Tile side in pixels (1..=16; a multiple of the pattern block).
    pub tile: u8,
    /// Dithering mode.
    pub dither: Dither,
    /// Eye rays per pixel (ignored by the patterning modes, which take one per block).
    pub sampling: Sampling,
    /// The band of tile rows to render, `[first, end)` (all by default). Bands of a frame
    /// rendered apart give the same pixels as the whole when the dithering carries nothing
    /// between tiles ([`Frame::bands_independent`]): that is how a host renders in parallel.
    pub rows: (u16, u16),
    /// Tone curve applied to the gray levels before dithering.
    pub tone: Tone,
    /// Silhouette lines ([`crate::outline`]): the farther pixel of two neighbours that hit
    /// different objects is drawn black.
    pub outline: bool,
    /// `Some(k)`: branches of the intersection tree weighing less than 2^-k are not traced, as
    /// with [`Tracer::set_cutoff`](crate::trace::Tracer::set_cutoff) (the larger of the two cutoffs
    /// holds; `k` above 14 counts as
    /// 14, [`Real::div_pow2`]); `None`: the tracer's own. 7 is half of
    /// one of the 64 gray steps a pixel's level takes.
    pub cutoff: Option<u8>,
}

/// One core's share of a frame's tiles ([`render_share`](super::render_share)): tile `(tx, ty)`
/// belongs to share `(tx + ty) % of`, a
/// checkerboard for two, so each share holds as much of every part of the picture as the
/// others. Shares rendered apart give the pixels of the whole frame when its bands are
/// independent ([`Frame::bands_independent`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Share {
    /// Which share, `0..of`.
    pub index: u8,
    /// How many shares the frame is split into (1: the whole frame).
    pub of: u8,
}

impl Share {
    /// The whole frame.
    pub const ALL: Share = Share { index: 0, of: 1 };

    /// Whether tile `(tx, ty)` is in this share.
    pub const fn holds(self, tx: usize, ty: usize) -> bool {
        let of = if self.of == 0 { 1 } else { self.of as usize };
        (tx + ty) % of == self.index as usize
    }

    /// How many of the tiles in tile rows `rows.0..rows.1` of a frame `tiles_x` tiles wide
    /// this share holds (in the order the render visits them).
    pub const fn tiles_in(self, tiles_x: usize, rows: (usize, usize)) -> usize {
        let mut n = 0;
        let mut ty = rows.0;
        while ty < rows.1 {
            let mut tx = 0;
            while tx < tiles_x {
                if self.holds(tx, ty) {
                    n += 1;
                }
                tx += 1;
            }
            ty += 1;
        }
        n
    }

    /// The share that holds tile `tx` alone of tile row `ty`, in a frame `tiles_x` tiles wide
    /// (at most 255): [`trace_share`](super::trace_share) of one band with it traces that one tile, so cores can
    /// take tiles one at a time, as they come free.
    pub const fn single(tx: usize, ty: usize, tiles_x: usize) -> Share {
        let of = if tiles_x == 0 { 1 } else { tiles_x };
        Share { index: ((tx + ty) % of) as u8, of: of as u8 }
    }

    pub(super) fn valid(self) -> bool {
        self.index < self.of
    }
}

impl Frame {
    /// Whether a render of this frame takes `camera`'s view, as [`render`](super::render)
    /// checks first: the frame has the shape the view was fitted to, and the scalar resolves the
    /// angle between its pixels. A loader that knows the frame it will render can so refuse a
    /// view where its scene says why (host-sim names the camera's line).
    pub fn check_view<R: Real>(&self, camera: &Camera<R>) -> Result<(), RenderError<core::convert::Infallible>> {
        resolves(camera, self)
    }

    /// [`Frame::check_view`] for a scene parsed from `text`: a view refused where the text sets
    /// it (the `camera` statement, NFF's `v`), so that every loader says the same thing at the
    /// same place (host-sim, and the scene slot's check as the board reads it).
    pub fn check_scene_view<'t, R: Real>(&self, text: &'t str, camera: &Camera<R>) -> Result<(), ViewRefused<'t>> {
        self.check_view(camera).map_err(|error| {
            let (line, col, word) = crate::scene::camera_statement(text).unwrap_or((1, 1, ""));
            ViewRefused { line, col, word, error }
        })
    }

    /// Width and height as `[u32; 2]` (what a camera is fitted to: [`crate::scene::CameraDesc::frame`]).
    pub fn size(&self) -> [u32; 2] {
        [u32::from(self.width), u32::from(self.height)]
    }

    /// A frame with 8x8 tiles, Bayer dithering and one ray per pixel.
    pub fn new(width: u16, height: u16) -> Self {
        Frame {
            width,
            height,
            tile: 8,
            dither: Dither::Bayer,
            sampling: Sampling::Center,
            rows: (0, u16::MAX),
            tone: Tone::LINEAR,
            outline: false,
            cutoff: None,
        }
    }

    /// Whether bands of tile rows (and tile shares) can be rendered apart and give the same
    /// pixels: true unless error diffusion or edge detection carries state from one tile row to
    /// the next (the outline does not: each tile traces its own apron, [`crate::outline`]).
    pub fn bands_independent(&self) -> bool {
        !self.dither.diffuses() && !self.edges()
    }

    /// Entries of `i16` scratch storage [`render`](super::render) needs: error-diffusion carries and the
    /// object ids of the row above the current band for edge detection.
    pub fn scratch_len(&self) -> usize {
        let w = self.width as usize;
        Ditherer::rows_len(self.dither, w) + Sampler::rows_len(self.sampling, self.dither.block(), w)
    }

    /// Entries of [`Scratch::with_cover`](super::Scratch::with_cover) a render of this frame uses (a few per tile).
    pub fn cover_len(&self) -> usize {
        super::cull::tiles::Tiling {
            t: self.tile.max(1) as usize,
            size: (self.width as usize, self.height as usize),
            margin: 0,
        }
        .len()
    }

    /// Entries of `i16` scratch storage [`trace_share`](super::trace_share) needs: [`Frame::scratch_len`] without
    /// the dither's carries (the levels are dithered later, by [`dither_band`](super::dither_band)).
    pub fn trace_scratch_len(&self) -> usize {
        self.scratch_len() - Ditherer::rows_len(self.dither, self.width as usize)
    }

    /// The frame's grid of tiles.
    #[inline(always)]
    pub const fn grid(&self) -> TileGrid {
        TileGrid::new(self.tile as usize, self.width as usize, self.height as usize)
    }

    /// Tiles [`super::trace_share`] keeps for `share` in the frame's band of tile rows.
    pub const fn tiles_len(&self, share: Share) -> usize {
        let grid = self.grid();
        share.tiles_in(grid.tiles().0, grid.rows(self.rows))
    }

    /// Whether the frame can be rendered progressively ([`render_pass`](super::render_pass)): its tiles are a
    /// multiple of 8 pixels (whole 8x8 blocks) and its dither shows one ray per pixel.
    pub fn progressive(&self) -> bool {
        self.tile > 0 && self.tile as usize <= MAX_TILE && self.tile.is_multiple_of(8) && self.dither.block() == 1
    }

    /// Entries of [`Traced`](super::Traced) storage a progressive render of `share` needs: one per pixel of
    /// the 2x2 grid of each of its tiles.
    pub const fn traced_len(&self, share: Share) -> usize {
        let grid = self.grid();
        let (tiles_x, tiles_y) = grid.tiles();
        share.tiles_in(tiles_x, (0, tiles_y)) * (grid.t / 2) * (grid.t / 2)
    }

    pub(super) fn edges(&self) -> bool {
        Sampler::refines_edges(self.sampling, self.dither.block())
    }
}

/// Why a render stopped.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RenderError<E> {
    /// The draw target failed.
    Draw(E),
    /// The progress hook asked to stop.
    Cancelled,
    /// The tile size is 0, above [`MAX_TILE`], or not a multiple of the pattern block.
    BadTile,
    /// The frame asks for edge sampling and the core was built without its `edge-sampling`
    /// feature.
    EdgesNotCompiled,
    /// The frame asks for two-level adaptive sampling and the core was built without its
    /// `coarse-sampling` feature.
    CoarseNotCompiled,
    /// The frame asks for error diffusion (Floyd-Steinberg, Atkinson) and the core was built
    /// without its `diffusion` feature.
    DiffusionNotCompiled,
    /// The scratch storage is smaller than [`Frame::scratch_len`].
    ScratchTooSmall {
        /// Entries needed.
        needed: usize,
    },
    /// The share is not one of its frame's (`index >= of`), or the frame's tiles depend on
    /// each other (error diffusion, edge sampling) and cannot be shared out.
    BadShare,
    /// The angle between neighbouring pixels is below what the scalar resolves: the view is
    /// too narrow (a telephoto) for this scalar at this frame size.
    ViewTooNarrow {
        /// The most pixels across and down the scalar resolves through the view.
        most: [u32; 2],
        /// The scalar's name.
        scalar: &'static str,
    },
    /// The frame's shape is not the one the scene's camera was fitted to (pixels would not be
    /// square): load the scene for this frame ([`crate::scene::CameraDesc::frame`]).
    FrameShape {
        /// The shape the camera was fitted to, in lowest terms.
        fitted: [u32; 2],
        /// The frame's width and height.
        frame: [u32; 2],
    },
    /// A progressive pass was asked of a frame that cannot be rendered progressively
    /// ([`Frame::progressive`]), or the pass is not 8, 4, 2 or 1, or the [`Traced`](super::Traced) storage is
    /// shorter than [`Frame::traced_len`].
    NotProgressive,
}

impl RenderError<core::convert::Infallible> {
    /// The same error for a render that draws into a target failing with `E` (a render that
    /// draws nothing, [`trace_share`](super::trace_share), cannot fail to draw).
    pub fn widen<E>(self) -> RenderError<E> {
        match self {
            RenderError::Draw(never) => match never {},
            RenderError::Cancelled => RenderError::Cancelled,
            RenderError::BadTile => RenderError::BadTile,
            RenderError::EdgesNotCompiled => RenderError::EdgesNotCompiled,
            RenderError::CoarseNotCompiled => RenderError::CoarseNotCompiled,
            RenderError::DiffusionNotCompiled => RenderError::DiffusionNotCompiled,
            RenderError::ScratchTooSmall { needed } => RenderError::ScratchTooSmall { needed },
            RenderError::BadShare => RenderError::BadShare,
            RenderError::ViewTooNarrow { most, scalar } => RenderError::ViewTooNarrow { most, scalar },
            RenderError::FrameShape { fitted, frame } => RenderError::FrameShape { fitted, frame },
            RenderError::NotProgressive => RenderError::NotProgressive,
        }
    }
}

/// A view the frame cannot take ([`Frame::check_scene_view`]), where the scene's text sets it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewRefused<'t> {
    /// 1-based line of the statement that sets the view.
    pub line: u32,
    /// 1-based column of its keyword.
    pub col: u32,
    /// Its keyword.
    pub word: &'t str,
    /// Why the view is refused.
    pub error: RenderError<core::convert::Infallible>,
}

impl fmt::Display for ViewRefused<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}, column {} at `{}`: {}", self.line, self.col, self.word, self.error)
    }
}

impl<E: fmt::Debug> fmt::Display for RenderError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Draw(e) => write!(f, "draw target failed: {e:?}"),
            RenderError::Cancelled => write!(f, "render cancelled"),
            RenderError::BadTile => {
                write!(f, "tile side must be 1..={MAX_TILE} and a multiple of the pattern block")
            }
            RenderError::EdgesNotCompiled => {
                write!(f, "this build leaves out edge sampling (the core's `edge-sampling` feature)")
            }
            RenderError::CoarseNotCompiled => {
                write!(f, "this build leaves out two-level adaptive sampling (the core's `coarse-sampling` feature)")
            }
            RenderError::DiffusionNotCompiled => {
                write!(f, "this build leaves out error diffusion (the core's `diffusion` feature)")
            }
            RenderError::ScratchTooSmall { needed } => {
                write!(f, "render scratch storage too small: {needed} entries needed")
            }
            RenderError::BadShare => {
                write!(
                    f,
                    "tile share out of range, or the frame carries state from tile to tile (error \
                     diffusion, edge sampling)"
                )
            }
            RenderError::ViewTooNarrow { most, scalar } => write!(
                f,
                "the view is too narrow for {scalar} at this size: through it {scalar} resolves at most {}x{} \
                 pixels (widen the field of view, render fewer pixels, or trace in f64)",
                most[0], most[1]
            ),
            RenderError::FrameShape { fitted, frame } => write!(
                f,
                "the scene's view was fitted to frames of shape {}:{}, not {}x{} (pixels would not be square): \
                 load the scene for this frame",
                fitted[0], fitted[1], frame[0], frame[1]
            ),
            RenderError::NotProgressive => {
                write!(
                    f,
                    "progressive passes need tiles of a multiple of 8, one ray per pixel, a pass of 8, \
                     4, 2 or 1 and room for the traced samples"
                )
            }
        }
    }
}

/// Whether `frame` can be rendered in `share`: its tile a multiple of its dither's block and at
/// most [`MAX_TILE`], its sampling and dither compiled in, and the share one of its independent bands
/// (when it is `dithered` here; kept levels only need independent tracing).
pub(super) fn check<E>(frame: &Frame, share: Share, dithered: bool) -> Result<(), RenderError<E>> {
    let (t, block) = (frame.tile as usize, frame.dither.block() as usize);
    if t == 0 || t > MAX_TILE || !t.is_multiple_of(block) {
        return Err(RenderError::BadTile);
    }
    if frame.edges() && !cfg!(feature = "edge-sampling") {
        return Err(RenderError::EdgesNotCompiled);
    }
    if matches!(frame.sampling, Sampling::Adaptive { coarse: true, .. }) && !cfg!(feature = "coarse-sampling") {
        return Err(RenderError::CoarseNotCompiled);
    }
    if frame.dither.diffuses() && !cfg!(feature = "diffusion") {
        return Err(RenderError::DiffusionNotCompiled);
    }
    let independent = if dithered { frame.bands_independent() } else { !frame.edges() };
    if !share.valid() || (share.of > 1 && !independent) {
        return Err(RenderError::BadShare);
    }
    Ok(())
}

/// Whether `frame` has the shape `camera` was fitted to, and `R` resolves the angle between
/// neighbouring pixels of `frame` through `camera`.
pub(super) fn resolves<R: Real, E>(camera: &Camera<R>, frame: &Frame) -> Result<(), RenderError<E>> {
    let size = frame.size();
    // The same shape: the frame's sides in the ratio of the camera's (in lowest terms, so a
    // frame of that shape has sides of at most 65,535 times them: the products fit in u32).
    let [a, b] = camera.shape;
    let same = a <= 0xFFFF && b <= 0xFFFF && size[0] * b == size[1] * a;
    if !same {
        return Err(RenderError::FrameShape { fitted: camera.shape, frame: size });
    }
    let [w, h] = camera.resolves;
    if size[0] <= w && size[1] <= h {
        Ok(())
    } else {
        Err(RenderError::ViewTooNarrow { most: camera.resolves, scalar: R::NAME })
    }
}

/// A frame's grid of tiles: tile `(tx, ty)` covers pixels from `(tx t, ty t)`, `t` on a side
/// except where the frame's right and bottom edges cut it. Every walk over a frame's tiles (the
/// tile loop, the bands, the per-tile object lists) takes its tiles from here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileGrid {
    /// Tile side in pixels (at least 1).
    pub t: usize,
    /// Frame width in pixels.
    pub w: usize,
    /// Frame height in pixels.
    pub h: usize,
}

impl TileGrid {
    /// The grid of a frame `w x h` pixels in tiles of side `t` (0 counts as 1).
    #[inline(always)]
    pub const fn new(t: usize, w: usize, h: usize) -> Self {
        TileGrid { t: if t == 0 { 1 } else { t }, w, h }
    }
    /// Tiles across and down.
    #[inline(always)]
    pub const fn tiles(&self) -> (usize, usize) {
        (self.w.div_ceil(self.t), self.h.div_ceil(self.t))
    }
    /// The band of tile rows `rows` (`[first, end)`) cut to the grid: `first <= end <= tiles down`.
    #[inline(always)]
    pub const fn rows(&self, rows: (u16, u16)) -> (usize, usize) {
        let down = self.tiles().1;
        let end = if (rows.1 as usize) < down { rows.1 as usize } else { down };
        let first = if (rows.0 as usize) < end { rows.0 as usize } else { end };
        (first, end)
    }
    /// Where tile `(tx, ty)` lies (it must be on the grid).
    #[inline(always)]
    pub fn at(&self, tx: usize, ty: usize) -> TileAt {
        let (x0, y0) = (tx * self.t, ty * self.t);
        TileAt { x0, y0, tw: self.t.min(self.w - x0), th: self.t.min(self.h - y0), t: self.t }
    }
}

/// Where a tile lies: its top-left pixel, its size and the frame's tile side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileAt {
    /// Its left column.
    pub x0: usize,
    /// Its top row.
    pub y0: usize,
    /// Its width (the tile side, or less at the frame's right edge).
    pub tw: usize,
    /// Its height (the tile side, or less at the frame's bottom edge).
    pub th: usize,
    /// The frame's tile side.
    pub t: usize,
}
