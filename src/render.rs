//! Tiles: the frame is rendered one small tile at a time into a fixed buffer, dithered and
//! handed to an `embedded_graphics` draw target in one `fill_contiguous` call. No full-frame
//! buffer exists; between tiles a hook reports progress and may cancel.

use crate::accel::{Accelerator, Query, Stats};
use crate::dither::{Dither, Ditherer, MAX_TILE};
use crate::scalar::Real;
pub use crate::sample::{level, Sampling};
use crate::sample::Sampler;
use crate::scene::Camera;
use crate::storage::Scratch;
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
    pub fn holds(self, tx: usize, ty: usize) -> bool {
        (tx + ty) % self.of.max(1) as usize == self.index as usize
    }

    fn valid(self) -> bool {
        self.index < self.of
    }
}

impl Frame {
    /// A frame with 8x8 tiles, Bayer dithering and one ray per pixel.
    pub fn new(width: u16, height: u16) -> Self {
        Frame { width, height, tile: 8, dither: Dither::Bayer, sampling: Sampling::Center, rows: (0, u16::MAX) }
    }

    /// Whether bands of tile rows can be rendered apart and give the same pixels: true unless
    /// error diffusion or edge detection carries state from one tile row to the next.
    pub fn bands_independent(&self) -> bool {
        !self.dither.diffuses() && !self.edges()
    }

    /// Entries of `i16` scratch storage [`render`] needs: error-diffusion carries and the
    /// object ids of the row above the current band for edge detection.
    pub fn scratch_len(&self) -> usize {
        let w = self.width as usize;
        Ditherer::rows_len(self.dither, w) + Sampler::rows_len(self.sampling, self.dither.block(), w)
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
    /// The scratch storage is smaller than [`Frame::scratch_len`].
    ScratchTooSmall {
        /// Entries needed.
        needed: usize,
    },
    /// The share is not one of its frame's (`index >= of`), or the frame's tiles depend on
    /// each other (error diffusion, edge sampling) and cannot be shared out.
    BadShare,
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
            RenderError::ScratchTooSmall { needed } => {
                write!(f, "render scratch storage too small: {needed} entries needed")
            }
            RenderError::BadShare => write!(f, "tile share out of range, or the dithering carries error from tile to tile"),
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
    let t = frame.tile as usize;
    let block = frame.dither.block() as usize;
    if t == 0 || t > MAX_TILE || !t.is_multiple_of(block) {
        return Err(RenderError::BadTile);
    }
    if frame.edges() && !cfg!(feature = "edge-sampling") {
        return Err(RenderError::EdgesNotCompiled);
    }
    if !share.valid() || (share.of > 1 && !frame.bands_independent()) {
        return Err(RenderError::BadShare);
    }
    let (w, h) = (frame.width as usize, frame.height as usize);
    let too_small = || RenderError::ScratchTooSmall { needed: frame.scratch_len() };
    let rows = scratch.rows.get_mut(..frame.scratch_len()).ok_or_else(too_small)?;
    let (carries, above) = rows.split_at_mut(Ditherer::rows_len(frame.dither, w));
    let mut dither = Ditherer::new(frame.dither, w, carries).ok_or_else(too_small)?;
    let mut sampler = Sampler::new(frame.sampling, frame.dither.block(), w, above).ok_or_else(too_small)?;
    let need = Query::mailbox_len(tracer.scene()).min(scratch.mailbox.len());
    let mut q = Query::new(&mut scratch.mailbox[..need]);
    let (tiles_x, tiles_y) = (w.div_ceil(t), h.div_ceil(t));
    let (first, end) = (frame.rows.0 as usize, (frame.rows.1 as usize).min(tiles_y));
    let total = (first..end).map(|ty| (0..tiles_x).filter(|&tx| share.holds(tx, ty)).count()).sum::<usize>() as u32;
    let mut done = 0;
    let cam = tracer.scene().camera();
    let (w4, h4) = (4 * w as i32, 4 * h as i32);
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    let mut bits = [BinaryColor::Off; MAX_TILE * MAX_TILE];
    for ty in first..end {
        dither.next_band();
        sampler.next_band();
        // Remembered occluders are forgotten at every band of tiles, so a band renders the same
        // whichever bands a core or thread rendered before it.
        q.forget_occluders();
        for tx in (0..tiles_x).filter(|&tx| share.holds(tx, ty)) {
            let (x0, y0) = (tx * t, ty * t);
            let (tw, th) = (t.min(w - x0), t.min(h - y0));
            // The objects this tile's eye rays can hit: those whose window meets the tile's
            // (widened by a block on each side, beyond any ray the sampler shoots in the tile).
            let m = 4 * block as i32;
            let (sx, sy) = ([4 * x0 as i32 - m, 4 * (x0 + tw) as i32 + m], [4 * y0 as i32 - m, 4 * (y0 + th) as i32 + m]);
            let (lo, hi) = (Camera::<R>::window_uv(sx[0], sy[1], w4, h4), Camera::<R>::window_uv(sx[1], sy[0], w4, h4));
            q.set_eye_candidates(tracer.scene().eye_candidates([lo[0], hi[0]], [lo[1], hi[1]]));
            let mut shoot = |sx: usize, sy: usize| {
                q.set_eye_ray(Some(Camera::<R>::window_uv(sx as i32, sy as i32, w4, h4)));
                let (v, id) = tracer.radiance_and_object(cam.ray(sx as i32, sy as i32, w4, h4), &mut q);
                (v, id as u16)
            };
            sampler.tile(x0, y0, tw, th, &mut shoot, &mut levels);
            dither.tile(x0, y0, tw, th, &levels[..tw * th], &mut bits);
            hooks.gray_tile(x0 as u16, y0 as u16, tw as u16, th as u16, &levels[..tw * th]);
            let area = Rectangle::new(Point::new(x0 as i32, y0 as i32), Size::new(tw as u32, th as u32));
            target.fill_contiguous(&area, bits[..tw * th].iter().copied()).map_err(RenderError::Draw)?;
            done += 1;
            if !hooks.progress(done, total) {
                return Err(RenderError::Cancelled);
            }
        }
    }
    Ok(q.stats)
}
