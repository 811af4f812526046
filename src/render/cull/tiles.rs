//! Which tiles of a frame an object can show in: every object's eye window
//! ([`crate::scene::EyeWindow`]) counted once per render into the tiles whose window it meets.
//! A tile that few windows meet shows only those objects, so its eye rays test them and need no
//! walk; one that none meets shows no object, and its eye rays have no hit. That is most of
//! the frame when a scene's objects crowd into part of the view (a cluster far off, a few
//! objects on no floor) or lie on a plain floor. For scenes of up to 64 objects each tile's own
//! candidate mask ([`crate::scene::Scene::eye_candidates`]) does the same; the lists serve the
//! larger ones, in one pass over the objects instead of one per tile.

use crate::bounds::{at_mut, span_mut};
use crate::scalar::Real;
use crate::scene::{Camera, EyeWindow, Scene};
use core::ops::Range;

/// A tile's rectangle on the window (2^-16 units, inclusive, as [`Camera::window_uv`] gives):
/// its pixels `x0..x0 + tw` by `y0..y0 + th`, widened by `margin` pixels on each side, on an
/// image of `(w4, h4)` quarter pixels. Returns the `u` and the `v` range.
pub(crate) fn tile_window<R: Real>(
    x: (usize, usize),
    y: (usize, usize),
    margin: usize,
    (w4, h4): (i32, i32),
) -> ([i32; 2], [i32; 2]) {
    let m = 4 * margin as i32;
    let (sx, sy) = ([4 * x.0 as i32 - m, 4 * (x.0 + x.1) as i32 + m], [4 * y.0 as i32 - m, 4 * (y.0 + y.1) as i32 + m]);
    let (lo, hi) = (Camera::<R>::window_uv(sx[0], sy[1], w4, h4), Camera::<R>::window_uv(sx[1], sy[0], w4, h4));
    ([lo[0], hi[0]], [lo[1], hi[1]])
}

/// The first `i` in `0..n` for which `holds(i)` is false, where `holds` is true up to some
/// index and false after it (bisection).
fn first_not(n: usize, holds: impl Fn(usize) -> bool) -> usize {
    let (mut lo, mut hi) = (0, n);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if holds(mid) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The tiles of a frame cut into `t`-pixel tiles, `size` pixels wide and high.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tiling {
    /// Tile side in pixels.
    pub t: usize,
    /// Frame width and height in pixels.
    pub size: (usize, usize),
    /// Pixels a tile's window is widened by on each side (beyond any ray its sampler shoots).
    pub margin: usize,
}

impl Tiling {
    /// Tiles across and down.
    pub fn tiles(&self) -> (usize, usize) {
        (self.size.0.div_ceil(self.t), self.size.1.div_ceil(self.t))
    }

    /// The window range of tile column `tx` (`u`) and of tile row `ty` (`v`).
    #[cfg(test)]
    fn ranges<R: Real>(&self, tx: usize, ty: usize) -> ([i32; 2], [i32; 2]) {
        (self.column::<R>(tx), self.row::<R>(ty))
    }

    /// The `u` range of tile column `tx`'s window (widened by the margin).
    fn column<R: Real>(&self, tx: usize) -> [i32; 2] {
        let (w, m) = (self.size.0, 4 * self.margin as i32);
        let x0 = tx * self.t;
        let w4 = 4 * w as i32;
        [
            Camera::<R>::window_u(4 * x0 as i32 - m, w4),
            Camera::<R>::window_u(4 * (x0 + self.t.min(w - x0)) as i32 + m, w4),
        ]
    }

    /// The `v` range of tile row `ty`'s window (widened by the margin; `v` points up).
    fn row<R: Real>(&self, ty: usize) -> [i32; 2] {
        let (h, m) = (self.size.1, 4 * self.margin as i32);
        let y0 = ty * self.t;
        let h4 = 4 * h as i32;
        [
            Camera::<R>::window_v(4 * (y0 + self.t.min(h - y0)) as i32 + m, h4),
            Camera::<R>::window_v(4 * y0 as i32 - m, h4),
        ]
    }

    /// Counts into `cover`'s first entries (one per tile, row by row; saturating) how many of
    /// `scene`'s objects have a window that meets each tile of tile rows `rows`, sums into the
    /// next the share of the tile each window covers (in 1/[`SHARE`] of the tile: the object
    /// tests an eye ray of the tile makes by the list, on average), and lists the first
    /// [`LIST`] of them per tile, in index order, in the entries after ([`Tiling::list`]).
    /// False, and nothing counted, if `cover` has fewer than [`Tiling::len`] entries.
    pub fn count<R: Real>(&self, scene: &Scene<'_, R>, rows: (usize, usize), cover: &mut [u32]) -> bool {
        let (nx, ny) = self.tiles();
        let (first, end) = (rows.0.min(ny), rows.1.min(ny));
        let Some(cover) = cover.get_mut(..self.len()) else { return false };
        let Some((counts, rest)) = cover.split_at_mut_checked(nx * ny) else { return false };
        let Some((shares, lists)) = rest.split_at_mut_checked(nx * ny) else { return false };
        span_mut(counts, first * nx..end * nx).fill(0);
        span_mut(shares, first * nx..end * nx).fill(0);
        for (i, o) in scene.objects().iter().enumerate() {
            let window = o.region.eye_window;
            let (cols, rows) = self.met::<R>(window);
            for ty in rows.start.max(first)..rows.end.min(end) {
                let v = self.row::<R>(ty);
                let dv = overlap([window[2], window[3]], v);
                for tx in cols.clone() {
                    let tile = ty * nx + tx;
                    let u = self.column::<R>(tx);
                    let covered = overlap([window[0], window[1]], u) * dv;
                    let whole = (i64::from(u[1]) - i64::from(u[0]) + 1) * (i64::from(v[1]) - i64::from(v[0]) + 1);
                    let share = (covered * SHARE as i64 / whole.max(1)) as u32;
                    let sum = at_mut(shares, tile);
                    *sum = sum.saturating_add(share);
                    let count = at_mut(counts, tile);
                    let k = *count as usize;
                    *count = count.saturating_add(1);
                    if k < LIST {
                        *at_mut(lists, tile * LIST + k) = i as u32;
                    }
                }
            }
        }
        true
    }

    /// The tile columns and the tile rows whose windows `window` meets (empty ranges if none).
    fn met<R: Real>(&self, window: EyeWindow) -> (Range<usize>, Range<usize>) {
        let (nx, ny) = self.tiles();
        let [u0, u1, v0, v1] = window;
        let u = |tx: usize| self.column::<R>(tx);
        let v = |ty: usize| self.row::<R>(ty);
        // Columns grow in u; rows fall in v (the window's v points up).
        let (a, b) = (first_not(nx, |tx| u(tx)[1] < u0), first_not(nx, |tx| u(tx)[0] <= u1));
        let (c, d) = (first_not(ny, |ty| v(ty)[0] > v1), first_not(ny, |ty| v(ty)[1] >= v0));
        (a..b.max(a), c..d.max(c))
    }

    /// Entries [`Tiling::count`] needs: a count, a share and [`LIST`] objects per tile.
    pub fn len(&self) -> usize {
        let (nx, ny) = self.tiles();
        nx * ny * (2 + LIST)
    }

    /// After [`Tiling::count`]: the objects whose window meets tile `(tx, ty)`, when the tile's
    /// eye rays cost less by the list than by a walk: at most [`LIST`] of them, whose windows
    /// cover the tile [`WALK_SHARE`] times at most (`None`: walk; or a tile `cover` has no
    /// entries for).
    pub fn list<'c>(&self, cover: &'c [u32], (tx, ty): (usize, usize)) -> Option<&'c [u32]> {
        let (nx, ny) = self.tiles();
        let tile = ty * nx + tx;
        let k = *cover.get(tile)? as usize;
        let share = *cover.get(nx * ny + tile)?;
        let cheaper = k <= LIST && share <= WALK_SHARE;
        cover.get(2 * nx * ny + tile * LIST..)?.get(..k).filter(|_| cheaper)
    }
}

/// The length of the overlap of the inclusive ranges `a` and `b` (0 if they do not meet).
fn overlap(a: [i32; 2], b: [i32; 2]) -> i64 {
    (i64::from(a[1].min(b[1])) - i64::from(a[0].max(b[0])) + 1).max(0)
}

/// The unit of a tile's share ([`Tiling::count`]): 1/256 of the tile.
const SHARE: u32 = 256;

/// The most a tile's listed windows may cover it (in 1/[`SHARE`] of the tile: object tests
/// per eye ray, on average) for its eye rays to test the list rather than walk. Measured on
/// the SPD's scenes at 512x512 (eye rays alone): a walk there tests about as many objects as
/// the list (5 per eye ray on the sphereflake) and steps through cells besides, so lists
/// win until their windows pile up; 1 or 2 made the eye rays of `balls`, `tree` and `teapot`
/// 20 to 60 % slower than 8, and 8 to 1000 measured alike.
pub(crate) const WALK_SHARE: u32 = 8 * SHARE;

/// Whether a render of a scene of `objects` objects lists them per tile: past the 64 a tile's
/// candidate mask holds ([`crate::scene::Scene::eye_candidates`]).
pub(crate) const fn lists(objects: usize) -> bool {
    objects > u64::BITS as usize
}

/// Most objects a tile lists: a tile with more has its eye rays walk the lattice. An eye ray
/// tests each listed object's window (a few comparisons) and the objects it meets, which costs
/// less than a walk through the cells in front of them while the windows do not pile up
/// ([`WALK_SHARE`]).
pub(crate) const LIST: usize = 32;

/// The objects the eye rays of the tile at `x` (its first column and its width) and `y` can hit:
/// those whose window meets the tile's
/// (widened by a `block` on each side, beyond any ray the sampler shoots in the tile), on an
/// image of `size` quarter pixels.
pub(crate) fn tile_candidates<R: Real>(
    scene: &Scene<'_, R>,
    x: (usize, usize),
    y: (usize, usize),
    block: usize,
    size: (i32, i32),
) -> u64 {
    let (u, v) = tile_window::<R>(x, y, block, size);
    scene.eye_candidates(u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every tile whose (widened) window meets an object's is among those `met` gives, and no
    /// other: checked against each tile's own rectangle, for windows of every size and place,
    /// off the image and over it whole, on frames whose last tiles are partial.
    #[test]
    fn the_tiles_met_are_those_whose_windows_meet() {
        let mut seed = 12345u64;
        let mut next = |range: i32| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 33) as i32).rem_euclid(2 * range + 1) - range
        };
        let mut some = 0;
        for (size, t, margin) in [((64, 40), 8, 1), ((53, 35), 8, 2), ((480, 300), 8, 1), ((20, 12), 4, 0)] {
            let tiling = Tiling { t, size, margin };
            let (nx, ny) = tiling.tiles();
            // Each tile's ranges are the rectangle a tile's candidate mask is taken over.
            for (tx, ty) in (0..nx).flat_map(|tx| (0..ny).map(move |ty| (tx, ty))) {
                let (x0, y0) = (tx * t, ty * t);
                let whole = tile_window::<f64>(
                    (x0, t.min(size.0 - x0)),
                    (y0, t.min(size.1 - y0)),
                    margin,
                    (4 * size.0 as i32, 4 * size.1 as i32),
                );
                assert_eq!(tiling.ranges::<f64>(tx, ty), whole, "{size:?} tile ({tx}, {ty})");
            }
            for k in 0..400 {
                let r = if k % 4 == 0 { 1 << 18 } else { 1 << 16 };
                let (a, b, c, d) = (next(r), next(r), next(r), next(r));
                let mut window =
                    if k == 0 { crate::scene::WHOLE_PLANE } else { [a.min(b), a.max(b), c.min(d), c.max(d)] };
                if k % 4 == 1 {
                    // Edges exactly on tiles' edges: touching counts as meeting.
                    let (tx, ty) = (a.unsigned_abs() as usize % nx, c.unsigned_abs() as usize % ny);
                    let (u, v) = tiling.ranges::<f64>(tx, ty);
                    window = [u[1], u[1].max(u[0] + b.abs() % 70000), v[1] - d.abs() % 70000, v[1]];
                    window[2] = window[2].min(window[3]);
                }
                if k % 4 == 3 {
                    let (tx, ty) = (a.unsigned_abs() as usize % nx, c.unsigned_abs() as usize % ny);
                    let (u, v) = tiling.ranges::<f64>(tx, ty);
                    window = [u[0] - b.abs() % 70000, u[0], v[0], v[0] + d.abs() % 70000];
                }
                let (cols, rows) = tiling.met::<f64>(window);
                for ty in 0..ny {
                    for tx in 0..nx {
                        let (u, v) = tiling.ranges::<f64>(tx, ty);
                        let meets = window[0] <= u[1] && u[0] <= window[1] && window[2] <= v[1] && v[0] <= window[3];
                        assert_eq!(
                            cols.contains(&tx) && rows.contains(&ty),
                            meets,
                            "{size:?} tile ({tx}, {ty}) window {window:?}"
                        );
                        some += usize::from(meets);
                    }
                }
            }
        }
        assert!(some > 1000, "only {some} tiles met");
    }

    #[test]
    fn bisection_finds_the_first_false() {
        assert_eq!(first_not(10, |i| i < 4), 4);
        assert_eq!(first_not(10, |_| true), 10);
        assert_eq!(first_not(10, |_| false), 0);
        assert_eq!(first_not(0, |_| true), 0);
    }
}
