//! Which cells of a crowded cell's lattice an object is listed in: those its own box meets
//! (its canonical shape's box, placed), not every cell of its world box. A long thin object
//! lying across the lattice (a cone of a tree, a cylinder of a ring) would otherwise be listed
//! in many cells it misses, and tested by every ray through them. Planning and building
//! count the same cells ([`for_each_cell`], [`count_cells`]).

use super::planes::{span, Planes};
use crate::math::Aabb;
use crate::scalar::Real;
use crate::scene::Object;
use crate::shape::Shape;

/// Calls `f` with the cell (per-axis indices) of every cell of the lattice with coordinate
/// lists `planes` that the box `b` overlaps and, given an object's oriented box, that it meets.
pub(super) fn for_each_cell<R: Real>(
    planes: &(impl Planes<R> + ?Sized),
    b: &Aabb<R>,
    oriented: Option<&Oriented>,
    mut f: impl FnMut([usize; 3]),
) {
    let r = span(planes, b);
    for z in r[2].0..=r[2].1 {
        for y in r[1].0..=r[1].1 {
            for x in r[0].0..=r[0].1 {
                if oriented.is_none_or(|o| o.meets(planes, [x, y, z])) {
                    f([x, y, z]);
                }
            }
        }
    }
}

/// The number of cells [`for_each_cell`] visits.
pub(super) fn count_cells<R: Real>(
    planes: &(impl Planes<R> + ?Sized),
    b: &Aabb<R>,
    oriented: Option<&Oriented>,
) -> usize {
    match oriented {
        // Every cell of the span: its size, not a walk over it (a large object in a fine
        // lattice spans millions).
        None => span(planes, b).iter().map(|(lo, hi)| (hi + 1).saturating_sub(*lo)).product(),
        Some(_) => {
            let mut n = 0;
            for_each_cell(planes, b, oriented, |_| n += 1);
            n
        }
    }
}

/// An object's own box (its canonical shape's, [`crate::shape::Shape::bounds`]) as the
/// lattice sees it: the map from world offsets to the object's space, and the margin cells are
/// grown by (twice the rounding padding the object's world box got). A long thin object lying
/// across the lattice (a cone of a tree, a cylinder of a ring) is then listed only in the
/// cells its own box meets, not in every cell of its world box.
pub(super) struct Oriented {
    to_object: [[f64; 3]; 3],
    origin: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
    margin: f64,
    /// For a triangle, how far past its long side (`x + z = 1` in its space) a cell may lie and
    /// still be listed: the widening of its own test ([`crate::shape::Shape::intersect`]), twice.
    hypotenuse: Option<f64>,
}

impl Oriented {
    /// The oriented box of `o`, or `None` when its world box is as tight (a sphere, a box
    /// along the axes: every cell of the world box meets it or nearly).
    pub(super) fn of<R: Real>(o: &Object<R>) -> Option<Self> {
        if matches!(o.shape, Shape::Sphere) {
            return None;
        }
        let m = o.world_to_object();
        let to_object = [0, 1, 2].map(|i| [0, 1, 2].map(|j| m.m[i][j].to_f64()));
        // Along the axes (a permutation of scaled axes): its world box is its own box.
        if to_object.iter().all(|row| row.iter().filter(|v| **v != 0.0).count() <= 1) {
            return None;
        }
        let (lo, hi) = o.shape.bounds();
        let origin = o.origin();
        Some(Oriented {
            to_object,
            origin: [origin.x.to_f64(), origin.y.to_f64(), origin.z.to_f64()],
            lo: [lo.x.to_f64(), lo.y.to_f64(), lo.z.to_f64()],
            hi: [hi.x.to_f64(), hi.y.to_f64(), hi.z.to_f64()],
            margin: 2.0 * o.bounds.pad_for::<R>(),
            hypotenuse: matches!(o.shape, Shape::Triangle).then(|| 2.0 * R::pad_eps().to_f64()),
        })
    }

    /// Whether cell `cell` of a lattice with coordinate lists `planes` can hold a point of the
    /// object: false when one of the object's own axes separates the cell (grown by the
    /// margin) from the object's box.
    pub(super) fn meets<R: Real>(&self, planes: &(impl Planes<R> + ?Sized), cell: [usize; 3]) -> bool {
        let side = |a: usize, k: usize| planes.plane(a, k).to_f64();
        let lo = [0, 1, 2].map(|a| side(a, cell[a]) - self.margin);
        let hi = [0, 1, 2].map(|a| side(a, cell[a] + 1) + self.margin);
        let centre = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]) - self.origin[a]);
        let half = [0, 1, 2].map(|a| 0.5 * (hi[a] - lo[a]));
        // The cell's range along a direction `row` of the object's space: centre and half width.
        let range = |row: [f64; 3]| {
            let c = row[0] * centre[0] + row[1] * centre[1] + row[2] * centre[2];
            let h = row[0].abs() * half[0] + row[1].abs() * half[1] + row[2].abs() * half[2];
            // f64's own rounding of these sums, far below the margin, allowed for all the same.
            (c, h + 1e-9 * (c.abs() + h))
        };
        let boxed = (0..3).all(|i| {
            let (c, h) = range(self.to_object[i]);
            c + h >= self.lo[i] && c - h <= self.hi[i]
        });
        // A triangle's third side: the cell's least x + z in the triangle's space at most 1.
        boxed
            && self.hypotenuse.is_none_or(|slack| {
                let (x, z) = (self.to_object[0], self.to_object[2]);
                let (c, h) = range([x[0] + z[0], x[1] + z[1], x[2] + z[2]]);
                c - h <= 1.0 + slack
            })
    }
}
