//! Machine-readable statistics (`render --json`, `stats --json`): the work the core counted,
//! with stable field names, documented in docs/json.md. The same values the text output prints.

use lattice_rt::{Lattice, Real, Stats};
use serde::Serialize;

/// Rays (or hits) by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ByKind {
    /// Eye (primary) rays.
    pub eye: u64,
    /// Shadow rays (hits: blocked).
    pub shadow: u64,
    /// Mirror rays.
    pub reflection: u64,
    /// Transmitted rays.
    pub refraction: u64,
    /// All four.
    pub total: u64,
}

impl ByKind {
    /// The four counts of the core's order (eye, shadow, reflection, refraction).
    pub fn of(v: [u64; 4]) -> ByKind {
        ByKind { eye: v[0], shadow: v[1], reflection: v[2], refraction: v[3], total: v.iter().sum() }
    }
}

/// What one render counted.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Work {
    /// Rays traced by kind.
    pub rays: ByKind,
    /// Of those, rays that hit an object (a shadow ray that hits is blocked).
    pub hits: ByKind,
    /// Exact ray-object intersection tests.
    pub object_tests: u64,
    /// Bounding-box inside tests (the paper's baseline method, and a lattice walk's box test
    /// before an object's own).
    pub inside_tests: u64,
    /// Lattice cells entered (the world lattice and sub-lattices).
    pub cells_visited: u64,
    /// Eye-ray object tests skipped because the ray passes outside the object's window.
    pub culled: u64,
    /// Wall time, milliseconds.
    pub time_ms: f64,
}

impl Work {
    /// The counts of `s` and the time taken.
    pub fn of(s: &Stats, elapsed: std::time::Duration) -> Work {
        Work {
            rays: ByKind::of(s.rays),
            hits: ByKind::of(s.hits),
            object_tests: s.object_tests,
            inside_tests: s.inside_tests,
            cells_visited: s.cells_visited,
            culled: s.culled,
            time_ms: elapsed.as_secs_f64() * 1e3,
        }
    }
}

/// A lattice's size.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LatticeSize {
    /// Cells per axis of the world lattice, then of each sub-lattice.
    pub lattices: Vec<[u32; 3]>,
    /// Cells of all lattices.
    pub cells: usize,
    /// Object references in the cells.
    pub references: usize,
    /// Bytes of lattice storage (lattices, coordinate lists, cells, references).
    pub bytes: usize,
}

impl LatticeSize {
    /// The size of `l`.
    pub fn of<R: Real>(l: &Lattice<'_, R>) -> LatticeSize {
        LatticeSize {
            lattices: l.lattices().iter().map(|g| [u32::from(g.n[0]), u32::from(g.n[1]), u32::from(g.n[2])]).collect(),
            cells: l.cell_count(),
            references: l.ref_count(),
            bytes: l.bytes(),
        }
    }
}

/// `render --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderReport {
    /// The scene file (`-`: standard input).
    pub scene: String,
    /// `f64`, `f32` or `fixed`.
    pub scalar: &'static str,
    /// `lattice`, `bbox` or `brute`.
    pub accel: &'static str,
    /// Frame width in pixels.
    pub width: u16,
    /// Frame height in pixels.
    pub height: u16,
    /// The lattice built (absent for `bbox` and `brute`).
    pub lattice: Option<LatticeSize>,
    /// What the render counted.
    pub work: Work,
}

/// One method's figures in `stats --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodWork {
    /// `lattice`, `bbox`, `brute`, or `default` (the tracer's own choice for eye rays).
    pub method: &'static str,
    /// Object tests per eye ray.
    pub object_tests_per_eye_ray: f64,
    /// Inside (bounding-box) tests per eye ray.
    pub inside_tests_per_eye_ray: f64,
    /// Cells visited per eye ray.
    pub cells_per_eye_ray: f64,
}

/// One method's full render in `stats --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodRender {
    /// `lattice`, `bbox` or `brute`.
    pub method: &'static str,
    /// Median wall time of the interleaved runs, milliseconds.
    pub median_ms: f64,
    /// The last run's counts.
    pub work: Work,
}

/// `stats --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StatsReport {
    /// The scene file (`-`: standard input).
    pub scene: String,
    /// `f64`, `f32` or `fixed`.
    pub scalar: &'static str,
    /// Frame width used to count work per ray.
    pub width: u16,
    /// Frame height.
    pub height: u16,
    /// Objects (primitives).
    pub objects: usize,
    /// Composite objects.
    pub composites: usize,
    /// Materials.
    pub materials: usize,
    /// Lights.
    pub lights: usize,
    /// Maximum depth of the intersection tree.
    pub depth: u8,
    /// The effects the scene calls for (`shadows`, `reflection`, `refraction`, `composites`).
    pub effects: Vec<&'static str>,
    /// The lattice built.
    pub lattice: LatticeSize,
    /// Lattice build time, milliseconds.
    pub build_ms: f64,
    /// Eye rays alone, each method answering every one (the paper's Table 1), then `default`.
    pub per_eye_ray: Vec<MethodWork>,
    /// Full renders with the tracer's defaults.
    pub full_render: Vec<MethodRender>,
    /// Whether every method drew the same frame.
    pub identical: bool,
}

/// Prints `v` as pretty JSON on standard output.
pub fn print_json(v: &impl Serialize) -> anyhow::Result<()> {
    crate::say!("{}", serde_json::to_string_pretty(v)?)?;
    Ok(())
}

/// `stats --spd --json`: the SPD protocol's counts (`crate::spd::protocol`).
#[derive(Clone, Debug, Serialize)]
pub struct SpdReport {
    /// Scene file.
    pub scene: String,
    /// Numeric type.
    pub scalar: &'static str,
    /// Objects (a polygon counts its triangles).
    pub objects: usize,
    /// The lattice's shape and memory.
    pub lattice: LatticeSize,
    /// One count with the lattice alone (as Havran measured), one with the tracer's defaults.
    pub counts: Vec<crate::spd::protocol::Count>,
}
