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

use crate::accel::{offer, Accelerator, Hit, Query};
use crate::math::{Aabb, Ray, Vec3};
use crate::scalar::Real;
use crate::scene::{Scene, NO_GROUP};
use core::fmt;

/// Marks a reference to a sub-lattice (composite) rather than an object.
const SUB_FLAG: u32 = 1 << 31;
/// Deepest nesting of lattices: the world and one level of composites.
pub const MAX_NESTING: usize = 2;

/// How the coordinate lists of a lattice are chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resolution {
    /// Cost heuristic: about `density * items` cells in all, shaped like the box
    /// (cells per axis proportional to the extent times the cube root of the item count).
    Auto {
        /// Target cells per item.
        density: f64,
    },
    /// A fixed number of equal cells per axis.
    Uniform([u16; 3]),
}

/// Where the planes of a coordinate list go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// Equal cells.
    Uniform,
    /// The paper's free coordinate lists `X(), Y(), Z()`: planes at quantiles of an even mix of
    /// the items' box centres and a uniform spread along each axis, so crowded regions get
    /// narrow cells while empty ones are not left with a few huge cells.
    Adaptive,
}

/// Choices for building a lattice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatticeConfig {
    /// Resolution of the world lattice.
    pub top: Resolution,
    /// Resolution of each composite's sub-lattice.
    pub sub: Resolution,
    /// Upper bound on cells per axis for [`Resolution::Auto`].
    pub max_per_axis: u16,
    /// Where the planes go.
    pub spacing: Spacing,
    /// Whether composites get sub-lattices (the paper's hierarchy); if not, their primitives
    /// are listed in the world lattice like any other (a flat lattice).
    pub nested: bool,
}

impl Default for LatticeConfig {
    fn default() -> Self {
        LatticeConfig {
            top: Resolution::Auto { density: 2.0 },
            sub: Resolution::Auto { density: 2.0 },
            max_per_axis: 64,
            spacing: Spacing::Uniform,
            nested: true,
        }
    }
}

/// Most cells per axis of any lattice.
pub const MAX_PER_AXIS: u16 = 1024;

/// One lattice (the world's or a composite's sub-lattice) inside the shared storage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid<R> {
    /// The region the lattice covers.
    pub bounds: Aabb<R>,
    /// Cells per axis.
    pub n: [u16; 3],
    /// Where each axis' coordinate list (`n + 1` entries) starts in the coordinate storage.
    pub coord_start: [u32; 3],
    /// Index of the first cell in the cell storage.
    pub cell_start: u32,
}

impl<R: Real> Grid<R> {
    /// An unused slot (for static storage arrays).
    pub const EMPTY: Self = Grid {
        bounds: Aabb {
            min: Vec3 { x: R::ZERO, y: R::ZERO, z: R::ZERO },
            max: Vec3 { x: R::ZERO, y: R::ZERO, z: R::ZERO },
        },
        n: [0; 3],
        coord_start: [0; 3],
        cell_start: 0,
    };
    fn cells(&self) -> usize {
        self.n.iter().map(|&v| v as usize).product()
    }
}

/// Caller-provided storage for a lattice.
#[derive(Debug)]
pub struct LatticeStorage<'a, R> {
    /// One entry per lattice (world + one per composite).
    pub grids: &'a mut [Grid<R>],
    /// All coordinate lists, concatenated.
    pub coords: &'a mut [R],
    /// Cells and references in one pool: per cell the index of its first reference (one
    /// extra entry at the end), then the references (object indices, or `SUB_FLAG |
    /// composite index`). Words beyond those are left to the caller ([`Lattice::build_leaving`]).
    pub words: &'a mut [u32],
}

/// How much storage a scene's lattice needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatticeSizes {
    /// Lattices (world and sub-lattices).
    pub grids: usize,
    /// Coordinate-list entries.
    pub coords: usize,
    /// Cell entries (cells + 1).
    pub cells: usize,
    /// References.
    pub refs: usize,
}

impl LatticeSizes {
    /// Words of [`LatticeStorage::words`] the lattice takes: its cells and references.
    pub fn words(&self) -> usize {
        self.cells + self.refs
    }
}

/// A storage slice too small for the lattice.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatticeError {
    /// Which storage ran out ("grids", "coords", "cells", "refs").
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

/// A built lattice over a scene.
#[derive(Debug)]
pub struct Lattice<'a, R> {
    grids: &'a [Grid<R>],
    coords: &'a [R],
    cells: &'a [u32],
    refs: &'a [u32],
    /// Objects in the scene it was built for (mailbox entries of composites follow them).
    objects: usize,
}

/// The items one lattice holds: the world holds free objects and composites, a sub-lattice
/// the objects of its composite.
fn for_each_item<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, grid: usize, mut f: impl FnMut(u32, &Aabb<R>)) {
    if grid == 0 {
        for (i, o) in scene.objects.iter().enumerate() {
            if o.group == NO_GROUP || !cfg.nested {
                f(i as u32, &o.bounds);
            }
        }
        if cfg.nested {
            for (g, grp) in scene.groups.iter().enumerate() {
                f(SUB_FLAG | g as u32, &grp.bounds);
            }
        }
    } else {
        let grp = &scene.groups[grid - 1];
        for i in grp.first as usize..grp.first as usize + grp.len as usize {
            f(i as u32, &scene.objects[i].bounds);
        }
    }
}

/// Cells per axis of lattice `g`.
fn grid_resolution<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, b: &Aabb<R>) -> [u16; 3] {
    let mut items = 0;
    for_each_item(scene, cfg, g, |_, _| items += 1);
    resolution(b, items, if g == 0 { cfg.top } else { cfg.sub }, cfg.max_per_axis)
}

fn grid_bounds<R: Real>(scene: &Scene<'_, R>, grid: usize) -> Aabb<R> {
    if grid == 0 {
        scene.world
    } else {
        scene.groups[grid - 1].bounds
    }
}

fn resolution<R: Real>(b: &Aabb<R>, items: usize, res: Resolution, max_axis: u16) -> [u16; 3] {
    match res {
        Resolution::Uniform(n) => n.map(|v| v.clamp(1, MAX_PER_AXIS)),
        Resolution::Auto { density } => {
            let ext = [0, 1, 2].map(|a| (b.max.axis(a) - b.min.axis(a)).to_f64().max(0.0));
            let longest = ext.iter().cloned().fold(0.0f64, f64::max);
            if longest <= 0.0 {
                return [1; 3];
            }
            // Cells ~ density * items; axes with a tiny extent are given at least one cell, so
            // the volume of the others is used (a flat box does not get a huge cell count).
            let floor = longest / max_axis as f64;
            let vol: f64 = ext.iter().map(|e| e.max(floor)).product();
            let k = libm::cbrt(density * items.max(1) as f64 / vol);
            ext.map(|e| (libm::round(e * k) as u16).clamp(1, max_axis.min(MAX_PER_AXIS)))
        }
    }
}

/// Plane `i` of a uniform coordinate list of `n` cells over `[lo, hi]`, computed from the
/// index (never accumulated); the last plane is exactly `hi`.
fn uniform_coord<R: Real>(lo: R, hi: R, n: u16, i: usize) -> R {
    if i == n as usize {
        hi
    } else {
        lo + (hi - lo) / R::from_i32(n as i32) * R::from_i32(i as i32)
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

/// Writes the `n + 1` planes of axis `a` of lattice `g` (bounds `b`) into `out`.
fn axis_planes<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, a: usize, b: &Aabb<R>, n: u16, out: &mut [R]) {
    let (lo, hi) = (b.min.axis(a), b.max.axis(a));
    match cfg.spacing {
        Spacing::Uniform => {
            for (i, c) in out.iter_mut().enumerate().take(n as usize + 1) {
                *c = uniform_coord(lo, hi, n, i);
            }
        }
        Spacing::Adaptive => adaptive_planes(scene, cfg, g, a, lo, hi, n, out),
    }
}

/// Planes at quantiles of the box centres mixed with a uniform spread, from a histogram of
/// 1024 bins (no allocation, no sorting). Out of line so its 4 KB histogram is only on the stack when used.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn adaptive_planes<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, a: usize, lo: R, hi: R, n: u16, out: &mut [R]) {
    const BINS: usize = 1024;
    let (l, h) = (lo.to_f64(), hi.to_f64());
    let width = (h - l).max(f64::MIN_POSITIVE);
    let mut hist = [0u32; BINS];
    let mut total = 0u32;
    for_each_item(scene, cfg, g, |_, ib| {
        let c = (ib.min.axis(a).to_f64() + ib.max.axis(a).to_f64()) * 0.5;
        let bin = (((c - l) / width) * BINS as f64).clamp(0.0, (BINS - 1) as f64) as usize;
        hist[bin] += 1;
        total += 1;
    });
    out[0] = lo;
    out[n as usize] = hi;
    // Planes at quantiles of a half-and-half mixture of the box centres and a uniform spread:
    // crowded regions get narrow cells without starving the empty ones.
    let share = |bin: usize, below: u32| 0.5 * bin as f64 / BINS as f64 + 0.5 * below as f64 / total.max(1) as f64;
    let (mut bin, mut below) = (0usize, 0u32);
    for (i, plane) in out.iter_mut().enumerate().take(n as usize).skip(1) {
        let target = i as f64 / n as f64;
        while bin < BINS - 1 && share(bin + 1, below + hist[bin]) <= target {
            below += hist[bin];
            bin += 1;
        }
        // Interpolate inside the bin, where the mixture grows linearly.
        let (a, b) = (share(bin, below), share(bin + 1, below + hist[bin]));
        let frac = if b > a { ((target - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
        *plane = R::from_f64(l + width * (bin as f64 + frac) / BINS as f64);
    }
    // Keep the list non-decreasing after rounding.
    for i in 1..=n as usize {
        if out[i] < out[i - 1] {
            out[i] = out[i - 1];
        }
    }
}

/// Storage entries of the planes of one lattice and of the references to its cells.
#[inline(never)]
fn plan_grid<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, b: &Aabb<R>, n: [u16; 3]) -> usize {
    let mut planes = [[R::ZERO; MAX_PER_AXIS as usize + 1]; 3];
    for (a, p) in planes.iter_mut().enumerate() {
        axis_planes(scene, cfg, g, a, b, n[a], p);
    }
    let mut refs = 0;
    for_each_item(scene, cfg, g, |_, ib| {
        let mut count = 1usize;
        for a in 0..3 {
            let c = &planes[a][..n[a] as usize + 1];
            count *= locate(c, ib.max.axis(a)) - locate(c, ib.min.axis(a)) + 1;
        }
        refs += count;
    });
    refs
}

/// [`locate_by`] over a stored coordinate list (`n + 1` entries).
#[inline]
fn locate<R: Real>(c: &[R], x: R) -> usize {
    locate_by(c.len() - 1, x, |i| c[i])
}

/// Cell index range `[lo, hi]` per axis overlapped by a box.
fn cell_range<R: Real>(coords: &[R], g: &Grid<R>, b: &Aabb<R>) -> [(usize, usize); 3] {
    [0, 1, 2].map(|a| {
        let s = g.coord_start[a] as usize;
        let c = &coords[s..s + g.n[a] as usize + 1];
        (locate(c, b.min.axis(a)), locate(c, b.max.axis(a)))
    })
}

impl<'a, R: Real> Lattice<'a, R> {
    /// Storage a scene needs with this configuration.
    pub fn plan(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> LatticeSizes {
        let grids = if cfg.nested { 1 + scene.groups.len() } else { 1 };
        let mut s = LatticeSizes { grids, cells: 1, ..Default::default() };
        for g in 0..grids {
            let b = grid_bounds(scene, g);
            let n = grid_resolution(scene, cfg, g, &b);
            s.coords += n.iter().map(|&v| v as usize + 1).sum::<usize>();
            s.cells += n.iter().map(|&v| v as usize).product::<usize>();
            s.refs += plan_grid(scene, cfg, g, &b, n);
        }
        s
    }

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
        let LatticeStorage { grids, coords, words } = storage;
        let ngrids = if cfg.nested { 1 + scene.groups.len() } else { 1 };
        if grids.len() < ngrids {
            return Err(LatticeError { capacity: "grids", needed: ngrids, available: grids.len() });
        }
        // Coordinate lists and cell ranges.
        let (mut nc, mut ncells) = (0usize, 0usize);
        for (g, slot) in grids.iter_mut().enumerate().take(ngrids) {
            let b = grid_bounds(scene, g);
            let n = grid_resolution(scene, cfg, g, &b);
            let mut grid = Grid { bounds: b, n, coord_start: [0; 3], cell_start: ncells as u32 };
            for a in 0..3 {
                let need = nc + n[a] as usize + 1;
                if need > coords.len() {
                    let total: usize = (0..ngrids)
                        .map(|g| grid_resolution(scene, cfg, g, &grid_bounds(scene, g)).iter().map(|&v| v as usize + 1).sum::<usize>())
                        .sum();
                    return Err(LatticeError { capacity: "coords", needed: total, available: coords.len() });
                }
                grid.coord_start[a] = nc as u32;
                axis_planes(scene, cfg, g, a, &b, n[a], &mut coords[nc..need]);
                nc = need;
            }
            ncells += grid.cells();
            *slot = grid;
        }
        if ncells + 1 > words.len() {
            return Err(LatticeError { capacity: "cells", needed: ncells + 1, available: words.len() });
        }
        let (cells, refs) = words.split_at_mut(ncells + 1);
        cells.iter_mut().for_each(|c| *c = 0);
        // Pass 1: count references per cell (into cells[i + 1]).
        let mut nrefs = 0usize;
        for (g, grid) in grids.iter().enumerate().take(ngrids) {
            for_each_item(scene, cfg, g, |_, ib| {
                visit_cells(coords, grid, ib, |c| {
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
        for (g, grid) in grids.iter().enumerate().take(ngrids) {
            for_each_item(scene, cfg, g, |item, ib| {
                visit_cells(coords, grid, ib, |c| {
                    refs[cells[c] as usize] = item;
                    cells[c] += 1;
                });
            });
        }
        for i in (1..cells.len()).rev() {
            cells[i] = cells[i - 1];
        }
        cells[0] = 0;
        let lattice = Lattice { grids: &grids[..ngrids], coords: &coords[..nc], cells, refs, objects: scene.objects.len() };
        Ok((lattice, rest))
    }

    /// Bytes the built lattice occupies (grids, coordinate lists, cells, references).
    pub fn bytes(&self) -> usize {
        size_of_val(self.grids)
            + size_of_val(self.coords)
            + size_of_val(self.cells)
            + size_of_val(self.refs)
    }

    /// The lattices: index 0 is the world, then one per composite.
    pub fn grids(&self) -> &[Grid<R>] {
        self.grids
    }

    /// Number of cells over all lattices.
    pub fn cell_count(&self) -> usize {
        self.cells.len() - 1
    }

    /// Number of references over all cells.
    pub fn ref_count(&self) -> usize {
        self.refs.len()
    }

    /// The coordinate list of lattice `g` along `axis`.
    pub fn coordinate_list(&self, g: usize, axis: usize) -> &[R] {
        let grid = &self.grids[g];
        let s = grid.coord_start[axis] as usize;
        &self.coords[s..s + grid.n[axis] as usize + 1]
    }

    /// Calls `visit(grid, cell_index, t_enter, t_exit)` for every cell of the world lattice the
    /// ray enters, in order, without testing objects (for tests and statistics).
    pub fn walk_cells(&self, ray: &Ray<R>, tmin: R, tmax: R, mut visit: impl FnMut([usize; 3], R, R)) {
        let inv = Inverse::new(ray);
        let Some((t0, t1)) = self.grids[0].bounds.clip(ray, tmin, tmax) else { return };
        let mut w = Walker::start(self, 0, ray, &inv, t0, t1);
        let mut enter = t0;
        loop {
            let exit = w.exit();
            visit(w.idx.map(|v| v as usize), enter, exit.min(t1));
            enter = exit;
            if !w.advance(self, ray, &inv) {
                break;
            }
        }
    }

    fn run(&self, scene: &Scene<'_, R>, ray: &Ray<R>, tmin: R, tmax: R, any: bool, q: &mut Query<'_>) -> Option<Hit<R>> {
        let (t0, t1) = self.grids[0].bounds.clip(ray, tmin, tmax)?;
        q.next_ray();
        let inv = Inverse::new(ray);
        let mut best: Option<Hit<R>> = None;
        let mut stack: [Option<Walker<R>>; MAX_NESTING] = [None; MAX_NESTING];
        let mut depth = 1;
        stack[0] = Some(Walker::start(self, 0, ray, &inv, t0, t1));
        q.stats.cells_visited += 1;
        while depth > 0 {
            let Some(w) = stack[depth - 1].as_mut() else { break };
            if w.ref_i < w.ref_end {
                let item = self.refs[w.ref_i as usize];
                w.ref_i += 1;
                if item & SUB_FLAG == 0 {
                    let i = item as usize;
                    if q.first_visit(i) && offer(scene, i, ray, tmin, tmax, &mut best, &mut q.stats) && any {
                        return best;
                    }
                } else {
                    let g = (item & !SUB_FLAG) as usize + 1;
                    let limit = best.map_or(tmax, |b| b.t);
                    if depth < MAX_NESTING && q.first_visit(self.objects + g - 1) {
                        if let Some((a, b)) = self.grids[g].bounds.clip(ray, tmin, limit) {
                            stack[depth] = Some(Walker::start(self, g, ray, &inv, a, b));
                            depth += 1;
                            q.stats.cells_visited += 1;
                        }
                    }
                }
                continue;
            }
            // The cell is done: stop if the best hit lies before its exit, else step.
            let done = best.is_some_and(|b| b.t < w.exit());
            if done || !w.advance(self, ray, &inv) {
                depth -= 1;
            } else {
                q.stats.cells_visited += 1;
            }
        }
        best
    }
}

/// Which axes a ray steps along (a zero component, +0.0 or -0.0, never steps).
///
/// Crossings are `(plane - o) / d`, one correctly rounded division, rather than a product with
/// a precomputed reciprocal: the reciprocal of a small component is coarse in fixed point, and
/// the division keeps every scalar's crossing within one rounding of the exact one.
struct Inverse<R> {
    moves: [bool; 3],
    _r: core::marker::PhantomData<R>,
}

impl<R: Real> Inverse<R> {
    fn new(ray: &Ray<R>) -> Self {
        let d = [ray.dir.x, ray.dir.y, ray.dir.z];
        Inverse { moves: d.map(|v| v != R::ZERO), _r: core::marker::PhantomData }
    }
}

/// The state of a walk through one lattice (one entry of the explicit stack).
#[derive(Clone, Copy, Debug)]
struct Walker<R> {
    grid: u16,
    idx: [i32; 3],
    step: [i32; 3],
    t_next: [R; 3],
    t_end: R,
    ref_i: u32,
    ref_end: u32,
}

impl<R: Real> Walker<R> {
    fn start(l: &Lattice<'_, R>, grid: usize, ray: &Ray<R>, inv: &Inverse<R>, t0: R, t1: R) -> Self {
        let g = &l.grids[grid];
        let p = ray.at(t0);
        let mut w = Walker {
            grid: grid as u16,
            idx: [0; 3],
            step: [0; 3],
            t_next: [R::MAX; 3],
            t_end: t1,
            ref_i: 0,
            ref_end: 0,
        };
        for a in 0..3 {
            let c = l.coordinate_list(grid, a);
            // With a zero direction component the coordinate is the origin's, exactly.
            let x = if inv.moves[a] { p.axis(a) } else { ray.origin.axis(a) };
            let i = locate(c, x);
            w.idx[a] = i as i32;
            if inv.moves[a] {
                let forward = ray.dir.axis(a) > R::ZERO;
                w.step[a] = if forward { 1 } else { -1 };
                let plane = if forward { c[i + 1] } else { c[i] };
                w.t_next[a] = (plane - ray.origin.axis(a)) / ray.dir.axis(a);
            }
        }
        w.load_cell(l, g);
        w
    }

    fn load_cell(&mut self, l: &Lattice<'_, R>, g: &Grid<R>) {
        let (nx, ny) = (g.n[0] as usize, g.n[1] as usize);
        let c = g.cell_start as usize + self.idx[0] as usize + nx * (self.idx[1] as usize + ny * self.idx[2] as usize);
        self.ref_i = l.cells[c];
        self.ref_end = l.cells[c + 1];
    }

    /// Parameter where the ray leaves the current cell.
    #[inline]
    fn exit(&self) -> R {
        self.t_next[0].min(self.t_next[1]).min(self.t_next[2])
    }

    /// Steps to the neighbouring cell; false when the ray leaves the lattice or its range.
    fn advance(&mut self, l: &Lattice<'_, R>, ray: &Ray<R>, inv: &Inverse<R>) -> bool {
        // Tie rule: x before y before z (strict comparisons keep the earlier axis).
        let mut a = 0;
        if self.t_next[1] < self.t_next[a] {
            a = 1;
        }
        if self.t_next[2] < self.t_next[a] {
            a = 2;
        }
        if !inv.moves[a] || self.t_next[a] > self.t_end {
            return false;
        }
        let g = &l.grids[self.grid as usize];
        let i = self.idx[a] + self.step[a];
        if i < 0 || i >= g.n[a] as i32 {
            return false;
        }
        self.idx[a] = i;
        let c = l.coordinate_list(self.grid as usize, a);
        let plane = if self.step[a] > 0 { c[i as usize + 1] } else { c[i as usize] };
        self.t_next[a] = (plane - ray.origin.axis(a)) / ray.dir.axis(a);
        self.load_cell(l, g);
        true
    }
}

/// Calls `f` with the global cell index of every cell of `grid` a box overlaps.
fn visit_cells<R: Real>(coords: &[R], grid: &Grid<R>, b: &Aabb<R>, mut f: impl FnMut(usize)) {
    let r = cell_range(coords, grid, b);
    let (nx, ny) = (grid.n[0] as usize, grid.n[1] as usize);
    for z in r[2].0..=r[2].1 {
        for y in r[1].0..=r[1].1 {
            for x in r[0].0..=r[0].1 {
                f(grid.cell_start as usize + x + nx * (y + ny * z));
            }
        }
    }
}

impl<R: Real> Accelerator<R> for Lattice<'_, R> {
    fn name(&self) -> &'static str {
        "lattice"
    }
    fn nearest(&self, scene: &Scene<'_, R>, ray: &Ray<R>, tmin: R, tmax: R, q: &mut Query<'_>) -> Option<Hit<R>> {
        self.run(scene, ray, tmin, tmax, false, q)
    }
    fn occluded(&self, scene: &Scene<'_, R>, ray: &Ray<R>, tmin: R, tmax: R, q: &mut Query<'_>) -> bool {
        self.run(scene, ray, tmin, tmax, true, q).is_some()
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
        let mut b = SceneBuilder::new(&mut st);
        random_scene(&mut b, &RandomScene { objects: n, group_size: group, spread: 0.0, seed: 7 }).unwrap();
        let scene = b.finish().unwrap();
        let s = Lattice::plan(&scene, &cfg);
        let (mut g, mut c, mut w) = (vec![Grid::EMPTY; s.grids], vec![0.0; s.coords], vec![0; s.words()]);
        let lat = Lattice::build(&scene, &cfg, LatticeStorage { grids: &mut g, coords: &mut c, words: &mut w }).unwrap();
        assert_eq!((lat.grids.len(), lat.coords.len(), lat.cells.len(), lat.refs.len()), (s.grids, s.coords, s.cells, s.refs));
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
        let mut b = SceneBuilder::new(&mut st);
        random_scene(&mut b, &RandomScene { objects: 20, group_size: 5, spread: 0.0, seed: 3 }).unwrap();
        let scene = b.finish().unwrap();
        let cfg = LatticeConfig::default();
        let s = Lattice::plan(&scene, &cfg);
        let (mut g, mut c, mut w) = (vec![Grid::EMPTY; s.grids], vec![0.0; s.coords], vec![0; s.words() - 1]);
        let e = Lattice::build(&scene, &cfg, LatticeStorage { grids: &mut g, coords: &mut c, words: &mut w }).unwrap_err();
        assert_eq!(e, LatticeError { capacity: "refs", needed: s.refs, available: s.refs - 1 });
        let mut g2 = vec![Grid::EMPTY; 1];
        let e = Lattice::build(&scene, &cfg, LatticeStorage { grids: &mut g2, coords: &mut c, words: &mut w }).unwrap_err();
        assert_eq!(e.capacity, "grids");
        assert_eq!(std::format!("{e}"), "lattice capacity `grids` too small: 5 entries needed, 1 available");
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
                lat.walk_cells(&Ray::new(Vec3::new(x, y, z0), Vec3::new(dx, dy, 1.0)), 0.0, f64::MAX, |c, _, _| v.push(c));
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
