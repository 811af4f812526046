//! Building a lattice into caller-provided storage: coordinate lists, then cells and references
//! in two passes (count, then fill).

use super::plan::{axis_planes, lattice_bounds, lattice_resolution};
use super::{for_each_item, locate, Lattice, LatticeConfig, SubLattice};
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
    /// Which storage ran out ("lattices", "coords", "cells", "refs").
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
            "lattice capacity `{}` too small: {} entries needed, {} available",
            self.capacity, self.needed, self.available
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
        if ncells + 1 > words.len() {
            return Err(LatticeError { capacity: "cells", needed: ncells + 1, available: words.len() });
        }
        let (cells, refs) = words.split_at_mut(ncells + 1);
        cells.iter_mut().for_each(|c| *c = 0);
        // Pass 1: count references per cell (into cells[i + 1]).
        let mut nrefs = 0usize;
        for (g, sub) in lattices.iter().enumerate().take(nlattices) {
            for_each_item(scene, cfg, g, |_, ib| {
                visit_cells(coords, sub, ib, |c| {
                    cells[c + 1] += 1;
                    nrefs += 1;
                });
            });
        }
        if nrefs > refs.len() {
            return Err(LatticeError { capacity: "refs", needed: nrefs, available: refs.len() });
        }
        let (refs, rest) = refs.split_at_mut(nrefs);
        for i in 1..cells.len() {
            cells[i] += cells[i - 1];
        }
        // Pass 2: fill, using cells[i] as a cursor; afterwards cells[i] is the end of cell i,
        // so shifting by one restores the starts.
        for (g, sub) in lattices.iter().enumerate().take(nlattices) {
            for_each_item(scene, cfg, g, |item, ib| {
                visit_cells(coords, sub, ib, |c| {
                    refs[cells[c] as usize] = item;
                    cells[c] += 1;
                });
            });
        }
        for i in (1..cells.len()).rev() {
            cells[i] = cells[i - 1];
        }
        cells[0] = 0;
        let lattice = Lattice { lattices: &lattices[..nlattices], coords: &coords[..nc], cells, refs, objects: scene.objects.len() };
        Ok((lattice, rest))
    }}

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
