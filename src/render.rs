//! Tiles: the frame is rendered one small tile at a time into a fixed buffer, dithered and
//! handed to an `embedded_graphics` draw target in one `fill_contiguous` call. No full-frame
//! buffer exists; between tiles a hook reports progress and may cancel.

use crate::accel::{Accelerator, Query, Stats};
use crate::dither::{ordered, Carry, Dither, LEVELS, MAX_TILE};
use crate::scalar::Real;
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
}

impl Frame {
    /// A frame with 8x8 tiles and Bayer dithering.
    pub fn new(width: u16, height: u16) -> Self {
        Frame { width, height, tile: 8, dither: Dither::Bayer }
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RenderError<E> {
    /// The draw target failed.
    Draw(E),
    /// The progress hook asked to stop.
    Cancelled,
    /// The tile size is 0, above [`MAX_TILE`], or not a multiple of the pattern block.
    BadTile,
    /// Error diffusion needs carry storage of `needed` entries.
    CarryTooSmall {
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
            RenderError::CarryTooSmall { needed } => {
                write!(f, "error-diffusion carry storage too small: {needed} entries needed")
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
/// `mailbox` is the accelerator's per-object scratch ([`Query::mailbox_len`] entries);
/// `carry` must hold [`Carry::len`]`(width)` entries when the mode diffuses error (else it may
/// be empty).
pub fn render<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color = BinaryColor>>(
    tracer: &Tracer<'_, '_, R, A>,
    frame: &Frame,
    target: &mut D,
    mailbox: &mut [u32],
    carry: &mut [i16],
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    let t = frame.tile as usize;
    let block = frame.dither.block() as usize;
    if t == 0 || t > MAX_TILE || t % block != 0 {
        return Err(RenderError::BadTile);
    }
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut carry = if frame.dither.diffuses() {
        Some(Carry::new(carry, w).ok_or(RenderError::CarryTooSmall { needed: Carry::len(w) })?)
    } else {
        None
    };
    let mut q = Query::new(mailbox);
    let (tiles_x, tiles_y) = (w.div_ceil(t), h.div_ceil(t));
    let total = (tiles_x * tiles_y) as u32;
    let cam = &tracer.scene.camera;
    let (w2, h2) = (2 * w as i32, 2 * h as i32);
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    let mut bits = [BinaryColor::Off; MAX_TILE * MAX_TILE];
    for ty in 0..tiles_y {
        if let Some(c) = carry.as_mut() {
            c.next_band();
        }
        for tx in 0..tiles_x {
            let (x0, y0) = (tx * t, ty * t);
            let (tw, th) = (t.min(w - x0), t.min(h - y0));
            // One ray per block, through the block's centre (doubled coordinates).
            for by in (0..th).step_by(block) {
                for bx in (0..tw).step_by(block) {
                    let (sx, sy) = (2 * (x0 + bx) + block, 2 * (y0 + by) + block);
                    let ray = cam.ray(sx as i32, sy as i32, w2, h2);
                    let l = level(tracer.radiance(ray, &mut q));
                    for y in by..(by + block).min(th) {
                        for x in bx..(bx + block).min(tw) {
                            levels[y * tw + x] = l;
                        }
                    }
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
            if !hooks.progress((ty * tiles_x + tx + 1) as u32, total) {
                return Err(RenderError::Cancelled);
            }
        }
    }
    Ok(q.stats)
}
