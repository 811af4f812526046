//! Silhouette lines for a 1-bit display. Where two neighbouring pixels' eye rays hit different
//! objects, the farther pixel of the pair is drawn black before dithering, so every object gets
//! a one-pixel outline outside its own area: thin parts (a chair's legs) stay visible against
//! a floor of the same gray, and dithering cannot blur an object into what lies behind it.
//!
//! It uses only what the tile's eye rays already returned ([`Hits`]: object and depth per
//! pixel), so it costs no ray. Pairs split by a tile border are compared with the column left
//! of the tile and the row above its band, which the outline keeps (one image row of scratch
//! storage); when the farther pixel of such a pair is in a tile already drawn, the line goes on
//! this tile's side instead, so it stays unbroken.

use crate::dither::MAX_TILE;
use crate::sample::Hits;
use crate::trace::NO_OBJECT;

/// Outline state carried between tiles (in render order: tile rows top to bottom, tiles left
/// to right).
#[derive(Debug)]
pub struct Outline<'r> {
    /// Object and depth key of the row above the current band, interleaved, one pair per column.
    above: &'r mut [i16],
    /// Object and depth key of the column left of the current tile.
    left: [(u16, u16); MAX_TILE],
}

impl<'r> Outline<'r> {
    /// Entries of `i16` storage the outline needs for an image `width` pixels wide.
    pub const fn rows_len(width: usize) -> usize {
        2 * width
    }

    /// An outline over storage of at least [`Outline::rows_len`] entries, or `None` if it is
    /// shorter.
    pub fn new(rows: &'r mut [i16], width: usize) -> Option<Self> {
        let above = rows.get_mut(..Self::rows_len(width))?;
        above.iter_mut().for_each(|v| *v = NO_OBJECT as u16 as i16);
        Some(Outline { above, left: [(NO_OBJECT as u16, u16::MAX); MAX_TILE] })
    }

    /// Call when a new band of tiles (a new tile row) starts.
    pub fn next_band(&mut self) {
        self.left = [(NO_OBJECT as u16, u16::MAX); MAX_TILE];
    }

    /// Draws the silhouettes of the `tw x th` tile at `(x0, y0)` into its `levels` (level 0
    /// where a line runs), from what its pixels hit.
    pub fn tile(&mut self, x0: usize, y0: usize, tw: usize, th: usize, hits: &Hits, levels: &mut [u8]) {
        let mut line = [false; MAX_TILE * MAX_TILE];
        for y in 0..th {
            for x in 0..tw {
                let i = y * tw + x;
                let here = (hits.object[i], hits.depth[i]);
                // Neighbours right and below are in this tile: the farther one of a pair gets
                // the line.
                for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                    if nx < tw && ny < th {
                        let j = ny * tw + nx;
                        let there = (hits.object[j], hits.depth[j]);
                        if here.0 != there.0 && here.1 != there.1 {
                            line[if here.1 > there.1 { i } else { j }] = true;
                        }
                    }
                }
                // Neighbours left and above in tiles already drawn: this pixel gets the line.
                let left = if x > 0 { None } else { Some(self.left[y]) };
                let up = if y > 0 { None } else { Some(self.column(x0 + x)) };
                let edge = |n: Option<(u16, u16)>| n.is_some_and(|n| n.0 != here.0 && n.1 != here.1);
                if (x0 + x > 0 && edge(left)) || (y0 + y > 0 && edge(up)) {
                    line[i] = true;
                }
            }
        }
        for (l, _) in levels.iter_mut().zip(&line).filter(|(_, &on)| on) {
            *l = 0;
        }
        for y in 0..th {
            let i = y * tw + tw - 1;
            self.left[y] = (hits.object[i], hits.depth[i]);
        }
        for x in 0..tw {
            let i = (th - 1) * tw + x;
            self.above[2 * (x0 + x)] = hits.object[i] as i16;
            self.above[2 * (x0 + x) + 1] = hits.depth[i] as i16;
        }
    }

    fn column(&self, x: usize) -> (u16, u16) {
        (self.above[2 * x] as u16, self.above[2 * x + 1] as u16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 6x4 tile: background (id NO_OBJECT) with a one-pixel-wide object 7 at column 2, in
    /// front of a floor (id 1) on the bottom row.
    fn scene() -> Hits {
        let mut h = Hits::new();
        for y in 0..4 {
            for x in 0..6 {
                let i = y * 6 + x;
                if x == 2 {
                    (h.object[i], h.depth[i]) = (7, 100);
                } else if y == 3 {
                    (h.object[i], h.depth[i]) = (1, 200);
                }
            }
        }
        h
    }

    fn art(levels: &[u8], w: usize) -> std::string::String {
        levels.chunks(w).map(|r| r.iter().map(|&l| if l == 0 { '#' } else { '.' }).collect::<std::string::String>() + "\n").collect()
    }

    #[test]
    fn the_farther_pixel_of_each_pair_is_outlined() {
        let mut store = [0i16; 12];
        let mut o = Outline::new(&mut store, 6).unwrap();
        o.next_band();
        let mut levels = [40u8; 24];
        o.tile(0, 0, 6, 4, &scene(), &mut levels);
        // The object stays; the background and the floor beside it, and the background above
        // the floor, become lines.
        assert_eq!(art(&levels, 6), ".#.#..\n.#.#..\n##.###\n.#.#..\n");
    }

    #[test]
    fn pairs_across_tile_borders_are_outlined_on_the_later_side() {
        let hits = scene();
        let mut store = [0i16; 12];
        let mut o = Outline::new(&mut store, 6).unwrap();
        o.next_band();
        // The same picture drawn as two 3-wide tiles: column 3 (background, farther than the
        // object at column 2) is in the second tile and is outlined there; the pairs inside
        // the first tile give what the whole tile gave.
        let split = |x0: usize| {
            let mut h = Hits::new();
            for y in 0..4 {
                for x in 0..3 {
                    h.object[y * 3 + x] = hits.object[y * 6 + x0 + x];
                    h.depth[y * 3 + x] = hits.depth[y * 6 + x0 + x];
                }
            }
            h
        };
        let (mut a, mut b) = ([40u8; 12], [40u8; 12]);
        o.tile(0, 0, 3, 4, &split(0), &mut a);
        o.tile(3, 0, 3, 4, &split(3), &mut b);
        let whole: std::vec::Vec<u8> = (0..4).flat_map(|y| a[y * 3..y * 3 + 3].iter().chain(&b[y * 3..y * 3 + 3]).copied().collect::<std::vec::Vec<_>>()).collect();
        let mut store = [0i16; 12];
        let mut one = Outline::new(&mut store, 6).unwrap();
        let mut levels = [40u8; 24];
        one.tile(0, 0, 6, 4, &hits, &mut levels);
        assert_eq!(art(&whole, 6), art(&levels, 6));
    }
}
