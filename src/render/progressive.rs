//! Progressive frames: pass 8 traces one ray per 8x8 block and shows it as the block, passes 4
//! and 2 add the rays that make 4x4 and 2x2 blocks, and pass 1 completes the frame with the
//! frame's own sampling, reusing every ray the earlier passes traced ([`Traced`]).

use super::frame::{Frame, RenderError, Share};
use super::pass::{Pass, Traced};
use super::scratch::Scratch;
use super::tiles::{render_tiles, KeptTile, Nowhere, Out};
use super::Hooks;
use crate::accel::{Accelerator, Stats};
use crate::dither::Shade;
use crate::scalar::Real;
use crate::trace::Tracer;
use embedded_graphics_core::draw_target::DrawTarget;

/// One pass of a progressive frame ([`Frame::progressive`]) over one share of its tiles: pass
/// 8, 4 or 2 shows one ray per block of that side (the ray through the block's top-left pixel,
/// traced now or by an earlier pass), pass 1 the finished frame, which is the frame [`render`](super::render)
/// draws. Run the passes in the order 8, 4, 2, 1 with the same `traced` storage (at least
/// [`Frame::traced_len`] entries; the rays each pass traces are kept there for the next).
/// Returns the statistics of this pass alone.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub fn render_pass<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color: Shade>, const E: u8>(
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
