//! A lattice within a byte budget: the lattice whose storage fits [`LatticeConfig::budget`]
//! and whose estimated cost per ray is least.
//!
//! When the configured lattice fits it is built as it is: the budget is a cap. Otherwise the
//! search scales the configured resolutions down in steps of 3/4 (cells per item for
//! [`Resolution::Auto`], the cube root of that per axis for [`Resolution::Uniform`]), the world
//! lattice and the sub-lattices each on their own, and tries a flat lattice at each world
//! scale too. Of the lattices that fit it keeps the one of least estimated cost: per lattice,
//! the cells a ray crosses times (one step plus the tests of a cell's share of references),
//! a sub-lattice weighted by the chance that a ray through the world crosses its box (the
//! ratio of their surface areas). Indices are 16-bit whenever they fit
//! ([`LatticeConfig::index16`]). When not even one cell per lattice fits, building fails with
//! a `budget` [`LatticeError`] and the caller falls back to a method that keeps no lattice
//! (bounding boxes or brute force).

use super::plan::ray_cost;
use super::{Lattice, LatticeConfig, LatticeError, LatticeSizes, Resolution};
use crate::math::Aabb;
use crate::scalar::Real;
use crate::scene::Scene;
use core::fmt;

/// Scale of the resolution between two steps of the search.
const STEP: f64 = 0.75;
/// Most steps per lattice kind: 0.75^60 is 3e-8 of the configured cells.
const STEPS: i32 = 60;

/// What building within a budget chose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// The configuration built: resolutions as chosen, no budget.
    pub cfg: LatticeConfig,
    /// Its storage.
    pub sizes: LatticeSizes,
    /// Bytes it takes in the scalar it was chosen for.
    pub bytes: usize,
    /// Cells per axis of the world lattice.
    pub world: [u16; 3],
    /// Fraction of the configured cells per item kept in the world lattice and in the
    /// sub-lattices (1: as configured).
    pub scale: (f64, f64),
    /// Estimated cost of a ray, in cell steps (see the module's documentation).
    pub cost: f64,
    /// Whether it fits the budget (always, without one).
    pub fits: bool,
}

impl fmt::Display for Choice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.world;
        write!(f, "{x}x{y}x{z} world cells")?;
        if self.cfg.nested && self.sizes.lattices > 1 {
            write!(f, " + {} sub-lattices", self.sizes.lattices - 1)?;
        } else if !self.cfg.nested {
            write!(f, " (flat)")?;
        }
        write!(
            f,
            ", {} cells, {} references, {}-bit indices, {} bytes",
            self.sizes.cells - 1,
            self.sizes.refs,
            if self.sizes.narrow { 16 } else { 32 },
            self.bytes,
        )?;
        if self.scale != (1.0, 1.0) {
            write!(f, " ({:.3} of the configured cells per item, {:.3} in sub-lattices)", self.scale.0, self.scale.1)?;
        }
        if !self.fits {
            write!(f, ": over the budget")?;
        }
        Ok(())
    }
}

/// `res` with `scale` of its cells.
fn scaled(res: Resolution, scale: f64) -> Resolution {
    match res {
        Resolution::Auto { density } => Resolution::Auto { density: density * scale },
        Resolution::Uniform(n) => {
            let k = libm::cbrt(scale);
            Resolution::Uniform(n.map(|v| (libm::round(v as f64 * k) as u16).max(1)))
        }
    }
}

/// Surface area of a box (at least the smallest positive number, for ratios).
fn area<R: Real>(b: &Aabb<R>) -> f64 {
    let e = [0, 1, 2].map(|a| (b.max.axis(a) - b.min.axis(a)).to_f64().max(0.0));
    (2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])).max(f64::MIN_POSITIVE)
}

/// The configuration to build: `cfg` itself without a budget, else the search's choice.
pub(super) fn resolve<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Result<LatticeConfig, LatticeError> {
    let Some(budget) = cfg.budget else { return Ok(*cfg) };
    let c = Lattice::choose(scene, cfg);
    if c.fits {
        Ok(c.cfg)
    } else {
        Err(LatticeError { capacity: "budget", needed: c.bytes, available: budget })
    }
}

impl<R: Real> Lattice<'_, R> {
    /// The lattice [`Lattice::build`] makes with `cfg`: without a budget, or when it fits, the
    /// configuration as it is; else the one of least estimated cost that fits, or the smallest
    /// there is (`fits` false).
    pub fn choose(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Choice {
        let exact = LatticeConfig { budget: None, ..*cfg };
        let assess = |c: LatticeConfig, scale: (f64, f64)| {
            let (mut cost, mut world_area, mut world) = (0.0, 1.0, [1; 3]);
            let sizes = Lattice::plan_exact(scene, &c, |g, b, n, refs| {
                let here = ray_cost(n, refs);
                if g == 0 {
                    (world_area, world) = (area(b), n);
                    cost += here;
                } else {
                    cost += here * (area(b) / world_area).min(1.0);
                }
            });
            let bytes = sizes.bytes::<R>();
            Choice { cfg: c, sizes, bytes, world, scale, cost, fits: cfg.budget.is_none_or(|b| bytes <= b) }
        };
        let configured = assess(exact, (1.0, 1.0));
        if configured.fits {
            return configured;
        }
        let nested = cfg.nested && !scene.composites.is_empty();
        let (mut best, mut smallest): (Option<Choice>, Choice) = (None, configured);
        let mut keep = |c: Choice| {
            if c.fits && best.is_none_or(|b| c.cost < b.cost) {
                best = Some(c);
            }
            if c.bytes < smallest.bytes {
                smallest = c;
            }
        };
        for kt in 0..STEPS {
            let st = libm::pow(STEP, kt as f64);
            let top = scaled(cfg.top, st);
            // Flat: the world lattice lists every primitive.
            let flat = assess(LatticeConfig { top, nested: false, ..exact }, (st, st));
            let single = flat.sizes.cells == 2;
            keep(flat);
            // Nested: sub-lattices from as configured down to one cell each.
            let subs = if nested { 0..STEPS } else { 0..0 };
            for ks in subs {
                let ss = libm::pow(STEP, ks as f64);
                let c = assess(LatticeConfig { top, sub: scaled(cfg.sub, ss), ..exact }, (st, ss));
                let all_single = c.sizes.cells - 1 == c.sizes.lattices;
                keep(c);
                if all_single {
                    break;
                }
            }
            // One world cell cannot shrink further.
            if single {
                break;
            }
        }
        best.unwrap_or(smallest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{random_scene, RandomScene};
    use crate::lattice::{LatticeStorage, SubLattice};
    use crate::scene::{Object, SceneBuilder};
    use std::vec;

    #[test]
    fn a_budget_is_never_exceeded_and_the_choice_is_what_is_built() {
        let mut st = vec![Object::<f64>::default(); 200];
        let mut parts = crate::Parts::default();
        let mut b = SceneBuilder::new(&mut st, &mut parts);
        random_scene(&mut b, &RandomScene { objects: 200, composite_size: 20, spread: 0.0, seed: 5 }).unwrap();
        let scene = b.finish().unwrap();
        let full = Lattice::choose(&scene, &LatticeConfig::default());
        assert!(full.fits && full.scale == (1.0, 1.0) && full.sizes.narrow);
        let mut last = f64::MIN;
        let mut budgets = [full.bytes * 2, full.bytes, full.bytes / 2, full.bytes / 4, full.bytes / 16, 2000, 600, 64];
        budgets.sort_unstable_by(|a, b| b.cmp(a));
        for budget in budgets {
            let cfg = LatticeConfig { budget: Some(budget), ..LatticeConfig::default() };
            let c = Lattice::choose(&scene, &cfg);
            let s = Lattice::plan(&scene, &cfg);
            let (mut g, mut co, mut w) = (vec![SubLattice::EMPTY; s.lattices], vec![0.0; s.coords], vec![0; s.words()]);
            let built =
                Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut co, words: &mut w });
            if c.fits {
                let lat = built.unwrap();
                assert!(c.bytes <= budget && lat.bytes() == c.bytes, "{budget}: {c}");
                assert!(c.cost >= last, "a smaller budget never gives a lattice of less estimated cost: {c}");
                last = c.cost;
                if budget >= full.bytes {
                    assert_eq!(c.bytes, full.bytes, "a budget that holds the configured lattice keeps it");
                }
            } else {
                let e = built.unwrap_err();
                assert_eq!((e.capacity, e.needed, e.available), ("budget", c.bytes, budget));
                assert!(std::format!("{e}").contains("bytes needed"));
                assert!(
                    c.sizes.cells - 1 == c.sizes.lattices && c.bytes > budget,
                    "fails only below one cell per lattice: {c}"
                );
            }
        }
    }
}
