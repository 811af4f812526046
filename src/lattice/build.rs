//! Building a lattice into caller-provided storage: coordinate lists, then cells and references
//! in two passes (count, then fill).

use super::plan::{axis_planes, lattice_bounds, lattice_resolution};
use super::{for_each_item, index, locate, Lattice, LatticeConfig, SubLattice};
use crate::math::Aabb;
use crate::scalar::Real;
use crate::scene::Scene;
use core::fmt;

/// Caller-provided storage for a lattice.
#[derive(Debug)]
pub struct LatticeStorage<'a, R> {
    /// One entry per lattice (world + one per composite).
    pub lattices: &'a mut [SubLattice<R>],
    /// All coordinate lists, concatenated.
    pub coords: &'a mut [R],
    /// Cells and references in one pool: per cell the index of its first reference (one
    /// extra entry at the end), then the references (object indices, or `SUB_FLAG |
    /// composite index`). Words beyond those are left to the caller ([`Lattice::build_leaving`]).
    pub words: &'a mut [u32],
}
/// A storage slice too small for the lattice.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatticeError {
    /// Which storage ran out ("lattices", "coords", "cells", "refs"), or "budget" when no
    /// lattice fits [`LatticeConfig::budget`] (then counted in bytes).
    pub capacity: &'static str,
    /// Entries needed.
    pub needed: usize,
    /// Entries available.
    pub available: usize,
}

impl fmt::Display for LatticeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "lattice capacity `{}` too small: {} {} needed, {} available",
            self.capacity,
            self.needed,
            if self.capacity == "budget" { "bytes" } else { "entries" },
            self.available
        )
    }
}

impl core::error::Error for LatticeError {}
/// Cell index range `[lo, hi]` per axis overlapped by a box.
fn cell_range<R: Real>(coords: &[R], g: &SubLattice<R>, b: &Aabb<R>) -> [(usize, usize); 3] {
    [0, 1, 2].map(|a| {
        let s = g.coord_start[a] as usize;
        let c = &coords[s..s + g.n[a] as usize + 1];
        (locate(c, b.min.axis(a)), locate(c, b.max.axis(a)))
    })
}
impl<'a, R: Real> Lattice<'a, R> {
    /// Builds the lattice into `storage`.
    pub fn build(scene: &Scene<'_, R>, cfg: &LatticeConfig, storage: LatticeStorage<'a, R>) -> Result<Self, LatticeError> {
        Self::build_leaving(scene, cfg, storage).map(|(lattice, _)| lattice)
    }

    /// Builds the lattice into `storage` and returns the words it left unused (the storage
    /// module hands them to the render as its scratch).
    pub fn build_leaving(
        scene: &Scene<'_, R>,
        cfg: &LatticeConfig,
        storage: LatticeStorage<'a, R>,
    ) -> Result<(Self, &'a mut [u32]), LatticeError> {
        #[cfg(feature = "budget")]
        let cfg = &super::budget::resolve(scene, cfg)?;
        let LatticeStorage { lattices, coords, words } = storage;
        let nlattices = if cfg.nested { 1 + scene.composites.len() } else { 1 };
        if lattices.len() < nlattices {
            return Err(LatticeError { capacity: "lattices", needed: nlattices, available: lattices.len() });
        }
        // Coordinate lists and cell ranges.
        let (mut nc, mut ncells) = (0usize, 0usize);
        for (g, slot) in lattices.iter_mut().enumerate().take(nlattices) {
            let b = lattice_bounds(scene, g);
            let n = lattice_resolution(scene, cfg, g, &b);
            let mut sub = SubLattice { bounds: b, n, coord_start: [0; 3], cell_start: ncells as u32 };
            for a in 0..3 {
                let need = nc + n[a] as usize + 1;
                if need > coords.len() {
                    let total: usize = (0..nlattices)
                        .map(|g| lattice_resolution(scene, cfg, g, &lattice_bounds(scene, g)).iter().map(|&v| v as usize + 1).sum::<usize>())
                        .sum();
                    return Err(LatticeError { capacity: "coords", needed: total, available: coords.len() });
                }
                sub.coord_start[a] = nc as u32;
                axis_planes(scene, cfg, g, a, &b, n[a], &mut coords[nc..need]);
                nc = need;
            }
            ncells += sub.cells();
            *slot = sub;
        }
        let lattices = &lattices[..nlattices];
        // Pass 0: count the references, which decides the index width.
        let mut nrefs = 0usize;
        for_each_ref(scene, cfg, coords, lattices, |_, _| nrefs += 1);
        let narrow = cfg.index16 && index::fits16(nrefs, scene.objects.len(), scene.composites.len());
        let per_word = if narrow { 2 } else { 1 };
        let cell_words = index::words(ncells + 1, narrow);
        if cell_words > words.len() {
            return Err(LatticeError { capacity: "cells", needed: ncells + 1, available: words.len() * per_word });
        }
        let (cells, refs) = words.split_at_mut(cell_words);
        let ref_words = index::words(nrefs, narrow);
        if ref_words > refs.len() {
            return Err(LatticeError { capacity: "refs", needed: nrefs, available: refs.len() * per_word });
        }
        let (refs, rest) = refs.split_at_mut(ref_words);
        cells.iter_mut().chain(refs.iter_mut()).for_each(|c| *c = 0);
        let get = |w: &[u32], i| index::get(w, narrow, i);
        let set = |w: &mut [u32], i, v| index::set(w, narrow, i, v);
        // Pass 1: count references per cell (into entry c + 1), then sum to cell ends.
        for_each_ref(scene, cfg, coords, lattices, |_, c| set(cells, c + 1, get(cells, c + 1) + 1));
        for i in 1..=ncells {
            set(cells, i, get(cells, i) + get(cells, i - 1));
        }
        // Pass 2: fill, using entry c as a cursor; afterwards entry c is the end of cell c, so
        // shifting by one restores the starts.
        for_each_ref(scene, cfg, coords, lattices, |item, c| {
            let at = get(cells, c);
            set(refs, at as usize, index::encode(item, narrow));
            set(cells, c, at + 1);
        });
        for i in (1..=ncells).rev() {
            set(cells, i, get(cells, i - 1));
        }
        set(cells, 0, 0);
        let lattice =
            Lattice { lattices, coords: &coords[..nc], cells, refs, entries: (ncells + 1, nrefs), narrow, objects: scene.objects.len() };
        Ok((lattice, rest))
    }
}

/// Calls `f(item, cell)` for every reference of every lattice, in storage order.
fn for_each_ref<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, coords: &[R], lattices: &[SubLattice<R>], mut f: impl FnMut(u32, usize)) {
    for (g, sub) in lattices.iter().enumerate() {
        for_each_item(scene, cfg, g, |item, ib| visit_cells(coords, sub, ib, |c| f(item, c)));
    }
}

/// Calls `f` with the global cell index of every cell of `sub` a box overlaps.
fn visit_cells<R: Real>(coords: &[R], sub: &SubLattice<R>, b: &Aabb<R>, mut f: impl FnMut(usize)) {
    let r = cell_range(coords, sub, b);
    let (nx, ny) = (sub.n[0] as usize, sub.n[1] as usize);
    for z in r[2].0..=r[2].1 {
        for y in r[1].0..=r[1].1 {
            for x in r[0].0..=r[0].1 {
                f(sub.cell_start as usize + x + nx * (y + ny * z));
            }
        }
    }
}
