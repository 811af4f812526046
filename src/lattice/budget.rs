//! A lattice within a byte budget: the densest lattice whose storage fits
//! [`LatticeConfig::budget`].
//!
//! The search scales the configured resolutions down in steps of 3/4 (cells per item for
//! [`Resolution::Auto`], the cube root of that per axis for [`Resolution::Uniform`]); at each
//! step it tries the configuration's sub-lattices, then a flat lattice. Indices are 16-bit
//! whenever they fit ([`LatticeConfig::index16`]). The first that fits is built; when not even a
//! single cell per lattice fits, building fails with a `budget` [`LatticeError`] and the
//! caller falls back to a method that needs no lattice (bounding boxes or brute force).

use super::plan::{lattice_bounds, lattice_resolution};
use super::{Lattice, LatticeConfig, LatticeError, LatticeSizes, Resolution};
use crate::scalar::Real;
use crate::scene::Scene;
use core::fmt;

/// Scale of the resolution between two steps of the search.
const STEP: f64 = 0.75;
/// Most steps: 0.75^80 is 1e-10 of the configured cells, far below one cell per lattice.
const STEPS: i32 = 80;

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
    /// Fraction of the configured cells per item kept (1: as configured).
    pub scale: f64,
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
            ", {} cells, {} references, {}-bit indices, {} bytes ({:.3} of the configured density)",
            self.sizes.cells - 1,
            self.sizes.refs,
            if self.sizes.narrow { 16 } else { 32 },
            self.bytes,
            self.scale
        )?;
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
    /// The lattice [`Lattice::build`] makes with `cfg`: without a budget the configuration as
    /// it is; with one the densest that fits, or the smallest there is (`fits` false).
    pub fn choose(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Choice {
        let exact = LatticeConfig { budget: None, ..*cfg };
        let choice = |c: LatticeConfig, scale: f64| {
            let sizes = Lattice::plan_exact(scene, &c);
            let bytes = sizes.bytes::<R>();
            let world = lattice_resolution(scene, &c, 0, &lattice_bounds(scene, 0));
            Choice { cfg: c, sizes, bytes, world, scale, fits: cfg.budget.is_none_or(|b| bytes <= b) }
        };
        let Some(_) = cfg.budget else { return choice(exact, 1.0) };
        let mut smallest: Option<Choice> = None;
        for k in 0..STEPS {
            let scale = libm::pow(STEP, k as f64);
            let c = LatticeConfig { top: scaled(cfg.top, scale), sub: scaled(cfg.sub, scale), ..exact };
            let shapes = if cfg.nested && !scene.composites.is_empty() { &[true, false][..] } else { &[cfg.nested][..] };
            let mut single = false;
            for &nested in shapes {
                let ch = choice(LatticeConfig { nested, ..c }, scale);
                if ch.fits {
                    return ch;
                }
                // One cell per lattice cannot shrink further.
                single = ch.sizes.cells - 1 == ch.sizes.lattices;
                if smallest.is_none_or(|s| ch.bytes < s.bytes) {
                    smallest = Some(ch);
                }
            }
            if single {
                break;
            }
        }
        smallest.expect("the search tries at least one lattice")
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
        let mut b = SceneBuilder::new(&mut st);
        random_scene(&mut b, &RandomScene { objects: 200, composite_size: 20, spread: 0.0, seed: 5 }).unwrap();
        let scene = b.finish().unwrap();
        let full = Lattice::choose(&scene, &LatticeConfig::default());
        assert!(full.fits && full.scale == 1.0 && full.sizes.narrow);
        let mut last = usize::MAX;
        let mut budgets = [full.bytes * 2, full.bytes, full.bytes / 2, full.bytes / 4, full.bytes / 16, 2000, 600, 64];
        budgets.sort_unstable_by(|a, b| b.cmp(a));
        for budget in budgets {
            let cfg = LatticeConfig { budget: Some(budget), ..LatticeConfig::default() };
            let c = Lattice::choose(&scene, &cfg);
            let s = Lattice::plan(&scene, &cfg);
            let (mut g, mut co, mut w) = (vec![SubLattice::EMPTY; s.lattices], vec![0.0; s.coords], vec![0; s.words()]);
            let built = Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut co, words: &mut w });
            if c.fits {
                let lat = built.unwrap();
                assert!(c.bytes <= budget && lat.bytes() == c.bytes, "{budget}: {c}");
                assert!(c.bytes <= last, "a smaller budget never gives a larger lattice");
                last = c.bytes;
                if budget >= full.bytes {
                    assert_eq!(c.bytes, full.bytes, "a budget that holds the configured lattice keeps it");
                }
            } else {
                let e = built.unwrap_err();
                assert_eq!((e.capacity, e.needed, e.available), ("budget", c.bytes, budget));
                assert!(std::format!("{e}").contains("bytes needed"));
                assert!(c.sizes.cells - 1 == c.sizes.lattices && c.bytes > budget, "fails only below one cell per lattice: {c}");
            }
        }
    }
}
