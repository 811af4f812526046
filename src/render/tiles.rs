//! The tile loop every render runs: per tile, which objects its eye rays can hit (cull), its
//! gray levels (sample), tone and silhouette lines (finish), then dithered and drawn or kept
//! (emit).

use super::frame::{check, resolves, Frame, RenderError, Share, TileAt};
use super::pass::{pass_tile, Pass};
use super::scratch::Scratch;
use super::Hooks;
use crate::accel::{Accelerator, Query, Stats};
use crate::dither::{Dither, Ditherer, Shade, MAX_TILE};
use crate::outline::Apron;
use crate::sample::{Hits, Sampler, Sampling, Shot};
use crate::scalar::Real;
use crate::trace::Tracer;
use crate::trace::Work;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;

/// Where the tile loop puts a finished tile: dithered and drawn, or kept as gray levels.
pub(super) enum Out<'o, D> {
    Draw(&'o mut D),
    Keep(&'o mut [KeptTile]),
}

/// The draw target of a render that draws nothing ([`trace_share`]).
pub(super) struct Nowhere;

impl embedded_graphics_core::geometry::OriginDimensions for Nowhere {
    fn size(&self) -> Size {
        Size::zero()
    }
}

impl DrawTarget for Nowhere {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;
    fn draw_iter<I: IntoIterator<Item = embedded_graphics_core::Pixel<BinaryColor>>>(
        &mut self,
        _: I,
    ) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// The tile loop of [`render_share`](super::render_share), [`trace_share`](super::trace_share)
/// and the progressive passes: the frame checked, the scratch cut into its rows, then per tile
/// of the share in the frame's band of rows, [`cull`], [`sample`], [`finish`] and [`emit`].
pub(super) fn render_tiles<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color: Shade>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    mut pass: Option<Pass<'_>>,
    mut out: Out<'_, D>,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    let keep = matches!(out, Out::Keep(_));
    check(frame, share, !keep)?;
    let tracer = &tracer.with_cutoff_at_least(frame.cutoff);
    resolves(tracer.scene().camera(), frame)?;
    // Kept levels are dithered later (by `dither_band`): the trace needs no carries, and an
    // ordered mode, which needs no storage, stands in for the frame's dither.
    let (mut dither, mut sampler) = rows(frame, if keep { Dither::Bayer } else { frame.dither }, scratch.rows)?;
    let grid = frame.grid();
    let culling = Culling::new(tracer.scene(), frame, scratch.cover);
    let need = Query::mailbox_len(tracer.scene()).min(scratch.mailbox.len());
    let mut work = Work::new(&mut scratch.mailbox[..need]);
    let ((tiles_x, _), (first, end)) = (grid.tiles(), grid.rows(frame.rows));
    let total = share.tiles_in(tiles_x, (first, end)) as u32;
    // Tiles of this share before the band range: their traced samples come first.
    let skipped = share.tiles_in(tiles_x, (0, first));
    let looks = Looks {
        // The outline is drawn on finished frames: a progressive frame's last pass, not its
        // previews.
        outline: frame.outline && pass.as_ref().is_none_or(|p| p.n == 1),
        // Only the outline and two-level sampling read depths: a frame without either keys none.
        keys: frame.outline || matches!(frame.sampling, Sampling::Adaptive { coarse: true, .. }),
        keep,
    };
    let (w4, h4) = (4 * grid.w as i32, 4 * grid.h as i32);
    let mut eyes = crate::camera::EyeRayCache::<R>::new(tracer.scene().camera(), w4, h4);
    let mut tile =
        TileWork { levels: [0; MAX_TILE * MAX_TILE], hits: Hits::new(), bits: [D::Color::DARK; MAX_TILE * MAX_TILE] };
    let (mut done, mut kept) = (0, 0);
    for ty in first..end {
        dither.next_band();
        sampler.next_band();
        // Remembered occluders are forgotten at every band of tiles, so a band renders the same
        // whichever bands a core or thread rendered before it.
        work.forget_occluders();
        for tx in (0..tiles_x).filter(|&tx| share.holds(tx, ty)) {
            let at = grid.at(tx, ty);
            let candidates = culling.tile(tracer.scene(), &mut work, (tx, ty), at);
            let traced = pass.as_mut().map(|Pass { n, traced, whole_share }| {
                let k = if *whole_share { skipped } else { 0 } + done as usize;
                let per_tile = (at.t / 2) * (at.t / 2);
                (*n, &mut traced[k * per_tile..(k + 1) * per_tile])
            });
            let mut ray = Eye { tracer, work: &mut work, cache: &mut eyes };
            sample(&mut ray, &mut sampler, at, (candidates, looks), traced, &mut tile, hooks);
            hooks.gray_tile(at.x0 as u16, at.y0 as u16, at.tw as u16, at.th as u16, &tile.levels[..at.tw * at.th]);
            // What a kept tile keeps of its sides (a drawn one keeps none: the compiler leaves it out).
            let mut sides = KeptTile::EMPTY;
            finish(&mut ray, &sampler, at, (frame, looks), (&mut tile, &mut sides));
            emit(&mut out, &mut dither, at, (&mut tile, &sides), &mut kept)?;
            done += 1;
            if !hooks.progress(done, total) {
                return Err(RenderError::Cancelled);
            }
        }
    }
    Ok(work.query.stats)
}

/// The dither and the sampler of a render, their rows cut from the scratch's. Inlined, so a
/// firmware's constant frame folds its modes into the tile loop (the code of the others left out).
#[inline(always)]
fn rows<'s, E>(
    frame: &Frame,
    mode: Dither,
    rows: &'s mut [i16],
) -> Result<(Ditherer<'s>, Sampler<'s>), RenderError<E>> {
    let w = frame.width as usize;
    let carries_len = Ditherer::rows_len(mode, w);
    let needed = carries_len + Sampler::rows_len(frame.sampling, frame.dither.block(), w);
    let too_small = || RenderError::ScratchTooSmall { needed };
    let rows = rows.get_mut(..needed).ok_or_else(too_small)?;
    let (carries, above) = rows.split_at_mut(carries_len);
    let dither = Ditherer::new(mode, w, carries).ok_or_else(too_small)?;
    let sampler = Sampler::new(frame.sampling, frame.dither.block(), w, above).ok_or_else(too_small)?;
    Ok((dither, sampler))
}

/// What a render draws beyond the gray levels: silhouette lines (`outline`), the depth keys the
/// lines and two-level sampling read (`keys`), and whether tiles are kept for a later dither.
#[derive(Clone, Copy)]
struct Looks {
    outline: bool,
    keys: bool,
    keep: bool,
}

/// A tile's working buffers: its gray levels, what its pixels hit, and its pixels once dithered.
struct TileWork<C> {
    levels: [u8; MAX_TILE * MAX_TILE],
    hits: Hits,
    bits: [C; MAX_TILE * MAX_TILE],
}

/// The eye rays of a render: each made by the camera's cache and traced with its window
/// position.
struct Eye<'e, 'q, 'c, 'a, 'b, R, A: ?Sized, const E: u8> {
    tracer: &'e Tracer<'a, 'b, R, A, E>,
    work: &'e mut Work<'q>,
    cache: &'e mut crate::camera::EyeRayCache<'c, R>,
}

impl<R: Real, A: Accelerator<R> + ?Sized, const E: u8> Eye<'_, '_, '_, '_, '_, R, A, E> {
    /// The eye ray through `(sx, sy)` (quarter pixels) and its window position.
    #[inline(always)]
    fn ray(&mut self, sx: usize, sy: usize) -> (crate::math::Ray<R>, Option<[i32; 2]>) {
        let (uv, ray) = self.cache.at(sx as i32, sy as i32);
        (ray, Some(uv))
    }
}

/// Which objects a tile's eye rays can hit: a mask of the first 64 ([`super::cull::tiles`]), or
/// past 64 objects a list per tile when the scratch has room for the lists.
struct Culling<'c> {
    tiling: super::cull::tiles::Tiling,
    /// Whether the scene lists its objects per tile (more than 64 of them).
    many: bool,
    /// Whether the lists were counted (room for them in the scratch).
    counted: bool,
    cover: &'c [u32],
    block: usize,
    size: (i32, i32),
}

impl<'c> Culling<'c> {
    /// For `frame` of `scene`, listing into `cover` when the scene needs lists.
    fn new<R: Real>(scene: &crate::scene::Scene<'_, R>, frame: &Frame, cover: &'c mut [u32]) -> Self {
        let (t, block) = (frame.tile as usize, frame.dither.block() as usize);
        let (w, h) = (frame.width as usize, frame.height as usize);
        let tiling = super::cull::tiles::Tiling { t, size: (w, h), margin: block };
        let many = cfg!(feature = "tile-lists") && super::cull::tiles::lists(scene.objects().len());
        let counted = many && tiling.count(scene, (frame.rows.0 as usize, frame.rows.1 as usize), cover);
        Culling { tiling, many, counted, cover, block, size: (4 * w as i32, 4 * h as i32) }
    }

    /// Step one of a tile, cull: tells the tracer's work the objects the tile's eye rays can hit, and
    /// returns them as a mask (`u64::MAX`: listed, or past 64 objects).
    #[inline(always)]
    fn tile<R: Real>(
        &self,
        scene: &crate::scene::Scene<'_, R>,
        work: &mut Work<'c>,
        (tx, ty): (usize, usize),
        at: TileAt,
    ) -> u64 {
        if self.many {
            work.set_eye_list(if self.counted { self.tiling.list(self.cover, (tx, ty)) } else { None });
            u64::MAX
        } else {
            let c = super::cull::tiles::tile_candidates(scene, (at.x0, at.tw), (at.y0, at.th), self.block, self.size);
            work.set_eye_candidates(c);
            c
        }
    }
}

/// Step two, sample: the tile's gray levels and hits, by the frame's sampling, or by a
/// progressive pass (`traced`: which pass, and the tile's kept rays).
#[inline(always)]
fn sample<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    eye: &mut Eye<'_, '_, '_, '_, '_, R, A, E>,
    sampler: &mut Sampler<'_>,
    at: TileAt,
    (candidates, looks): (u64, Looks),
    traced: Option<(u8, &mut [super::Traced])>,
    tile: &mut TileWork<impl Shade>,
    hooks: &mut impl Hooks,
) {
    let tracer = eye.tracer;
    let size = eye.cache.size();
    let mut alone = |xs: [usize; 2], ys: [usize; 2], id: u16, far: u16| {
        super::cull::block::alone(tracer, candidates, (at.x0, at.y0), (xs, ys), id, far, size)
    };
    let mut shoot = |sx: usize, sy: usize| -> Shot<R> {
        let (ray, uv) = eye.ray(sx, sy);
        let (v, id, depth) = tracer.eye_sample(ray, uv, eye.work);
        hooks.sampled();
        (v, id as u16, if looks.keys { depth.depth_key() } else { u16::MAX })
    };
    let TileWork { levels, hits, .. } = tile;
    match traced {
        None => sampler.tile(at.x0, at.y0, at.tw, at.th, &mut shoot, &mut alone, levels, hits),
        Some((n, kept)) => pass_tile(n, sampler, at, kept, &mut shoot, &mut alone, levels, hits),
    }
}

/// Step three, finish: the tone curve, then the silhouette lines (inside the tile and across its
/// borders, or for a kept tile inside it, its sides kept for the dither).
#[inline(always)]
fn finish<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    eye: &mut Eye<'_, '_, '_, '_, '_, R, A, E>,
    sampler: &Sampler<'_>,
    at: TileAt,
    (frame, looks): (&Frame, Looks),
    (tile, sides): (&mut TileWork<impl Shade>, &mut KeptTile),
) {
    let TileAt { x0, y0, tw, th, .. } = at;
    let TileWork { levels, hits, .. } = tile;
    let levels = &mut levels[..tw * th];
    if !frame.tone.is_linear() {
        levels.iter_mut().for_each(|l| *l = frame.tone.apply(*l));
    }
    if !looks.outline {
        return;
    }
    // The apron: what the eye rays through the column left of the tile and the row above it hit
    // (the tile's eye candidates cover them: they are a pixel away).
    let mut probe = |x: usize, y: usize| -> (u16, u16) {
        let (ray, uv) = eye.ray(4 * x + 2, 4 * y + 2);
        let (id, depth) = eye.tracer.eye_hit(ray, uv, eye.work);
        (id as u16, depth.depth_key())
    };
    if !looks.keep {
        outline_tile(at, sampler, &mut probe, hits, levels);
        return;
    }
    // Lines across the borders are drawn when the band is dithered, from the sides kept here: no
    // apron rays (2x2 grids and pattern blocks alone trace their right column's and bottom row's
    // pixels again, through the centres).
    let hit = |x: usize, y: usize| (hits.object[y * tw + x], hits.depth[y * tw + x]);
    let mut exact =
        |x: usize, y: usize| if sampler.exact(x, y, tw, th, hits) { hit(x, y) } else { probe(x0 + x, y0 + y) };
    (0..th).for_each(|y| sides.left[y] = hit(0, y));
    (0..tw).for_each(|x| sides.top[x] = hit(x, 0));
    sampler.side(th, |y| exact(tw - 1, y), &mut sides.right);
    sampler.side(tw, |x| exact(x, th - 1), &mut sides.bottom);
    crate::outline::tile(tw, th, hits, Apron { left: None, up: None }, levels);
}

/// Step four, emit: the tile dithered and drawn, or kept (as tile `kept`, which then counts it).
#[inline(always)]
fn emit<D: DrawTarget<Color: Shade>>(
    out: &mut Out<'_, D>,
    dither: &mut Ditherer<'_>,
    at: TileAt,
    (tile, sides): (&mut TileWork<D::Color>, &KeptTile),
    kept: &mut usize,
) -> Result<(), RenderError<D::Error>> {
    let TileAt { x0, y0, tw, th, .. } = at;
    let n = tw * th;
    match out {
        Out::Keep(store) => {
            let stored = &mut store[*kept];
            *stored = *sides;
            stored.levels[..n].copy_from_slice(&tile.levels[..n]);
            *kept += 1;
        }
        Out::Draw(target) => {
            let TileWork { levels, bits, .. } = tile;
            dither.tile(x0, y0, tw, th, &levels[..n], bits);
            let area = Rectangle::new(Point::new(x0 as i32, y0 as i32), Size::new(tw as u32, th as u32));
            target.fill_contiguous(&area, bits[..n].iter().copied()).map_err(RenderError::Draw)?;
        }
    }
    Ok(())
}

/// Silhouette lines on a tile's `levels`: its own `hits`, and its apron: the right column of
/// the tile left of it and the bottom row of the tile above, as those tiles keep their sides
/// ([`Sampler::side`]), from what `probe` answers (the eye ray through a pixel's centre).
fn outline_tile(
    at: TileAt,
    sampler: &Sampler<'_>,
    probe: &mut impl FnMut(usize, usize) -> (u16, u16),
    hits: &Hits,
    levels: &mut [u8],
) {
    let TileAt { x0, y0, tw, th, .. } = at;
    let (mut left, mut up) = ([(0u16, 0u16); MAX_TILE], [(0u16, 0u16); MAX_TILE]);
    if x0 > 0 {
        sampler.side(th, |y| probe(x0 - 1, y0 + y), &mut left);
    }
    if y0 > 0 {
        sampler.side(tw, |x| probe(x0 + x, y0 - 1), &mut up);
    }
    let apron = Apron { left: (x0 > 0).then_some(&left[..th]), up: (y0 > 0).then_some(&up[..tw]) };
    crate::outline::tile(tw, th, hits, apron, levels);
}

/// What trace, then dither keeps of a traced tile until it is dithered ([`trace_share`](super::trace_share),
/// [`dither_band`](super::dither_band)): its gray levels (tone curve and the silhouette lines inside it applied),
/// and for the lines across its borders what its pixels hit (object and depth key) along its
/// four sides: the left column and top row as sampled, and the right column and bottom row as
/// the apron of the tiles right of it and below takes them
/// ([`Sampler::side`](crate::sample::Sampler::side): the eye rays
/// through their centres, or with adaptive sampling the fill between two traced pixels that
/// hit the same object).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeptTile {
    /// Gray levels, row-major, `tw * th` of them.
    pub levels: [u8; MAX_TILE * MAX_TILE],
    /// The left column's hits, one per tile row.
    pub left: [(u16, u16); MAX_TILE],
    /// The top row's hits, one per tile column.
    pub top: [(u16, u16); MAX_TILE],
    /// The right column's rays through the centres, one per tile row.
    pub right: [(u16, u16); MAX_TILE],
    /// The bottom row's rays through the centres, one per tile column.
    pub bottom: [(u16, u16); MAX_TILE],
}

impl KeptTile {
    /// Nothing kept yet.
    pub const EMPTY: KeptTile = KeptTile {
        levels: [0; MAX_TILE * MAX_TILE],
        left: [(0, 0); MAX_TILE],
        top: [(0, 0); MAX_TILE],
        right: [(0, 0); MAX_TILE],
        bottom: [(0, 0); MAX_TILE],
    };
}

impl Default for KeptTile {
    fn default() -> Self {
        Self::EMPTY
    }
}
