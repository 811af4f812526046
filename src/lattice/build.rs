//! Building a lattice into caller-provided storage: coordinate lists, then cells and references
//! in two passes (count, then fill).

use super::config::uniform_coord;
use super::oriented::{self, Oriented};
use super::plan::{axis_planes, lattice_bounds, lattice_resolution};
use super::{cluster, for_each_item, index, planes, Lattice, LatticeConfig, SubLattice};
use crate::math::Aabb;
use crate::scalar::Real;
use crate::scene::{Object, Scene};
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
impl<'a, R: Real> Lattice<'a, R> {
    /// Builds the lattice into `storage`.
    pub fn build(
        scene: &Scene<'_, R>,
        cfg: &LatticeConfig,
        storage: LatticeStorage<'a, R>,
    ) -> Result<Self, LatticeError> {
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
        let (nlattices, nc, ncells) = place_lattices(scene, cfg, lattices, coords)?;
        let lattices = &lattices[..nlattices];
        let (cells, refs, rest, nrefs, narrow) = index_cells(scene, cfg, (coords, lattices), words, ncells)?;
        let lattice = Lattice {
            lattices,
            coords: &coords[..nc],
            cells,
            refs,
            entries: (ncells + 1, nrefs),
            narrow,
            objects: scene.objects.len(),
        };
        Ok((lattice, rest))
    }
}

/// Stores the lattices (the world, each composite's when nested, then each dense cell's) in
/// `lattices` and their coordinate lists in `coords`: how many lattices, coordinates and cells.
fn place_lattices<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    lattices: &mut [SubLattice<R>],
    coords: &mut [R],
) -> Result<(usize, usize, usize), LatticeError> {
    let short = |capacity: &'static str, available: usize| {
        let s = Lattice::plan_exact(scene, cfg, |_, _, _, _| {});
        LatticeError { capacity, needed: if capacity == "lattices" { s.lattices } else { s.coords }, available }
    };
    // Coordinate lists and cell ranges: the world, the composites, then the dense cells.
    let (mut nc, mut ncells, mut nlattices, all_coords) = (0usize, 0usize, 0usize, coords.len());
    // `place(.., planes)` stores a lattice; `planes(axis, out)` writes its coordinate lists.
    let mut place = |lattices: &mut [SubLattice<R>],
                     coords: &mut [R],
                     nc: &mut usize,
                     b: Aabb<R>,
                     n: [u16; 3],
                     dense_cell: u32,
                     planes: &dyn Fn(usize, &mut [R])| {
        let available = lattices.len();
        let slot = lattices.get_mut(nlattices).ok_or_else(|| short("lattices", available))?;
        let mut sub = SubLattice { bounds: b, n, coord_start: [0; 3], cell_start: ncells as u32, dense_cell };
        for a in 0..3 {
            let need = *nc + n[a] as usize + 1;
            if need > coords.len() {
                return Err(short("coords", all_coords));
            }
            sub.coord_start[a] = *nc as u32;
            planes(a, &mut coords[*nc..need]);
            *nc = need;
        }
        ncells += sub.cells();
        nlattices += 1;
        *slot = sub;
        Ok(())
    };
    let base = if cfg.nested { 1 + scene.composites.len() } else { 1 };
    for g in 0..base {
        let b = lattice_bounds(scene, g);
        let n = lattice_resolution(scene, cfg, g, &b);
        place(lattices, coords, &mut nc, b, n, u32::MAX, &|a, out| axis_planes(scene, cfg, g, a, &b, n[a], out))?;
    }
    // The world's planes stay where they are while the dense cells' follow them; a dense
    // cell's lattice has equal cells.
    let (world, more) = coords.split_at_mut(nc);
    let wp = planes_of(world, &lattices[0]);
    let mut more_used = 0;
    let mut failed = Ok(());
    cluster::for_each_dense(scene, cfg, &wp, |d| {
        if failed.is_ok() {
            let uniform = |a: usize, out: &mut [R]| {
                let (lo, hi) = (d.bounds.min.axis(a), d.bounds.max.axis(a));
                out.iter_mut().enumerate().for_each(|(i, c)| *c = uniform_coord(lo, hi, d.n[a], i));
            };
            failed = place(lattices, more, &mut more_used, d.bounds, d.n, d.cell as u32, &uniform);
        }
    });
    failed?;
    // The dense cells' coordinate starts were counted from the end of the world's.
    for sub in &mut lattices[base..nlattices] {
        sub.coord_start = sub.coord_start.map(|v| v + nc as u32);
    }
    nc += more_used;
    Ok((nlattices, nc, ncells))
}

/// The cells' reference lists in `words`: counted (which decides the index width), then each
/// cell's start summed and the references filled. Returns the cells' words, the references',
/// the words left, the reference count and whether the index is 16-bit.
#[allow(clippy::type_complexity)]
fn index_cells<'w, R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    (coords, lattices): (&[R], &[SubLattice<R>]),
    words: &'w mut [u32],
    ncells: usize,
) -> Result<(&'w mut [u32], &'w mut [u32], &'w mut [u32], usize, bool), LatticeError> {
    let nlattices = lattices.len();
    // Pass 0: count the references, which decides the index width.
    let mut nrefs = 0usize;
    for_each_ref(scene, cfg, coords, lattices, |_, _| nrefs += 1);
    let narrow = cfg.index16 && index::fits16(nrefs, scene.objects.len(), nlattices - 1);
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
    Ok((cells, refs, rest, nrefs, narrow))
}

/// A lattice's coordinate lists.
fn planes_of<'c, R: Real>(coords: &'c [R], sub: &SubLattice<R>) -> [&'c [R]; 3] {
    [0, 1, 2].map(|a| {
        let s = sub.coord_start[a] as usize;
        &coords[s..s + sub.n[a] as usize + 1]
    })
}

/// Calls `f(item, cell)` for every reference of every lattice, in storage order. A dense
/// cell of the world holds its composites, its free objects too large to move
/// ([`cluster::moves`]) and its own lattice instead of the others.
fn for_each_ref<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    coords: &[R],
    lattices: &[SubLattice<R>],
    mut f: impl FnMut(u32, usize),
) {
    let base = if cfg.nested { 1 + scene.composites.len() } else { 1 };
    let dense = &lattices[base..];
    let find = |c: usize| dense.binary_search_by_key(&(c as u32), |d| d.dense_cell).ok();
    let world = &lattices[0];
    let wp = planes_of(coords, world);
    let object = |item: u32| (item & index::SUB_FLAG == 0).then(|| &scene.objects[item as usize]);
    for_each_item(scene, cfg, 0, |item, ib| {
        visit_cells(coords, world, ib, object(item), |c| match find(c) {
            Some(k) if item & index::SUB_FLAG == 0 && cluster::moves(&planes::cell_box(&wp, c), ib) => {
                visit_cells(coords, &dense[k], ib, object(item), |c| f(item, c))
            }
            _ => f(item, c),
        })
    });
    for (k, d) in dense.iter().enumerate() {
        f(index::SUB_FLAG | (base - 1 + k) as u32, d.dense_cell as usize);
    }
    for (g, sub) in lattices.iter().enumerate().take(base).skip(1) {
        for_each_item(scene, cfg, g, |item, ib| visit_cells(coords, sub, ib, None, |c| f(item, c)));
    }
}

/// Calls `f` with the global cell index of every cell of `sub` a box overlaps; for an object
/// given, only the cells its own box meets ([`Oriented`]).
fn visit_cells<R: Real>(
    coords: &[R],
    sub: &SubLattice<R>,
    b: &Aabb<R>,
    object: Option<&Object<R>>,
    mut f: impl FnMut(usize),
) {
    let (nx, ny) = (sub.n[0] as usize, sub.n[1] as usize);
    oriented::for_each_cell(&planes_of(coords, sub), b, object.and_then(Oriented::of).as_ref(), |[x, y, z]| {
        f(sub.cell_start as usize + x + nx * (y + ny * z))
    });
}
