//! Silhouette lines for a 1-bit display. Where two neighbouring pixels' eye rays hit different
//! objects, the farther pixel of the pair is drawn black before dithering, so every object gets
//! a one-pixel outline outside its own area: thin parts (a chair's legs) stay visible against
//! a floor of the same gray, and dithering cannot blur an object into what lies behind it.
//!
//! Pairs inside a tile use what the tile's eye rays returned ([`Hits`]: object and depth per
//! pixel). Pairs split by the tile's left or top border compare with its **apron**: the column
//! of pixels left of the tile and the row above it, found by hit-only eye rays (the nearest
//! object and its distance, no shading) that the tile traces itself (with adaptive sampling
//! only where the neighbour tile traced a ray: `Sampler::side`). A tile therefore needs
//! nothing from any other tile, so frames with an outline split into bands and tile shares (two
//! cores) like any other; the pixel inside the tile gets the line of such a pair, so it stays
//! unbroken. Pairs split by the right and bottom borders are the next tiles' apron pairs.

use crate::sample::Hits;

/// What a tile's apron hit: object and depth key per pixel of the column left of the tile
/// (`left`, one per tile row) and of the row above it (`up`, one per tile column); `None` at
/// the frame's own left or top edge.
#[derive(Clone, Copy, Debug)]
pub struct Apron<'a> {
    /// The column left of the tile.
    pub left: Option<&'a [(u16, u16)]>,
    /// The row above the tile.
    pub up: Option<&'a [(u16, u16)]>,
}

/// Whether two pixels' hits (object, depth key) make a line between them: other objects at
/// other depths.
fn differ(a: (u16, u16), b: (u16, u16)) -> bool {
    a.0 != b.0 && a.1 != b.1
}

/// The lines across a `tw x th` tile's left and top borders alone, drawn into its `levels`
/// (level 0): where its left column's and top row's hits (`left`, `top`) differ from the
/// apron's. With the lines inside the tile ([`tile`] with no apron) these are [`tile`]'s lines.
pub fn apron(tw: usize, th: usize, left: &[(u16, u16)], top: &[(u16, u16)], apron: Apron<'_>, levels: &mut [u8]) {
    borders(tw, th, |y| left.get(y).copied(), |x| top.get(x).copied(), apron, levels);
}

/// [`apron`] with the tile's left column's and top row's hits as `left(y)` and `top(x)`.
fn borders(
    tw: usize,
    th: usize,
    left: impl Fn(usize) -> Option<(u16, u16)>,
    top: impl Fn(usize) -> Option<(u16, u16)>,
    apron: Apron<'_>,
    levels: &mut [u8],
) {
    if let Some(column) = apron.left {
        for (y, &n) in column.iter().enumerate().take(th) {
            if left(y).is_some_and(|here| differ(n, here)) {
                levels[y * tw] = 0;
            }
        }
    }
    if let Some(row) = apron.up {
        for (x, &n) in row.iter().enumerate().take(tw) {
            if top(x).is_some_and(|here| differ(n, here)) {
                levels[x] = 0;
            }
        }
    }
}

/// Draws the silhouettes of a `tw x th` tile into its `levels` (level 0 where a line runs),
/// from what its pixels hit and what its apron hit. Each pair of neighbours inside the tile
/// (along its rows, then down its columns) draws the farther pixel's line; a pixel beside the
/// apron gets the line of its pair across the border. A line only ever sets a level to 0 and is
/// decided by the hits alone, so the order the pairs are visited in does not change the result.
pub fn tile(tw: usize, th: usize, hits: &Hits, apron: Apron<'_>, levels: &mut [u8]) {
    let n = (tw * th).min(levels.len()).min(hits.object.len());
    let (objects, depths, levels) = (&hits.object[..n], &hits.depth[..n], &mut levels[..n]);
    // The objects first: most pairs are of one object, and their depths are not read.
    let mut pair = |i: usize, j: usize| {
        if objects[i] != objects[j] {
            let (a, b) = (depths[i], depths[j]);
            if a != b {
                levels[if a > b { i } else { j }] = 0;
            }
        }
    };
    for row in (0..n).step_by(tw.max(1)) {
        for i in row + 1..(row + tw).min(n) {
            pair(i - 1, i);
        }
    }
    for i in tw..n {
        pair(i - tw, i);
    }
    let hit = |i: usize| Some((*objects.get(i)?, *depths.get(i)?));
    borders(tw, th, |y| hit(y * tw), hit, apron, levels);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::NO_OBJECT;

    /// A 6x4 picture: background (id NO_OBJECT) with a one-pixel-wide object 7 at column 2, in
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
                } else {
                    (h.object[i], h.depth[i]) = (NO_OBJECT as u16, u16::MAX);
                }
            }
        }
        h
    }

    fn art(levels: &[u8], w: usize) -> std::string::String {
        levels
            .chunks(w)
            .map(|r| r.iter().map(|&l| if l == 0 { '#' } else { '.' }).collect::<std::string::String>() + "\n")
            .collect()
    }

    const NO_APRON: Apron<'static> = Apron { left: None, up: None };

    #[test]
    fn the_farther_pixel_of_each_pair_is_outlined() {
        let mut levels = [40u8; 24];
        tile(6, 4, &scene(), NO_APRON, &mut levels);
        // The object stays; the background and the floor beside it, and the background above
        // the floor, become lines.
        assert_eq!(art(&levels, 6), ".#.#..\n.#.#..\n##.###\n.#.#..\n");
    }

    #[test]
    fn pairs_across_the_left_border_are_outlined_inside_the_tile() {
        let hits = scene();
        // The same picture drawn as two 3-wide tiles; the second tile's apron is the first
        // tile's last column. Column 3 (background, farther than the object at column 2) gets
        // its line in the second tile, as the whole picture drew it.
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
        let left: std::vec::Vec<(u16, u16)> = (0..4).map(|y| (hits.object[y * 6 + 2], hits.depth[y * 6 + 2])).collect();
        let (mut a, mut b) = ([40u8; 12], [40u8; 12]);
        tile(3, 4, &split(0), NO_APRON, &mut a);
        tile(3, 4, &split(3), Apron { left: Some(&left), up: None }, &mut b);
        let whole: std::vec::Vec<u8> = (0..4)
            .flat_map(|y| a[y * 3..y * 3 + 3].iter().chain(&b[y * 3..y * 3 + 3]).copied().collect::<std::vec::Vec<_>>())
            .collect();
        let mut levels = [40u8; 24];
        tile(6, 4, &hits, NO_APRON, &mut levels);
        assert_eq!(art(&whole, 6), art(&levels, 6));
    }

    #[test]
    fn a_row_above_of_another_object_outlines_the_top_row() {
        let hits = scene();
        // Above the tile lies something nearer than the background everywhere: every top-row
        // pixel that is not that object gets a line.
        let up = [(9u16, 50u16); 6];
        let mut levels = [40u8; 24];
        tile(6, 4, &hits, Apron { left: None, up: Some(&up) }, &mut levels);
        assert_eq!(&art(&levels, 6)[..7], "######\n");
    }
}
