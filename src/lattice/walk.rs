//! Walking a lattice: from cell to neighbouring cell by index arithmetic (3D-DDA), with an
//! explicit bounded stack of walkers for sub-lattices (the paper's steps 1-14).

use super::{index, locate, Lattice, MAX_NESTING};
use crate::accel::{offer, reach, slack, Hit, Query};
use crate::bounds::at;
use crate::math::{Aabb, Ray, Vec3};
use crate::scalar::Real;
use crate::scene::Scene;

impl<R: Real> Lattice<'_, R> {
    /// Calls `visit(sub, cell_index, t_enter, t_exit)` for every cell of the world lattice the
    /// ray enters, in order, without testing objects (for tests and statistics).
    pub fn walk_cells(&self, ray: &Ray<R>, tmin: R, tmax: R, mut visit: impl FnMut([usize; 3], R, R)) {
        let inv = Inverse::new(ray, false, R::ZERO);
        let Some((t0, t1)) = inv.clip(&self.lattices[0].bounds.padded(slack(ray)), tmin, tmax) else { return };
        let mut slot = None;
        let w = Walker::start_in(&mut slot, self, 0, ray, &inv, t0, t1);
        let mut enter = t0;
        loop {
            let exit = w.exit();
            visit(w.idx.map(|v| v as usize), enter, exit.min(t1));
            enter = exit;
            if !w.advance(self, &inv) {
                break;
            }
        }
    }

    pub(super) fn run(
        &self,
        scene: &Scene<'_, R>,
        ray: &Ray<R>,
        tmin: R,
        tmax: R,
        any: bool,
        q: &mut Query<'_>,
    ) -> Option<Hit<R>> {
        let slack = slack(ray);
        // A window culls an object before its test for less than the box test costs.
        let inv = Inverse::new(ray, q.filter.tests_boxes() && !q.filter.by_windows(), slack);
        let (t0, t1) = inv.clip(&self.lattices[0].bounds.padded(slack), tmin, tmax)?;
        q.next_ray();
        let mut best: Option<Hit<R>> = None;
        let mut stack: [Option<Walker<R>>; MAX_NESTING] = [None; MAX_NESTING];
        let mut depth = 1;
        Walker::start_in(&mut stack[0], self, 0, ray, &inv, t0, t1);
        q.stats.cells_visited += 1;
        'walk: while depth > 0 {
            let Some(w) = stack[depth - 1].as_mut() else { break };
            // The cell's references, with the walker fixed for the loop (its place in the stack
            // is not looked up again per reference).
            while w.ref_i < w.ref_end {
                let item = index::decode(index::get(self.refs, self.narrow, w.ref_i as usize), self.narrow);
                w.ref_i += 1;
                match item {
                    Ok(i) => {
                        if q.first_visit(i)
                            && inv.may_meet(scene, i, tmin, reach(&best, tmax), q)
                            && offer(scene, i, ray, tmin, tmax, &mut best, q)
                            && any
                        {
                            return best;
                        }
                    }
                    Err(composite) => {
                        let g = composite + 1;
                        let limit = reach(&best, tmax);
                        if depth < MAX_NESTING && q.first_visit(self.objects + composite) {
                            if let Some((a, b)) = inv.clip(&self.lattices[g].bounds.padded(slack), tmin, limit) {
                                Walker::start_in(&mut stack[depth], self, g, ray, &inv, a, b);
                                depth += 1;
                                q.stats.cells_visited += 1;
                                continue 'walk;
                            }
                        }
                    }
                }
            }
            // The cell is done: stop if the best hit's tie window ends before its exit, else step.
            let done = best.is_some() && reach(&best, tmax) < w.exit();
            if done || !w.advance(self, &inv) {
                depth -= 1;
            } else {
                q.stats.cells_visited += 1;
            }
        }
        best
    }
}

/// What a walk keeps of a ray for its crossings: which axes it steps along (a zero
/// component, +0.0 or -0.0, never steps), and per axis the factor a crossing uses.
///
/// A crossing is `(plane - o) * (1 / d)` in floats and `(plane - o) / d` in fixed point
/// ([`Real::WALK_BY_RECIPROCAL`]): either keeps every scalar's crossing within a rounding or two
/// of the exact one, and the walk only chooses which objects are tested.
struct Inverse<R> {
    moves: [bool; 3],
    origin: [R; 3],
    factor: [R; 3],
    /// `1 / d` per axis (zero where the ray does not move along it): what [`Inverse::may_meet`]
    /// and [`Inverse::clip`] multiply by, in every scalar.
    inv: Vec3<R>,
    /// Whether [`Inverse::may_meet`] tests boxes for this ray ([`Filter::box_tests`], and not
    /// through windows; in fixed point only while no direction component reaches 64, so the
    /// reciprocal's rounding stays within the padding).
    boxes: bool,
    /// The origin plus and minus the walk's slack: what [`Inverse::may_meet`] takes the sides
    /// of an object's box from ([`Aabb::clip_grown_by_inverse`]), instead of growing the box.
    grown: (Vec3<R>, Vec3<R>),
}

impl<R: Real> Inverse<R> {
    /// The ray's inverse, for box tests too where `boxes` ([`Inverse::may_meet`]) with boxes
    /// grown by `slack`.
    fn new(ray: &Ray<R>, boxes: bool, slack: R) -> Self {
        let d = [ray.dir.x, ray.dir.y, ray.dir.z];
        let boxes = boxes && (R::WALK_BY_RECIPROCAL || ray.dir.max_abs() < R::from_i32(64));
        let inv = d.map(|v| if v != R::ZERO { v.recip() } else { R::ZERO });
        Inverse {
            moves: d.map(|v| v != R::ZERO),
            origin: [ray.origin.x, ray.origin.y, ray.origin.z],
            factor: if R::WALK_BY_RECIPROCAL { inv } else { d },
            inv: Vec3::new(inv[0], inv[1], inv[2]),
            boxes,
            grown: if boxes {
                (ray.origin + Vec3::new(slack, slack, slack), ray.origin - Vec3::new(slack, slack, slack))
            } else {
                (ray.origin, ray.origin)
            },
        }
    }

    /// Whether the ray can meet object `i` on `[tmin, limit]`: the slab test of its box grown
    /// by `slack` (the walk's [`slack`]: what it grows every box by), by the ray's reciprocals,
    /// before the exact test. A cell is bigger than many of the objects listed in it, so many
    /// rays that pass a small object's cell miss its box, and this test is six products where
    /// the exact one maps the ray into object space. It rejects no object the exact test would
    /// hit on that range, as the walk's own clip of a sub-lattice's box rejects none of its
    /// members. Counted as an inside test.
    #[inline]
    fn may_meet(&self, scene: &Scene<'_, R>, i: usize, tmin: R, limit: R, q: &mut Query<'_>) -> bool {
        if !self.boxes {
            return true;
        }
        q.stats.inside_tests += 1;
        at(scene.objects, i).bounds.clip_grown_by_inverse(self.grown, self.inv, tmin, limit).is_some()
    }

    /// [`Aabb::clip`] of the ray by `b` on `[t0, t1]`, the same range, from the reciprocals
    /// taken once per ray: a lattice's box (the world's at the start, a sub-lattice's at each
    /// entry) costs no division. Out of line, as [`Aabb::clip`] is: the box test stays the one
    /// slab test inlined into the walk.
    ///
    /// From strictly inside the box (every ray a scene's tracer casts starts inside the world's,
    /// and a secondary ray inside the sub-lattice of its point) on a range from zero on, every
    /// side behind the origin is crossed at or before zero, so only the three ahead cut the
    /// range: three products instead of six, and the same range.
    #[inline(never)]
    fn clip(&self, b: &Aabb<R>, t0: R, t1: R) -> Option<(R, R)> {
        let o = Vec3::new(self.origin[0], self.origin[1], self.origin[2]);
        let inside = b.strictly_holds(o);
        if !(inside && t0 >= R::ZERO) {
            return b.clip_by_inverse(o, self.inv, t0, t1);
        }
        let mut t1 = t1;
        for a in 0..3 {
            let inv = self.inv.axis(a);
            let ahead = if inv > R::ZERO { b.max.axis(a) } else { b.min.axis(a) };
            if inv != R::ZERO {
                t1 = t1.min((ahead - o.axis(a)) * inv);
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// The ray parameter where the ray crosses `plane` on axis `a` (which it moves along).
    #[inline(always)]
    fn crossing(&self, a: usize, plane: R) -> R {
        if R::WALK_BY_RECIPROCAL {
            (plane - self.origin[a]) * self.factor[a]
        } else {
            (plane - self.origin[a]) / self.factor[a]
        }
    }
}

/// The state of a walk through one lattice (one entry of the explicit stack).
#[derive(Clone, Copy, Debug)]
struct Walker<R> {
    idx: [i32; 3],
    /// Cells on each axis.
    n: [i32; 3],
    /// Per axis +1 or -1 (0 on an axis the ray does not move along).
    step: [i32; 3],
    /// What a step on each axis adds to the cell number (the axis' stride times its step).
    stride: [i32; 3],
    /// Where each axis' coordinate list starts in the coordinate storage, moved one on for an
    /// axis stepped forward: the next plane is then always `coords[plane_at[a] + idx[a]]`.
    plane_at: [i32; 3],
    /// Number of the current cell in the cell storage.
    cell: u32,
    t_next: [R; 3],
    t_end: R,
    ref_i: u32,
    ref_end: u32,
}

impl<R: Real> Walker<R> {
    /// A walker of lattice `sub` for `ray` on `[t0, t1]`, set up where it lies in `slot`: a
    /// walker returned by value is copied into the walk's stack whole (a `memcpy` call on a
    /// Cortex-M).
    fn start_in<'s>(
        slot: &'s mut Option<Self>,
        l: &Lattice<'_, R>,
        sub: usize,
        ray: &Ray<R>,
        inv: &Inverse<R>,
        t0: R,
        t1: R,
    ) -> &'s mut Self {
        let g = &l.lattices[sub];
        let p = ray.at(t0);
        let n = g.n.map(i32::from);
        let w = slot.insert(Walker {
            idx: [0; 3],
            n,
            step: [0; 3],
            stride: [0; 3],
            plane_at: g.coord_start.map(|v| v as i32),
            cell: g.cell_start,
            t_next: [R::MAX; 3],
            t_end: t1,
            ref_i: 0,
            ref_end: 0,
        });
        let strides = [1, n[0], n[0] * n[1]];
        for a in 0..3 {
            let c = l.coordinate_list(sub, a);
            // With a zero direction component the coordinate is the origin's, exactly.
            let x = if inv.moves[a] { p.axis(a) } else { ray.origin.axis(a) };
            let i = locate(c, x);
            w.idx[a] = i as i32;
            w.cell += (i as i32 * strides[a]) as u32;
            if inv.moves[a] {
                let forward = ray.dir.axis(a) > R::ZERO;
                w.step[a] = if forward { 1 } else { -1 };
                w.stride[a] = w.step[a] * strides[a];
                w.plane_at[a] += i32::from(forward);
                w.t_next[a] = inv.crossing(a, l.coords[(w.plane_at[a] + w.idx[a]) as usize]);
            }
        }
        w.load_cell(l);
        w
    }

    #[inline(always)]
    fn load_cell(&mut self, l: &Lattice<'_, R>) {
        self.ref_i = l.cell_start(self.cell as usize);
        self.ref_end = l.cell_start(self.cell as usize + 1);
    }

    /// Parameter where the ray leaves the current cell.
    #[inline]
    fn exit(&self) -> R {
        self.t_next[0].min(self.t_next[1]).min(self.t_next[2])
    }

    /// Steps to the neighbouring cell; false when the ray leaves the lattice or its range.
    #[inline]
    fn advance(&mut self, l: &Lattice<'_, R>, inv: &Inverse<R>) -> bool {
        // Tie rule: x before y before z (strict comparisons keep the earlier axis).
        let mut a = usize::from(self.t_next[1] < self.t_next[0]);
        if self.t_next[2] < self.t_next[a] {
            a = 2;
        }
        // An axis the ray does not move along has `t_next = R::MAX`, never below `t_end`
        // unless the range is unbounded; `step == 0` stops it then.
        if self.step[a] == 0 || self.t_next[a] > self.t_end {
            return false;
        }
        let i = self.idx[a] + self.step[a];
        if i < 0 || i >= self.n[a] {
            return false;
        }
        self.idx[a] = i;
        self.cell = self.cell.wrapping_add(self.stride[a] as u32);
        self.t_next[a] = inv.crossing(a, l.coords[(self.plane_at[a] + i) as usize]);
        self.load_cell(l);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::Inverse;
    use crate::fixed::Fx;
    use crate::generate::Rng;
    use crate::math::{Aabb, Ray, Vec3};
    use crate::scalar::Real;

    /// A random point near a box of corners -2 and 3 on every axis: inside, outside, or on a
    /// side or a corner.
    fn point<R: Real>(rng: &mut Rng) -> Vec3<R> {
        let c = |rng: &mut Rng| match rng.below(5) {
            0 => R::from_i32(-2),
            1 => R::from_i32(3),
            2 => R::from_f64(rng.range(-4.0, 5.0)),
            _ => R::from_f64(rng.range(-1.9, 2.9)),
        };
        Vec3::new(c(rng), c(rng), c(rng))
    }

    /// A random direction, some components zero or tiny.
    fn direction<R: Real>(rng: &mut Rng) -> Vec3<R> {
        let c = |rng: &mut Rng| match rng.below(6) {
            0 => R::ZERO,
            1 => R::from_f64(rng.range(-1e-4, 1e-4)),
            _ => R::from_f64(rng.range(-1.0, 1.0)),
        };
        Vec3::new(c(rng), c(rng), c(rng))
    }

    fn clips_as_the_box_does<R: Real>() {
        let b = Aabb {
            min: Vec3::new(R::from_i32(-2), R::from_i32(-2), R::from_i32(-2)),
            max: Vec3::new(R::from_i32(3), R::from_i32(3), R::from_i32(3)),
        };
        let mut rng = Rng::new(7);
        let mut inside = 0;
        for _ in 0..100_000 {
            let ray = Ray::new(point(&mut rng), direction(&mut rng));
            let t0 = if rng.below(2) == 0 { R::ZERO } else { R::from_f64(rng.range(-1.0, 2.0)) };
            let t1 = if rng.below(2) == 0 { R::MAX } else { R::from_f64(rng.range(0.0, 9.0)) };
            let want = b.clip(&ray, t0, t1);
            assert_eq!(Inverse::new(&ray, false, R::ZERO).clip(&b, t0, t1), want, "{ray:?} on [{t0:?}, {t1:?}]");
            inside += usize::from(b.strictly_holds(ray.origin));
        }
        // Both of the clip's ways were taken.
        assert!(inside > 5_000 && inside < 95_000, "{inside} rays from inside");
    }

    #[test]
    fn a_walk_clips_a_lattice_box_as_the_box_clips_the_ray() {
        clips_as_the_box_does::<f64>();
        clips_as_the_box_does::<f32>();
        clips_as_the_box_does::<Fx>();
    }
}
