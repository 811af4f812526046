//! Progressive frames: pass 8 traces one ray per 8x8 block and shows it as the block, passes 4
//! and 2 add the rays that make 4x4 and 2x2 blocks, and pass 1 completes the frame with the
//! frame's own sampling, reusing every ray the earlier passes traced ([`Traced`]).

use super::bands::KeptTile;
use super::frame::{Frame, RenderError, Share, TileAt};
use super::tiles::{render_tiles, Nowhere, Out};
use super::Hooks;
use crate::accel::{Accelerator, Stats};
use crate::dither::MAX_TILE;
use crate::sample::{level, Hits, Sampler, Shot};
use crate::scalar::Real;
use crate::storage::Scratch;
use crate::trace::Tracer;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::pixelcolor::BinaryColor;

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
/// traced now or by an earlier pass), pass 1 the finished frame, which is the frame [`render`](super::render)
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

/// [`trace_share`](super::trace_share) for pass `pass` of a progressive frame ([`render_pass`]): the pass's tiles
/// kept for [`dither_band`](super::dither_band), the rays it traces kept in `traced` for the next pass. `traced`
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

/// A pass of a progressive frame as the tile loop takes it: which pass, and the rays kept
/// between passes, for the whole share (its tiles before `frame`'s rows first) or for the tiles
/// of `frame`'s rows alone.
pub(super) struct Pass<'t> {
    pub(super) n: u8,
    pub(super) traced: &'t mut [Traced],
    pub(super) whole_share: bool,
}

/// A tile of pass `n` of a progressive frame: a preview of `n`x`n` blocks (each side a constant
/// in its own copy of the loop: no division), or the finished tile (`n` 1) from the rays `kept`.
#[allow(clippy::too_many_arguments)]
pub(super) fn pass_tile<R: Real>(
    n: u8,
    sampler: &mut Sampler<'_>,
    at: TileAt,
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
    TileAt { x0, y0, tw, th, t }: TileAt,
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
    TileAt { x0, y0, tw, th, t }: TileAt,
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
