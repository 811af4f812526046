//! Trace, then dither: the tiles of one core's share traced and kept as gray levels
//! ([`trace_share`], [`KeptTile`]), then dithered band by band in the frame's order
//! ([`dither_band`], [`dither_tiles`]), so two cores can trace a frame whose dither carries error
//! from tile to tile and still draw it bit for bit as [`super::render`] does.

use super::frame::{Frame, RenderError, Share, TileAt};
use super::scratch::Scratch;
use super::tiles::{render_tiles, KeptTile, Nowhere, Out};
use super::Hooks;
use crate::accel::{Accelerator, Stats};
use crate::dither::{Ditherer, Shade, MAX_TILE};
use crate::outline::Apron;
use crate::scalar::Real;
use crate::trace::Tracer;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;

/// The first half of a frame rendered **trace, then dither**: one share's tiles in the frame's
/// band of tile rows, traced and kept ([`KeptTile`]) for [`dither_band`] instead of dithered
/// and drawn: tile `k` of the share in the band (in the order the render visits them) in
/// `kept[k]`; `kept` holds at least [`Frame::tiles_len`] tiles. Unlike [`render_share`](super::render_share),
/// frames whose dithering carries error from tile to tile (Floyd-Steinberg, Atkinson) can be
/// traced in shares this way: the cores trace, and one dithers the finished bands in order.
/// Silhouette lines across a tile's borders need no apron rays here: [`dither_band`] takes
/// them from the neighbours' kept edges (as [`Sampler::side`](crate::sample::Sampler::side) gives them: the same apron
/// [`render`](super::render) finds with its hit-only rays).
///
/// `scratch` needs [`Frame::trace_scratch_len`] rows (no dither carries).
pub fn trace_share<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    kept: &mut [KeptTile],
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<core::convert::Infallible>> {
    if kept.len() < frame.tiles_len(share) {
        return Err(RenderError::ScratchTooSmall { needed: frame.tiles_len(share) });
    }
    render_tiles::<_, _, Nowhere, E>(tracer, frame, share, None, Out::Keep(kept), scratch, hooks)
}

/// The second half of trace, then dither ([`trace_share`]): dithers tile row `ty` of `frame`
/// from its kept tiles (`tile(tx)`: tile `tx` of the row) and draws it into `target`, tile by
/// tile in the order [`render`](super::render) draws them, so bands dithered in order give
/// [`render`](super::render)'s frame
/// bit for bit. The band ends at the first tile `tile` has nothing for. With silhouette lines,
/// `above` (the frame's width of entries) holds what the bottom row of the band above hit and
/// is left holding this band's (shorter storage is refused: `ScratchTooSmall`). The band is
/// drawn in one `fill_contiguous` call (a display then gets it in one transfer, not one per
/// tile), from `band`, at least the frame's width times the tile side of pixels. `ditherer`
/// carries error between bands: make it once per frame ([`Ditherer::new`] over
/// [`Ditherer::rows_len`] entries). [`dither_tiles`] dithers a band in parts.
pub fn dither_band<'l, D: DrawTarget<Color: Shade>>(
    frame: &Frame,
    ty: usize,
    tile: impl Fn(usize) -> Option<&'l KeptTile>,
    (above, band): (&mut [(u16, u16)], &mut [D::Color]),
    ditherer: &mut Ditherer<'_>,
    target: &mut D,
) -> Result<(), RenderError<D::Error>> {
    let mut left = [(0, 0); MAX_TILE];
    dither_tiles(frame, (ty, 0), tile, (above, band, &mut left), ditherer, target).map(|_| ())
}

/// What [`dither_tiles`] keeps between the parts of a band and between bands: the row above
/// the band's hits, the band's pixels and the right column's hits of the last tile dithered.
/// `C` is the panel's pixel ([`Shade`]).
pub type BandRows<'a, C> = (&'a mut [(u16, u16)], &'a mut [C], &'a mut [(u16, u16); MAX_TILE]);

/// [`dither_band`] in parts, as the tiles of a band come in: dithers tile row `ty` of `frame`
/// from tile `from` on, as far as `tile` has them (`tile(tx)`: tile `tx` of the row, `None`
/// where the part ends), and draws those tiles in one `fill_contiguous` call. Returns the
/// first tile it did not dither (the row's tile count once the band is done): the next call's
/// `from`. A band dithered part after part, from tile 0 on and each part where the last
/// ended, is bit for bit the band [`dither_band`] draws. `left` holds, between the parts, the
/// right column's hits of the last tile dithered (the silhouette lines' apron); `above` and
/// `band` are as for [`dither_band`].
pub fn dither_tiles<'l, D: DrawTarget<Color: Shade>>(
    frame: &Frame,
    (ty, from): (usize, usize),
    tile: impl Fn(usize) -> Option<&'l KeptTile>,
    (above, band, left): BandRows<'_, D::Color>,
    ditherer: &mut Ditherer<'_>,
    target: &mut D,
) -> Result<usize, RenderError<D::Error>> {
    let grid = frame.grid();
    let (t, w, h) = (grid.t, grid.w, grid.h);
    if frame.outline && above.len() < w {
        return Err(RenderError::ScratchTooSmall { needed: w });
    }
    let rows = t.min(h.saturating_sub(ty * t));
    let Some(band) = band.get_mut(..w * rows) else {
        return Err(RenderError::ScratchTooSmall { needed: w * rows });
    };
    let (tiles, start) = (grid.tiles().0, from * t);
    let mut bits = [D::Color::DARK; MAX_TILE * MAX_TILE];
    let mut levels = [0u8; MAX_TILE * MAX_TILE];
    if from == 0 {
        ditherer.next_band();
    }
    let mut tx = from;
    while tx < tiles {
        let TileAt { x0, y0, tw, th, .. } = grid.at(tx, ty);
        let Some(kept) = tile(tx) else { break };
        levels[..tw * th].copy_from_slice(&kept.levels[..tw * th]);
        if frame.outline {
            let up = above.get(x0..x0 + tw).filter(|_| ty > 0);
            let apron = Apron { left: Some(&left[..th]).filter(|_| tx > 0), up };
            crate::outline::apron(tw, th, &kept.left[..th], &kept.top[..tw], apron, &mut levels[..tw * th]);
            if let Some(row) = above.get_mut(x0..x0 + tw) {
                row.copy_from_slice(&kept.bottom[..tw]);
            }
            left[..th].copy_from_slice(&kept.right[..th]);
        }
        ditherer.tile(x0, y0, tw, th, &levels[..tw * th], &mut bits);
        for (y, row) in bits[..tw * th].chunks(tw).enumerate() {
            band[y * w + x0..y * w + x0 + tw].copy_from_slice(row);
        }
        tx += 1;
    }
    let end = (tx * t).min(w);
    if end <= start {
        return Ok(tx);
    }
    // The part, row by row: a whole band as one slice (the common case, and the cheapest
    // iterator to draw from).
    let area = Rectangle::new(Point::new(start as i32, (ty * t) as i32), Size::new((end - start) as u32, rows as u32));
    let drawn = if end - start == w {
        target.fill_contiguous(&area, band.iter().copied())
    } else {
        target.fill_contiguous(&area, band.chunks(w).flat_map(|row| row[start..end].iter().copied()))
    };
    drawn.map(|()| tx).map_err(RenderError::Draw)
}
