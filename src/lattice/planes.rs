//! A lattice's planes: its coordinate lists, stored ([`Planes`] on three slices) or computed
//! for equal cells over a box ([`Uniform`]), and what the planning steps read of them: the
//! cells a box spans ([`span`]) and a cell's box ([`cell_box`]).

use super::config::uniform_coord;
use super::locate_by;
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;

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
pub(super) fn locate_on<R: Real>(planes: &(impl Planes<R> + ?Sized), a: usize, x: R) -> usize {
    locate_by(planes.cells(a), x, |i| planes.plane(a, i))
}

/// The box of world cell `c` on the coordinate lists `planes`.
pub(super) fn cell_box<R: Real>(planes: &(impl Planes<R> + ?Sized), c: usize) -> Aabb<R> {
    let n = [0, 1, 2].map(|a| planes.cells(a));
    let [x, y, z] = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
    Aabb {
        min: Vec3::new(planes.plane(0, x), planes.plane(1, y), planes.plane(2, z)),
        max: Vec3::new(planes.plane(0, x + 1), planes.plane(1, y + 1), planes.plane(2, z + 1)),
    }
}
