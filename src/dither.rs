//! Turning gray levels (0..=64, the paper's 65 levels) into 1-bit pixels.
//!
//! * [`Dither::Bayer`]: ordered dither with the 8x8 Bayer matrix, one gray per pixel;
//! * [`Dither::BlueNoise`]: ordered dither with a 16x16 blue-noise mask (void-and-cluster,
//!   made at build time), one gray per pixel: no regular texture, no error carried;
//! * [`Dither::Pattern`]: the paper's bit-map patterning: one traced sample per NxN block,
//!   shown as the NxN dot pattern of its level (N = 8 gives the paper's 65 levels);
//! * [`Dither::FloydSteinberg`] and [`Dither::Atkinson`]: error diffusion, run in tile order
//!   with bounded carry buffers (four rows of the image width and two columns of a tile).
//!
//! Error diffusion in tile order: error flowing right or down reaches its pixel exactly as in
//! raster order, across tile borders too. Error flowing down-left into a tile that is already
//! drawn is given to the pixel straight below instead, so no error is lost; this is the only
//! difference from a raster-order pass. At the image's left edge the down-left share goes
//! straight below as well, rather than out of the image: no error is lost there either, and the
//! border columns are lit as often as the rest (a dropped share drew a seam).

use embedded_graphics_core::pixelcolor::{BinaryColor, Gray2, GrayColor, PixelColor};

/// Highest gray level (white).
pub const LEVELS: u8 = 64;

/// A pixel a dither writes: the shades a panel shows, `STEPS + 1` of them evenly spaced from
/// dark (step 0) to lit (step `STEPS`). [`BinaryColor`] is the 1-bit panel's pixel (one step);
/// [`Gray2`] the gray mode's four shades (three steps), shown on a 1-bit OLED as subframes.
pub trait Shade: PixelColor {
    /// Steps above dark (1: two shades, 3: four).
    const STEPS: u8;
    /// The dark pixel.
    const DARK: Self;
    /// The shade of step `k` (`0..=STEPS`; larger steps are lit).
    fn from_step(k: u8) -> Self;
    /// This pixel's step, `0..=STEPS`: the subframes (of `STEPS`) it is lit in.
    fn step(self) -> u8;
}

impl Shade for BinaryColor {
    const STEPS: u8 = 1;
    const DARK: Self = BinaryColor::Off;
    #[inline(always)]
    fn from_step(k: u8) -> Self {
        BinaryColor::from(k != 0)
    }
    #[inline(always)]
    fn step(self) -> u8 {
        u8::from(self.is_on())
    }
}

impl Shade for Gray2 {
    const STEPS: u8 = 3;
    const DARK: Self = Gray2::BLACK;
    #[inline(always)]
    fn from_step(k: u8) -> Self {
        Gray2::new(k.min(3))
    }
    #[inline(always)]
    fn step(self) -> u8 {
        self.luma()
    }
}

/// A dithering mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dither {
    /// 8x8 Bayer ordered dither, one sample per pixel.
    Bayer,
    /// Ordered dither with a 16x16 void-and-cluster blue-noise mask, one sample per pixel.
    BlueNoise,
    /// The paper's patterning: one sample per NxN block (N = 2, 4 or 8).
    Pattern(u8),
    /// Floyd-Steinberg error diffusion.
    FloydSteinberg,
    /// Atkinson error diffusion (diffuses 6/8 of the error).
    Atkinson,
}

impl Dither {
    /// Side of the block that shares one traced sample.
    pub fn block(&self) -> u8 {
        match self {
            Dither::Pattern(n) => *n,
            _ => 1,
        }
    }
    /// Whether the mode needs carry buffers.
    pub const fn diffuses(&self) -> bool {
        matches!(self, Dither::FloydSteinberg | Dither::Atkinson)
    }
}

/// The 8x8 Bayer index matrix (0..=63).
pub const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// Ordered dither of one pixel: `level` of 64 against an NxN Bayer pattern (N = 1, 2, 4, 8).
/// The NxN matrix is the top-left corner of the 8x8 one divided down, which is the Bayer
/// matrix of that size; the level is first rounded to the N*N + 1 levels it can show.
pub fn ordered(level: u8, x: u32, y: u32, n: u8) -> BinaryColor {
    ordered_by(level, x, y, n.clamp(1, 8) as u32)
}

/// A level's place between two shades of `C`: the step below it (`0..=STEPS`) and how far
/// it is above that step, in 64ths of a step (a level of 64 with one step is step 1, 0 above).
#[inline(always)]
fn between<C: Shade>(level: u8) -> (u32, u32) {
    let q = level.min(LEVELS) as u32 * C::STEPS as u32;
    (q / LEVELS as u32, q % LEVELS as u32)
}

/// [`ordered`] with `n` already in 1..=8: inlined where `n` is a constant, its divisions are
/// shifts.
#[inline(always)]
fn ordered_by<C: Shade>(level: u8, x: u32, y: u32, n: u32) -> C {
    let cells = n * n;
    let (base, above) = between::<C>(level);
    let q = (above * cells + 32) / 64; // 0..=cells
    let shift = 64 / cells;
    let t = BAYER8[(y % n) as usize][(x % n) as usize] as u32 / shift;
    C::from_step((base + u32::from(q > t)) as u8)
}

// BLUE_NOISE and GAMMA, made by the crate's build.rs.
include!(concat!(env!("OUT_DIR"), "/display.rs"));

/// Ordered dither of one pixel against the blue-noise mask: of the mask's 256 ranks, the lowest
/// `level * 4` are on (so level 32 lights half the pixels, 0 none and 64 all).
pub fn blue_noise(level: u8, x: u32, y: u32) -> BinaryColor {
    let rank = BLUE_NOISE[(y % 16) as usize][(x % 16) as usize] as u32;
    BinaryColor::from(rank < level.min(LEVELS) as u32 * 4)
}

/// A tone curve applied to gray levels before dithering: level `l` of 64 shows as
/// `64 * (l / 64)^(gamma / 10)`, rounded (tables made at build time). Below 10 it lifts dark
/// grays, above 10 it deepens them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tone {
    /// The exponent in tenths, 5..=20 (10: unchanged).
    pub gamma_tenths: u8,
}

impl Tone {
    /// Levels unchanged.
    pub const LINEAR: Tone = Tone { gamma_tenths: 10 };
    /// Exponents the tables hold, in tenths.
    pub const RANGE: core::ops::RangeInclusive<u8> = 5..=20;

    /// Whether the curve changes any level.
    pub fn is_linear(self) -> bool {
        self.gamma_tenths == 10 || !Self::RANGE.contains(&self.gamma_tenths)
    }

    /// Level `l` (0..=64) through the curve; exponents outside [`Tone::RANGE`] leave it unchanged.
    pub fn apply(self, l: u8) -> u8 {
        match GAMMA.get(self.gamma_tenths.wrapping_sub(*Self::RANGE.start()) as usize) {
            Some(curve) if !self.is_linear() => curve[l.min(LEVELS) as usize],
            _ => l,
        }
    }
}

/// A tile's error accumulator with its border: `acc[y][x + 1]` is the error arriving at tile
/// pixel `(x, y)`, for `x` in `-1..w + 2` and `y` in `0..h + 2` (a tile at the image's left
/// or right edge counts the [`EDGE_PAD`] columns beyond it among its pixels).
type Acc = [[i16; MAX_TILE + 2 * EDGE_PAD + 3]; MAX_TILE + 2];

/// Columns dithered beyond each side of the image and not drawn, each row's first (or last) gray
/// carried into them: the border columns then get and give error as every other column does.
/// With the row's start seeded (`row_seed`), they keep the border columns within the
/// interior's spread (`error_diffusion_draws_no_seam_at_the_edges`); without them column 0 was
/// lit too seldom or too often and columns 1 and 2 the other way (a seam).
pub const EDGE_PAD: usize = 6;

/// Error put into the first pad column of row `y` (at most half a gray range either way, in
/// error units): every row starts from its own pseudo-random state rather than the same one,
/// which lined the first columns up into stripes. A hash of `y` alone: the same on every board.
#[inline]
fn row_seed(y: usize) -> i16 {
    let mut h = (y as u32).wrapping_mul(0x9E37_79B1) ^ 0x7F4A_7C15;
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    (h % 1025) as i16 - 512
}

// An error-diffusion kernel dithers one row `y` of a tile: each pixel's level plus the error
// arriving at it (`acc[y][x + 1]`) is set or not, and its error `err` goes to its neighbours,
// each share `err * weight / divisor` (rounded towards zero). Written out, not a table walked
// per pixel: the weights are constants, the divisor a shift, and no index is checked at run
// time.

/// A pixel of level `level` (0..=64) with error `arriving`: the shade of `C` nearest it, and
/// its error. With one step that is lit or not at half the range; with `STEPS` steps, step `k`
/// stands for `k / STEPS` of the range (rounded to error units) and the nearest is taken.
#[inline(always)]
fn quantize<C: Shade>(level: u8, arriving: i16) -> (C, i16) {
    let v = level as i16 * SCALE + arriving;
    if C::STEPS == 1 {
        let on = v >= (LEVELS as i16 / 2) * SCALE;
        return (C::from_step(u8::from(on)), v - if on { LEVELS as i16 * SCALE } else { 0 });
    }
    let (n, full) = (i32::from(C::STEPS), i32::from(LEVELS as i16 * SCALE));
    // `full` is a power of two: the floor of the division is an arithmetic shift.
    let k = ((i32::from(v) * n + full / 2) >> full.trailing_zeros()).clamp(0, n);
    (C::from_step(k as u8), (i32::from(v) - (k * full + n / 2) / n) as i16)
}

/// Floyd-Steinberg: 7/16 right, 3/16 below left, 5/16 below, 1/16 below right. The error going
/// right and the two entries of the row below still taking shares are carried in locals along
/// the row: per pixel one entry of each row is read and one of the row below written.
#[inline(always)]
fn floyd_steinberg<C: Shade>(acc: &mut Acc, y: usize, levels: &[u8], out: &mut [C]) {
    let w = levels.len().min(out.len()).min(MAX_TILE + 2 * EDGE_PAD);
    let (above, below) = acc.split_at_mut(y + 1);
    let (row, below) = (&mut above[y], &mut below[0]);
    // `right`: the error arriving at the pixel; `b0`, `b1`: the row below's entries under the
    // pixel's left neighbour and under the pixel, with the shares they have so far.
    // The carried errors stay far inside i16 (a pixel's error is within a level range of 0, and
    // its shares sum to it), so they are summed as i32, which a Cortex-M0+ does without
    // sign-extending every step, and stored back as they were: the same values.
    let (mut right, mut b0, mut b1) = (i32::from(row[1]), i32::from(below[0]), i32::from(below[1]));
    for x in 0..w {
        let (px, err) = quantize::<C>(levels[x], right as i16);
        out[x] = px;
        let err = i32::from(err);
        right = i32::from(row[x + 2]) + err * 7 / 16;
        below[x] = (b0 + err * 3 / 16) as i16;
        b0 = b1 + err * 5 / 16;
        b1 = i32::from(below[x + 2]) + err / 16;
    }
    row[w + 1] = right as i16;
    below[w] = b0 as i16;
    below[w + 1] = b1 as i16;
}

/// Atkinson: 1/8 to each of two right, three below and one two rows below (6/8 of the error).
#[inline(always)]
fn atkinson<C: Shade>(acc: &mut Acc, y: usize, levels: &[u8], out: &mut [C]) {
    for (x, (&l, px)) in levels.iter().zip(out.iter_mut()).enumerate().take(MAX_TILE + 2 * EDGE_PAD) {
        let (shade, err) = quantize::<C>(l, acc[y][x + 1]);
        *px = shade;
        let (e, c) = (err / 8, x + 1);
        acc[y][c + 1] += e;
        acc[y][c + 2] += e;
        acc[y + 1][c - 1] += e;
        acc[y + 1][c] += e;
        acc[y + 1][c + 1] += e;
        acc[y + 2][c] += e;
    }
}

/// Largest tile side the renderer supports: 16, or 8 with the `tile8` feature, which makes
/// every per-tile buffer a quarter the size (firmware whose frames have 8x8 tiles).
pub const MAX_TILE: usize = if cfg!(feature = "tile8") { 8 } else { 16 };
/// Error units per gray level.
const SCALE: i16 = 16;

/// Error-diffusion state carried between tiles: `4 * (width + 2 * EDGE_PAD)` entries of caller
/// storage (two rows arriving at the current band, two rows leaving it, each with the columns
/// beyond both sides of the image) and two columns per tile row.
#[derive(Debug)]
pub struct Carry<'c> {
    rows: &'c mut [i16],
    width: usize,
    right: [[i16; 2]; MAX_TILE],
    /// The right border of the rows above the image ([`rows_above`]) to the next tile.
    above_right: [[i16; 2]; TOP_PAD],
    incoming: usize,
}

impl<'c> Carry<'c> {
    /// Entries of storage needed for an image `width` pixels wide.
    pub const fn len(width: usize) -> usize {
        4 * (width + 2 * EDGE_PAD)
    }
    /// Carry state over caller storage of at least [`Carry::len`] entries (it is cleared).
    pub fn new(rows: &'c mut [i16], width: usize) -> Option<Self> {
        let rows = rows.get_mut(..Self::len(width))?;
        rows.iter_mut().for_each(|v| *v = 0);
        Some(Carry { rows, width, right: [[0; 2]; MAX_TILE], above_right: [[0; 2]; TOP_PAD], incoming: 0 })
    }
    /// Row `k` of the half `which`: entry `EDGE_PAD + x` for image column `x`.
    fn row(&mut self, which: usize, k: usize) -> &mut [i16] {
        let w = self.width + 2 * EDGE_PAD;
        let i = (which * 2 + k) * w;
        &mut self.rows[i..i + w]
    }
    /// Call when a new band of tiles (a new tile row) starts.
    pub fn next_band(&mut self) {
        // The rows that left the previous band (the half `1 - incoming`) are the rows arriving
        // at this one (the half `incoming`).
        let out = 1 - self.incoming;
        let w = self.width + 2 * EDGE_PAD;
        // The two halves never overlap: a copy between them (`copy_within` would link a
        // `memmove` of 1.3 KB into the firmware for this one use).
        let (first, second) = self.rows[..4 * w].split_at_mut(2 * w);
        let (from, to) = if out == 0 { (&mut *first, &mut *second) } else { (&mut *second, &mut *first) };
        to.copy_from_slice(from);
        from.iter_mut().for_each(|v| *v = 0);
        self.right = [[0; 2]; MAX_TILE];
    }

    /// Error-diffuses one tile at `(x0, y0)`, `w x h` levels in row-major order, into `out`.
    /// Never inlined: its accumulators then take stack only while a tile is dithered, not for
    /// the whole of its caller's render loop (the deepest stack is the tracer's, below it).
    #[inline(never)]
    pub fn tile<C: Shade>(
        &mut self,
        mode: Dither,
        (x0, y0): (usize, usize),
        w: usize,
        h: usize,
        levels: &[u8],
        out: &mut [C],
    ) {
        // Each kernel inlined as a constant: its weights unrolled and its divisor a shift, not
        // a division call per neighbour (a Cortex-M0+ has no divide instruction).
        if mode == Dither::Atkinson {
            self.diffuse(atkinson::<C>, (x0, y0), w, h, levels, out);
        } else {
            self.diffuse(floyd_steinberg::<C>, (x0, y0), w, h, levels, out);
        }
    }

    /// [`Carry::tile`] with one kernel.
    ///
    /// The tile's accumulator has a border (a column left of the tile, two right of it and two
    /// rows below), so every pixel sends its error with the same unchecked additions; the
    /// border is then handed on: the left column to the tile's first column as its row starts
    /// (the pixel there is already drawn, so its error goes straight below instead), the right
    /// columns to the next tile, the rows below to the next band, and what falls beyond the
    /// pads or the last row is dropped. A tile at the image's left (right) edge dithers the
    /// [`EDGE_PAD`] columns beyond it too, as pixels that are not drawn; at the left edge each
    /// row starts with its `row_seed`.
    #[inline(always)]
    fn diffuse<C: Shade>(
        &mut self,
        kernel: impl Fn(&mut Acc, usize, &[u8], &mut [C]),
        (x0, y0): (usize, usize),
        w: usize,
        h: usize,
        levels: &[u8],
        out: &mut [C],
    ) {
        // No tile is larger (the render's tiles are at most MAX_TILE on a side); saying so lets
        // the kernel's indices go unchecked.
        let (w, h) = (w.min(MAX_TILE), h.min(MAX_TILE));
        // Columns dithered before and after the tile's own: the pads at the image's edges.
        let lead = if x0 == 0 { EDGE_PAD } else { 0 };
        let trail = if x0 + w >= self.width { EDGE_PAD } else { 0 };
        let span = lead + w + trail;
        // The carry rows' entry of the tile's accumulator column 1 (its first column dithered).
        let first = x0 + EDGE_PAD - lead;
        let mut acc: Acc = [[0; MAX_TILE + 2 * EDGE_PAD + 3]; MAX_TILE + 2];
        // Gather what earlier tiles sent here.
        let inc = self.incoming;
        for k in 0..2.min(h) {
            let row = self.row(inc, k);
            for (a, r) in acc[k][1..].iter_mut().zip(&mut row[first..first + span]) {
                *a += core::mem::take(r);
            }
        }
        for y in 0..h {
            acc[y][1 + lead] += self.right[y][0];
            if w > 1 {
                acc[y][2 + lead] += self.right[y][1];
            }
            if lead > 0 {
                acc[y][1] += row_seed(y0 + y);
            }
        }
        self.right = [[0; 2]; MAX_TILE];
        if y0 == 0 && h > 0 {
            let edges = (first, lead, w, x0 + w >= self.width);
            rows_above(&kernel, &mut acc, &padded(&levels[..w], lead, span), edges, &mut self.above_right);
        }
        for y in 0..h {
            // The left border's error (what went down-left) to the pixel straight below.
            let left = core::mem::take(&mut acc[y][0]);
            acc[y][1] += left;
            let (row, px) = (&levels[y * w..(y + 1) * w], &mut out[y * w..(y + 1) * w]);
            if span == w {
                kernel(&mut acc, y, row, px);
            } else {
                let mut drawn = [C::DARK; MAX_TILE + 2 * EDGE_PAD];
                kernel(&mut acc, y, &padded(row, lead, span)[..span], &mut drawn[..span]);
                px.copy_from_slice(&drawn[lead..lead + w]);
            }
        }
        // The right border to the next tile (none beyond the right pad).
        if trail == 0 {
            for (y, row) in acc.iter().enumerate().take(h) {
                for k in 0..2 {
                    if x0 + w + k < self.width {
                        self.right[y][k] += row[lead + w + 1 + k];
                    }
                }
            }
        }
        // The rows below to the next band: the left border's column to the tile's first, the
        // others where they fall in the image or its pads.
        let out_rows = 1 - inc;
        let end = self.width + 2 * EDGE_PAD;
        for k in 0..2 {
            let below = acc[h + k];
            let row = self.row(out_rows, k);
            row[first] += below[0];
            for (c, &e) in below[1..span + 3].iter().enumerate() {
                if first + c < end {
                    row[first + c] += e;
                }
            }
        }
    }
}

/// Rows dithered above the image and not drawn, each the first row's grays: the first rows
/// then get error from above as every other row does (without them, a flat gray's first rows
/// were lit all or nothing, or in a regular pattern, up to 14 standard deviations off the
/// field's mean).
const TOP_PAD: usize = 16;

/// A tile row of `span` grays: `row` after `lead` pad grays, the pads carrying its first and
/// last grays.
fn padded(row: &[u8], lead: usize, span: usize) -> [u8; MAX_TILE + 2 * EDGE_PAD] {
    let w = row.len();
    let mut padded = [row[0]; MAX_TILE + 2 * EDGE_PAD];
    padded[lead..lead + w].copy_from_slice(row);
    padded[lead + w..span].fill(row[w - 1]);
    padded
}

/// Dithers the [`TOP_PAD`] rows above a first-band tile (`row`: its first row, padded; `lead`
/// pad columns before its `w`, and whether it is the band's last) in an accumulator of their
/// own, as its own rows are dithered: each row's error handed right to the next tile through
/// `right`, and at the image's left edge each row started from its own seed. The error they
/// send to the two rows below them is added to `acc`'s first two rows. Out of line, so its
/// accumulator takes stack only meanwhile.
#[inline(never)]
fn rows_above<C: Shade>(
    kernel: &impl Fn(&mut Acc, usize, &[u8], &mut [C]),
    acc: &mut Acc,
    row: &[u8; MAX_TILE + 2 * EDGE_PAD],
    (first, lead, w, last): (usize, usize, usize, bool),
    right: &mut [[i16; 2]; TOP_PAD],
) {
    let span = lead + w + if last { EDGE_PAD } else { 0 };
    let mut above: Acc = [[0; MAX_TILE + 2 * EDGE_PAD + 3]; MAX_TILE + 2];
    let mut drawn = [C::DARK; MAX_TILE + 2 * EDGE_PAD];
    // The first row from a seed per column, as each row starts from one: no start-up pattern.
    for (c, a) in above[0][1..=span].iter_mut().enumerate() {
        // The hash of the carry column before it: the same number on 32- and 64-bit targets
        // (`row_seed` hashes the low 32 bits; the QEMU and board frames are held to host-sim's).
        *a = row_seed((first + c).wrapping_sub(1));
    }
    // `y`: the accumulator's row, rolled back to the top when it fills (the rows above may be
    // more than a tile's).
    let mut y = 0;
    for (k, r) in right.iter_mut().enumerate() {
        let [r0, r1] = core::mem::take(r);
        above[y][1 + lead] += r0;
        if w > 1 {
            above[y][2 + lead] += r1;
        }
        if lead > 0 {
            // Seeds of their own: not the image rows' (`usize::MAX - k` is no row of a frame).
            above[y][1] += row_seed(usize::MAX - k);
        }
        let left = core::mem::take(&mut above[y][0]);
        above[y][1] += left;
        kernel(&mut above, y, &row[..span], &mut drawn[..span]);
        if !last {
            *r = [above[y][lead + w + 1], above[y][lead + w + 2]];
        }
        y += 1;
        if y == MAX_TILE {
            above[0] = above[MAX_TILE];
            above[1] = above[MAX_TILE + 1];
            above[2..].iter_mut().for_each(|row| *row = [0; MAX_TILE + 2 * EDGE_PAD + 3]);
            y = 0;
        }
    }
    for k in 0..2 {
        for (a, e) in acc[k].iter_mut().zip(above[y + k]) {
            *a += e;
        }
    }
}

/// Dithers tiles in the render's order, owning the state its mode carries between tiles
/// (error diffusion's carries; ordered modes carry nothing).
#[derive(Debug)]
pub struct Ditherer<'c> {
    mode: Dither,
    carry: Option<Carry<'c>>,
}

impl<'c> Ditherer<'c> {
    /// Entries of `i16` storage `mode` needs for an image `width` pixels wide.
    pub fn rows_len(mode: Dither, width: usize) -> usize {
        if mode.diffuses() {
            Carry::len(width)
        } else {
            0
        }
    }

    /// A ditherer over storage of at least [`Ditherer::rows_len`] entries, or `None` if it is
    /// shorter, or if `mode` diffuses error and the core was built without its `diffusion`
    /// feature.
    pub fn new(mode: Dither, width: usize, rows: &'c mut [i16]) -> Option<Self> {
        if mode.diffuses() && !cfg!(feature = "diffusion") {
            return None;
        }
        let carry = if mode.diffuses() { Some(Carry::new(rows, width)?) } else { None };
        Some(Ditherer { mode, carry })
    }

    /// Call when a new band of tiles (a new tile row) starts.
    pub fn next_band(&mut self) {
        if let Some(c) = self.carry.as_mut() {
            c.next_band();
        }
    }

    /// Dithers the `w x h` tile of `levels` (row-major) at `(x0, y0)` into `out`.
    pub fn tile<C: Shade>(&mut self, x0: usize, y0: usize, w: usize, h: usize, levels: &[u8], out: &mut [C]) {
        // Without the `diffusion` feature no ditherer has carries, and their code is not linked.
        match self.carry.as_mut().filter(|_| cfg!(feature = "diffusion")) {
            Some(c) => c.tile(self.mode, (x0, y0), w, h, levels, out),
            None if self.mode == Dither::BlueNoise => {
                // Row by row against the mask's row (the same pixels as `blue_noise`).
                for y in 0..h {
                    let mask = &BLUE_NOISE[(y0 + y) % 16];
                    for x in 0..w {
                        let l = *crate::bounds::at(levels, y * w + x);
                        let (base, above) = between::<C>(l);
                        *crate::bounds::at_mut(out, y * w + x) =
                            C::from_step((base + u32::from((mask[(x0 + x) % 16] as u32) < above * 4)) as u8);
                    }
                }
            }
            None => {
                // Each pattern size its own copy of the loop, with `n` a constant.
                let mut each = |n: u32| {
                    for y in 0..h {
                        for x in 0..w {
                            let (l, gx, gy) = (levels[y * w + x], (x0 + x) as u32, (y0 + y) as u32);
                            out[y * w + x] = ordered_by(l, gx, gy, n);
                        }
                    }
                };
                match if self.mode == Dither::Bayer { 8 } else { self.mode.block().clamp(1, 8) } {
                    8 => each(8),
                    4 => each(4),
                    2 => each(2),
                    n => each(u32::from(n)),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn art(w: usize, px: &[BinaryColor]) -> std::string::String {
        px.chunks(w)
            .map(|r| r.iter().map(|c| if c.is_on() { '#' } else { '.' }).collect::<std::string::String>() + "\n")
            .collect()
    }

    #[test]
    fn blue_noise_tiles_are_the_mask_pixel_by_pixel() {
        // A tile anywhere in the frame (partial tiles too) shows exactly what `blue_noise` gives
        // each of its pixels.
        let mut d = Ditherer::new(Dither::BlueNoise, 40, &mut []).unwrap();
        for (x0, y0, w, h) in [(0, 0, 8, 8), (8, 16, 8, 8), (24, 5, 16, 11), (33, 7, 7, 3)] {
            let levels: std::vec::Vec<u8> = (0..w * h).map(|i| ((i * 37 + x0 * 5 + y0) % 65) as u8).collect();
            let mut out = [BinaryColor::Off; MAX_TILE * MAX_TILE];
            d.tile(x0, y0, w, h, &levels, &mut out);
            for (i, &l) in levels.iter().enumerate() {
                assert_eq!(
                    out[i],
                    blue_noise(l, (x0 + i % w) as u32, (y0 + i / w) as u32),
                    "tile at ({x0}, {y0}), pixel {i}"
                );
            }
        }
    }

    #[test]
    fn bayer_half_gray_is_a_checkerboard() {
        let px: std::vec::Vec<_> = (0..16).map(|i| ordered(32, i % 4, i / 4, 8)).collect();
        assert_eq!(art(4, &px), "#.#.\n.#.#\n#.#.\n.#.#\n");
    }

    #[test]
    fn bayer_extremes_are_solid() {
        for (level, on) in [(0u8, false), (64, true)] {
            assert!((0..64).all(|i| ordered(level, i % 8, i / 8, 8).is_on() == on));
        }
    }

    #[test]
    fn pattern8_quarter_gray_sets_sixteen_dots() {
        let px: std::vec::Vec<_> = (0..64).map(|i| ordered(16, i % 8, i / 8, 8)).collect();
        assert_eq!(
            art(8, &px),
            "#.#.#.#.\n\
             ........\n\
             #.#.#.#.\n\
             ........\n\
             #.#.#.#.\n\
             ........\n\
             #.#.#.#.\n\
             ........\n"
        );
    }

    #[test]
    fn blue_noise_mask_holds_every_rank_once_and_lights_level_quarters() {
        let mut seen = [false; 256];
        BLUE_NOISE.iter().flatten().for_each(|&r| seen[r as usize] = true);
        assert!(seen.iter().all(|&s| s));
        for level in [0u8, 16, 32, 48, 64] {
            let on = (0..256).filter(|&i| blue_noise(level, i % 16, i / 16).is_on()).count();
            assert_eq!(on, level as usize * 4);
        }
    }

    #[test]
    fn blue_noise_half_gray_has_no_clumps() {
        // Blue noise spreads the dots: at half gray few 2x2 squares are all on or all off (white
        // noise makes about one in eight solid).
        let solid = (0..256)
            .filter(|&i| {
                let (x, y) = (i % 16, i / 16);
                let px = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)].map(|(a, b)| blue_noise(32, a, b).is_on());
                px.iter().all(|&p| p) || px.iter().all(|&p| !p)
            })
            .count();
        assert!(solid < 256 / 16, "{solid} solid 2x2 squares of 256");
    }

    #[test]
    fn tone_curves_fix_the_ends_and_bend_the_middle() {
        for g in Tone::RANGE {
            let t = Tone { gamma_tenths: g };
            assert_eq!((t.apply(0), t.apply(64)), (0, 64));
            let mid = t.apply(32);
            assert!((g < 10 && mid > 32) || (g == 10 && mid == 32) || (g > 10 && mid < 32), "gamma {g}: {mid}");
        }
        assert_eq!(Tone { gamma_tenths: 30 }.apply(17), 17);
    }

    #[test]
    fn pattern2_has_five_levels() {
        let count = |l| (0..4).filter(|&i| ordered(l, i % 2, i / 2, 2).is_on()).count();
        assert_eq!([0, 16, 32, 48, 64].map(count), [0, 1, 2, 3, 4]);
    }

    #[test]
    fn floyd_steinberg_half_gray_in_tiles_keeps_half_the_dots() {
        let (w, h, t) = (16usize, 16usize, 8usize);
        let mut store = [0i16; Carry::len(16)];
        let mut carry = Carry::new(&mut store, w).unwrap();
        let mut img = [BinaryColor::Off; 256];
        for by in 0..h / t {
            carry.next_band();
            for bx in 0..w / t {
                let mut out = [BinaryColor::Off; 64];
                carry.tile(Dither::FloydSteinberg, (bx * t, by * t), t, t, &[32u8; 64], &mut out);
                for y in 0..t {
                    for x in 0..t {
                        img[(by * t + y) * w + bx * t + x] = out[y * t + x];
                    }
                }
            }
        }
        let on = img.iter().filter(|c| c.is_on()).count();
        assert_eq!(on, 128, "\n{}", art(w, &img));
    }

    /// Per column, how many of an `w x h` flat field of `level` are lit, dithered by `mode` in
    /// tiles of `t x t` as the render orders them.
    fn column_counts(mode: Dither, w: usize, h: usize, t: usize, level: u8) -> std::vec::Vec<u32> {
        lit_counts(mode, w, h, t, level).0
    }

    /// How often each row of the field [`column_counts`] dithers is lit.
    fn row_counts(mode: Dither, w: usize, h: usize, t: usize, level: u8) -> std::vec::Vec<u32> {
        lit_counts(mode, w, h, t, level).1
    }

    /// The lit pixels of each column and of each row of a `w x h` flat field of `level`,
    /// dithered by `mode` in `t x t` tiles in the render's order.
    fn lit_counts(mode: Dither, w: usize, h: usize, t: usize, level: u8) -> (std::vec::Vec<u32>, std::vec::Vec<u32>) {
        let mut store = std::vec![0i16; Carry::len(w)];
        let mut carry = Carry::new(&mut store, w).unwrap();
        let (mut cols, mut rows) = (std::vec![0u32; w], std::vec![0u32; h]);
        for y0 in (0..h).step_by(t) {
            carry.next_band();
            for x0 in (0..w).step_by(t) {
                let (tw, th) = (t.min(w - x0), t.min(h - y0));
                let mut out = [BinaryColor::Off; MAX_TILE * MAX_TILE];
                carry.tile(mode, (x0, y0), tw, th, &[level; MAX_TILE * MAX_TILE][..tw * th], &mut out[..tw * th]);
                for (i, px) in out[..tw * th].iter().enumerate() {
                    cols[x0 + i % tw] += u32::from(px.is_on());
                    rows[y0 + i / tw] += u32::from(px.is_on());
                }
            }
        }
        (cols, rows)
    }

    #[test]
    fn error_diffusion_draws_no_seam_at_the_top() {
        // The three first rows look like the interior's rows (first-look: Atkinson's row 0 lit
        // on all 400 pixels of a flat 41 of 64, 13.9 standard deviations off the mean; Floyd-
        // Steinberg's row 2 on 267 of 400 at 56 of 64, 12.7 off; 362 of the 378 rows below
        // outside the interior's spread). A row is outside when it is further from the field's
        // mean than binomial noise allows (3 standard deviations) and than every interior row;
        // rows drawn like the interior's are so by chance for one of every `interior + 1`, so
        // no more top rows than that may be outside, and none by more than a standard deviation.
        let (mut outside, mut by_chance) = (0, 0.0);
        for mode in [Dither::FloydSteinberg, Dither::Atkinson] {
            for (w, h) in [(128, 64), (400, 240), (72, 40)] {
                for t in [4, 8, MAX_TILE] {
                    for level in (2..63).step_by(3) {
                        let lit = row_counts(mode, w, h, t, level);
                        let total: u32 = lit.iter().sum();
                        let p = f64::from(total) / (w * h) as f64;
                        let (mean, sd) = (p * w as f64, (w as f64 * p * (1.0 - p)).sqrt().max(1.0));
                        let dev = |y: usize| (f64::from(lit[y]) - mean) / sd;
                        let texture = (6..h - 6).map(|y| dev(y).abs()).fold(3.0, f64::max);
                        by_chance += 3.0 / (h - 12 + 1) as f64;
                        for y in [0, 1, 2] {
                            outside += usize::from(dev(y).abs() > texture);
                            assert!(
                                dev(y).abs() <= texture + 1.0,
                                "{mode:?} {w}x{h} tiles {t} level {level}: row {y} lit {} times against a \
                                 mean of {mean:.1} ({:.2} sd, the interior within {texture:.2}): first {:?}",
                                lit[y],
                                dev(y),
                                &lit[..4],
                            );
                        }
                    }
                }
            }
        }
        assert!(
            outside as f64 <= by_chance,
            "{outside} top rows outside the interior's spread, {by_chance:.1} by chance"
        );
    }

    #[test]
    fn error_diffusion_draws_no_seam_at_the_edges() {
        // A seam is a border column lit more or less often than the field's mean (first-look:
        // columns 0, 1 and 2 lit 22, 42 and 19 times of 64 at a mean of 29). Error diffusion's
        // columns have a texture of their own (regular dot lattices at some grays), so each of
        // the three outermost columns on both sides must stay as near the mean as binomial noise
        // allows (3 standard deviations) or as the interior's columns do, whichever is more.
        for mode in [Dither::FloydSteinberg, Dither::Atkinson] {
            for (w, h) in [(128, 64), (400, 240), (72, 40)] {
                for t in [4, 8, MAX_TILE] {
                    for level in (2..63).step_by(3) {
                        let lit = column_counts(mode, w, h, t, level);
                        let total: u32 = lit.iter().sum();
                        let p = f64::from(total) / (w * h) as f64;
                        let (mean, sd) = (p * h as f64, (h as f64 * p * (1.0 - p)).sqrt().max(1.0));
                        let dev = |x: usize| (f64::from(lit[x]) - mean) / sd;
                        let texture = (6..w - 6).map(|x| dev(x).abs()).fold(3.0, f64::max);
                        for x in [0, 1, 2, w - 3, w - 2, w - 1] {
                            assert!(
                                dev(x).abs() <= texture,
                                "{mode:?} {w}x{h} tiles {t} level {level}: column {x} lit {} times against a \
                                 mean of {mean:.1} ({:.2} sd, the interior within {texture:.2}): first {:?}, \
                                 last {:?}",
                                lit[x],
                                dev(x),
                                &lit[..4],
                                &lit[w - 4..]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn atkinson_mid_gray_tile_pattern() {
        let mut store = [0i16; Carry::len(4)];
        let mut carry = Carry::new(&mut store, 4).unwrap();
        carry.next_band();
        let mut out = [BinaryColor::Off; 16];
        carry.tile(Dither::Atkinson, (0, 0), 4, 4, &[40u8; 16], &mut out);
        // The rows above the image (dithered, not drawn) hand their error on: the tile is lit
        // in proportion to its gray, 10 of 16 at 40 of 64, and no row is all on (row 0 was, with
        // nothing above it).
        assert_eq!(art(4, &out), "##.#\n##.#\n.##.\n.##.\n");
        assert_eq!(out.iter().filter(|p| p.is_on()).count(), 10);
    }

    /// A `w x h` flat field of `level` dithered to four shades by `mode` in `t x t` tiles, as
    /// the render orders them: each pixel's step (0..=3).
    fn gray_steps(mode: Dither, w: usize, h: usize, t: usize, level: u8) -> std::vec::Vec<u8> {
        let mut store = std::vec![0i16; Ditherer::rows_len(mode, w)];
        let mut d = Ditherer::new(mode, w, &mut store).unwrap();
        let mut steps = std::vec![0u8; w * h];
        for y0 in (0..h).step_by(t) {
            d.next_band();
            for x0 in (0..w).step_by(t) {
                let (tw, th) = (t.min(w - x0), t.min(h - y0));
                let mut out = [Gray2::BLACK; MAX_TILE * MAX_TILE];
                d.tile(x0, y0, tw, th, &[level; MAX_TILE * MAX_TILE][..tw * th], &mut out[..tw * th]);
                for (i, px) in out[..tw * th].iter().enumerate() {
                    steps[(y0 + i / tw) * w + x0 + i % tw] = px.step();
                }
            }
        }
        steps
    }

    #[test]
    fn four_shades_keep_every_level_between_its_two_steps() {
        // Every level of 64, in every mode: each pixel is one of the two steps around the
        // level (or the level's own step), and the field's mean is the level within half a
        // level (Floyd-Steinberg; ordered modes within a level, their masks' quantization).
        // Atkinson diffuses 6/8 of each error by design, which pulls a field towards its
        // nearest step: only its steps are checked.
        for mode in [Dither::FloydSteinberg, Dither::Atkinson, Dither::Bayer, Dither::BlueNoise] {
            for level in 0..=LEVELS {
                let (w, h) = (48, 32);
                let steps = gray_steps(mode, w, h, 16, level);
                let exact = f64::from(level) * 3.0 / 64.0;
                let (lo, hi) = (exact.floor() as u8, exact.ceil() as u8);
                assert!(steps.iter().all(|&k| k == lo || k == hi), "{mode:?} level {level}: {steps:?}");
                let mean = steps.iter().map(|&k| f64::from(k)).sum::<f64>() / (w * h) as f64 * 64.0 / 3.0;
                if mode != Dither::Atkinson {
                    assert!((mean - f64::from(level)).abs() <= 1.0, "{mode:?} level {level}: mean {mean}");
                }
            }
        }
    }

    #[test]
    fn four_shades_show_their_own_levels_flat() {
        // The levels the shades stand for (0, 21.3, 42.7, 64 of 64, rounded) come out as one
        // flat step: no dither noise where the panel can show the gray itself.
        for (level, step) in [(0u8, 0u8), (21, 1), (43, 2), (64, 3)] {
            let steps = gray_steps(Dither::FloydSteinberg, 40, 24, 8, level);
            let off = steps.iter().filter(|&&k| k != step).count();
            assert!(off * 50 <= steps.len(), "level {level}: {off} pixels off step {step}");
        }
    }
}
