//! The lattice: the paper's lattice-structured space subdivision.
//!
//! The world range (the viewpoint and every object) is cut into cells by per-axis coordinate
//! lists `X(), Y(), Z()`; every composite object gets a sub-lattice over its own box. A cell
//! lists the objects (and sub-lattices) whose padded box overlaps it. A ray walks from cell to
//! neighbouring cell by index arithmetic (3D-DDA) and tests only what the cells it visits hold.
//!
//! Storage is caller-provided ([`LatticeStorage`]); [`Lattice::plan`] says how much a scene
//! needs, and [`Lattice::build`] fails with a [`LatticeError`] naming the capacity that ran out.
//!
//! Traversal, with the paper's steps 1-14 in mind:
//! * the walk starts where the ray enters the world box and keeps an explicit bounded stack of
//!   walkers: entering a sub-lattice pushes one (step 8), leaving it pops (step 12);
//! * crossing parameters are computed from the coordinate list each step
//!   (`(X(a+1) - o) / d`), never accumulated, so long walks do not drift;
//! * tie rule: when two or three axes cross at the same `t`, x steps before y before z; the
//!   cells in between are visited with zero length, so no cell is skipped;
//! * a direction component of +0.0 or -0.0 never steps on that axis, and the start cell on it
//!   is found from the origin alone, so both zeros give the same cells;
//! * mailboxing: each object and sub-lattice is tested at most once per ray;
//! * the walk stops once the best hit lies strictly before the current cell's exit: all
//!   untested objects lie in later cells, so their hits are no nearer (boxes are padded for
//!   rounding), and the answer equals brute force.

#[cfg(feature = "budget")]
mod budget;
mod build;
mod cluster;
mod config;
mod index;
mod oriented;
mod plan;
mod planes;
mod walk;

#[cfg(feature = "budget")]
pub use budget::Choice;
pub use build::{LatticeError, LatticeStorage};
pub use config::{LatticeConfig, Resolution, Spacing, MAX_PER_AXIS};
pub use plan::LatticeSizes;

use crate::accel::{Accelerator, Hit, Query};
use crate::math::{Aabb, Ray, Vec3};
use crate::scalar::Real;
use crate::scene::{Scene, NO_COMPOSITE};

use index::SUB_FLAG;
/// Deepest nesting of lattices: the world and one level of composites and dense cells.
pub const MAX_NESTING: usize = 2;

/// One lattice (the world's or a composite's sub-lattice) inside the shared storage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubLattice<R> {
    /// The region the lattice covers.
    pub bounds: Aabb<R>,
    /// Cells per axis.
    pub n: [u16; 3],
    /// Where each axis' coordinate list (`n + 1` entries) starts in the coordinate storage.
    pub coord_start: [u32; 3],
    /// Index of the first cell in the cell storage.
    pub cell_start: u32,
    /// For a dense cell's lattice, the number of the world cell it serves; [`u32::MAX`] for
    /// the world and composites.
    pub dense_cell: u32,
}

impl<R: Real> SubLattice<R> {
    /// An unused slot (for static storage arrays).
    pub const EMPTY: Self = SubLattice {
        bounds: Aabb {
            min: Vec3 { x: R::ZERO, y: R::ZERO, z: R::ZERO },
            max: Vec3 { x: R::ZERO, y: R::ZERO, z: R::ZERO },
        },
        n: [0; 3],
        coord_start: [0; 3],
        cell_start: 0,
        dense_cell: u32::MAX,
    };
    fn cells(&self) -> usize {
        self.n.iter().map(|&v| v as usize).product()
    }
}

/// A built lattice over a scene.
#[derive(Debug)]
pub struct Lattice<'a, R> {
    lattices: &'a [SubLattice<R>],
    coords: &'a [R],
    /// Per cell the index of its first reference, and one entry more (packed, see `narrow`).
    cells: &'a [u32],
    /// References (packed, see `narrow`).
    refs: &'a [u32],
    /// Entries in `cells` (cells + 1) and in `refs`.
    entries: (usize, usize),
    /// Whether `cells` and `refs` hold 16-bit indices, two to a word.
    narrow: bool,
    /// Objects in the scene it was built for (mailbox entries of composites follow them).
    objects: usize,
}

/// Calls `f(item, box)` for the items lattice `g` holds (the world, `0`, or composite `g - 1`'s):
/// an object index, or `SUB_FLAG |` composite index. A dense cell's lattice is filled by the build.
fn for_each_item<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, mut f: impl FnMut(u32, &Aabb<R>)) {
    match g.checked_sub(1) {
        None => {
            for (i, o) in scene.objects.iter().enumerate() {
                if o.composite == NO_COMPOSITE || !cfg.nested {
                    f(i as u32, &o.bounds);
                }
            }
            if cfg.nested {
                for (g, grp) in scene.composites.iter().enumerate() {
                    f(SUB_FLAG | g as u32, &grp.bounds);
                }
            }
        }
        Some(k) => {
            let grp = &scene.composites[k];
            for i in grp.first as usize..grp.first as usize + grp.len as usize {
                f(i as u32, &scene.objects[i].bounds);
            }
        }
    }
}

/// Index of the cell holding `x` in a coordinate list of `n` cells given by `c(i)`, clamped to
/// `0..n`: the largest `i < n` with `c(i) <= x`, by bisection.
#[inline]
fn locate_by<R: Real>(n: usize, x: R, c: impl Fn(usize) -> R) -> usize {
    let (mut lo, mut hi) = (0usize, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if c(mid) <= x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// [`locate_by`] over a stored coordinate list (`n + 1` entries).
#[inline]
fn locate<R: Real>(c: &[R], x: R) -> usize {
    locate_by(c.len() - 1, x, |i| c[i])
}
/// A lattice's tables: lattices, coordinate lists, packed cell starts and references, their
/// entry counts and whether they are 16-bit.
pub(crate) type Tables<'a, R> = (&'a [SubLattice<R>], &'a [R], (&'a [u32], &'a [u32]), (usize, usize), bool);

impl<'a, R> Lattice<'a, R> {
    /// A lattice over tables built before, as [`bake::source`](crate::bake) writes them: for
    /// baked tables only, which hold a built lattice.
    #[doc(hidden)]
    pub const fn from_tables(
        lattices: &'a [SubLattice<R>],
        coords: &'a [R],
        (cells, refs): (&'a [u32], &'a [u32]),
        entries: (usize, usize),
        narrow: bool,
        objects: usize,
    ) -> Self {
        Lattice { lattices, coords, cells, refs, entries, narrow, objects }
    }

    /// The lattice's tables (for baking).
    #[cfg_attr(not(feature = "bake"), allow(dead_code))]
    pub(crate) fn tables(&self) -> Tables<'a, R> {
        (self.lattices, self.coords, (self.cells, self.refs), self.entries, self.narrow)
    }
}

impl<'a, R: Real> Lattice<'a, R> {
    /// Bytes the built lattice occupies (lattices, coordinate lists, cells, references).
    pub fn bytes(&self) -> usize {
        size_of_val(self.lattices) + size_of_val(self.coords) + size_of_val(self.cells) + size_of_val(self.refs)
    }

    /// The lattices: index 0 is the world, then one per composite.
    pub fn lattices(&self) -> &[SubLattice<R>] {
        self.lattices
    }

    /// Number of cells over all lattices.
    pub fn cell_count(&self) -> usize {
        self.entries.0 - 1
    }

    /// Number of references over all cells.
    pub fn ref_count(&self) -> usize {
        self.entries.1
    }

    /// Whether cell starts and references are 16-bit ([`LatticeConfig::index16`]).
    pub fn narrow(&self) -> bool {
        self.narrow
    }

    /// Index of the first reference of cell `c` (`c` up to the cell count: one past the last
    /// cell gives the number of references).
    #[inline(always)]
    fn cell_start(&self, c: usize) -> u32 {
        index::get(self.cells, self.narrow, c)
    }

    /// The coordinate list of lattice `g` along `axis`.
    pub fn coordinate_list(&self, g: usize, axis: usize) -> &[R] {
        let sub = &self.lattices[g];
        let s = sub.coord_start[axis] as usize;
        &self.coords[s..s + sub.n[axis] as usize + 1]
    }
}

impl<R: Real> Accelerator<R> for Lattice<'_, R> {
    fn name(&self) -> &'static str {
        "lattice"
    }
    fn nearest(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<Hit<R>> {
        self.run(s, ray, t0, t1, false, q)
    }
    fn occluded(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<u32> {
        self.run(s, ray, t0, t1, true, q).map(|h| h.object)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{random_scene, RandomScene, Rng};
    use crate::scene::{Object, SceneBuilder};
    use std::vec;
    use std::vec::Vec;

    fn scene_storage(n: usize) -> Vec<Object<f64>> {
        vec![Object::default(); n]
    }

    fn with_lattice(n: usize, group: usize, cfg: LatticeConfig, f: impl FnOnce(&Scene<'_, f64>, &Lattice<'_, f64>)) {
        let mut st = scene_storage(n);
        let mut parts = crate::Parts::default();
        let mut b = SceneBuilder::new(&mut st, &mut parts);
        random_scene(&mut b, &RandomScene { objects: n, composite_size: group, spread: 0.0, seed: 7 }).unwrap();
        let scene = b.finish().unwrap();
        let s = Lattice::plan(&scene, &cfg);
        let (mut g, mut c, mut w) = (vec![SubLattice::EMPTY; s.lattices], vec![0.0; s.coords], vec![0; s.words()]);
        let lat =
            Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut c, words: &mut w }).unwrap();
        assert_eq!(
            (lat.lattices.len(), lat.coords.len(), lat.cell_count() + 1, lat.ref_count()),
            (s.lattices, s.coords, s.cells, s.refs)
        );
        assert_eq!(lat.cells.len() + lat.refs.len(), s.words());
        assert_eq!(lat.bytes(), s.bytes::<f64>());
        f(&scene, &lat);
    }

    #[test]
    fn plan_gives_exactly_the_storage_build_uses() {
        with_lattice(50, 0, LatticeConfig::default(), |_, _| {});
        with_lattice(30, 4, LatticeConfig::default(), |_, _| {});
    }

    #[test]
    fn too_little_storage_names_the_capacity_and_the_size_needed() {
        let mut st = scene_storage(20);
        let mut parts = crate::Parts::default();
        let mut b = SceneBuilder::new(&mut st, &mut parts);
        random_scene(&mut b, &RandomScene { objects: 20, composite_size: 5, spread: 0.0, seed: 3 }).unwrap();
        let scene = b.finish().unwrap();
        // 16-bit indices count two to a word, 32-bit ones one.
        for (index16, short) in [(false, 1), (true, 2)] {
            let cfg = LatticeConfig { index16, ..LatticeConfig::default() };
            let s = Lattice::plan(&scene, &cfg);
            assert_eq!(s.narrow, index16);
            let (mut g, mut c, mut w) =
                (vec![SubLattice::EMPTY; s.lattices], vec![0.0; s.coords], vec![0; s.words() - 1]);
            let e = Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut c, words: &mut w })
                .unwrap_err();
            assert_eq!(
                e,
                LatticeError { capacity: "refs", needed: s.refs, available: s.refs.next_multiple_of(short) - short }
            );
        }
        let cfg = LatticeConfig::default();
        let s = Lattice::plan(&scene, &cfg);
        let (mut c, mut w) = (vec![0.0; s.coords], vec![0; s.words()]);
        let mut g2 = vec![SubLattice::EMPTY; 1];
        let e = Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g2, coords: &mut c, words: &mut w })
            .unwrap_err();
        assert_eq!(e.capacity, "lattices");
        assert_eq!(std::format!("{e}"), "lattice capacity `lattices` too small: 5 entries needed, 1 available");
    }

    #[test]
    fn walk_steps_to_face_neighbours_only_even_through_corners() {
        let cfg = LatticeConfig { top: Resolution::Uniform([6, 6, 6]), ..LatticeConfig::default() };
        with_lattice(20, 0, cfg, |scene, lat| {
            let w = scene.world;
            let mut rng = Rng::new(11);
            for i in 0..2000 {
                // Half the rays run exactly through lattice points (cell corners).
                let pick = |rng: &mut Rng, a: usize| {
                    let c = lat.coordinate_list(0, a);
                    c[rng.below(c.len() as u64) as usize]
                };
                let o = Vec3::new(pick(&mut rng, 0), pick(&mut rng, 1), pick(&mut rng, 2));
                let p = if i % 2 == 0 {
                    Vec3::new(pick(&mut rng, 0), pick(&mut rng, 1), pick(&mut rng, 2))
                } else {
                    Vec3::new(rng.range(w.min.x, w.max.x), rng.range(w.min.y, w.max.y), rng.range(w.min.z, w.max.z))
                };
                if p == o {
                    continue;
                }
                let ray = Ray::new(o, p - o);
                let mut prev: Option<[usize; 3]> = None;
                let mut last_t = f64::MIN;
                lat.walk_cells(&ray, 0.0, f64::MAX, |c, t0, _| {
                    if let Some(q) = prev {
                        let steps: usize = (0..3).map(|a| c[a].abs_diff(q[a])).sum();
                        assert_eq!(steps, 1, "skipped from {q:?} to {c:?} on {ray:?}");
                    }
                    assert!(t0 >= last_t, "cells out of order");
                    last_t = t0;
                    prev = Some(c);
                });
            }
        });
    }

    #[test]
    fn plus_and_minus_zero_directions_visit_the_same_cells() {
        let cfg = LatticeConfig { top: Resolution::Uniform([5, 5, 5]), ..LatticeConfig::default() };
        with_lattice(10, 0, cfg, |_, lat| {
            let (x, y) = (lat.coordinate_list(0, 0)[2], lat.coordinate_list(0, 1)[3]);
            let z0 = lat.coordinate_list(0, 2)[0];
            let cells = |dx: f64, dy: f64| {
                let mut v = Vec::new();
                lat.walk_cells(&Ray::new(Vec3::new(x, y, z0), Vec3::new(dx, dy, 1.0)), 0.0, f64::MAX, |c, _, _| {
                    v.push(c)
                });
                v
            };
            let plus = cells(0.0, 0.0);
            assert_eq!(plus.len(), 5, "one cell per z slab: {plus:?}");
            assert_eq!(plus, cells(-0.0, 0.0));
            assert_eq!(plus, cells(0.0, -0.0));
            assert_eq!(plus, cells(-0.0, -0.0));
        });
    }
}
