//! The tile scheduler of trace, then dither on two cores: which tile each core traces next,
//! and which bands core 0 may dither.
//!
//! Each tile being traced or waiting for its dithering has one slot of storage (what it keeps
//! for its dithering, and in a progressive build its rays between passes). The slots are a ring
//! of whole bands: tile `k` has slot `k % slots`, so a frame taller than the ring reuses a
//! band's slots once core 0 has dithered it (a 400x240 frame's 375 tiles in three bands' worth);
//! a progressive frame, whose tiles keep rays between passes, needs a slot per tile. A slot is
//! *free* (to be traced), then *done* (to be dithered), then free again for the next tile that
//! maps to it, or the next progressive pass. The cores take tiles one at a
//! time in raster order, pass after pass ([`Schedule::take`]); core 0 takes a band's done slots
//! when all of them are done ([`Schedule::ready`]) and frees them once it has dithered them
//! ([`Schedule::free`]). Every step is one short critical section.

use core::cell::RefCell;
use critical_section::Mutex;
use lattice_rt::render::RenderError;
use lattice_rt::{Frame, KeptTile, Scratch, Share, Stats, Traced};

/// What tracing one tile gave.
pub type Traced1 = Result<Stats, RenderError<core::convert::Infallible>>;

/// Traces one tile of a frame: pass index `p`, the band it is in, the share that holds it
/// alone, what it keeps, and the rays it keeps between progressive passes.
pub type TraceTile<'a> =
    dyn FnMut(&mut Scratch<'_>, usize, Frame, Share, &mut [KeptTile], &mut [Traced]) -> Traced1 + 'a;

/// One tile's storage in trace, then dither: what it keeps for its dithering, and in a
/// progressive build its rays between passes (a build without passes keeps the board's arrays
/// of slots at one pointer each: they are on core 0's stack).
pub struct Slot<'l, const RAYS: usize> {
    kept: &'l mut KeptTile,
    #[cfg(feature = "progressive")]
    rays: &'l mut [Traced; RAYS],
}

impl<'l, const RAYS: usize> Slot<'l, RAYS> {
    /// The slot of `kept` and `rays`.
    #[allow(unused_variables)]
    fn new(kept: &'l mut KeptTile, rays: &'l mut [Traced; RAYS]) -> Self {
        Slot {
            kept,
            #[cfg(feature = "progressive")]
            rays,
        }
    }

    /// What the tile keeps for its dithering.
    pub fn kept(&self) -> &KeptTile {
        self.kept
    }

    /// What the tile keeps and its rays (none without passes).
    fn parts(&mut self) -> (&mut KeptTile, &mut [Traced]) {
        #[cfg(feature = "progressive")]
        return (&mut *self.kept, &mut self.rays[..]);
        #[cfg(not(feature = "progressive"))]
        (&mut *self.kept, &mut [])
    }
}

/// What a core gets when it asks for the next tile: the tile (once traced, what tracing it
/// gave), or why there is none.
pub enum Take<T> {
    /// The next tile, or what tracing it gave.
    Tile(T),
    /// The next tile's last pass is not dithered yet: ask again.
    Wait,
    /// Every tile of every pass is taken.
    Finished,
}

/// The slots (`TILES` of them at most): free to trace, done to dither, and the next tile to
/// trace.
struct Board<'l, const TILES: usize, const RAYS: usize> {
    free: [Option<Slot<'l, RAYS>>; TILES],
    done: [Option<Slot<'l, RAYS>>; TILES],
    next: usize,
}

/// The schedule of one frame's `passes` passes over its tiles, at most `TILES_X` across, in a
/// ring of at most `TILES` slots.
pub struct Schedule<'l, const TILES: usize, const TILES_X: usize, const RAYS: usize> {
    board: Mutex<RefCell<Board<'l, TILES, RAYS>>>,
    frame: Frame,
    /// The frame's tiles.
    tiles: usize,
    tiles_x: usize,
    /// The slots in the ring: whole bands.
    slots: usize,
    passes: usize,
}

impl<'l, const TILES: usize, const TILES_X: usize, const RAYS: usize> Schedule<'l, TILES, TILES_X, RAYS> {
    /// The schedule of `frame` in `passes` passes, its tiles' slots in `kept` and `rays` (whole
    /// bands of them: as many as fit in `TILES` and both lengths). `None` when not one band fits,
    /// or when a progressive frame (more than one pass) has fewer slots than tiles.
    pub fn new(frame: &Frame, passes: usize, kept: &'l mut [KeptTile], rays: &'l mut [[Traced; RAYS]]) -> Option<Self> {
        let (tiles_x, down) = frame.grid().tiles();
        if tiles_x > TILES_X {
            return None;
        }
        let tiles = tiles_x * down;
        let room = TILES.min(kept.len()).min(rays.len());
        let slots = (room / tiles_x * tiles_x).min(tiles);
        if slots == 0 || (passes > 1 && slots < tiles) {
            return None;
        }
        let mut board = Board { free: [const { None }; TILES], done: [const { None }; TILES], next: 0 };
        for (slot, (kept, rays)) in board.free.iter_mut().zip(kept.iter_mut().zip(rays.iter_mut())).take(slots) {
            *slot = Some(Slot::new(kept, rays));
        }
        Some(Schedule { board: Mutex::new(RefCell::new(board)), frame: *frame, tiles, tiles_x, slots, passes })
    }

    /// The first slot of band `band`'s tiles (a band's slots follow each other).
    fn band_slot(&self, band: usize) -> usize {
        band * self.tiles_x % self.slots
    }

    /// Tiles across the frame.
    pub fn tiles_x(&self) -> usize {
        self.tiles_x
    }

    /// Bands of tiles down the frame.
    pub fn bands(&self) -> usize {
        self.tiles.div_ceil(self.tiles_x)
    }

    /// Takes the next tile if it is free, traces it with `trace` and marks it done (handed over
    /// even when the trace failed, so no core waits for it).
    pub fn take(&self, scratch: &mut Scratch<'_>, trace: &mut TraceTile<'_>) -> Take<Traced1> {
        let taken = critical_section::with(|cs| {
            let mut b = self.board.borrow(cs).borrow_mut();
            let i = b.next;
            if i >= self.passes * self.tiles {
                return Take::Finished;
            }
            match b.free[i % self.tiles % self.slots].take() {
                Some(slot) => {
                    b.next += 1;
                    Take::Tile((i / self.tiles, i % self.tiles, slot))
                }
                None => Take::Wait,
            }
        });
        let (p, k, mut slot) = match taken {
            Take::Tile(tile) => tile,
            Take::Wait => return Take::Wait,
            Take::Finished => return Take::Finished,
        };
        let (tx, ty) = (k % self.tiles_x, k / self.tiles_x);
        let band = Frame { rows: (ty as u16, ty as u16 + 1), ..self.frame };
        let (kept, rays) = slot.parts();
        let traced = trace(scratch, p, band, Share::single(tx, ty, self.tiles_x), core::slice::from_mut(kept), rays);
        critical_section::with(|cs| self.board.borrow(cs).borrow_mut().done[k % self.slots] = Some(slot));
        Take::Tile(traced)
    }

    /// The done slots of band `band` from tile `from` on, taken for dithering: when all of the
    /// band's tiles from there are done, or with `parts` when any are (the frame's last band
    /// goes in parts, so what is left on the bus once the last tile is traced is its part).
    pub fn ready(&self, band: usize, from: usize, parts: bool) -> Option<[Option<Slot<'l, RAYS>>; TILES_X]> {
        critical_section::with(|cs| {
            let mut b = self.board.borrow(cs).borrow_mut();
            let first = self.band_slot(band);
            let row = &mut b.done[first + from..first + self.tiles_x];
            let traced = row.iter().take_while(|r| r.is_some()).count();
            if traced == 0 || (traced < row.len() && !parts) {
                return None;
            }
            let mut out = [const { None }; TILES_X];
            out.iter_mut().zip(row.iter_mut()).take(traced).for_each(|(o, r)| *o = r.take());
            Some(out)
        })
    }

    /// Frees the slots of `part` (band `band` from tile `from` on) for the next pass.
    pub fn free(&self, band: usize, from: usize, part: &mut [Option<Slot<'l, RAYS>>; TILES_X]) {
        critical_section::with(|cs| {
            let mut b = self.board.borrow(cs).borrow_mut();
            let first = self.band_slot(band);
            for (tx, slot) in part.iter_mut().enumerate() {
                if let Some(slot) = slot.take() {
                    b.free[first + from + tx] = Some(slot);
                }
            }
        });
    }

    /// Marks every tile taken: core 0 stopped at an error, so no tile of a later pass will be
    /// freed, and a core waiting for one must stop waiting.
    pub fn stop(&self) {
        critical_section::with(|cs| self.board.borrow(cs).borrow_mut().next = usize::MAX);
    }
}
