//! One tile of a progressive pass: a preview of `n`x`n` blocks, one ray each, or the finished
//! tile from the rays the earlier passes kept ([`Traced`]).

use super::frame::TileAt;
use crate::dither::MAX_TILE;
use crate::sample::{level, Hits, Sampler, Shot};
use crate::scalar::Real;

/// What a progressive render keeps of one ray it traced on the 2x2 grid: its gray level and
/// what it hit ([`render_pass`](super::render_pass)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traced {
    /// Gray level (0..=64).
    pub level: u8,
    /// Object hit (modulo 2^16).
    pub object: u16,
    /// Depth key of the hit.
    pub depth: u16,
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
pub(super) fn kept_at(t: usize, x: usize, y: usize) -> usize {
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
