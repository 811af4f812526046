//! Tiles: the frame is rendered one small tile at a time into a fixed buffer, dithered and
//! handed to an `embedded_graphics` draw target in one `fill_contiguous` call. No full-frame
//! buffer exists; between tiles a hook reports progress and may cancel.
//!
//! A frame can also be rendered **progressively** ([`render_pass`]), the paper's patterning
//! turned into time: pass 8 traces one ray per 8x8 block and shows it as the block, passes 4
//! and 2 add the rays that make 4x4 and 2x2 blocks, and pass 1 completes the frame with the
//! frame's own sampling. Every ray a pass traces on the 2x2 grid is kept ([`Traced`]) and
//! reused by the passes after it, so no ray is traced twice and the last pass draws exactly the
//! frame [`render`] draws.
//!
//! Rooms: `frame` (the frame, its share, its tile grid and its checks), `tiles` (the tile loop
//! every render runs, in named steps), `progressive` (the passes) and `bands` (trace, then
//! dither: how two cores share a frame).

mod bands;
pub(crate) mod cull;
pub(crate) mod frame;
mod pass;
mod progressive;
mod scratch;
mod tiles;

pub use crate::sample::{level, Hits, Sampling, Shot};
pub use bands::{dither_band, dither_tiles, trace_share, BandRows};
pub use frame::{Frame, RenderError, Share, TileGrid, ViewRefused};
pub use pass::Traced;
pub use progressive::{render_pass, trace_pass};
#[cfg(feature = "alloc")]
pub use scratch::HeapScratch;
pub use scratch::Scratch;
pub use tiles::KeptTile;

use crate::accel::{Accelerator, Stats};
use crate::dither::Shade;
use crate::scalar::Real;
use crate::trace::Tracer;
use embedded_graphics_core::draw_target::DrawTarget;
use tiles::{render_tiles, Out};

/// Callbacks between tiles, and one inside them.
pub trait Hooks {
    /// A finished tile of gray levels (0..=64) at `(x, y)`, `w x h`, row-major.
    fn gray_tile(&mut self, _x: u16, _y: u16, _w: u16, _h: u16, _levels: &[u8]) {}
    /// Called after each eye sample a tile traces (with the rays it spawned): progress finer
    /// than a tile, for a board's watchdog, as one tile of a heavy scene can take seconds.
    #[inline(always)]
    fn sampled(&mut self) {}
    /// Called after each tile; return false to cancel the render.
    fn progress(&mut self, _done: u32, _total: u32) -> bool {
        true
    }
}

/// Hooks that do nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoHooks;
impl Hooks for NoHooks {}

/// Renders a frame tile by tile into `target`, returning the statistics.
///
/// `scratch` comes from the storage the scene was loaded into ([`crate::storage`]); its rows
/// must hold [`Frame::scratch_len`] entries (none for Bayer or patterning with one ray per
/// pixel).
pub fn render<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color: Shade>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    render_share(tracer, frame, Share::ALL, target, scratch, hooks)
}

/// [`render`] of one share of the frame's tiles (one core's, when cores split a frame; the
/// frame stays what the picture is, the share says which of its tiles this call draws).
///
/// Kept out of line so the firmware report can check that nothing it calls uses floating point
/// when the scalar is fixed point.
#[inline(never)]
pub fn render_share<R: Real, A: Accelerator<R> + ?Sized, D: DrawTarget<Color: Shade>, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    frame: &Frame,
    share: Share,
    target: &mut D,
    scratch: &mut Scratch<'_>,
    hooks: &mut impl Hooks,
) -> Result<Stats, RenderError<D::Error>> {
    render_tiles(tracer, frame, share, None, Out::Draw(target), scratch, hooks)
}
