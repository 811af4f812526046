//! The SPD's testing protocol (its Readme, *Testing Procedures*), so that our ray counts are
//! comparable with the published ones: 512x512 pixels, one eye ray through each pixel
//! **corner** (513 x 513 = 263,169), a tree of depth 5 counting the eye ray as 1 (the tracer's
//! depth 4), no contribution cutoff, a shadow ray only where the surface faces the light,
//! a mirror ray from every surface with `Ks > 0`, Snell refraction with total internal
//! reflection reflected. The counts it gives are the ray invariants Havran and Sixta published
//! per scene (`docs/havran_stats_grids.txt` in the SPD).

use lattice_rt::accel::{RayKind, Stats};
use lattice_rt::camera::Camera;
use lattice_rt::trace::{EyeRays, Work};
use lattice_rt::{Accelerator, Ray, Real, Scene, Tracer};
use serde::Serialize;
use std::time::{Duration, Instant};

/// The protocol's image: 512 x 512 pixels, eye rays through their 513 x 513 corners.
pub const RESOLUTION: u16 = 512;

/// The tree's depth in the tracer's counting (the eye ray is depth 0; the SPD's 5 levels).
pub const DEPTH: u8 = 4;

/// How the tracer is set up for a count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Setup {
    /// The accelerator alone, as Havran measured the published structures: no mailbox, no
    /// shadow-ray coherence, no eye windows or hulls, no box test before an object's test.
    AsHavran,
    /// The tracer's own defaults where they apply to single rays: the mailbox, shadow-ray
    /// coherence, box tests (eye windows and per-tile lists need the tile loop: not here).
    Defaults,
}

/// The ray invariants of a scene under the protocol: the same for every correct ray tracer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Invariants {
    /// Eye rays cast (263,169).
    pub eye_rays: u64,
    /// Eye rays that hit an object.
    pub eye_hits: u64,
    /// Shadow rays cast.
    pub shadow_rays: u64,
    /// Shadow rays that hit an object before the light.
    pub shadow_blocked: u64,
    /// Reflection and refraction rays cast.
    pub secondary_rays: u64,
    /// Reflection and refraction rays that hit an object.
    pub secondary_hits: u64,
}

impl Invariants {
    /// The invariants of a run's statistics.
    pub fn of(s: &Stats) -> Self {
        let (p, sh, rl, rf) = (
            RayKind::Primary as usize,
            RayKind::Shadow as usize,
            RayKind::Reflection as usize,
            RayKind::Refraction as usize,
        );
        Invariants {
            eye_rays: s.rays[p],
            eye_hits: s.hits[p],
            shadow_rays: s.rays[sh],
            shadow_blocked: s.hits[sh],
            secondary_rays: s.rays[rl] + s.rays[rf],
            secondary_hits: s.hits[rl] + s.hits[rf],
        }
    }

    /// All rays cast.
    pub fn all_rays(&self) -> u64 {
        self.eye_rays + self.shadow_rays + self.secondary_rays
    }

    /// The invariants in the order of Havran's table, with their names.
    pub fn named(&self) -> [(&'static str, u64); 6] {
        [
            ("eye rays", self.eye_rays),
            ("eye rays hitting", self.eye_hits),
            ("shadow rays", self.shadow_rays),
            ("shadow rays blocked", self.shadow_blocked),
            ("secondary rays", self.secondary_rays),
            ("secondary rays hitting", self.secondary_hits),
        ]
    }
}

/// One count: the invariants, the work per ray (all rays) and the time it took.
#[derive(Clone, Debug, Serialize)]
pub struct Count {
    /// How the tracer was set up.
    pub setup: Setup,
    /// The ray invariants.
    pub invariants: Invariants,
    /// Object intersection tests per ray (Havran's N_IT).
    pub tests_per_ray: f64,
    /// Lattice cells stepped through per ray (Havran's N_TS).
    pub steps_per_ray: f64,
    /// Trace time, one thread (ms).
    pub ms: f64,
}

/// Traces `scene` (its camera fitted to a square frame) under the protocol with `accel`.
pub fn count<R: Real, A: Accelerator<R>>(scene: &Scene<'_, R>, accel: &A, setup: Setup) -> Count {
    let mut tracer = Tracer::new(scene, accel);
    // DEPTH is below the tracer's deepest (MAX_DEPTH): this cannot fail.
    let _ = tracer.set_max_depth(DEPTH);
    tracer.set_cutoff(R::ZERO);
    tracer.set_every_ray(true);
    tracer.set_eye_rays(EyeRays::Plain);
    let as_havran = setup == Setup::AsHavran;
    tracer.set_shadow_coherence(!as_havran);
    tracer.set_box_tests(!as_havran);
    let mut mailbox = vec![0u32; if as_havran { 0 } else { lattice_rt::accel::Query::mailbox_len(scene) }];
    let mut work = Work::new(&mut mailbox);
    let camera = scene.camera();
    let t0 = Instant::now();
    for y in 0..=i32::from(RESOLUTION) {
        for x in 0..=i32::from(RESOLUTION) {
            tracer.eye_sample(corner_ray(camera, x, y), None, &mut work);
        }
    }
    let took: Duration = t0.elapsed();
    let s = work.stats();
    let inv = Invariants::of(s);
    let rays = inv.all_rays().max(1) as f64;
    Count {
        setup,
        invariants: inv,
        tests_per_ray: s.object_tests as f64 / rays,
        steps_per_ray: s.cells_visited as f64 / rays,
        ms: took.as_secs_f64() * 1e3,
    }
}

/// The camera ray through pixel corner `(x, y)` of the protocol's image (0..=512 each).
pub fn corner_ray<R: Real>(camera: &Camera<R>, x: i32, y: i32) -> Ray<R> {
    let n = 2 * i32::from(RESOLUTION);
    camera.ray(2 * x, 2 * y, n, n)
}
