//! What a lattice is asked to be: its configuration ([`LatticeConfig`]) and the arithmetic of
//! uniform coordinate lists (how many cells per axis, where plane `i` goes), which both the
//! planner and the dense cells' own lattices use.

use crate::math::Aabb;
use crate::scalar::Real;

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
    /// A world cell holding more than this many free objects (of no composite) gets a
    /// sub-lattice of its own, built like a composite's (`sub` resolution); 0: never. Needs
    /// `nested`.
    pub split: u16,
    /// Whether cell starts and references may be 16-bit, two to a word, when they fit (at most
    /// 65 535 references, 32 767 objects and composites): the lattice's index memory halves.
    pub index16: bool,
    /// Most bytes the lattice may take ([`LatticeSizes::bytes`](super::LatticeSizes::bytes)); building then picks the
    /// lattice of least estimated cost within it (`Lattice::choose`). `None`: the resolutions
    /// as configured (feature `budget`).
    #[cfg(feature = "budget")]
    pub budget: Option<usize>,
}

impl Default for LatticeConfig {
    fn default() -> Self {
        LatticeConfig {
            top: Resolution::Auto { density: 2.0 },
            sub: Resolution::Auto { density: 2.0 },
            max_per_axis: 64,
            spacing: Spacing::Uniform,
            nested: true,
            split: 16,
            index16: true,
            #[cfg(feature = "budget")]
            budget: None,
        }
    }
}

/// Most cells per axis of any lattice.
pub const MAX_PER_AXIS: u16 = 1024;

pub(super) fn resolution<R: Real>(b: &Aabb<R>, items: usize, res: Resolution, max_axis: u16) -> [u16; 3] {
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
pub(super) fn uniform_coord<R: Real>(lo: R, hi: R, n: u16, i: usize) -> R {
    if i == n as usize {
        hi
    } else {
        lo + (hi - lo) / R::from_i32(n as i32) * R::from_i32(i as i32)
    }
}
