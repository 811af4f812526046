//! A lattice's planes: its coordinate lists, stored ([`Planes`] on three slices) or computed
//! for equal cells over a box ([`Uniform`]), and what the planning steps read of them: the
//! cells a box spans ([`span`]) and a cell's box ([`cell_box`]).

use super::config::uniform_coord;
use super::locate_by;
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;

/// A lattice's coordinate lists, stored or computed.
pub(super) trait Planes<R: Real> {
    /// Cells on axis `a`.
    fn cells(&self, a: usize) -> usize;
    /// Plane `i` (0 to `cells(a)`) of axis `a`.
    fn plane(&self, a: usize, i: usize) -> R;
    /// The cell of axis `a` that coordinate `x` falls in: the last whose lower plane is at most
    /// `x` (the first cell below them all), by bisection.
    fn locate(&self, a: usize, x: R) -> usize {
        locate_by(self.cells(a), x, |i| self.plane(a, i))
    }
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
    /// The cell a division puts `x` in, moved to where the planes as computed put it: the
    /// bisection's answer (the planes rise with `i`) in a few plane computations, not
    /// `log2(cells)` (the dense cells' scan locates every object in every pass).
    fn locate(&self, a: usize, x: R) -> usize {
        let n = self.cells(a);
        let (lo, hi) = (self.bounds.min.axis(a).to_f64(), self.bounds.max.axis(a).to_f64());
        let guess = if hi > lo { (x.to_f64() - lo) / (hi - lo) * n as f64 } else { 0.0 };
        // `as` saturates: NaN and negatives to 0, the far side to the last cell.
        let mut i = (guess as usize).min(n.saturating_sub(1));
        while i > 0 && self.plane(a, i) > x {
            i -= 1;
        }
        while i + 1 < n && self.plane(a, i + 1) <= x {
            i += 1;
        }
        i
    }
}

/// Cell index range `[lo, hi]` per axis a box overlaps on the coordinate lists `planes`.
pub(super) fn span<R: Real>(planes: &(impl Planes<R> + ?Sized), b: &Aabb<R>) -> [(usize, usize); 3] {
    [0, 1, 2].map(|a| (locate_on(planes, a, b.min.axis(a)), locate_on(planes, a, b.max.axis(a))))
}

/// The cell of axis `a` that coordinate `x` falls in.
pub(super) fn locate_on<R: Real>(planes: &(impl Planes<R> + ?Sized), a: usize, x: R) -> usize {
    planes.locate(a, x)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::Rng;

    /// Equal cells locate a coordinate where bisection over the same planes does, in every
    /// scalar, for boxes near and far, wide and thin, and coordinates inside, on the planes and
    /// outside.
    fn uniform_locates_as_bisection<R: Real>() {
        let mut rng = Rng::new(11);
        for case in 0..2000 {
            let scale = [1e-3, 1.0, 1e3, R::LIMIT / 8.0][case % 4];
            let lo = rng.range(-scale, scale);
            let hi = lo + rng.range(0.0, scale);
            let n = [1, 2, 3, 7, 64, 1024][rng.below(6) as usize];
            let bounds = Aabb { min: Vec3::new(lo, lo, lo).cast::<R>(), max: Vec3::new(hi, hi, hi).cast::<R>() };
            let u = Uniform { bounds: &bounds, n: [n as u16; 3] };
            for k in 0..20 {
                let x = match k % 4 {
                    0 => R::from_f64(rng.range(lo - (hi - lo), hi + (hi - lo))),
                    1 => u.plane(0, rng.below(n as u64 + 1) as usize),
                    _ => R::from_f64(rng.range(lo, hi)),
                };
                let bisected = locate_by(n, x, |i| u.plane(0, i));
                assert_eq!(u.locate(0, x), bisected, "{}: {lo}..{hi} in {n} cells, x {x:?}", R::NAME);
            }
        }
    }

    #[test]
    fn uniform_cells_locate_as_bisection_in_every_scalar() {
        uniform_locates_as_bisection::<f64>();
        uniform_locates_as_bisection::<f32>();
        uniform_locates_as_bisection::<crate::Fx>();
    }
}
