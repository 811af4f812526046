//! Tiles: the frame is rendered one small tile at a time into a fixed buffer, dithered and
//! handed to an `embedded_graphics` draw target in one `fill_contiguous` call. No full-frame
//! buffer exists; between tiles a hook reports progress and may cancel.
//!
//! A frame can also be rendered **progressively** ([`render_pass`]), the paper's patterning
//! turned into time: pass 8 traces one ray per 8x8 block and shows it as the block, passes 4
//! and 2 add the rays that make 4x4 and 2x2 blocks, and pass 1 completes the frame with the
//! frame's own sampling. Every ray a pass traces on the 2x2 grid is kept ([`Traced`]) and
//! reused by the passes after it, so no ray is traced twice and the last pass draws exactly the
//! frame [`render`] draws.

use crate::accel::{Accelerator, Query, Stats};
use crate::dither::{Dither, Ditherer, Tone, MAX_TILE};
use crate::outline::Apron;
use crate::sample::Sampler;
pub use crate::sample::{level, Hits, Sampling, Shot};
use crate::scalar::Real;
use crate::scene::Camera;
use crate::trace::Tracer;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;

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
    /// with [`Tracer::set_cutoff`] (the larger of the two cutoffs holds; `k` above 14 counts as
    /// 14, [`Real::div_pow2`]); `None`: the tracer's own. 7 is half of
    /// one of the 64 gray steps a pixel's level takes.
    pub cutoff: Option<u8>,
}

/// One core's share of a frame's tiles ([`render_share`]): tile `(tx, ty)` belongs to share `(tx + ty) % of`, a
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
    /// (at most 255): [`trace_share`] of one band with it traces that one tile, so cores can
    /// take tiles one at a time, as they come free.
    pub const fn single(tx: usize, ty: usize, tiles_x: usize) -> Share {
        let of = if tiles_x == 0 { 1 } else { tiles_x };
        Share { index: ((tx + ty) % of) as u8, of: of as u8 }
    }

    fn valid(self) -> bool {
        self.index < self.of
    }
}

impl Frame {
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

    /// Entries of `i16` scratch storage [`render`] needs: error-diffusion carries and the
    /// object ids of the row above the current band for edge detection.
    pub fn scratch_len(&self) -> usize {
        let w = self.width as usize;
        Ditherer::rows_len(self.dither, w) + Sampler::rows_len(self.sampling, self.dither.block(), w)
    }

    /// Entries of [`Scratch::with_cover`] a render of this frame uses (a few per tile).
    pub fn cover_len(&self) -> usize {
        crate::cull::tiles::Tiling {
            t: self.tile.max(1) as usize,
            size: (self.width as usize, self.height as usize),
            margin: 0,
        }
        .len()
    }

    /// Entries of `i16` scratch storage [`trace_share`] needs: [`Frame::scratch_len`] without
    /// the dither's carries (the levels are dithered later, by [`dither_band`]).
    pub fn trace_scratch_len(&self) -> usize {
        self.scratch_len() - Ditherer::rows_len(self.dither, self.width as usize)
    }

    /// Tiles [`trace_share`] keeps for `share` in the frame's band of tile rows.
    pub const fn tiles_len(&self, share: Share) -> usize {
        let t = if self.tile == 0 { 1 } else { self.tile as usize };
        let (tiles_x, tiles_y) = ((self.width as usize).div_ceil(t), (self.height as usize).div_ceil(t));
        let end = if (self.rows.1 as usize) < tiles_y { self.rows.1 as usize } else { tiles_y };
        let first = if (self.rows.0 as usize) < end { self.rows.0 as usize } else { end };
        share.tiles_in(tiles_x, (first, end))
    }

    /// Whether the frame can be rendered progressively ([`render_pass`]): its tiles are a
    /// multiple of 8 pixels (whole 8x8 blocks) and its dither shows one ray per pixel.
    pub fn progressive(&self) -> bool {
        self.tile > 0 && self.tile as usize <= MAX_TILE && self.tile.is_multiple_of(8) && self.dither.block() == 1
    }

    /// Entries of [`Traced`] storage a progressive render of `share` needs: one per pixel of
    /// the 2x2 grid of each of its tiles.
    pub const fn traced_len(&self, share: Share) -> usize {
        let t = if self.tile == 0 { 1 } else { self.tile as usize };
        let (tiles_x, tiles_y) = ((self.width as usize).div_ceil(t), (self.height as usize).div_ceil(t));
        share.tiles_in(tiles_x, (0, tiles_y)) * (t / 2) * (t / 2)
    }

    fn edges(&self) -> bool {
        Sampler::refines_edges(self.sampling, self.dither.block())
    }
}

/// Callbacks between tiles.
pub trait Hooks {
    /// A finished tile of gray levels (0..=64) at `(x, y)`, `w x h`, row-major.
    fn gray_tile(&mut self, _x: u16, _y: u16, _w: u16, _h: u16, _levels: &[u8]) {}
    /// Called after each tile; return false to cancel the render.
    fn progress(&mut self, _done: u32, _total: u32) -> bool {
        true
    }
}

/// Hooks that do nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoHooks;
impl Hooks for NoHooks {}

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
    /// ([`Frame::progressive`]), or the pass is not 8, 4, 2 or 1, or the [`Traced`] storage is
    /// shorter than [`Frame::traced_len`].
    NotProgressive,
}

impl RenderError<core::convert::Infallible> {
    /// The same error for a render that draws into a target failing with `E` (a render that
    /// draws nothing, [`trace_share`], cannot fail to draw).
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

impl<E: fmt::Debug> fmt::Display for RenderError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Draw(e) => write!(f, "draw target failed: {e:?}"),
            RenderError::Cancelled => write!(f, "render cancelled"),
            RenderError::BadTile => {
                write!(f, "tile side must be 1..={MAX_TILE} and a multiple of the pattern block")
            }
            RenderError::EdgesNotCompiled => write!(f, "this build leaves out edge sampling (the core's `edge-sampling` feature)"),
            RenderError::CoarseNotCompiled => write!(f, "this build leaves out two-level adaptive sampling (the core's `coarse-sampling` feature)"),
            RenderError::DiffusionNotCompiled => write!(f, "this build leaves out error diffusion (the core's `diffusion` feature)"),
            RenderError::ScratchTooSmall { needed } => {
                write!(f, "render scratch storage too small: {needed} entries needed")
            }
            RenderError::BadShare => write!(f, "tile share out of range, or the frame carries state from tile to tile (error diffusion, edge sampling)"),
            RenderError::ViewTooNarrow { most, scalar } => write!(
                f,
                "the view is too narrow for {scalar} at this size: through it {scalar} resolves at most {}x{} pixels (widen the field of view, render fewer pixels, or trace in f64)",
                most[0], most[1]
            ),
            RenderError::FrameShape { fitted, frame } => write!(
                f,
                "the scene's view was fitted to frames of shape {}:{}, not {}x{} (pixels would not be square): load the scene for this frame",
                fitted[0], fitted[1], frame[0], frame[1]
            ),
            RenderError::NotProgressive => write!(f, "progressive passes need tiles of a multiple of 8, one ray per pixel, a pass of 8, 4, 2 or 1 and room for the traced samples"),
        }
    }
}

/// Renders a frame tile by tile into `target`, returning the statistics.
///
/// `scratch` comes from the storage the scene was loaded into ([`crate::storage`]); its rows
/// must hold [`Frame::scratch_len`] entries (none for Bayer or patterning with one ray per
/// pixel).
pub fn render<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    render_share(tracer, frame, Share::ALL, target, scratch, hooks)
}

/// [`render`] of one share of the frame's tiles (one core's, when cores split a frame; the
/// frame stays what the picture is, the share says which of its tiles this call draws).
///
/// Kept out of line so the firmware report can check that nothing it calls uses floating point
/// when the scalar is fixed point.
#[inline(never)]
pub fn render_share<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    render_tiles(tracer, frame, share, None, Out::Draw(target), scratch, hooks)
}

/// What trace, then dither keeps of a traced tile until it is dithered ([`trace_share`],
/// [`dither_band`]): its gray levels (tone curve and the silhouette lines inside it applied),
/// and for the lines across its borders what its pixels hit (object and depth key) along its
/// four sides: the left column and top row as sampled, and the right column and bottom row as
/// the apron of the tiles right of it and below takes them ([`Sampler::side`]: the eye rays
/// through their centres, or with adaptive sampling the fill between two traced pixels that
/// hit the same object).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeptTile {
    /// Gray levels, row-major, `tw * th` of them.
    pub levels: [u8; MAX_TILE * MAX_TILE],
    /// The left column's hits, one per tile row.
    pub left: [(u16, u16); MAX_TILE],
    /// The top row's hits, one per tile column.
    pub top: [(u16, u16); MAX_TILE],
    /// The right column's rays through the centres, one per tile row.
    pub right: [(u16, u16); MAX_TILE],
    /// The bottom row's rays through the centres, one per tile column.
    pub bottom: [(u16, u16); MAX_TILE],
}

impl KeptTile {
    /// Nothing kept yet.
    pub const EMPTY: KeptTile = KeptTile {
        levels: [0; MAX_TILE * MAX_TILE],
        left: [(0, 0); MAX_TILE],
        top: [(0, 0); MAX_TILE],
        right: [(0, 0); MAX_TILE],
        bottom: [(0, 0); MAX_TILE],
    };
}

impl Default for KeptTile {
    fn default() -> Self {
        Self::EMPTY
    }
}

/// The first half of a frame rendered **trace, then dither**: one share's tiles in the frame's
/// band of tile rows, traced and kept ([`KeptTile`]) for [`dither_band`] instead of dithered
/// and drawn: tile `k` of the share in the band (in the order the render visits them) in
/// `kept[k]`; `kept` holds at least [`Frame::tiles_len`] tiles. Unlike [`render_share`],
/// frames whose dithering carries error from tile to tile (Floyd-Steinberg, Atkinson) can be
/// traced in shares this way: the cores trace, and one dithers the finished bands in order.
/// Silhouette lines across a tile's borders need no apron rays here: [`dither_band`] takes
/// them from the neighbours' kept edges (as [`Sampler::side`] gives them: the same apron
/// [`render`] finds with its hit-only rays).
///
/// `scratch` needs [`Frame::trace_scratch_len`] rows (no dither carries).
pub fn trace_share<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    kept: &mut [KeptTile],
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<core::convert::Infallible>> {
    if kept.len() < frame.tiles_len(share) {
        return Err(RenderError::ScratchTooSmall { needed: frame.tiles_len(share) });
    }
    render_tiles::<_, _, Nowhere, E>(tracer, frame, share, None, Out::Keep(kept), scratch, hooks)
}

/// [`trace_share`] for pass `pass` of a progressive frame ([`render_pass`]): the pass's tiles
/// kept for [`dither_band`], the rays it traces kept in `traced` for the next pass. `traced`
/// holds the rays of `share`'s tiles in `frame`'s rows alone, in the order they are traced (at
/// least [`Frame::tiles_len`] times `(tile / 2)^2` entries), the same storage through passes 8,
/// 4, 2 and 1; so each tile can have its own. Only the last pass has silhouette lines: dither
/// the others with the frame's `outline` off. Bands traced and dithered in order give
/// [`render_pass`]'s picture of the pass, bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn trace_pass<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    pass: u8,
    traced: &mut [Traced],
    kept: &mut [KeptTile],
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<core::convert::Infallible>> {
    let per_tile = (frame.tile as usize / 2) * (frame.tile as usize / 2);
    if !frame.progressive() || ![8, 4, 2, 1].contains(&pass) || traced.len() < frame.tiles_len(share) * per_tile {
        return Err(RenderError::NotProgressive);
    }
    if kept.len() < frame.tiles_len(share) {
        return Err(RenderError::ScratchTooSmall { needed: frame.tiles_len(share) });
    }
    render_tiles::<_, _, Nowhere, E>(
        tracer,
        frame,
        share,
        Some(Pass { n: pass, traced, whole_share: false }),
        Out::Keep(kept),
        scratch,
        hooks,
    )
}

/// The second half of trace, then dither ([`trace_share`]): dithers tile row `ty` of `frame`
/// from its kept tiles (`tile(tx)`: tile `tx` of the row) and draws it into `target`, tile by
/// tile in the order [`render`] draws them, so bands dithered in order give [`render`]'s frame
/// bit for bit. The band ends at the first tile `tile` has nothing for. With silhouette lines,
/// `above` (the frame's width of entries) holds what the bottom row of the band above hit and
/// is left holding this band's (shorter storage is refused: `ScratchTooSmall`). The band is
/// drawn in one `fill_contiguous` call (a display then gets it in one transfer, not one per
/// tile), from `band`, at least the frame's width times the tile side of pixels. `ditherer`
/// carries error between bands: make it once per frame ([`Ditherer::new`] over
/// [`Ditherer::rows_len`] entries). [`dither_tiles`] dithers a band in parts.
pub fn dither_band<'l, D: DrawTarget<Color = BinaryColor>>(
    frame: &Frame,
    ty: usize,
    tile: impl Fn(usize) -> Option<&'l KeptTile>,
    (above, band): (&mut [(u16, u16)], &mut [BinaryColor]),
    ditherer: &mut Ditherer<'_>,
    target: &mut D,
) -> Result<(), RenderError<D::Error>> {
    let mut left = [(0, 0); MAX_TILE];
    dither_tiles(frame, (ty, 0), tile, (above, band, &mut left), ditherer, target).map(|_| ())
}

/// What [`dither_tiles`] keeps between the parts of a band and between bands: the row above
/// the band's hits, the band's pixels and the right column's hits of the last tile dithered.
pub type BandRows<'a> = (&'a mut [(u16, u16)], &'a mut [BinaryColor], &'a mut [(u16, u16); MAX_TILE]);

/// [`dither_band`] in parts, as the tiles of a band come in: dithers tile row `ty` of `frame`
/// from tile `from` on, as far as `tile` has them (`tile(tx)`: tile `tx` of the row, `None`
/// where the part ends), and draws those tiles in one `fill_contiguous` call. Returns the
/// first tile it did not dither (the row's tile count once the band is done): the next call's
/// `from`. A band dithered part after part, from tile 0 on and each part where the last
/// ended, is bit for bit the band [`dither_band`] draws. `left` holds, between the parts, the
/// right column's hits of the last tile dithered (the silhouette lines' apron); `above` and
/// `band` are as for [`dither_band`].
pub fn dither_tiles<'l, D: DrawTarget<Color = BinaryColor>>(
    frame: &Frame,
    (ty, from): (usize, usize),
    tile: impl Fn(usize) -> Option<&'l KeptTile>,
    (above, band, left): BandRows<'_>,
    ditherer: &mut Ditherer<'_>,
    target: &mut D,
) -> Result<usize, RenderError<D::Error>> {
    let (t, w, h) = (frame.tile as usize, frame.width as usize, frame.height as usize);
    if frame.outline && above.len() < w {
        return Err(RenderError::ScratchTooSmall { needed: w });
    }
    let rows = t.min(h.saturating_sub(ty * t));
    let Some(band) = band.get_mut(..w * rows) else {
        return Err(RenderError::ScratchTooSmall { needed: w * rows });
    };
    let (tiles, start) = (w.div_ceil(t), from * t);
    let mut bits = [BinaryColor::Off; MAX_TILE * MAX_TILE];
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    if from == 0 {
        ditherer.next_band();
    }
    let mut tx = from;
    while tx < tiles {
        let (x0, y0) = (tx * t, ty * t);
        let (tw, th) = (t.min(w - x0), t.min(h - y0));
        let Some(kept) = tile(tx) else { break };
        levels[..tw * th].copy_from_slice(&kept.levels[..tw * th]);
        if frame.outline {
            let up = above.get(x0..x0 + tw).filter(|_| ty > 0);
            let apron = Apron { left: Some(&left[..th]).filter(|_| tx > 0), up };
            crate::outline::apron(tw, th, &kept.left[..th], &kept.top[..tw], apron, &mut levels[..tw * th]);
            if let Some(row) = above.get_mut(x0..x0 + tw) {
                row.copy_from_slice(&kept.bottom[..tw]);
            }
            left[..th].copy_from_slice(&kept.right[..th]);
        }
        ditherer.tile(x0, y0, tw, th, &levels[..tw * th], &mut bits);
        for (y, row) in bits[..tw * th].chunks(tw).enumerate() {
            band[y * w + x0..y * w + x0 + tw].copy_from_slice(row);
        }
        tx += 1;
    }
    let end = (tx * t).min(w);
    if end <= start {
        return Ok(tx);
    }
    // The part, row by row: a whole band as one slice (the common case, and the cheapest
    // iterator to draw from).
    let area = Rectangle::new(Point::new(start as i32, (ty * t) as i32), Size::new((end - start) as u32, rows as u32));
    let drawn = if end - start == w {
        target.fill_contiguous(&area, band.iter().copied())
    } else {
        target.fill_contiguous(&area, band.chunks(w).flat_map(|row| row[start..end].iter().copied()))
    };
    drawn.map(|()| tx).map_err(RenderError::Draw)
}

/// Where the tile loop puts a finished tile: dithered and drawn, or kept as gray levels.
enum Out<'o, D> {
    Draw(&'o mut D),
    Keep(&'o mut [KeptTile]),
}

/// The draw target of a render that draws nothing ([`trace_share`]).
struct Nowhere;

impl embedded_graphics_core::geometry::OriginDimensions for Nowhere {
    fn size(&self) -> Size {
        Size::zero()
    }
}

impl DrawTarget for Nowhere {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;
    fn draw_iter<I: IntoIterator<Item = embedded_graphics_core::Pixel<BinaryColor>>>(
        &mut self,
        _: I,
    ) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// What a progressive render keeps of one ray it traced on the 2x2 grid: its gray level and
/// what it hit ([`render_pass`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traced {
    /// Gray level (0..=64).
    pub level: u8,
    /// Object hit (modulo 2^16).
    pub object: u16,
    /// Depth key of the hit.
    pub depth: u16,
}

/// One pass of a progressive frame ([`Frame::progressive`]) over one share of its tiles: pass
/// 8, 4 or 2 shows one ray per block of that side (the ray through the block's top-left pixel,
/// traced now or by an earlier pass), pass 1 the finished frame, which is the frame [`render`]
/// draws. Run the passes in the order 8, 4, 2, 1 with the same `traced` storage (at least
/// [`Frame::traced_len`] entries; the rays each pass traces are kept there for the next).
/// Returns the statistics of this pass alone.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub fn render_pass<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    pass: u8,
    traced: &mut [Traced],
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    if !frame.progressive() || ![8, 4, 2, 1].contains(&pass) || traced.len() < frame.traced_len(share) {
        return Err(RenderError::NotProgressive);
    }
    render_tiles(
        tracer,
        frame,
        share,
        Some(Pass { n: pass, traced, whole_share: true }),
        Out::Draw(target),
        scratch,
        hooks,
    )
}

/// A pass of a progressive frame as the tile loop takes it: which pass, and the rays kept
/// between passes, for the whole share (its tiles before `frame`'s rows first) or for the tiles
/// of `frame`'s rows alone.
struct Pass<'t> {
    n: u8,
    traced: &'t mut [Traced],
    whole_share: bool,
}

/// The tile loop of [`render_share`] and [`render_pass`].
fn render_tiles<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    mut pass: Option<Pass<'_>>,
    mut out: Out<'_, D>,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    let keep = matches!(out, Out::Keep(_));
    check(frame, share, !keep)?;
    let tracer = &tracer.with_cutoff_at_least(frame.cutoff);
    resolves(tracer.scene().camera(), frame)?;
    let (t, block) = (frame.tile as usize, frame.dither.block() as usize);
    let (w, h) = (frame.width as usize, frame.height as usize);
    // Kept levels are dithered later (by `dither_band`): the trace needs no carries, and an
    // ordered mode, which needs no storage, stands in for the frame's dither.
    let mode = if keep { Dither::Bayer } else { frame.dither };
    let carries_len = Ditherer::rows_len(mode, w);
    let needed = carries_len + Sampler::rows_len(frame.sampling, frame.dither.block(), w);
    let too_small = || RenderError::ScratchTooSmall { needed };
    let rows = scratch.rows.get_mut(..needed).ok_or_else(too_small)?;
    let (carries, above) = rows.split_at_mut(carries_len);
    let mut dither = Ditherer::new(mode, w, carries).ok_or_else(too_small)?;
    let mut sampler = Sampler::new(frame.sampling, frame.dither.block(), w, above).ok_or_else(too_small)?;
    // The outline is drawn on finished frames: a progressive frame's last pass, not its previews.
    let outline = frame.outline && pass.as_ref().is_none_or(|p| p.n == 1);
    let keys = frame.outline || matches!(frame.sampling, Sampling::Adaptive { coarse: true, .. });
    // Past 64 objects the tiles' candidate masks hold every object: list the objects whose
    // windows meet each tile instead, when the scratch has room.
    let tiling = crate::cull::tiles::Tiling { t, size: (w, h), margin: block };
    let many = cfg!(feature = "tile-lists") && crate::cull::tiles::lists(tracer.scene().objects().len());
    let counted = many && tiling.count(tracer.scene(), (frame.rows.0 as usize, frame.rows.1 as usize), scratch.cover);
    let cover: &[u32] = scratch.cover;
    let need = Query::mailbox_len(tracer.scene()).min(scratch.mailbox.len());
    let mut q = Query::new(&mut scratch.mailbox[..need]);
    let (tiles_x, tiles_y) = (w.div_ceil(t), h.div_ceil(t));
    let (first, end) = (frame.rows.0 as usize, (frame.rows.1 as usize).min(tiles_y));
    let total = share.tiles_in(tiles_x, (first, end)) as u32;
    // Tiles of this share before the band range: their traced samples come first.
    let skipped = share.tiles_in(tiles_x, (0, first.min(tiles_y)));
    let per_tile = (t / 2) * (t / 2);
    let mut done = 0;
    let cam = tracer.scene().camera();
    let (w4, h4) = (4 * w as i32, 4 * h as i32);
    // The eye ray through `(sx, sy)` (quarter pixels), its window position given to the query.
    let mut window = crate::camera::EyeRayCache::<R>::new(cam, w4, h4);
    let mut eye = |q: &mut Query<'_>, sx: usize, sy: usize| {
        let (uv, ray) = window.at(sx as i32, sy as i32);
        q.set_eye_ray(Some(uv));
        ray
    };
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    let mut hits = Hits::new();
    let mut bits = [BinaryColor::Off; MAX_TILE * MAX_TILE];
    let mut kept = 0;
    for ty in first..end {
        dither.next_band();
        sampler.next_band();
        // Remembered occluders are forgotten at every band of tiles, so a band renders the same
        // whichever bands a core or thread rendered before it.
        q.forget_occluders();
        for tx in (0..tiles_x).filter(|&tx| share.holds(tx, ty)) {
            let (x0, y0) = (tx * t, ty * t);
            let (tw, th) = (t.min(w - x0), t.min(h - y0));
            let at = Block { x0, y0, tw, th, t };
            let candidates = if many {
                q.set_eye_list(if counted { tiling.list(cover, (tx, ty)) } else { None });
                u64::MAX
            } else {
                let c = crate::cull::tiles::tile_candidates(
                    tracer.scene(),
                    (at.x0, at.tw),
                    (at.y0, at.th),
                    block,
                    (w4, h4),
                );
                q.set_eye_candidates(c);
                c
            };
            let mut alone = |xs: [usize; 2], ys: [usize; 2], id: u16, far: u16| {
                crate::cull::block::alone(tracer, candidates, (x0, y0), (xs, ys), id, far, (w4, h4))
            };
            let mut shoot = |sx: usize, sy: usize| -> Shot<R> {
                let ray = eye(&mut q, sx, sy);
                let (v, id, depth) = tracer.eye_sample(ray, &mut q);
                // Only the outline and two-level sampling read depths: a frame without either
                // keys none.
                (v, id as u16, if keys { depth.depth_key() } else { u16::MAX })
            };
            match pass.as_mut() {
                None => sampler.tile(x0, y0, tw, th, &mut shoot, &mut alone, &mut levels, &mut hits),
                Some(Pass { n, traced, whole_share }) => {
                    let k = if *whole_share { skipped } else { 0 } + done as usize;
                    pass_tile(
                        *n,
                        &mut sampler,
                        at,
                        &mut traced[k * per_tile..(k + 1) * per_tile],
                        &mut shoot,
                        &mut alone,
                        &mut levels,
                        &mut hits,
                    );
                }
            }
            hooks.gray_tile(x0 as u16, y0 as u16, tw as u16, th as u16, &levels[..tw * th]);
            if !frame.tone.is_linear() {
                levels[..tw * th].iter_mut().for_each(|l| *l = frame.tone.apply(*l));
            }
            let mut sides = KeptTile::EMPTY;
            if outline {
                // The apron: what the eye rays through the column left of the tile and the row
                // above it hit (the tile's eye candidates cover them: they are a pixel away).
                let mut probe = |x: usize, y: usize| -> (u16, u16) {
                    let ray = eye(&mut q, 4 * x + 2, 4 * y + 2);
                    let (id, depth) = tracer.eye_hit(ray, &mut q);
                    (id as u16, depth.depth_key())
                };
                if keep {
                    // Lines across the borders are drawn when the band is dithered, from the
                    // sides kept here: no apron rays (2x2 grids and pattern blocks alone trace
                    // their right column's and bottom row's pixels again, through the centres).
                    let hit = |x: usize, y: usize| (hits.object[y * tw + x], hits.depth[y * tw + x]);
                    let mut exact = |x: usize, y: usize| {
                        if sampler.exact(x, y, tw, th, &hits) {
                            hit(x, y)
                        } else {
                            probe(x0 + x, y0 + y)
                        }
                    };
                    (0..th).for_each(|y| sides.left[y] = hit(0, y));
                    (0..tw).for_each(|x| sides.top[x] = hit(x, 0));
                    sampler.side(th, |y| exact(tw - 1, y), &mut sides.right);
                    sampler.side(tw, |x| exact(x, th - 1), &mut sides.bottom);
                    crate::outline::tile(tw, th, &hits, Apron { left: None, up: None }, &mut levels[..tw * th]);
                } else {
                    outline_tile(Block { x0, y0, tw, th, t }, &sampler, &mut probe, &hits, &mut levels[..tw * th]);
                }
            }
            match &mut out {
                Out::Keep(store) => {
                    sides.levels[..tw * th].copy_from_slice(&levels[..tw * th]);
                    store[kept] = sides;
                    kept += 1;
                }
                Out::Draw(target) => {
                    dither.tile(x0, y0, tw, th, &levels[..tw * th], &mut bits);
                    let area = Rectangle::new(Point::new(x0 as i32, y0 as i32), Size::new(tw as u32, th as u32));
                    target.fill_contiguous(&area, bits[..tw * th].iter().copied()).map_err(RenderError::Draw)?;
                }
            }
            done += 1;
            if !hooks.progress(done, total) {
                return Err(RenderError::Cancelled);
            }
        }
    }
    Ok(q.stats)
}

/// A tile of pass `n` of a progressive frame: a preview of `n`x`n` blocks (each side a constant
/// in its own copy of the loop: no division), or the finished tile (`n` 1) from the rays `kept`.
#[allow(clippy::too_many_arguments)]
fn pass_tile<R: Real>(
    n: u8,
    sampler: &mut Sampler<'_>,
    at: Block,
    kept: &mut [Traced],
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    hits: &mut Hits,
) {
    match n {
        8 => preview_tile::<R, 8>(at, kept, shoot, levels),
        4 => preview_tile::<R, 4>(at, kept, shoot, levels),
        2 => preview_tile::<R, 2>(at, kept, shoot, levels),
        _ => finish_tile(sampler, at, kept, shoot, alone, levels, hits),
    }
}

/// Whether `frame` can be rendered in `share`: its tile a multiple of its dither's block and at
/// most [`MAX_TILE`], its sampling and dither compiled in, and the share one of its independent bands
/// (when it is `dithered` here; kept levels only need independent tracing).
fn check<E>(frame: &Frame, share: Share, dithered: bool) -> Result<(), RenderError<E>> {
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
fn resolves<R: Real, E>(camera: &Camera<R>, frame: &Frame) -> Result<(), RenderError<E>> {
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

/// Silhouette lines on a tile's `levels`: its own `hits`, and its apron: the right column of
/// the tile left of it and the bottom row of the tile above, as those tiles keep their sides
/// ([`Sampler::side`]), from what `probe` answers (the eye ray through a pixel's centre).
fn outline_tile(
    at: Block,
    sampler: &Sampler<'_>,
    probe: &mut impl FnMut(usize, usize) -> (u16, u16),
    hits: &Hits,
    levels: &mut [u8],
) {
    let Block { x0, y0, tw, th, .. } = at;
    let (mut left, mut up) = ([(0u16, 0u16); MAX_TILE], [(0u16, 0u16); MAX_TILE]);
    if x0 > 0 {
        sampler.side(th, |y| probe(x0 - 1, y0 + y), &mut left);
    }
    if y0 > 0 {
        sampler.side(tw, |x| probe(x0 + x, y0 - 1), &mut up);
    }
    let apron = Apron { left: (x0 > 0).then_some(&left[..th]), up: (y0 > 0).then_some(&up[..tw]) };
    crate::outline::tile(tw, th, hits, apron, levels);
}

/// Where a tile lies: its top-left pixel, its size and the frame's tile side.
#[derive(Clone, Copy)]
struct Block {
    x0: usize,
    y0: usize,
    tw: usize,
    th: usize,
    t: usize,
}

/// Where the ray through pixel `(x, y)` of a tile of side `t` is kept: one entry per pixel of
/// the tile's 2x2 grid, `(t / 2)^2` of them.
fn kept_at(t: usize, x: usize, y: usize) -> usize {
    (y / 2) * (t / 2) + x / 2
}

/// One tile of the last progressive pass: the frame's own sampling, with the rays of the 2x2
/// grid taken from the earlier passes (`kept`): a level l comes back as the brightness l / 64,
/// whose level is l again.
fn finish_tile<R: Real>(
    sampler: &mut Sampler<'_>,
    Block { x0, y0, tw, th, t }: Block,
    kept: &[Traced],
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    hits: &mut Hits,
) {
    let sixty_fourth = R::ONE / R::from_i32(64);
    let mut reuse = |sx: usize, sy: usize| -> Shot<R> {
        let (x, y) = ((sx / 4).wrapping_sub(x0), (sy / 4).wrapping_sub(y0));
        if sx % 4 == 2 && sy % 4 == 2 && x % 2 == 0 && y % 2 == 0 && x < tw && y < th {
            let k = kept[kept_at(t, x, y)];
            (R::from_i32(k.level as i32) * sixty_fourth, k.object, k.depth)
        } else {
            shoot(sx, sy)
        }
    };
    sampler.tile(x0, y0, tw, th, &mut reuse, alone, levels, hits)
}

/// One tile of preview pass `N` (8, 4 or 2): one ray per `N`x`N` block, through its top-left
/// pixel, traced now unless an earlier pass traced it (it lies on the grid of side `2N`), and
/// kept in `kept` for the passes after.
fn preview_tile<R: Real, const N: usize>(
    Block { x0, y0, tw, th, t }: Block,
    kept: &mut [Traced],
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
) {
    for by in (0..th).step_by(N) {
        let rows = by..(by + N).min(th);
        for bx in (0..tw).step_by(N) {
            let k = if N < 8 && bx % (2 * N) == 0 && by % (2 * N) == 0 {
                kept[kept_at(t, bx, by)]
            } else {
                let (v, object, depth) = shoot(4 * (x0 + bx) + 2, 4 * (y0 + by) + 2);
                let k = Traced { level: level(v), object, depth };
                kept[kept_at(t, bx, by)] = k;
                k
            };
            let cols = bx..(bx + N).min(tw);
            for y in rows.clone() {
                let row = y * tw;
                levels[row + cols.start..row + cols.end].fill(k.level);
            }
        }
    }
}

/// The memory a render works in: the mailbox (one stamp per primitive and per composite,
/// so a ray tests each once; a shorter one only costs repeated tests) and the rows
/// ([`Frame::scratch_len`] entries; error diffusion and edge detection fail without them).
#[derive(Debug)]
pub struct Scratch<'a> {
    pub(crate) mailbox: &'a mut [u32],
    pub(crate) rows: &'a mut [i16],
    pub(crate) cover: &'a mut [u32],
}

impl<'a> Scratch<'a> {
    /// Scratch in caller-owned slices.
    pub fn new(mailbox: &'a mut [u32], rows: &'a mut [i16]) -> Self {
        Scratch { mailbox, rows, cover: &mut [] }
    }

    /// With room to list which objects' eye windows meet each tile ([`Frame::cover_len`]
    /// entries): in a scene of more than 64 objects, the eye rays of a tile that few windows
    /// meet then test those objects without walking the lattice (the same frame, sooner).
    /// Without it (or with too few entries, or without the `tile-lists` feature) every eye ray
    /// walks.
    pub fn with_cover(self, cover: &'a mut [u32]) -> Self {
        Scratch { cover, ..self }
    }
}
