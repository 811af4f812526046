//! Planning a lattice: its resolution, where its planes go, and how much storage it needs.

use super::config::{resolution, uniform_coord, LatticeConfig, Resolution, Spacing, MAX_PER_AXIS};
use super::oriented::{count_cells, Oriented};
use super::{cluster, for_each_item, planes, Lattice};
use crate::math::Aabb;
use crate::scalar::Real;
use crate::scene::Scene;

/// How much storage a scene's lattice needs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatticeSizes {
    /// Lattices (world and sub-lattices).
    pub lattices: usize,
    /// Coordinate-list entries.
    pub coords: usize,
    /// Cell entries (cells + 1).
    pub cells: usize,
    /// References.
    pub refs: usize,
    /// Whether cell starts and references are 16-bit, two to a word.
    pub narrow: bool,
}

impl LatticeSizes {
    /// Words of [`LatticeStorage::words`](super::LatticeStorage::words) the lattice takes: its
    /// cell starts and references, each packed two to a word when narrow.
    pub fn words(&self) -> usize {
        super::index::words(self.cells, self.narrow) + super::index::words(self.refs, self.narrow)
    }

    /// Bytes the lattice takes in scalar `R`: lattice headers, coordinate lists and words.
    pub fn bytes<R>(&self) -> usize {
        self.lattices * size_of::<super::SubLattice<R>>() + self.coords * size_of::<R>() + self.words() * 4
    }
}
/// Cells per axis of lattice `g` over `b`. An automatic resolution with equal cells is then
/// moved by one cell on an axis whose planes fall on the items' faces ([`off_the_faces`]).
pub(super) fn lattice_resolution<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    b: &Aabb<R>,
) -> [u16; 3] {
    let mut count = 0;
    for_each_item(scene, cfg, g, |_, _| count += 1);
    let res = if g == 0 { cfg.top } else { cfg.sub };
    let mut n = resolution(b, count, res, cfg.max_per_axis);
    if g == 0 && matches!(res, Resolution::Auto { .. }) && cluster::possible(scene, cfg) {
        n = past_the_clusters(scene, cfg, b, n, count, res);
    }
    if let Resolution::Auto { density } = res {
        let coarser = |k: f64| resolution(b, count, Resolution::Auto { density: density * k }, cfg.max_per_axis);
        n = past_the_overlaps(n, count, coarser, |m| plan_refs(scene, cfg, g, b, m));
    }
    if matches!(res, Resolution::Auto { .. }) && cfg.spacing == Spacing::Uniform {
        off_the_faces(scene, cfg, g, b, n, count)
    } else {
        n
    }
}

/// The world resolution again for the items the world lattice keeps. Free objects crowded into
/// dense cells (module `cluster`) go to those cells' own lattices, so the world's cells need
/// not be fine enough for them: a loose cluster of thousands in a big sparse scene would
/// otherwise cut the whole scene into cells for thousands, and every ray would step through
/// that many empty cells. The world lattice keeps the items not centred in a dense cell, and one
/// reference per dense cell; with no dense cell, `n` stands.
#[inline(never)]
fn past_the_clusters<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    b: &Aabb<R>,
    n: [u16; 3],
    items: usize,
    res: Resolution,
) -> [u16; 3] {
    let (centred, cells) = with_planes(scene, cfg, 0, b, n, |planes| {
        let (mut centred, mut cells) = (0, 0);
        cluster::for_each_dense(scene, cfg, planes, |d| {
            centred += d.centred;
            cells += 1;
        });
        (centred, cells)
    });
    if cells == 0 {
        return n;
    }
    resolution(b, items.saturating_sub(centred) + cells, res, cfg.max_per_axis)
}

/// References per item above which [`past_the_overlaps`] looks for a coarser lattice.
const SPREAD: usize = 8;

/// Cost of an object test in cell steps, for [`ray_cost`].
const TEST: f64 = 2.0;

/// Estimated cost of a ray through a lattice of `n` cells per axis holding `refs` references,
/// in cell steps: the cells it crosses (half of them per axis, and the first) times one step
/// plus the tests of a cell's share of the references.
pub(super) fn ray_cost(n: [u16; 3], refs: usize) -> f64 {
    let cells = n.iter().map(|&v| v as f64).product::<f64>();
    let crossed = 1.0 + n.iter().map(|&v| v as f64).sum::<f64>() / 2.0;
    crossed * (1.0 + TEST * refs as f64 / cells)
}

/// A coarser resolution for items that overlap one another. Items at one place (5,000 spheres
/// written with one centre) or wrapped around each other are listed in every cell they span,
/// however fine the cells: finer cells then only multiply the references (millions of them,
/// for a lattice that separates nothing) and the steps of every ray. Lattices with an eighth of
/// the cells, then an eighth of that, down to one cell, are estimated ([`ray_cost`]); the least
/// costly is taken when it costs less than half what `n` does. Items that a finer lattice
/// separates, as in every scene made of parts, make the coarser lattices cost more, and `n`
/// stands. The search is made only when the `items` are listed in more than [`SPREAD`] cells
/// each on average (it costs a pass over them per candidate). `coarser(k)` is the resolution for `k` of the cells per item, `refs(m)` the
/// references of a lattice of `m` cells per axis.
fn past_the_overlaps(
    n: [u16; 3],
    items: usize,
    coarser: impl Fn(f64) -> [u16; 3],
    refs: impl Fn([u16; 3]) -> usize,
) -> [u16; 3] {
    let listed = refs(n);
    // Items listed in a few cells each are separated by the cells: no search.
    if listed <= SPREAD * items {
        return n;
    }
    let here = ray_cost(n, listed);
    let (mut best, mut least, mut scale) = (n, here, 1.0);
    let mut m = n;
    while m != [1; 3] {
        scale /= 8.0;
        let next = coarser(scale);
        // The search ends where the count stops shrinking (a resolution already clamped).
        if next.iter().map(|&v| v as usize).product::<usize>() >= m.iter().map(|&v| v as usize).product::<usize>() {
            break;
        }
        m = next;
        let cost = ray_cost(m, refs(m));
        if cost < least {
            (best, least) = (m, cost);
        }
    }
    if least < here / 2.0 {
        best
    } else {
        n
    }
}

/// A regular scene (a floor of equal tiles) whose pitch is the cell width puts every plane on
/// the items' faces, and each item, padded for rounding, then reaches a sliver into the cells
/// on both sides: three cells an axis instead of two. Per axis, of `n - 1`, `n` and `n + 1`
/// cells the count whose cells an item overlaps least beyond what a random placement gives
/// (`1 + extent / cell width`) is taken, when `n`'s excess is more than a quarter of a cell per
/// item: a scene without such a coincidence keeps `n`.
fn off_the_faces<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    b: &Aabb<R>,
    n: [u16; 3],
    items: usize,
) -> [u16; 3] {
    let max = cfg.max_per_axis.clamp(1, MAX_PER_AXIS);
    let cand = |a: usize, k: usize| (n[a] as i32 - 1 + k as i32).clamp(1, max as i32) as u16;
    let mut excess = [[0.0f64; 3]; 3];
    let range = [0, 1, 2].map(|a| (b.min.axis(a).to_f64(), b.max.axis(a).to_f64()));
    for_each_item(scene, cfg, g, |_, ib| {
        for (a, row) in excess.iter_mut().enumerate() {
            let (lo, hi) = range[a];
            if hi <= lo {
                continue;
            }
            let (x0, x1) = (ib.min.axis(a).to_f64().max(lo), ib.max.axis(a).to_f64().min(hi));
            for (k, e) in row.iter_mut().enumerate() {
                let m = cand(a, k) as f64;
                let w = (hi - lo) / m;
                // max/min, not clamp: clamp's assertion would link float formatting in.
                let cell = |x: f64| libm::floor((x - lo) / w).max(0.0).min(m - 1.0);
                *e += cell(x1) - cell(x0) + 1.0 - (1.0 + (x1 - x0).max(0.0) / w).min(m);
            }
        }
    });
    [0, 1, 2].map(|a| {
        let e = excess[a];
        let best = (0..3).min_by(|&i, &j| e[i].total_cmp(&e[j])).unwrap_or(1);
        if e[1] > 0.25 * items as f64 && e[best] < e[1] {
            cand(a, best)
        } else {
            n[a]
        }
    })
}

/// The region lattice `sub` covers: a composite's box, or for the world lattice the box of
/// every object. The paper's world range also holds the viewpoint, but no ray needs a cell
/// without objects: a ray from outside enters at the box (the walk clips every ray to it), and
/// the empty space between the eye and the scene costs no steps.
pub(super) fn lattice_bounds<R: Real>(scene: &Scene<'_, R>, sub: usize) -> Aabb<R> {
    if sub == 0 {
        let mut objects = scene.objects.iter().map(|o| o.bounds);
        match objects.next() {
            Some(first) => objects.fold(first, |b, o| b.union(&o)),
            None => scene.world,
        }
    } else {
        scene.composites[sub - 1].bounds
    }
}

/// Writes the `n + 1` planes of axis `a` of lattice `g` (bounds `b`) into `out`.
pub(super) fn axis_planes<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    a: usize,
    b: &Aabb<R>,
    n: u16,
    out: &mut [R],
) {
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
fn adaptive_planes<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    a: usize,
    lo: R,
    hi: R,
    n: u16,
    out: &mut [R],
) {
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

/// References to the cells of lattice `g` (over `b`, `n` cells per axis).
#[inline(never)]
fn plan_refs<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, g: usize, b: &Aabb<R>, n: [u16; 3]) -> usize {
    with_planes(scene, cfg, g, b, n, |planes| {
        let mut refs = 0;
        // The world lattice lists an object only in the cells its own box meets (module
        // `oriented`); a composite's lattice in every cell of its world box.
        for_each_item(scene, cfg, g, |item, ib| {
            let object = (g == 0 && item & super::index::SUB_FLAG == 0).then(|| &scene.objects[item as usize]);
            refs += count_cells(planes, ib, object.and_then(Oriented::of).as_ref());
        });
        refs
    })
}

/// `work` over the coordinate lists of lattice `g` over `b` with `n` cells per axis, as
/// [`axis_planes`] writes them: equal cells computed when asked, adaptive ones written into
/// lists on the stack (12 KB in fixed point for [`MAX_PER_AXIS`] planes an axis, out of line
/// so that only they pay it).
fn with_planes<R: Real, T>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    b: &Aabb<R>,
    n: [u16; 3],
    work: impl FnOnce(&dyn planes::Planes<R>) -> T,
) -> T {
    match cfg.spacing {
        Spacing::Uniform => work(&planes::Uniform { bounds: b, n }),
        Spacing::Adaptive => listed_planes(scene, cfg, g, b, n, work),
    }
}

/// [`with_planes`] for adaptive spacing.
#[inline(never)]
fn listed_planes<R: Real, T>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    g: usize,
    b: &Aabb<R>,
    n: [u16; 3],
    work: impl FnOnce(&dyn planes::Planes<R>) -> T,
) -> T {
    let mut planes = [[R::ZERO; MAX_PER_AXIS as usize + 1]; 3];
    for (a, p) in planes.iter_mut().enumerate() {
        axis_planes(scene, cfg, g, a, b, n[a], p);
    }
    work(&[0, 1, 2].map(|a| &planes[a][..n[a] as usize + 1]))
}
impl<R: Real> Lattice<'_, R> {
    /// Storage a scene needs with this configuration (within its budget, if it has one: see
    /// `Lattice::choose`).
    pub fn plan(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> LatticeSizes {
        #[cfg(feature = "budget")]
        return Self::choose(scene, cfg).sizes;
        #[cfg(not(feature = "budget"))]
        Self::plan_exact(scene, cfg, |_, _, _, _| {})
    }

    /// Storage a scene needs with these resolutions (no budget); `each(g, bounds, cells per
    /// axis, references)` sees every lattice on the way.
    pub(super) fn plan_exact(
        scene: &Scene<'_, R>,
        cfg: &LatticeConfig,
        mut each: impl FnMut(usize, &Aabb<R>, [u16; 3], usize),
    ) -> LatticeSizes {
        let mut s = LatticeSizes { cells: 1, ..Default::default() };
        plan_each(scene, cfg, |g, b, n, refs| {
            each(g, b, n, refs);
            s.lattices += 1;
            s.coords += n.iter().map(|&v| v as usize + 1).sum::<usize>();
            s.cells += n.iter().map(|&v| v as usize).product::<usize>();
            s.refs += refs;
        });
        s.narrow = cfg.index16 && super::index::fits16(s.refs, scene.objects.len(), s.lattices - 1);
        s
    }
}

/// Calls `f(g, bounds, cells per axis, references)` for every lattice `cfg` builds: the world,
/// the composites', then the dense cells'.
fn plan_each<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, mut f: impl FnMut(usize, &Aabb<R>, [u16; 3], usize)) {
    let lattices = if cfg.nested { 1 + scene.composites.len() } else { 1 };
    let wb = lattice_bounds(scene, 0);
    let wn = lattice_resolution(scene, cfg, 0, &wb);
    // A dense cell's free objects move to its own lattice, which the cell references instead.
    let mut moved = 0;
    plan_dense(scene, cfg, &wb, wn, |_, _, _, free| moved += free - 1);
    f(0, &wb, wn, plan_refs(scene, cfg, 0, &wb, wn) - moved);
    for g in 1..lattices {
        let b = lattice_bounds(scene, g);
        let n = lattice_resolution(scene, cfg, g, &b);
        f(g, &b, n, plan_refs(scene, cfg, g, &b, n));
    }
    let mut g = lattices;
    plan_dense(scene, cfg, &wb, wn, |b, n, refs, _| {
        f(g, b, n, refs);
        g += 1;
    });
}

/// Calls `f(bounds, cells per axis, references, free objects of the world cell)` for
/// the lattice of every dense world cell (module `cluster`) of the world lattice over `wb`.
#[inline(never)]
fn plan_dense<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    wb: &Aabb<R>,
    wn: [u16; 3],
    mut f: impl FnMut(&Aabb<R>, [u16; 3], usize, usize),
) {
    if !cluster::possible(scene, cfg) {
        return;
    }
    with_planes(scene, cfg, 0, wb, wn, |planes| {
        cluster::for_each_dense(scene, cfg, planes, |d| f(&d.bounds, d.n, d.refs, d.free))
    });
}
