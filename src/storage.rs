//! Storage: all memory a frame needs, in one place. [`Storage`] holds it in arrays whose
//! capacities are const parameters (heapless style: firmware sizes them at build time);
//! with the `alloc` feature, `HeapStorage` holds the same on the heap, sized at run time by
//! [`Sizes::of`]. Both lend a [`StorageView`] that erases the capacities, so the code that
//! loads a scene ([`crate::load`]), builds its lattice and hands the rest to the render is
//! written once. This module holds memory; it neither parses nor renders.
//!
//! The view is used up in the order the data flows: objects (the scene), then lattices,
//! coordinate lists and the word pool (the lattice's cells and references), then what is
//! left of the pool and the `i16` rows (the render's [`Scratch`]).

use crate::accel::Query;
use crate::lattice::{Lattice, LatticeConfig, LatticeError, LatticeStorage, SubLattice};
use crate::render::frame::Frame;
use crate::render::Scratch;
use crate::scalar::Real;
use crate::scene::{Object, Parts, Scene};
use core::borrow::BorrowMut;

/// How much of each kind of storage a scene and a frame need.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sizes {
    /// Primitives.
    pub objects: usize,
    /// Lattices (world and sub-lattices).
    pub lattices: usize,
    /// Coordinate-list entries.
    pub coords: usize,
    /// `u32` words: the lattice's cells and references, then the render's mailbox (one per
    /// primitive and one per composite).
    pub words: usize,
    /// `i16` entries of the render's rows: error-diffusion carries and the object ids above a
    /// band ([`Frame::scratch_len`]).
    pub rows: usize,
}

impl Sizes {
    /// What `scene` needs to be rendered as `frame`, with a lattice built by `cfg` (`None`:
    /// an accelerator that needs no storage, such as the bounding-box method).
    pub fn of<R: Real>(scene: &Scene<'_, R>, cfg: Option<&LatticeConfig>, frame: &Frame) -> Self {
        let lattice = cfg.map(|c| Lattice::plan(scene, c)).unwrap_or_default();
        Sizes {
            objects: scene.objects.len(),
            lattices: lattice.lattices,
            coords: lattice.coords,
            words: lattice.words() + Query::mailbox_len(scene),
            rows: frame.scratch_len(),
        }
    }

    /// Bytes these sizes take in scalar `R` (saturating: a host checks a limit against it
    /// before allocating).
    pub fn bytes<R>(&self) -> usize {
        [
            self.objects.saturating_mul(size_of::<Object<R>>()),
            self.lattices.saturating_mul(size_of::<SubLattice<R>>()),
            self.coords.saturating_mul(size_of::<R>()),
            self.words.saturating_mul(4),
            self.rows.saturating_mul(2),
        ]
        .into_iter()
        .fold(0, usize::saturating_add)
    }

    /// The larger of each size: storage for either.
    pub fn max(self, o: Sizes) -> Sizes {
        Sizes {
            objects: self.objects.max(o.objects),
            lattices: self.lattices.max(o.lattices),
            coords: self.coords.max(o.coords),
            words: self.words.max(o.words),
            rows: self.rows.max(o.rows),
        }
    }
}

/// All memory a frame needs (see [`Sizes`] for what each part holds), in whatever holds it:
/// arrays ([`Storage`]) or, with the `alloc` feature, vectors (`HeapStorage`). One type, so
/// lending the [`StorageView`] is written once.
#[derive(Debug)]
pub struct Buffers<O, P, L, C, W, S> {
    objects: O,
    /// The scene's composites, materials and lights ([`Parts`]).
    parts: P,
    lattices: L,
    coords: C,
    words: W,
    rows: S,
}

/// All memory a frame needs, with capacities fixed at compile time. It is plain arrays: put
/// it on the stack or in a `static`.
pub type Storage<
    R,
    const OBJECTS: usize,
    const LATTICES: usize,
    const COORDS: usize,
    const WORDS: usize,
    const ROWS: usize,
> = Buffers<[Object<R>; OBJECTS], Parts<R>, [SubLattice<R>; LATTICES], [R; COORDS], [u32; WORDS], [i16; ROWS]>;

/// All memory a frame needs, on the heap, sized at run time (the host's [`Storage`]).
#[cfg(feature = "alloc")]
pub type HeapStorage<R> = Buffers<
    alloc::vec::Vec<Object<R>>,
    Parts<R>,
    alloc::vec::Vec<SubLattice<R>>,
    alloc::vec::Vec<R>,
    alloc::vec::Vec<u32>,
    alloc::vec::Vec<i16>,
>;

impl<O, P, L, C, W, S> Buffers<O, P, L, C, W, S> {
    /// The storage with its capacities erased.
    pub fn view<R: Real>(&mut self) -> StorageView<'_, R>
    where
        O: AsMut<[Object<R>]>,
        P: BorrowMut<Parts<R>>,
        L: AsMut<[SubLattice<R>]>,
        C: AsMut<[R]>,
        W: AsMut<[u32]>,
        S: AsMut<[i16]>,
    {
        StorageView::new(
            self.objects.as_mut(),
            self.parts.borrow_mut(),
            self.lattices.as_mut(),
            self.coords.as_mut(),
            self.words.as_mut(),
            self.rows.as_mut(),
        )
    }

    /// Bytes this storage occupies.
    pub fn bytes<R>(&self) -> usize
    where
        O: AsRef<[Object<R>]>,
        L: AsRef<[SubLattice<R>]>,
        C: AsRef<[R]>,
        W: AsRef<[u32]>,
        S: AsRef<[i16]>,
    {
        size_of_val(self.objects.as_ref())
            + size_of::<Parts<R>>()
            + size_of_val(self.lattices.as_ref())
            + size_of_val(self.coords.as_ref())
            + size_of_val(self.words.as_ref())
            + size_of_val(self.rows.as_ref())
    }
}

impl<R: Real, const O: usize, const G: usize, const C: usize, const W: usize, const S: usize>
    Storage<R, O, G, C, W, S>
{
    /// Empty storage.
    pub fn new() -> Self {
        Buffers {
            objects: [Object::default(); O],
            parts: Parts::new(),
            lattices: [SubLattice::EMPTY; G],
            coords: [R::ZERO; C],
            words: [0; W],
            rows: [0; S],
        }
    }

    /// The capacities as [`Sizes`].
    pub const fn sizes() -> Sizes {
        Sizes { objects: O, lattices: G, coords: C, words: W, rows: S }
    }
}

impl<R: Real, const O: usize, const G: usize, const C: usize, const W: usize, const S: usize> Default
    for Storage<R, O, G, C, W, S>
{
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(feature = "alloc")]
impl<R: Real> HeapStorage<R> {
    /// Storage of exactly `sizes`.
    pub fn new(sizes: Sizes) -> Self {
        use alloc::vec;
        Buffers {
            objects: vec![Object::default(); sizes.objects],
            parts: Parts::new(),
            lattices: vec![SubLattice::EMPTY; sizes.lattices],
            coords: vec![R::ZERO; sizes.coords],
            words: vec![0; sizes.words],
            rows: vec![0; sizes.rows],
        }
    }
}

/// Storage with its capacities erased: the slices of a [`Storage`] or `HeapStorage` (or
/// any the caller owns), used up as a frame is set up.
#[derive(Debug)]
pub struct StorageView<'a, R> {
    objects: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
    rest: FrameStorage<'a, R>,
}

/// The part of a [`StorageView`] that follows the scene: the lattice's storage and the
/// render's scratch.
#[derive(Debug)]
pub struct FrameStorage<'a, R> {
    lattices: &'a mut [SubLattice<R>],
    coords: &'a mut [R],
    words: &'a mut [u32],
    rows: &'a mut [i16],
}

impl<'a, R: Real> StorageView<'a, R> {
    /// A view of caller-owned slices.
    pub fn new(
        objects: &'a mut [Object<R>],
        parts: &'a mut Parts<R>,
        lattices: &'a mut [SubLattice<R>],
        coords: &'a mut [R],
        words: &'a mut [u32],
        rows: &'a mut [i16],
    ) -> Self {
        StorageView { objects, parts, rest: FrameStorage { lattices, coords, words, rows } }
    }

    /// The scene's storage (objects and parts, for a [`crate::SceneBuilder`]) and the rest.
    #[allow(clippy::type_complexity)]
    pub fn split(self) -> ((&'a mut [Object<R>], &'a mut Parts<R>), FrameStorage<'a, R>) {
        ((self.objects, self.parts), self.rest)
    }
}

impl<'a, R: Real> FrameStorage<'a, R> {
    /// Builds the lattice of `scene` with `cfg`; the words it leaves and the rows become the
    /// render's scratch.
    pub fn lattice(
        self,
        scene: &Scene<'_, R>,
        cfg: &LatticeConfig,
    ) -> Result<(Lattice<'a, R>, Scratch<'a>), LatticeError> {
        let storage = LatticeStorage { lattices: self.lattices, coords: self.coords, words: self.words };
        let (lattice, mailbox) = Lattice::build_leaving(scene, cfg, storage)?;
        Ok((lattice, Scratch::new(mailbox, self.rows)))
    }

    /// No lattice (an accelerator that needs no storage): every word is scratch.
    pub fn scratch(self) -> Scratch<'a> {
        Scratch::new(self.words, self.rows)
    }
}
