//! Dense cells: a world cell that holds more than [`LatticeConfig::split`] free objects (objects
//! of no composite) gets a lattice of its own, a two-level grid found while the lattice is
//! planned. A scene whose objects crowd into a few cells without a declared composite (a
//! teapot in a stadium written out by another program) then gets what the paper gives
//! composites; the world cell keeps its composites and one reference to the cell's lattice.
//!
//! A dense cell's lattice covers the cell's box with equal cells, as many as the `sub`
//! resolution gives its objects, so finding the dense cells and planning their lattices takes
//! a pass or two over the free objects per 4096 world cells and no storage.

use super::plan::{resolution, uniform_coord};
use super::{locate_by, LatticeConfig, NO_COMPOSITE};
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;
use crate::scene::Scene;

/// World cells counted at a time while looking for dense cells (the counters live on the stack).
const CHUNK: usize = 4096;

/// A dense world cell and its lattice.
#[derive(Clone, Copy, Debug)]
pub(super) struct Dense<R> {
    /// Number of the world cell.
    pub cell: usize,
    /// Free objects the world lattice assigns to it.
    pub free: usize,
    /// The cell's box: the region of its lattice.
    pub bounds: Aabb<R>,
    /// Cells per axis of its lattice.
    pub n: [u16; 3],
    /// References to its lattice's cells.
    pub refs: usize,
}

/// A lattice's coordinate lists, stored or computed.
pub(super) trait Planes<R> {
    /// Cells on axis `a`.
    fn cells(&self, a: usize) -> usize;
    /// Plane `i` (0 to `cells(a)`) of axis `a`.
    fn plane(&self, a: usize, i: usize) -> R;
}

/// Stored coordinate lists, one per axis.
impl<R: Real> Planes<R> for [&[R]; 3] {
    fn cells(&self, a: usize) -> usize {
        self[a].len() - 1
    }
    fn plane(&self, a: usize, i: usize) -> R {
        self[a][i]
    }
}

/// Equal cells over a box: the planes [`uniform_coord`] gives, as stored, computed when asked
/// (no list on the stack, which for [`super::MAX_PER_AXIS`] planes an axis is 12 KB in fixed
/// point).
pub(super) struct Uniform<'b, R> {
    /// The box.
    pub bounds: &'b Aabb<R>,
    /// Cells per axis.
    pub n: [u16; 3],
}

impl<R: Real> Planes<R> for Uniform<'_, R> {
    fn cells(&self, a: usize) -> usize {
        self.n[a] as usize
    }
    fn plane(&self, a: usize, i: usize) -> R {
        uniform_coord(self.bounds.min.axis(a), self.bounds.max.axis(a), self.n[a], i)
    }
}

/// Cell index range `[lo, hi]` per axis a box overlaps on the coordinate lists `planes`.
pub(super) fn span<R: Real>(planes: &(impl Planes<R> + ?Sized), b: &Aabb<R>) -> [(usize, usize); 3] {
    [0, 1, 2].map(|a| (locate_on(planes, a, b.min.axis(a)), locate_on(planes, a, b.max.axis(a))))
}

/// The cell of axis `a` that coordinate `x` falls in.
fn locate_on<R: Real>(planes: &(impl Planes<R> + ?Sized), a: usize, x: R) -> usize {
    locate_by(planes.cells(a), x, |i| planes.plane(a, i))
}

/// Cells a box overlaps in a range from [`span`].
pub(super) fn cells_in(r: &[(usize, usize); 3]) -> usize {
    r.iter().map(|&(lo, hi)| hi - lo + 1).product()
}

/// The free objects: index and box.
pub(super) fn free_objects<'s, R: Real>(scene: &'s Scene<'_, R>) -> impl Iterator<Item = (usize, &'s Aabb<R>)> {
    scene.objects.iter().enumerate().filter(|(_, o)| o.composite == NO_COMPOSITE).map(|(i, o)| (i, &o.bounds))
}

/// Whether any world cell can be dense: sub-lattices on, `split` not 0, and more free objects
/// than `split`.
pub(super) fn possible<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> bool {
    cfg.nested && cfg.split > 0 && free_objects(scene).nth(cfg.split as usize).is_some()
}

/// Calls `f` for every dense cell of the world lattice whose coordinate lists are `planes`, in
/// cell order.
pub(super) fn for_each_dense<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, planes: &(impl Planes<R> + ?Sized), f: impl FnMut(&Dense<R>)) {
    if possible(scene, cfg) {
        scan(scene, cfg, planes, f);
    }
}

/// [`for_each_dense`]'s work, out of line so that its counters are on the stack only when a
/// scene can have a dense cell.
#[inline(never)]
fn scan<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, planes: &(impl Planes<R> + ?Sized), mut f: impl FnMut(&Dense<R>)) {
    let split = cfg.split as usize;
    let n = [0, 1, 2].map(|a| planes.cells(a));
    let (slab, total) = (n[0] * n[1], n[0] * n[1] * n[2]);
    let xyz = |c: usize| [c % n[0], (c / n[0]) % n[1], c / slab];
    let dense = |c: usize, free: usize| {
        let [x, y, z] = xyz(c);
        let bounds = Aabb {
            min: Vec3::new(planes.plane(0, x), planes.plane(1, y), planes.plane(2, z)),
            max: Vec3::new(planes.plane(0, x + 1), planes.plane(1, y + 1), planes.plane(2, z + 1)),
        };
        Dense { cell: c, free, bounds, n: resolution(&bounds, free, cfg.sub, cfg.max_per_axis), refs: 0 }
    };
    let (mut counts, mut refs) = ([0u32; CHUNK], [0u32; CHUNK]);
    for base in (0..total).step_by(CHUNK) {
        let end = (base + CHUNK).min(total);
        let (z0, z1) = (base / slab, (end - 1) / slab);
        // Calls `visit(cell - base, object box)` for every cell of the chunk each free object
        // overlaps.
        let each = |visit: &mut dyn FnMut(usize, &Aabb<R>)| {
            for (_, b) in free_objects(scene) {
                let (lz, hz) = (locate_on(planes, 2, b.min.z), locate_on(planes, 2, b.max.z));
                if hz < z0 || lz > z1 {
                    continue;
                }
                let r = span(planes, b);
                for z in lz.max(z0)..=hz.min(z1) {
                    for y in r[1].0..=r[1].1 {
                        for x in r[0].0..=r[0].1 {
                            let c = x + n[0] * (y + n[1] * z);
                            if (base..end).contains(&c) {
                                visit(c - base, b);
                            }
                        }
                    }
                }
            }
        };
        counts.iter_mut().for_each(|k| *k = 0);
        each(&mut |i, _| counts[i] += 1);
        if !counts.iter().any(|&k| k as usize > split) {
            continue;
        }
        refs.iter_mut().for_each(|k| *k = 0);
        each(&mut |i, b| {
            if counts[i] as usize > split {
                let d = dense(base + i, counts[i] as usize);
                refs[i] += cells_in(&span(&Uniform { bounds: &d.bounds, n: d.n }, b)) as u32;
            }
        });
        for i in 0..end - base {
            if counts[i] as usize > split {
                f(&Dense { refs: refs[i] as usize, ..dense(base + i, counts[i] as usize) });
            }
        }
    }
}
