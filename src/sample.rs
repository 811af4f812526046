//! Eye-ray sampling of a tile: how many eye rays each pixel gets, and the gray level (0..=64)
//! each pixel ends with. The [`Sampler`] owns the state that crosses tile borders (the object
//! ids of the column left of the tile and of the row above the band), so the render's tile
//! loop only asks it for a tile of levels.

use crate::dither::{LEVELS, MAX_TILE};
use crate::scalar::Real;
use crate::trace::NO_OBJECT;

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
    /// mirror and refraction edges inside one object; above 64 turns this test off). Needs the
    /// core's `edge-sampling` feature (on by default).
    Edges {
        /// Gray-level jump (of 64) that also counts as an edge.
        contrast: u8,
    },
    /// Adaptive sub-sampling (trades accuracy for time): one ray through every second pixel
    /// in each direction (and the tile's last row and column); a pixel in between takes the
    /// mean level of the traced pixels around it when they hit the same object and their
    /// levels differ by at most `contrast`, and its own ray otherwise. About a third of the
    /// eye rays (and of the shadow rays they cast) where the picture is smooth; the error
    /// against one ray per pixel is in the accuracy study.
    Adaptive {
        /// Largest gray-level difference (of 64) between traced neighbours that is filled in.
        contrast: u8,
        /// Two levels: the first pass traces every fourth row and column (and the last), a
        /// second fills or traces the pixels of every second line between them in the same
        /// way, except where another object than the one their rays hit can appear in the
        /// pixels between (its eye window meets them, and its eye hull where the build keeps
        /// one, `scene::EyeHull`), or where that object mirrors or refracts (the caller's
        /// `alone`, [`Sampler::tile`]); the third is the one-level sampler's second pass. About
        /// a third fewer eye rays where the picture is smooth; no object the windows show is
        /// skipped, but a shadow or a gradient narrower than four pixels between traced pixels
        /// of one object can be. Needs the core's `coarse-sampling` feature (on by default).
        coarse: bool,
    },
}

/// What one eye ray brings back: brightness, the object it hit (modulo 2^16: ids only need to
/// differ between neighbours) and a key of its distance ([`Real::depth_key`]).
pub type Shot<R> = (R, u16, u16);

/// Per pixel of a tile (row-major, the tile's width), what its eye ray hit: the object and the
/// depth key of the hit. Filled by [`Sampler::tile`]; the outline reads it.
#[derive(Clone, Copy, Debug)]
pub struct Hits {
    /// Object id (modulo 2^16; `NO_OBJECT as u16` for the background).
    pub object: [u16; MAX_TILE * MAX_TILE],
    /// Depth key of the hit (`u16::MAX`-like for the background: larger than any hit's).
    pub depth: [u16; MAX_TILE * MAX_TILE],
}

impl Hits {
    /// Nothing hit yet.
    pub const fn new() -> Self {
        Hits { object: [NO_OBJECT as u16; MAX_TILE * MAX_TILE], depth: [u16::MAX; MAX_TILE * MAX_TILE] }
    }
}

impl Default for Hits {
    fn default() -> Self {
        Self::new()
    }
}

/// Gray level (0..=64) of a brightness in `[0, 1]`, rounded to nearest. `v * 64` is taken as
/// `v * 2^6` ([`Real::mul_pow2`]): the same value, a shift in fixed point.
pub fn level<R: Real>(v: R) -> u8 {
    const { assert!(LEVELS == 1 << 6) };
    (v.mul_pow2(R::pow2(6)) + R::HALF).floor_clamped(LEVELS)
}

/// Samples tiles in the render's order (tile rows top to bottom, tiles left to right).
#[derive(Debug)]
pub struct Sampler<'r> {
    mode: Sampling,
    /// Side of the block that shares one eye ray (the patterning dithers' block).
    block: usize,
    /// Whether edges are refined (edge sampling, one ray per pixel).
    edges: bool,
    /// Object ids (modulo 2^16) of the row above the current band, one per image column.
    above: &'r mut [i16],
    /// Object ids of the column left of the current tile.
    left: [u16; MAX_TILE],
}

impl<'r> Sampler<'r> {
    /// Entries of `i16` storage the sampler needs for an image `width` pixels wide.
    pub fn rows_len(mode: Sampling, block: u8, width: usize) -> usize {
        if Self::refines_edges(mode, block) {
            width
        } else {
            0
        }
    }

    /// Whether `mode` with blocks of `block` pixels refines edges.
    pub fn refines_edges(mode: Sampling, block: u8) -> bool {
        matches!(mode, Sampling::Edges { .. }) && block == 1
    }

    /// A sampler over storage of at least [`Sampler::rows_len`] entries, or `None` if it is
    /// shorter.
    pub fn new(mode: Sampling, block: u8, width: usize, rows: &'r mut [i16]) -> Option<Self> {
        let edges = Self::refines_edges(mode, block);
        let above = rows.get_mut(..Self::rows_len(mode, block, width))?;
        above.iter_mut().for_each(|v| *v = NO_OBJECT as u16 as i16);
        Some(Sampler { mode, block: block.max(1) as usize, edges, above, left: [NO_OBJECT as u16; MAX_TILE] })
    }

    /// Call when a new band of tiles (a new tile row) starts.
    pub fn next_band(&mut self) {
        self.left = [NO_OBJECT as u16; MAX_TILE];
    }

    /// Gray levels of the `tw x th` tile at `(x0, y0)` into `levels` (row-major), and what
    /// each pixel's ray hit into `hits`. `shoot(sx, sy)` traces the eye ray through
    /// `(sx / 4, sy / 4)` pixels from the top-left corner. `alone(xs, ys, object, far)` says
    /// whether the pixels of the tile's columns `xs[0]..=xs[1]` and rows `ys[0]..=ys[1]`, whose
    /// corners' rays all hit `object` (the farthest at depth key `far`), may be filled from them
    /// in the coarse level of
    /// [`Sampling::Adaptive`] (no other object can appear there, as `Scene::eye_candidates`
    /// finds them, and `object` neither mirrors nor refracts); no other sampling asks it.
    #[allow(clippy::too_many_arguments)]
    pub fn tile<R: Real>(
        &mut self,
        x0: usize,
        y0: usize,
        tw: usize,
        th: usize,
        shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
        alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
        levels: &mut [u8; MAX_TILE * MAX_TILE],
        hits: &mut Hits,
    ) {
        let block = self.block;
        if let (Sampling::Adaptive { contrast, coarse }, 1) = (self.mode, block) {
            return adaptive((x0, y0), (tw, th), contrast, coarse, shoot, alone, levels, hits);
        }
        // One ray per block through the block's centre; Grid2x2 takes four per pixel.
        for by in (0..th).step_by(block) {
            for bx in (0..tw).step_by(block) {
                let (cx, cy) = (4 * (x0 + bx) + 2 * block, 4 * (y0 + by) + 2 * block);
                let (v, id, depth) =
                    if self.mode == Sampling::Grid2x2 && block == 1 { grid2x2(shoot, cx, cy) } else { shoot(cx, cy) };
                let l = level(v);
                for y in by..(by + block).min(th) {
                    for x in bx..(bx + block).min(tw) {
                        levels[y * tw + x] = l;
                        hits.object[y * tw + x] = id;
                        hits.depth[y * tw + x] = depth;
                    }
                }
            }
        }
        // Without the feature the branch is a constant false and its code is not linked.
        if cfg!(feature = "edge-sampling") && self.edges {
            self.refine_edges(x0, y0, tw, th, shoot, levels, &hits.object);
        }
    }

    /// Whether what pixel `(x, y)` of a `tw x th` tile hit (`hits`, as [`Sampler::tile`] left
    /// them) is what the eye ray through its centre hits, whatever the scene: one ray per pixel
    /// through its centre, a pixel the adaptive first pass traces, or one between traced pixels
    /// that hit different objects (the next pass traces those). (Other filled pixels, blocks
    /// and 2x2 grids are not.)
    pub fn exact(&self, x: usize, y: usize, tw: usize, th: usize, hits: &Hits) -> bool {
        match (self.mode, self.block) {
            (Sampling::Adaptive { coarse, .. }, 1) => {
                if first_pass(coarse, x, tw) && first_pass(coarse, y, th) {
                    return true;
                }
                let (xs, ys) = if traced(x, tw) && traced(y, th) {
                    (between(x, tw), between(y, th))
                } else {
                    around(x, y, tw, th)
                };
                let id = |(nx, ny): (usize, usize)| hits.object[ny * tw + nx];
                let first = id((xs[0], ys[0]));
                (0..4).any(|i| id((xs[i % 2], ys[i / 2])) != first)
            }
            (Sampling::Grid2x2, _) => false,
            (_, block) => block == 1,
        }
    }

    /// The hits along a tile's right column or bottom row (`n` pixels) as silhouette lines
    /// across tile borders take them, into `out`; `exact(i)` is what the eye ray through pixel
    /// `i`'s centre hits. With adaptive sampling a pixel between two traced ones whose rays hit
    /// the same object takes that object and the nearer depth, as the sampler's fill does, so
    /// neither the tile nor its neighbour traces a ray for it (about 6 of a tile's 15 side
    /// pixels); every other pixel takes its exact hit. With the coarse level the pixels of
    /// every fourth line (and the last) take their exact hits, then those between two of them
    /// on every second line are filled (or not) in the same way from the two, then the rest.
    pub fn side(&self, n: usize, mut exact: impl FnMut(usize) -> (u16, u16), out: &mut [(u16, u16)]) {
        let (fills, coarse) = match (self.mode, self.block) {
            (Sampling::Adaptive { coarse, .. }, 1) => (true, coarse),
            _ => (false, false),
        };
        for i in (0..n).filter(|&i| !fills || first_pass(coarse, i, n)) {
            out[i] = exact(i);
        }
        // A pixel between two whose hits are one object takes it and the nearer depth, as the
        // sampler's fill does; else its exact hit.
        let mut fill = |out: &mut [(u16, u16)], i: usize, [a, b]: [usize; 2]| {
            let (a, b) = (out[a], out[b]);
            out[i] = if a.0 == b.0 { (a.0, a.1.min(b.1)) } else { exact(i) };
        };
        if coarse {
            for i in (0..n).filter(|&i| traced(i, n) && !coarse_line(i, n)) {
                fill(out, i, between(i, n));
            }
        }
        if fills {
            for i in (0..n).filter(|&i| !traced(i, n)) {
                fill(out, i, [i - 1, i + 1]);
            }
        }
    }

    /// Re-samples pixels on an edge with the 2x2 grid. A pixel is on an edge if its eye ray
    /// hit another object than a neighbour's: left and above come from the tiles already
    /// drawn, right and below from this tile; a pair split by a later tile's border is caught
    /// by that later pixel.
    #[allow(clippy::too_many_arguments)]
    fn refine_edges<R: Real>(
        &mut self,
        x0: usize,
        y0: usize,
        tw: usize,
        th: usize,
        shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
        levels: &mut [u8; MAX_TILE * MAX_TILE],
        ids: &[u16; MAX_TILE * MAX_TILE],
    ) {
        let centre = *levels;
        let threshold = match self.mode {
            Sampling::Edges { contrast } => contrast,
            _ => u8::MAX,
        };
        for y in 0..th {
            for x in 0..tw {
                let id = ids[y * tw + x];
                let l = if x > 0 { ids[y * tw + x - 1] } else { self.left[y] };
                let u = if y > 0 { ids[(y - 1) * tw + x] } else { self.above[x0 + x] as u16 };
                let r = if x + 1 < tw { ids[y * tw + x + 1] } else { id };
                let d = if y + 1 < th { ids[(y + 1) * tw + x] } else { id };
                let edge = (x0 + x > 0 && l != id) || (y0 + y > 0 && u != id) || r != id || d != id;
                // A shadow, mirror or refraction edge inside one object shows as a jump in the
                // one-ray levels of this tile.
                let c = centre[y * tw + x];
                let jump = |n: u8| c.abs_diff(n) >= threshold;
                let contrast = (x > 0 && jump(centre[y * tw + x - 1]))
                    || (y > 0 && jump(centre[(y - 1) * tw + x]))
                    || (x + 1 < tw && jump(centre[y * tw + x + 1]))
                    || (y + 1 < th && jump(centre[(y + 1) * tw + x]));
                if edge || contrast {
                    let (cx, cy) = (4 * (x0 + x) + 2, 4 * (y0 + y) + 2);
                    levels[y * tw + x] = level(grid2x2(shoot, cx, cy).0);
                }
            }
        }
        for y in 0..th {
            self.left[y] = ids[y * tw + tw - 1];
        }
        for x in 0..tw {
            self.above[x0 + x] = ids[(th - 1) * tw + x] as i16;
        }
    }
}

/// Whether tile row or column `i` of `n` is traced in the adaptive first pass: every second
/// one, and the last.
fn traced(i: usize, n: usize) -> bool {
    i.is_multiple_of(2) || i + 1 == n
}

/// The lines [`traced`] picks of `n`, in order: every second one from the first, then the last.
fn traced_lines(n: usize) -> Lines {
    Lines { at: 0, step: 2, n }
}

/// Lines `0, step, 2 step, ...` of `n`, then the last if it is not one of them, in order: a
/// counter and two tests per line, fewer instructions than a stepped range chained with the
/// last line (the panels' chair frame on QEMU: 0.5 % fewer on the Cortex-M0+, 0.3 % on the M33).
#[derive(Clone, Copy, Debug)]
struct Lines {
    at: usize,
    step: usize,
    n: usize,
}

impl Iterator for Lines {
    type Item = usize;
    #[inline]
    fn next(&mut self) -> Option<usize> {
        let i = self.at;
        if i >= self.n {
            return None;
        }
        // After the last line, none; else the next step, or the last line if that is nearer.
        self.at = if i + 1 == self.n { self.n } else { (i + self.step).min(self.n - 1) };
        Some(i)
    }
}

/// Whether tile row or column `i` of `n` is traced in the first pass of adaptive sampling in
/// one level ([`traced`]) or in two ([`coarse_line`]).
fn first_pass(coarse: bool, i: usize, n: usize) -> bool {
    if coarse {
        coarse_line(i, n)
    } else {
        traced(i, n)
    }
}

/// Whether tile row or column `i` of `n` is traced in the coarse level's first pass: every
/// fourth one, and the last.
fn coarse_line(i: usize, n: usize) -> bool {
    i.is_multiple_of(4) || i + 1 == n
}

/// The lines [`coarse_line`] picks of `n`, in order.
fn coarse_lines(n: usize) -> Lines {
    Lines { at: 0, step: 4, n }
}

/// The coarse lines a line `i` of `n` lies on or between: `[i, i]` on one, else the one two
/// before and the next (two after, or the last line, one after).
fn between(i: usize, n: usize) -> [usize; 2] {
    if coarse_line(i, n) {
        [i, i]
    } else {
        [i - 2, (i + 2).min(n - 1)]
    }
}

/// The traced pixels an untraced pixel `(x, y)` of a `tw x th` tile is filled from, as columns
/// and rows (each pair repeats a line the pixel is on): left and right, above and below, or
/// the four corners.
fn around(x: usize, y: usize, tw: usize, th: usize) -> ([usize; 2], [usize; 2]) {
    let xs = if traced(x, tw) { [x, x] } else { [x - 1, x + 1] };
    let ys = if traced(y, th) { [y, y] } else { [y - 1, y + 1] };
    (xs, ys)
}

/// [`Sampling::Adaptive`] over one tile: the first pass traces the pixels of traced rows and
/// columns, the second fills or traces each other pixel from its two or four traced
/// neighbours (they are one pixel away: traced lines are at most two apart). A filled pixel
/// takes the object of its neighbours and the nearest of their depths. With `coarse` the first
/// pass traces the pixels of every fourth line (and the last) and a pass between fills or
/// traces the rest of the traced lines' pixels from them (two lines away, or one before the
/// last), where `alone` allows.
#[allow(clippy::too_many_arguments)]
fn adaptive<R: Real>(
    (x0, y0): (usize, usize),
    (tw, th): (usize, usize),
    contrast: u8,
    coarse: bool,
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    hits: &mut Hits,
) {
    let ids = &mut hits.object;
    let depths = &mut hits.depth;
    let centre = |x: usize, y: usize| (4 * (x0 + x) + 2, 4 * (y0 + y) + 2);
    // Without the feature the branch is a constant false and its code is not linked (the
    // render refuses such frames: `RenderError::CoarseNotCompiled`).
    if cfg!(feature = "coarse-sampling") && coarse {
        coarse_pass(((x0, y0), (tw, th)), contrast, (shoot, alone), (levels, hits));
    } else {
        for y in traced_lines(th) {
            for x in traced_lines(tw) {
                let (cx, cy) = centre(x, y);
                let (v, id, depth) = shoot(cx, cy);
                let i = at(y * tw + x);
                (levels[i], ids[i], depths[i]) = (level(v), id, depth);
            }
        }
    }
    refine((x0, y0), (tw, th), contrast, shoot, levels, hits);
}

/// Two-level sampling's first pass over a tile: the rays of the coarse lines, then on the
/// traced lines between them each pixel filled from two or four coarse neighbours where
/// [`fill`] allows (and `alone` says nothing else can show there), else traced.
#[inline(always)]
fn coarse_pass<R: Real>(
    ((x0, y0), (tw, th)): ((usize, usize), (usize, usize)),
    contrast: u8,
    (shoot, alone): (
        &mut impl FnMut(usize, usize) -> Shot<R>,
        &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    ),
    (levels, Hits { object: ids, depth: depths }): (&mut [u8; MAX_TILE * MAX_TILE], &mut Hits),
) {
    let centre = |x: usize, y: usize| (4 * (x0 + x) + 2, 4 * (y0 + y) + 2);
    for y in coarse_lines(th) {
        for x in coarse_lines(tw) {
            shoot_at(shoot, levels, ids, depths, y * tw + x, centre(x, y));
        }
    }
    // The pass between, row by row in pixel order.
    for y in traced_lines(th) {
        let ys = between(y, th);
        for x in traced_lines(tw).filter(|&x| !(coarse_line(x, tw) && coarse_line(y, th))) {
            let xs = between(x, tw);
            let i = y * tw + x;
            // Two neighbours on a coarse line, else the four corners.
            let filled = if xs[0] == xs[1] || ys[0] == ys[1] {
                fill(levels, ids, depths, i, [ys[0] * tw + xs[0], ys[1] * tw + xs[1]], contrast, |id, far| {
                    alone(xs, ys, id, far)
                })
            } else {
                fill(
                    levels,
                    ids,
                    depths,
                    i,
                    [ys[0] * tw + xs[0], ys[0] * tw + xs[1], ys[1] * tw + xs[0], ys[1] * tw + xs[1]],
                    contrast,
                    |id, far| alone(xs, ys, id, far),
                )
            };
            if !filled {
                shoot_at(shoot, levels, ids, depths, i, centre(x, y));
            }
        }
    }
}

/// The second pass of adaptive sampling, row by row in pixel order (so rays are shot in the
/// same order): on a traced row the pixels between two traced ones (odd columns but the last),
/// on any other row every pixel, from the pixels above and below it or from the four corners.
#[inline(always)]
fn refine<R: Real>(
    (x0, y0): (usize, usize),
    (tw, th): (usize, usize),
    contrast: u8,
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    hits: &mut Hits,
) {
    let ids = &mut hits.object;
    let depths = &mut hits.depth;
    let centre = |x: usize, y: usize| (4 * (x0 + x) + 2, 4 * (y0 + y) + 2);
    for y in 0..th {
        let row = y * tw;
        if traced(y, th) {
            let mut x = 1;
            while x + 1 < tw {
                let i = row + x;
                if !fill(levels, ids, depths, i, [i - 1, i + 1], contrast, |_, _| true) {
                    shoot_at(shoot, levels, ids, depths, i, centre(x, y));
                }
                x += 2;
            }
        } else {
            for x in 0..tw {
                let i = row + x;
                let filled = if traced(x, tw) {
                    fill(levels, ids, depths, i, [i - tw, i + tw], contrast, |_, _| true)
                } else {
                    fill(levels, ids, depths, i, [i - tw - 1, i - tw + 1, i + tw - 1, i + tw + 1], contrast, |_, _| {
                        true
                    })
                };
                if !filled {
                    shoot_at(shoot, levels, ids, depths, i, centre(x, y));
                }
            }
        }
    }
}

/// Pixel `i`'s entry: `i` itself, masked to the tiles' storage (a power of two), which every
/// index [`adaptive`] asks for already lies in; so no index is checked at run time.
#[inline(always)]
fn at(i: usize) -> usize {
    i & (MAX_TILE * MAX_TILE - 1)
}

/// Fills untraced pixel `i` from the traced pixels `ns` around it ([`around`]: two on its row
/// or column, each counted twice in the mean of four, or the four corners) when they hit one
/// object and their levels lie within `contrast`: the mean level, the first's object and the
/// nearest depth, if `allowed(object, farthest depth)` too. Returns whether it did; else the
/// pixel is traced.
#[inline]
fn fill<const N: usize>(
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    ids: &mut [u16; MAX_TILE * MAX_TILE],
    depths: &mut [u16; MAX_TILE * MAX_TILE],
    i: usize,
    ns: [usize; N],
    contrast: u8,
    allowed: impl FnOnce(u16, u16) -> bool,
) -> bool {
    let first = ids[at(ns[0])];
    let (mut lo, mut hi, mut sum, mut same, mut near) = (u8::MAX, 0u8, 0u32, true, u16::MAX);
    for k in ns.iter().map(|&k| at(k)) {
        let l = levels[k];
        lo = lo.min(l);
        hi = hi.max(l);
        sum += l as u32;
        same &= ids[k] == first;
        near = near.min(depths[k]);
    }
    if !(same && hi - lo <= contrast && allowed(first, ns.iter().map(|&k| depths[at(k)]).fold(0, u16::max))) {
        return false;
    }
    // Two pixels counted twice: (2 sum + 2) / 4 = (sum + 1) / 2, rounded up.
    let mean = if N == 2 { sum.div_ceil(2) } else { (sum + 2) / 4 };
    let i = at(i);
    (levels[i], ids[i], depths[i]) = (mean as u8, first, near);
    true
}

/// Traces untraced pixel `i` through its centre `(cx, cy)` (quarter pixels). Out of line: the
/// later passes call it from several places, and `shoot` (the tracer, inlined into it) is
/// large.
#[inline(never)]
fn shoot_at<R: Real>(
    shoot: &mut impl FnMut(usize, usize) -> Shot<R>,
    levels: &mut [u8; MAX_TILE * MAX_TILE],
    ids: &mut [u16; MAX_TILE * MAX_TILE],
    depths: &mut [u16; MAX_TILE * MAX_TILE],
    i: usize,
    (cx, cy): (usize, usize),
) {
    let (v, id, depth) = shoot(cx, cy);
    let i = at(i);
    (levels[i], ids[i], depths[i]) = (level(v), id, depth);
}

/// The mean of four eye rays on a 2x2 grid around the pixel centre `(cx, cy)` (quarter-pixel
/// units), with the object and depth the first of them hit.
fn grid2x2<R: Real>(shoot: &mut impl FnMut(usize, usize) -> Shot<R>, cx: usize, cy: usize) -> Shot<R> {
    let mut sum = R::ZERO;
    let mut first = (NO_OBJECT as u16, u16::MAX);
    for (k, (dx, dy)) in [(0, 0), (2, 0), (0, 2), (2, 2)].into_iter().enumerate() {
        let (v, id, depth) = shoot(cx - 1 + dx, cy - 1 + dy);
        sum += v;
        if k == 0 {
            first = (id, depth);
        }
    }
    (sum * (R::HALF * R::HALF), first.0, first.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`level`]'s power of two gives what the product with 64 gives, in every scalar.
    #[test]
    fn level_is_the_product_with_64_rounded() {
        fn check<R: Real>(v: R) {
            assert_eq!(
                level(v),
                (v * R::from_i32(LEVELS as i32) + R::HALF).floor_clamped(LEVELS),
                "{} {}",
                R::NAME,
                v.to_f64()
            );
        }
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let raw = ((x as i32) >> (x % 15) as i32).max(-i32::MAX);
            check(crate::Fx(raw));
            let v = raw as f64 / 65536.0 / 1024.0;
            check(v);
            check(v as f32);
        }
    }

    /// With adaptive sampling a tile side asks for the exact hit of its traced pixels and of a
    /// pixel between traced ones that hit different objects, and fills the rest as the sampler
    /// does (the object, the nearer depth); with one ray per pixel it asks for every pixel.
    #[test]
    fn a_side_asks_only_for_the_pixels_sampling_traced() {
        let truth = [(5, 10), (5, 11), (5, 12), (9, 3), (9, 4), (9, 5), (9, 6), (9, 7)];
        let side = |mode: Sampling| {
            let sampler = Sampler::new(mode, 1, 16, &mut []).unwrap();
            let (mut asked, mut n, mut out) = ([usize::MAX; 8], 0, [(0, 0); 8]);
            sampler.side(
                8,
                |i| {
                    asked[n] = i;
                    n += 1;
                    truth[i]
                },
                &mut out,
            );
            (asked, out)
        };
        let (asked, out) = side(Sampling::Adaptive { contrast: 4, coarse: false });
        assert_eq!(asked, [0, 2, 4, 6, 7, 3, usize::MAX, usize::MAX]);
        assert_eq!(out, [(5, 10), (5, 10), (5, 12), (9, 3), (9, 4), (9, 4), (9, 6), (9, 7)]);
        let (asked, out) = side(Sampling::Center);
        assert_eq!(asked, [0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(out, truth);
    }

    /// A made-up picture for the sampler's tests, per quarter-pixel position: two objects with
    /// a gradient and a shadow, crossed by thin diagonal stripes of a third.
    fn picture(sx: usize, sy: usize) -> Shot<f64> {
        let (x, y) = (sx / 4, sy / 4);
        let id = if (x * 7 + y * 3) % 23 < 2 {
            3
        } else if x < 20 {
            1
        } else {
            2
        };
        let v = match id {
            1 => ((x + y) % 64) as f64 / 64.0,
            2 if (x / 3 + y / 5) % 7 == 0 => 0.2,
            _ => 0.5,
        };
        (v, id, (x + 2 * y) as u16)
    }

    /// Samples one tile of [`picture`] at `(x0, y0)` with `mode`, `alone` answering the coarse
    /// level; returns the levels, the hits and the eye rays traced.
    fn sample(
        mode: Sampling,
        at: (usize, usize, usize, usize),
        alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    ) -> ([u8; MAX_TILE * MAX_TILE], Hits, usize) {
        sample_of(picture, mode, at, alone)
    }

    /// [`sample`] of another picture.
    fn sample_of(
        picture: fn(usize, usize) -> Shot<f64>,
        mode: Sampling,
        (x0, y0, tw, th): (usize, usize, usize, usize),
        alone: &mut impl FnMut([usize; 2], [usize; 2], u16, u16) -> bool,
    ) -> ([u8; MAX_TILE * MAX_TILE], Hits, usize) {
        let mut sampler = Sampler::new(mode, 1, 64, &mut []).unwrap();
        let (mut levels, mut hits, mut rays) = ([0; MAX_TILE * MAX_TILE], Hits::new(), 0);
        let mut shoot = |sx: usize, sy: usize| {
            rays += 1;
            picture(sx, sy)
        };
        sampler.tile(x0, y0, tw, th, &mut shoot, alone, &mut levels, &mut hits);
        (levels, hits, rays)
    }

    /// The lines a pass walks are every `step`-th from the first, then the last, in order and
    /// once each, in every tile size.
    #[test]
    fn lines_are_every_step_and_the_last() {
        for n in 0..=MAX_TILE {
            for step in [2, 4] {
                let mut want: std::vec::Vec<usize> = (0..n).step_by(step).collect();
                if n > 0 && !(n - 1).is_multiple_of(step) {
                    want.push(n - 1);
                }
                assert_eq!(Lines { at: 0, step, n }.collect::<std::vec::Vec<_>>(), want, "{n} by {step}");
            }
        }
    }

    /// What the coarse level asks before it fills pixels.
    type Alone<'a> = dyn FnMut([usize; 2], [usize; 2], u16, u16) -> bool + 'a;

    const ONE_LEVEL: Sampling = Sampling::Adaptive { contrast: 4, coarse: false };
    const TWO_LEVELS: Sampling = Sampling::Adaptive { contrast: 4, coarse: true };

    /// In every tile size, with either level count and whatever `alone` answers, a pixel
    /// [`Sampler::exact`] calls exact holds what its centre's ray hits; with `alone` always
    /// false, two levels sample what one does.
    #[test]
    fn exact_pixels_hold_their_rays_in_every_tile_size() {
        let mut coin = 0x9e37_79b9u32;
        for tw in 1..=MAX_TILE {
            for th in 1..=MAX_TILE {
                let at = (3 * tw, 5 * th, tw, th);
                let alones: [&mut Alone<'_>; 3] =
                    [&mut |_, _, _, _| true, &mut |_, _, _, _| false, &mut |_, _, _, _| {
                        coin ^= coin << 13;
                        coin ^= coin >> 17;
                        coin ^= coin << 5;
                        coin & 1 == 0
                    }];
                for (k, alone) in alones.into_iter().enumerate() {
                    for mode in [ONE_LEVEL, TWO_LEVELS] {
                        let (_, hits, _) = sample(mode, at, &mut |xs, ys, id, far| alone(xs, ys, id, far));
                        let sampler = Sampler::new(mode, 1, 64, &mut []).unwrap();
                        for (x, y) in (0..th)
                            .flat_map(|y| (0..tw).map(move |x| (x, y)))
                            .filter(|&(x, y)| sampler.exact(x, y, tw, th, &hits))
                        {
                            let (_, id, depth) = picture(4 * (at.0 + x) + 2, 4 * (at.1 + y) + 2);
                            assert_eq!(
                                (hits.object[y * tw + x], hits.depth[y * tw + x]),
                                (id, depth),
                                "{tw}x{th} {mode:?} alone #{k}: pixel ({x}, {y})"
                            );
                        }
                    }
                }
                let (one, one_hits, one_rays) = sample(ONE_LEVEL, at, &mut |_, _, _, _| true);
                let (two, two_hits, two_rays) = sample(TWO_LEVELS, at, &mut |_, _, _, _| false);
                assert_eq!(
                    (one, one_hits.object, one_hits.depth, one_rays),
                    (two, two_hits.object, two_hits.depth, two_rays),
                    "{tw}x{th}"
                );
            }
        }
    }

    /// Where the picture is one object of one level, two levels trace the 5x5 pixels of every
    /// fourth line of a 16x16 tile, and the window's answer is what holds them back.
    #[test]
    fn two_levels_trace_every_fourth_line_where_the_picture_is_smooth() {
        let at = (40, 32, MAX_TILE, MAX_TILE);
        let flat: fn(usize, usize) -> Shot<f64> = |_, _| (0.5, 2, 7);
        let lines = coarse_lines(MAX_TILE).count();
        let mut asked = 0;
        let (levels, _, rays) = sample_of(flat, TWO_LEVELS, at, &mut |xs, ys, id, _| {
            asked += 1;
            assert!(xs[0] <= xs[1] && ys[0] <= ys[1] && xs[1] < MAX_TILE && ys[1] < MAX_TILE && id == 2);
            true
        });
        assert_eq!(rays, lines * lines);
        assert!(asked > 0 && levels[..MAX_TILE * MAX_TILE].iter().all(|&l| l == 32));
        let (_, _, one_rays) = sample_of(flat, ONE_LEVEL, at, &mut |_, _, _, _| true);
        let (_, _, held) = sample_of(flat, TWO_LEVELS, at, &mut |_, _, _, _| false);
        assert!(rays < one_rays && held == one_rays, "{rays} {one_rays} {held}");
    }

    /// With two levels a tile side asks for the exact hits of every fourth pixel and the last,
    /// then of those between on every second line whose two neighbours there differ, then of
    /// the rest whose neighbours differ.
    #[test]
    fn a_side_in_two_levels_asks_every_fourth_pixel_first() {
        let truth = [(5, 10), (5, 11), (5, 12), (5, 13), (9, 3), (9, 4), (9, 5), (9, 6), (9, 7), (9, 8)];
        let sampler = Sampler::new(TWO_LEVELS, 1, 16, &mut []).unwrap();
        let (mut asked, mut out) = (std::vec::Vec::new(), [(0, 0); 10]);
        sampler.side(
            10,
            |i| {
                asked.push(i);
                truth[i]
            },
            &mut out,
        );
        // 0, 4, 8, 9 first; 2 lies between 0 and 4 (objects 5 and 9): asked; 6 between 4 and
        // 8 (9 and 9): filled; then 1 (5, 5) and 5, 7 (9, 9) filled, 3 between 2 and 4 (5, 9).
        assert_eq!(asked, [0, 4, 8, 9, 2, 3]);
        assert_eq!(out, [(5, 10), (5, 10), (5, 12), (5, 13), (9, 3), (9, 3), (9, 3), (9, 3), (9, 7), (9, 8)]);
    }
}
