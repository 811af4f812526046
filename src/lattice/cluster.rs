//! Dense cells: a world cell that holds more than [`LatticeConfig::split`] free objects (objects
//! of no composite) gets a lattice of its own, a two-level grid found while the lattice is
//! planned. A scene whose objects crowd into a few cells without a declared composite (a
//! teapot in a stadium written out by another program) then gets what the paper gives
//! composites; the world cell keeps its composites and one reference to the cell's lattice.
//!
//! A dense cell's lattice covers the cell's box with equal cells, as many as the `sub`
//! resolution gives its objects, so finding the dense cells and planning their lattices takes
//! a pass or two over the free objects per 4096 world cells and no storage.

use super::config::resolution;
use super::oriented::{count_cells, Oriented};
use super::planes::{cell_box, locate_on, span, Planes, Uniform};
use super::{LatticeConfig, NO_COMPOSITE};
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;
use crate::scene::Scene;

/// World cells counted at a time while looking for dense cells, without a heap (their tallies
/// live on the stack, 4 KB: a board that parses its scene keeps the scene's storage on the same
/// stack, and the 32 KB of 2,048 tallies overflowed the `parse` image's on the Whitted scene).
#[cfg(not(feature = "alloc"))]
const CHUNK: usize = 256;
/// Most world cells counted at a time with a heap (feature `alloc`): 64 MB of tallies, more
/// than the largest world lattice the automatic resolution makes (`max_per_axis` 64: 262,144
/// cells), so that a host's scan passes over the objects once, however many there are.
#[cfg(feature = "alloc")]
const HEAP_CHUNK: usize = 1 << 22;

/// What the scan counts per world cell of a chunk.
#[derive(Clone, Copy)]
struct Tally {
    /// Free objects that would move to the cell's lattice.
    count: u32,
    /// Of those, the ones centred in the cell.
    centred: u32,
    /// The part of the cell they occupy ([`Occupied`]).
    occupied: u32,
    /// References to the cell's lattice's cells.
    refs: u32,
}

impl Tally {
    /// Nothing counted.
    const ZERO: Tally = Tally { count: 0, centred: 0, occupied: NOTHING, refs: 0 };
}

/// A dense world cell and its lattice.
#[derive(Clone, Copy, Debug)]
pub(super) struct Dense<R> {
    /// Number of the world cell.
    pub cell: usize,
    /// Free objects the world lattice assigns to it that move to its lattice ([`moves`]).
    pub free: usize,
    /// Of those, the ones whose box centre lies in the cell (each object is counted in one cell
    /// at most).
    pub centred: usize,
    /// The cell's box: the region of its lattice.
    pub bounds: Aabb<R>,
    /// Cells per axis of its lattice.
    pub n: [u16; 3],
    /// References to its lattice's cells.
    pub refs: usize,
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
pub(super) fn for_each_dense<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    planes: &(impl Planes<R> + ?Sized),
    f: impl FnMut(&Dense<R>),
) {
    if possible(scene, cfg) {
        scan(scene, cfg, planes, f);
    }
}

/// Whether a free object with box `b` in a dense world cell `cell` moves to the cell's lattice:
/// it is small beside the cell, at most half as long on every axis. A larger one (the floor
/// under a cluster) stays in the world cell's list; in the cell's lattice it would be listed in
/// most of its cells, and it would stretch the lattice's box over the whole cell.
pub(super) fn moves<R: Real>(cell: &Aabb<R>, b: &Aabb<R>) -> bool {
    (0..3).all(|a| small_beside(b, a, cell.min.axis(a), cell.max.axis(a)))
}

/// Whether box `b` is at most half as long on axis `a` as the span `lo..hi`: [`moves`] on one
/// axis.
fn small_beside<R: Real>(b: &Aabb<R>, a: usize, lo: R, hi: R) -> bool {
    let len = b.max.axis(a) - b.min.axis(a);
    len + len <= hi - lo
}

/// Steps per axis in which a dense cell's lattice box is kept, inside the world cell.
const STEPS: u32 = 32;
/// An empty [`Occupied`] box.
const NOTHING: u32 = u32::MAX;

/// The part of a world cell its moving objects occupy, in [`STEPS`] of the cell per axis,
/// packed in a word (per axis the first step and the last, five bits each): the dense cell's
/// lattice covers only that, so a cluster in a corner of a big cell gets its cells where it is.
struct Occupied;

impl Occupied {
    /// The steps `b` reaches on each axis of `cell`, packed.
    fn of<R: Real>(cell: &Aabb<R>, b: &Aabb<R>) -> u32 {
        let mut w = 0;
        for a in 0..3 {
            let (lo, hi) = (cell.min.axis(a).to_f64(), cell.max.axis(a).to_f64());
            let (min, max) = (b.min.axis(a).to_f64(), b.max.axis(a).to_f64());
            let step = |x: f64| if hi > lo { (x - lo) / (hi - lo) * STEPS as f64 } else { 0.0 };
            // max/min, not clamp: clamp's assertion would link float formatting in.
            let mut first = libm::floor(step(min)).max(0.0).min((STEPS - 1) as f64) as u32;
            let mut last = (libm::ceil(step(max)).max(0.0) as u32).max(first + 1).min(STEPS) - 1;
            // A side far nearer the middle than the cell is wide is lost in `x - lo` (a cell
            // of a scene with one object reaching far out): the step found then lies beyond it.
            // The planes as the region places them decide.
            while first > 0 && step_plane(lo, hi, first) > min {
                first -= 1;
            }
            while last + 1 < STEPS && step_plane(lo, hi, last + 1) < max {
                last += 1;
            }
            w |= (first | last << 5) << (10 * a);
        }
        w
    }

    /// The smallest packed box holding both.
    fn union(p: u32, q: u32) -> u32 {
        if p == NOTHING {
            return q;
        }
        let field = |w: u32, a: usize, k: usize| (w >> (10 * a + 5 * k)) & 31;
        (0..3).fold(0, |w, a| {
            w | (field(p, a, 0).min(field(q, a, 0)) | field(p, a, 1).max(field(q, a, 1)) << 5) << (10 * a)
        })
    }

    /// The packed box `p` in world coordinates inside `cell`, its inner planes moved outwards
    /// by the scalar's padding (as [`Aabb::cast_padded`] rounds), so no object's edge is left out.
    fn region<R: Real>(cell: &Aabb<R>, p: u32) -> Aabb<R> {
        let at = |a: usize, k: u32, out: R| {
            let (lo, hi) = (cell.min.axis(a), cell.max.axis(a));
            match k {
                0 => lo,
                STEPS => hi,
                _ => {
                    let v = R::from_f64(step_plane(lo.to_f64(), hi.to_f64(), k));
                    (v + out * (v.abs() + R::ONE) * R::pad_eps()).max(lo).min(hi)
                }
            }
        };
        let (first, last) =
            ([0, 1, 2].map(|a| (p >> (10 * a)) & 31), [0, 1, 2].map(|a| ((p >> (10 * a + 5)) & 31) + 1));
        let (down, up) = (-R::ONE, R::ONE);
        Aabb {
            min: Vec3::new(at(0, first[0], down), at(1, first[1], down), at(2, first[2], down)),
            max: Vec3::new(at(0, last[0], up), at(1, last[1], up), at(2, last[2], up)),
        }
    }
}

/// Plane `k` of the [`STEPS`] across `lo..hi`, where [`Occupied::region`] places it (before its
/// padding).
fn step_plane(lo: f64, hi: f64, k: u32) -> f64 {
    lo + (hi - lo) * k as f64 / STEPS as f64
}

/// What [`scan`] calls per object and cell: the cell's number in its chunk, its box, the object's
/// box, the object's index.
type Visit<'v, R> = dyn FnMut(usize, &Aabb<R>, &Aabb<R>, usize) + 'v;

/// [`for_each_dense`]'s work, out of line so that its tallies are on the stack only when a
/// scene can have a dense cell; with a heap, on the heap, one chunk for the whole lattice.
#[inline(never)]
fn scan<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    planes: &(impl Planes<R> + ?Sized),
    f: impl FnMut(&Dense<R>),
) {
    #[cfg(feature = "alloc")]
    {
        let total = (0..3).map(|a| planes.cells(a)).product::<usize>();
        let mut tallies = alloc::vec![Tally::ZERO; total.clamp(1, HEAP_CHUNK)];
        scan_in(scene, cfg, planes, &mut tallies, f);
    }
    #[cfg(not(feature = "alloc"))]
    scan_in(scene, cfg, planes, &mut [Tally::ZERO; CHUNK], f);
}

/// [`scan`] over chunks of as many world cells as there are `tallies`: per chunk a pass over
/// the free objects that counts, and when a cell of the chunk is dense, two more that find
/// the part each dense cell's objects occupy and count its lattice's references.
fn scan_in<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    planes: &(impl Planes<R> + ?Sized),
    tallies: &mut [Tally],
    mut f: impl FnMut(&Dense<R>),
) {
    let split = cfg.split as usize;
    let n = [0, 1, 2].map(|a| planes.cells(a));
    let (slab, total) = (n[0] * n[1], n[0] * n[1] * n[2]);
    // A dense cell's lattice: over the part of the cell its moving objects occupy.
    let dense = |c: usize, free: usize, occupied: u32| {
        let bounds = Occupied::region(&cell_box(planes, c), occupied);
        Dense { cell: c, free, centred: 0, bounds, n: resolution(&bounds, free, cfg.sub, cfg.max_per_axis), refs: 0 }
    };
    let size = tallies.len();
    for base in (0..total).step_by(size) {
        let end = (base + size).min(total);
        let (z0, z1) = (base / slab, (end - 1) / slab);
        // Calls `visit(cell - base, cell box, object box)` for every cell of the chunk each free
        // object overlaps and would move to, were the cell dense.
        let each = |visit: &mut Visit<'_, R>| {
            for (o, b) in free_objects(scene) {
                let (lz, hz) = (locate_on(planes, 2, b.min.z), locate_on(planes, 2, b.max.z));
                if hz < z0 || lz > z1 {
                    continue;
                }
                // Only the cells the object's own box meets, as the build lists it.
                let oriented = scene.objects.get(o).and_then(Oriented::of);
                let r = span(planes, b);
                // [`moves`] axis by axis, so that a large object (one that moves nowhere) costs
                // a test per row, not one per cell of its span.
                let small = |a: usize, i: usize| small_beside(b, a, planes.plane(a, i), planes.plane(a, i + 1));
                for z in (lz.max(z0)..=hz.min(z1)).filter(|&z| small(2, z)) {
                    for y in (r[1].0..=r[1].1).filter(|&y| small(1, y)) {
                        for x in (r[0].0..=r[0].1).filter(|&x| small(0, x)) {
                            let c = x + n[0] * (y + n[1] * z);
                            if (base..end).contains(&c) && oriented.as_ref().is_none_or(|k| k.meets(planes, [x, y, z]))
                            {
                                visit(c - base, &cell_box(planes, c), b, o);
                            }
                        }
                    }
                }
            }
        };
        tallies.iter_mut().for_each(|t| *t = Tally::ZERO);
        each(&mut |i, _, _, _| tallies[i].count += 1);
        if !tallies.iter().any(|t| t.count as usize > split) {
            continue;
        }
        each(&mut |i, cell, b, _| {
            let t = &mut tallies[i];
            if t.count as usize > split {
                t.occupied = Occupied::union(t.occupied, Occupied::of(cell, b));
                let centre = (b.min + b.max) * R::HALF;
                t.centred +=
                    u32::from((0..3).all(|a| centre.axis(a) >= cell.min.axis(a) && centre.axis(a) < cell.max.axis(a)));
            }
        });
        each(&mut |i, _, b, o| {
            let t = &mut tallies[i];
            if t.count as usize > split {
                let d = dense(base + i, t.count as usize, t.occupied);
                let oriented = scene.objects.get(o).and_then(Oriented::of);
                t.refs += count_cells(&Uniform { bounds: &d.bounds, n: d.n }, b, oriented.as_ref()) as u32;
            }
        });
        for (i, t) in tallies.iter().enumerate().take(end - base) {
            if t.count as usize > split {
                f(&Dense {
                    centred: t.centred as usize,
                    refs: t.refs as usize,
                    ..dense(base + i, t.count as usize, t.occupied)
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::Rng;

    /// The region of the packed union of boxes holds each box's part in the cell, in every
    /// scalar, and stays inside the cell.
    fn occupied_holds_its_boxes<R: Real>() {
        let mut rng = Rng::new(5);
        for case in 0..600 {
            let lo = Vec3::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0), rng.range(-50.0, 50.0));
            let size = Vec3::new(rng.range(0.0, 9.0), rng.range(0.0, 9.0), rng.range(0.0, 9.0));
            // Half the cells are vast around boxes near the origin (a scene with one object
            // reaching far out), so that a box's coordinate is lost beside the cell's side in a
            // float sum: the lattice's dense cells of such scenes.
            let far = (R::LIMIT / 16.0).min(1e80);
            let cell = if case % 2 == 0 {
                Aabb { min: lo, max: lo + size }
            } else {
                let half = far * rng.range(0.5, 1.0);
                Aabb { min: Vec3::new(-half, -half, -half), max: Vec3::new(half, half, half * rng.range(1.0, 7.0)) }
            };
            let cell = Aabb { min: cell.min.cast::<R>(), max: cell.max.cast::<R>() };
            let boxes: std::vec::Vec<Aabb<R>> = (0..1 + rng.below(4))
                .map(|_| {
                    let mut p = |a: usize| {
                        let (l, h) = (cell.min.axis(a).to_f64(), cell.max.axis(a).to_f64());
                        let (l, h) = if h - l > 1e3 { (-3.0, 3.0) } else { (l, h) };
                        let (x, y) = (rng.range(l - 1.0, h + 1.0), rng.range(l - 1.0, h + 1.0));
                        (R::from_f64(x.min(y)), R::from_f64(x.max(y)))
                    };
                    let (x, y, z) = (p(0), p(1), p(2));
                    Aabb { min: Vec3::new(x.0, y.0, z.0), max: Vec3::new(x.1, y.1, z.1) }
                })
                .collect();
            let packed = boxes.iter().fold(NOTHING, |w, b| Occupied::union(w, Occupied::of(&cell, b)));
            let r = Occupied::region(&cell, packed);
            for a in 0..3 {
                assert!(
                    r.min.axis(a) >= cell.min.axis(a) && r.max.axis(a) <= cell.max.axis(a),
                    "{} outside the cell",
                    R::NAME
                );
                for b in &boxes {
                    let (l, h) = (b.min.axis(a).max(cell.min.axis(a)), b.max.axis(a).min(cell.max.axis(a)));
                    if l <= h {
                        assert!(
                            r.min.axis(a) <= l && r.max.axis(a) >= h,
                            "{}: axis {a}: {:?} does not hold {:?}",
                            R::NAME,
                            r,
                            b
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn occupied_region_holds_every_box_in_every_scalar() {
        occupied_holds_its_boxes::<f64>();
        occupied_holds_its_boxes::<f32>();
        occupied_holds_its_boxes::<crate::Fx>();
    }
}
