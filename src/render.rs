//! Tiles: the frame is rendered one small tile at a time into a fixed buffer, dithered and
//! handed to an `embedded_graphics` draw target in one `fill_contiguous` call. No full-frame
//! buffer exists; between tiles a hook reports progress and may cancel.

use crate::accel::{Accelerator, Query, Stats};
use crate::dither::{ordered, Carry, Dither, LEVELS, MAX_TILE};
use crate::scalar::Real;
use crate::storage::Scratch;
use crate::trace::{Effects, Tracer, NO_OBJECT};
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;

/// How many eye rays a pixel gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// One ray through the centre of each pixel (or of each pattern block).
    Center,
    /// Four rays per pixel on a 2x2 grid, averaged.
    Grid2x2,
    /// One ray per pixel, and the 2x2 grid only where a neighbouring pixel's eye ray hit a
    /// different object (the paper's "area anti-aliasing only at object edges"), or where the
    /// one-ray gray levels of neighbours in the tile differ by at least `contrast` (shadow,
    /// mirror and refraction edges inside one object; above 64 turns this test off).
    Edges {
        /// Gray-level jump (of 64) that also counts as an edge.
        contrast: u8,
    },
}

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
        (if self.dither.diffuses() { Carry::len(w) } else { 0 }) + if self.edges() { w } else { 0 }
    }

    fn edges(&self) -> bool {
        matches!(self.sampling, Sampling::Edges { .. }) && self.dither.block() == 1
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
    /// The frame asks for an effect the tracer was compiled without.
    NotCompiled(Effects),
    /// The scratch storage is smaller than [`Frame::scratch_len`].
    ScratchTooSmall {
        /// Entries needed.
        needed: usize,
    },
}

impl<E: fmt::Debug> fmt::Display for RenderError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Draw(e) => write!(f, "draw target failed: {e:?}"),
            RenderError::Cancelled => write!(f, "render cancelled"),
            RenderError::BadTile => {
                write!(f, "tile side must be 1..={MAX_TILE} and a multiple of the pattern block")
            }
            RenderError::NotCompiled(e) => write!(f, "this build leaves out {e}"),
            RenderError::ScratchTooSmall { needed } => {
                write!(f, "render scratch storage too small: {needed} entries needed")
            }
        }
    }
}

/// Gray level (0..=64) of a brightness in `[0, 1]`, rounded to nearest.
pub fn level<R: Real>(v: R) -> u8 {
    let l = v * R::from_i32(LEVELS as i32) + R::HALF;
    // Bisection over the 65 levels: no float-to-int conversion the scalar may not have.
    let mut lo = 0u8;
    let mut hi = LEVELS + 1;
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if R::from_i32(mid as i32) <= l {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Renders a frame tile by tile into `target`, returning the statistics.
///
/// Kept out of line so the firmware report can check that nothing it calls uses floating point
/// when the scalar is fixed point.
///
/// `scratch` comes from the storage the scene was loaded into ([`crate::storage`]); its rows
/// must hold [`Frame::scratch_len`] entries (none for Bayer or patterning with one ray per
/// pixel).
#[inline(never)]
pub fn render<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    let t = frame.tile as usize;
    let block = frame.dither.block() as usize;
    if t == 0 || t > MAX_TILE || !t.is_multiple_of(block) {
        return Err(RenderError::BadTile);
    }
    if frame.edges() && !Effects::from_bits(E).contains(Effects::EDGE_AA) {
        return Err(RenderError::NotCompiled(Effects::EDGE_AA));
    }
    let (w, h) = (frame.width as usize, frame.height as usize);
    let rows = scratch.rows.get_mut(..frame.scratch_len()).ok_or(RenderError::ScratchTooSmall { needed: frame.scratch_len() })?;
    let (carry_store, above) = rows.split_at_mut(if frame.dither.diffuses() { Carry::len(w) } else { 0 });
    let mut carry = if frame.dither.diffuses() { Carry::new(carry_store, w) } else { None };
    above.iter_mut().for_each(|v| *v = NO_OBJECT as u16 as i16);
    let need = Query::mailbox_len(tracer.scene()).min(scratch.mailbox.len());
    let mut q = Query::new(&mut scratch.mailbox[..need]);
    let (tiles_x, tiles_y) = (w.div_ceil(t), h.div_ceil(t));
    let (first, end) = (frame.rows.0 as usize, (frame.rows.1 as usize).min(tiles_y));
    let total = (tiles_x * end.saturating_sub(first)) as u32;
    let cam = &tracer.scene().camera;
    let (w4, h4) = (4 * w as i32, 4 * h as i32);
    // An eye ray through the point (sx / 4, sy / 4) in pixels from the top-left corner.
    // Edge detection compares object ids modulo 2^16 (they only need to differ between
    // neighbours), so the id row above the band fits the i16 scratch.
    let mut shoot = |sx: usize, sy: usize, q: &mut Query<'_>| {
        let (v, id) = tracer.radiance_and_object(cam.ray(sx as i32, sy as i32, w4, h4), q);
        (v, id as u16)
    };
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    let mut ids = [NO_OBJECT as u16; MAX_TILE * MAX_TILE];
    let mut left;
    let mut bits = [BinaryColor::Off; MAX_TILE * MAX_TILE];
    for ty in first..end {
        if let Some(c) = carry.as_mut() {
            c.next_band();
        }
        left = [NO_OBJECT as u16; MAX_TILE];
        for tx in 0..tiles_x {
            let (x0, y0) = (tx * t, ty * t);
            let (tw, th) = (t.min(w - x0), t.min(h - y0));
            // One ray per block through the block's centre; Grid2x2 takes four per pixel.
            for by in (0..th).step_by(block) {
                for bx in (0..tw).step_by(block) {
                    let (cx, cy) = (4 * (x0 + bx) + 2 * block, 4 * (y0 + by) + 2 * block);
                    let (v, id) = if frame.sampling == Sampling::Grid2x2 && block == 1 {
                        grid2x2(&mut shoot, cx, cy, &mut q)
                    } else {
                        shoot(cx, cy, &mut q)
                    };
                    let l = level(v);
                    for y in by..(by + block).min(th) {
                        for x in bx..(bx + block).min(tw) {
                            levels[y * tw + x] = l;
                            ids[y * tw + x] = id;
                        }
                    }
                }
            }
            if Effects::from_bits(E).contains(Effects::EDGE_AA) && frame.edges() {
                // A pixel is on an edge if its eye ray hit another object than a neighbour's:
                // left and above come from the tiles already drawn, right and below from this
                // tile; a pair split by a later tile's border is caught by that later pixel.
                let centre = levels;
                let threshold = match frame.sampling {
                    Sampling::Edges { contrast } => contrast,
                    _ => u8::MAX,
                };
                for y in 0..th {
                    for x in 0..tw {
                        let id = ids[y * tw + x];
                        let l = if x > 0 { ids[y * tw + x - 1] } else { left[y] };
                        let u = if y > 0 { ids[(y - 1) * tw + x] } else { above[x0 + x] as u16 };
                        let r = if x + 1 < tw { ids[y * tw + x + 1] } else { id };
                        let d = if y + 1 < th { ids[(y + 1) * tw + x] } else { id };
                        let edge = (x0 + x > 0 && l != id) || (y0 + y > 0 && u != id) || r != id || d != id;
                        // A shadow, mirror or refraction edge inside one object shows as a jump in
                        // the one-ray levels of this tile.
                        let c = centre[y * tw + x];
                        let jump = |n: u8| c.abs_diff(n) >= threshold;
                        let contrast = (x > 0 && jump(centre[y * tw + x - 1]))
                            || (y > 0 && jump(centre[(y - 1) * tw + x]))
                            || (x + 1 < tw && jump(centre[y * tw + x + 1]))
                            || (y + 1 < th && jump(centre[(y + 1) * tw + x]));
                        if edge || contrast {
                            let (cx, cy) = (4 * (x0 + x) + 2, 4 * (y0 + y) + 2);
                            levels[y * tw + x] = level(grid2x2(&mut shoot, cx, cy, &mut q).0);
                        }
                    }
                }
                for y in 0..th {
                    left[y] = ids[y * tw + tw - 1];
                }
                for x in 0..tw {
                    above[x0 + x] = ids[(th - 1) * tw + x] as i16;
                }
            }
            match carry.as_mut() {
                Some(c) => c.tile(frame.dither, x0, tw, th, &levels[..tw * th], &mut bits),
                None => {
                    let n = if frame.dither == Dither::Bayer { 8 } else { block as u8 };
                    for y in 0..th {
                        for x in 0..tw {
                            bits[y * tw + x] = ordered(levels[y * tw + x], (x0 + x) as u32, (y0 + y) as u32, n);
                        }
                    }
                }
            }
            hooks.gray_tile(x0 as u16, y0 as u16, tw as u16, th as u16, &levels[..tw * th]);
            let area = Rectangle::new(Point::new(x0 as i32, y0 as i32), Size::new(tw as u32, th as u32));
            target.fill_contiguous(&area, bits[..tw * th].iter().copied()).map_err(RenderError::Draw)?;
            if !hooks.progress(((ty - first) * tiles_x + tx + 1) as u32, total) {
                return Err(RenderError::Cancelled);
            }
        }
    }
    Ok(q.stats)
}

/// The mean of four eye rays on a 2x2 grid around the pixel centre `(cx, cy)` (quarter-pixel
/// units), and the object the first of them hit.
fn grid2x2<R: Real>(shoot: &mut impl FnMut(usize, usize, &mut Query<'_>) -> (R, u16), cx: usize, cy: usize, q: &mut Query<'_>) -> (R, u16) {
    let mut sum = R::ZERO;
    let mut first = NO_OBJECT as u16;
    for (k, (dx, dy)) in [(0, 0), (2, 0), (0, 2), (2, 2)].into_iter().enumerate() {
        let (v, id) = shoot(cx - 1 + dx, cy - 1 + dy, q);
        sum += v;
        if k == 0 {
            first = id;
        }
    }
    (sum * (R::HALF * R::HALF), first)
}
