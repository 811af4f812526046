//! `cargo xtask bench`: the paper's Table 1 reproduced, then scaling to 100 000 primitives, and
//! the lattice's resolution choice against a sweep. Writes `docs/performance.md` and a plot.

use anyhow::Result;
use host_sim::load::{build_lattice, lattice_storage, object_storage, parse_scene, read, SceneStore};
use host_sim::output::write_atomic;
use host_sim::run::render_band;
use host_sim::shared::median;
use host_sim::shared::plot_link;
use lattice_rt::generate::{random_object, random_scene, RandomScene, Rng};
use lattice_rt::lattice::{Resolution, Spacing};
use lattice_rt::scene::Object;
use lattice_rt::{
    Accelerator, BoundingBox, BruteForce, Effects, EyeRays, Frame, LatticeConfig, Query, Ray, Scene, Tracer, Vec3,
};
use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

/// The paper's Table 1 (min:sec, IBM PC/AT): bounding box and lattice.
const PAPER: [(&str, usize, f64, f64); 4] = [
    ("chair", 7, 48.0 * 60.0 + 32.0, 19.0 * 60.0 + 30.0),
    ("desk", 17, 63.0 * 60.0 + 17.0, 23.0 * 60.0 + 54.0),
    ("polyhedron", 13, 55.0 * 60.0 + 24.0, 20.0 * 60.0 + 32.0),
    ("spheres", 2, 34.0 * 60.0 + 49.0, 17.0 * 60.0 + 20.0),
];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Method {
    Brute,
    Bbox,
    Flat,
    Nested,
    /// The nested lattice, its walk testing an object's box before the object
    /// (`Tracer::set_box_tests`).
    Boxes,
    /// The nested lattice with host-sim's default eye rays (object windows, `EyeRays`) and box tests.
    Windows,
}
const METHODS: [Method; 6] =
    [Method::Brute, Method::Bbox, Method::Flat, Method::Nested, Method::Boxes, Method::Windows];

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Brute => "brute force",
            Method::Bbox => "bounding box",
            Method::Flat => "flat lattice",
            Method::Nested => "nested lattice",
            Method::Boxes => "nested lattice + box tests",
            Method::Windows => "nested lattice + eye windows (default)",
        }
    }
}

/// Renders with one method; returns (render time, lattice build time, lattice bytes, stats, bits).
fn frame_with(
    scene: &Scene<'_, f64>,
    m: Method,
    frame: &Frame,
    primary_only: bool,
) -> Result<(Duration, Duration, usize, lattice_rt::Stats, Vec<u8>)> {
    let cfg = LatticeConfig { nested: m != Method::Flat, ..LatticeConfig::default() };
    let mut bufs = lattice_storage(scene, &cfg)?;
    let t0 = Instant::now();
    let lattice = build_lattice(&mut bufs, scene, &cfg)?;
    let build = t0.elapsed();
    let bytes = lattice.bytes();
    let a: &(dyn Accelerator<f64> + Sync) = match m {
        Method::Brute => &BruteForce,
        Method::Bbox => &BoundingBox,
        _ => &lattice,
    };
    let mut t = Tracer::new(scene, a);
    // The paper's methods as they were; the last row is what the tracer does by default.
    if m != Method::Windows {
        t.set_eye_rays(EyeRays::Plain);
    }
    t.set_box_tests(matches!(m, Method::Boxes | Method::Windows));
    if primary_only {
        t.set_max_depth(0).expect("depth 0 is always valid");
        t.set_effects(Effects::NONE);
    }
    let r = render_band(&t, frame, false)?;
    Ok((r.elapsed, build, bytes, r.stats, r.bits))
}

/// What [`per_ray`] measured: the median time per ray, and per ray the exact object tests, the
/// box (inside) tests before them and the lattice cells entered.
struct PerRay {
    time: Duration,
    tests: f64,
    boxes: f64,
    cells: f64,
}

/// Mean time and work per ray of `nearest` over a set of rays.
fn per_ray(scene: &Scene<'_, f64>, a: &dyn Accelerator<f64>, rays: &[Ray<f64>], runs: usize) -> PerRay {
    let mut mb = vec![0; lattice_rt::Query::mailbox_len(scene)];
    let mut times = Vec::new();
    let mut stats = lattice_rt::Stats::default();
    for _ in 0..runs.max(1) {
        let mut q = Query::new(&mut mb);
        let t0 = Instant::now();
        for r in rays {
            std::hint::black_box(a.nearest(scene, r, 0.0, f64::MAX, &mut q));
        }
        times.push(t0.elapsed() / rays.len().max(1) as u32);
        stats = q.stats;
    }
    let per = |v: u64| v as f64 / rays.len() as f64;
    PerRay {
        time: median(times),
        tests: per(stats.object_tests),
        boxes: per(stats.inside_tests),
        cells: per(stats.cells_visited),
    }
}

/// Eye rays through the centres of a `w` x `h` grid of pixels.
pub fn camera_rays(scene: &Scene<'_, f64>, w: i32, h: i32) -> Vec<Ray<f64>> {
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| scene.camera().ray(2 * x + 1, 2 * y + 1, 2 * w, 2 * h))
        .collect()
}

/// The shape generated scenes' views are fitted to: the paper's 160x100 (the POV-Ray comparison's
/// 480x300 and the eye-ray grids' 64x40 have it too).
pub const GENERATED_FRAME: [u32; 2] = [160, 100];

/// A generated scene: `n` random primitives, or the clustered "teapot in a stadium": most of
/// them in one dense composite far from the sparse rest.
pub fn generated(n: usize, clustered: bool, storage: &mut SceneStore<f64>) -> Result<Scene<'_, f64>> {
    generated_as(n, clustered, true, storage)
}

/// The clustered scene of [`generated`] with the cluster not declared a composite: its
/// primitives are loose among the others, as in a scene another program wrote out.
pub fn loose(n: usize, storage: &mut SceneStore<f64>) -> Result<Scene<'_, f64>> {
    generated_as(n, true, false, storage)
}

/// The issue's own check: `n` loose primitives packed into a cube of side 2 on a floor 160
/// units wide ringed by 40 boxes, seen from the floor's edge.
pub fn stadium(n: usize, storage: &mut SceneStore<f64>) -> Result<Scene<'_, f64>> {
    storage.objects = vec![Object::default(); n + 41];
    let mut b = storage.builder();
    let mut rng = Rng::new(3000 + n as u64);
    b.add_material(lattice_rt::scene::Material::DEFAULT)?;
    b.add_light(lattice_rt::scene::Light::Directional { to_light: Vec3::new(0.4, 1.0, -0.5), intensity: 1.0 })?;
    let scaled = |s: Vec3<f64>, at: Vec3<f64>| lattice_rt::Affine::translate(at).after(&lattice_rt::Affine::scale(s));
    b.add_object(lattice_rt::Shape::Box, scaled(Vec3::new(160.0, 1.0, 160.0), Vec3::new(-80.0, -1.0, -80.0)), 0)?;
    for i in 0..40 {
        let a = i as f64 * core::f64::consts::TAU / 40.0;
        b.add_object(
            lattice_rt::Shape::Box,
            scaled(Vec3::new(4.0, 6.0, 4.0), Vec3::new(70.0 * a.cos() - 2.0, 0.0, 70.0 * a.sin() - 2.0)),
            0,
        )?;
    }
    for _ in 0..n {
        let c = Vec3::new(rng.range(-1.0, 1.0), rng.range(0.0, 2.0), rng.range(-1.0, 1.0));
        let (s, t) = random_object(&mut rng, c, 0.04);
        b.add_object(s, t, 0)?;
    }
    b.camera.eye = Vec3::new(0.0, 12.0, -75.0);
    b.camera.look = Vec3::new(0.0, 1.0, 0.0);
    b.camera.frame = GENERATED_FRAME;
    Ok(b.finish()?)
}

fn generated_as(n: usize, clustered: bool, declared: bool, storage: &mut SceneStore<f64>) -> Result<Scene<'_, f64>> {
    storage.objects = vec![Object::default(); n];
    let mut b = storage.builder();
    if !clustered {
        random_scene(&mut b, &RandomScene { objects: n, composite_size: 0, spread: 0.0, seed: n as u64 })?;
    } else {
        let mut rng = Rng::new(7 + n as u64);
        let side = 6.0 * (n as f64).cbrt().max(2.0);
        b.add_material(lattice_rt::scene::Material::DEFAULT)?;
        b.add_light(lattice_rt::scene::Light::Directional { to_light: Vec3::new(0.4, 1.0, -0.5), intensity: 1.0 })?;
        let sparse = n / 10;
        for _ in 0..sparse {
            let c = Vec3::new(rng.range(0.0, side), rng.range(0.0, side * 0.2), rng.range(0.0, side));
            let (s, t) = random_object(&mut rng, c, 0.8);
            b.add_object(s, t, 0)?;
        }
        // The teapot: the other 90 % packed into a cube of side 2, a composite when declared.
        let at = Vec3::new(side * 0.8, side * 0.1, side * 0.8);
        if declared {
            b.begin_composite(lattice_rt::Affine::translate(at))?;
        }
        for _ in sparse..n {
            let c = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            let (s, t) = random_object(&mut rng, if declared { c } else { c + at }, 0.04);
            b.add_object(s, t, 0)?;
        }
        if declared {
            b.end_composite()?;
        }
        b.camera.eye = Vec3::new(side * 0.5, side * 0.6, -side * 0.6);
        b.camera.look = Vec3::new(side * 0.8, side * 0.1, side * 0.8);
    }
    b.camera.frame = GENERATED_FRAME;
    Ok(b.finish()?)
}

/// `n` unit spheres at one place: objects no lattice separates.
fn coincident(n: usize, storage: &mut SceneStore<f64>) -> Result<Scene<'_, f64>> {
    storage.objects = vec![Object::default(); n];
    let mut b = storage.builder();
    b.add_material(lattice_rt::scene::Material::DEFAULT)?;
    b.add_light(lattice_rt::scene::Light::Directional { to_light: Vec3::new(0.4, 1.0, -0.5), intensity: 1.0 })?;
    for _ in 0..n {
        b.add_object(lattice_rt::Shape::Sphere, lattice_rt::Affine::identity(), 0)?;
    }
    b.camera.eye = Vec3::new(0.0, 0.0, -5.0);
    b.camera.look = Vec3::new(0.0, 0.0, 0.0);
    b.camera.frame = GENERATED_FRAME;
    Ok(b.finish()?)
}

/// How building grows with the objects, whatever their arrangement: the scene's validation and
/// the lattice's planning and building, timed, and the lattice's bytes per object.
fn building(md: &mut String, quick: bool, runs: usize) -> Result<()> {
    let sizes: &[usize] = if quick { &[1_000, 10_000] } else { &[1_000, 10_000, 25_000, 100_000, 1_000_000] };
    type Make = fn(usize, &mut SceneStore<f64>) -> Result<Scene<'_, f64>>;
    let kinds: [(&str, Make); 3] =
        [("random", |n, st| generated(n, false, st)), ("loose cluster", loose), ("coincident spheres", coincident)];
    writeln!(
        md,
        "## Building
"
    )?;
    writeln!(md, "The generated scenes above, the clustered one with its cluster loose (not declared a composite),")?;
    writeln!(md, "and N unit spheres at one place. Scene: validating the objects (`SceneBuilder::finish`);")?;
    writeln!(md, "lattice: planning its storage and building it with the defaults. Medians of {runs} runs.\n")?;
    writeln!(md, "| arrangement | N | scene ms | lattice ms | lattice bytes/object | references/object |")?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    let bar = host_sim::progress::bar(kinds.len() * sizes.len(), "building");
    let mut random = Vec::new();
    for (name, make) in kinds {
        for &n in sizes {
            let (mut scene_t, mut lattice_t, mut bytes, mut refs) = (Vec::new(), Vec::new(), 0, 0);
            for _ in 0..runs {
                let mut st = SceneStore::default();
                let t0 = Instant::now();
                let scene = make(n, &mut st)?;
                scene_t.push(t0.elapsed());
                let cfg = LatticeConfig::default();
                let t1 = Instant::now();
                let mut bufs = lattice_storage(&scene, &cfg)?;
                let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
                lattice_t.push(t1.elapsed());
                (bytes, refs) = (lattice.bytes(), lattice.ref_count());
            }
            let (s, l) = (median(scene_t).as_secs_f64() * 1e3, median(lattice_t).as_secs_f64() * 1e3);
            if name == "random" {
                random.push((n, s + l));
            }
            let per = |v: usize| v as f64 / n as f64;
            writeln!(md, "| {name} | {n} | {s:.1} | {l:.1} | {:.1} | {:.2} |", per(bytes), per(refs))?;
            bar.inc(1);
        }
    }
    drop(bar);
    let at = |n: usize| random.iter().find(|(m, _)| *m == n).map(|(_, t)| *t);
    if let (Some(a), Some(b)) = (at(25_000), at(100_000)) {
        let r = b / a;
        let verdict = if r <= 4.5 { "met" } else { "not met" };
        writeln!(md, "\nRandom, 100,000 objects against 25,000: {r:.2}x the time (4x the objects; target at most 4.5x, {verdict}).")?;
    }
    writeln!(md)?;
    Ok(())
}

/// The command.
pub fn bench_cmd(quick: bool, runs: usize, out: &Path, plot: &Path) -> Result<()> {
    let runs = if quick { 1 } else { runs.max(1) };
    let mut md = String::new();
    writeln!(md, "# Performance\n\nWritten by `cargo xtask bench{}` on the host (f64, one core). Times are\nmedians of {runs} runs, the methods interleaved in each run so drift on a shared machine hits all alike.\n", if quick { " --quick" } else { "" })?;
    table1(&mut md, runs)?;
    let series = scaling(&mut md, quick, runs)?;
    building(&mut md, quick, runs)?;
    resolution_sweep(&mut md, quick, runs)?;
    writeln!(md, "\n![time per ray against N]({})\n", plot_link(out, plot))?;
    md.push_str(&against_povray(quick, runs)?);
    crate::plot::loglog(plot, "Time per ray against scene size", "primitives N", "microseconds per ray", &series)?;
    // The SPD's tables are `cargo xtask spd`'s: carried over as they are.
    let old = std::fs::read_to_string(out).unwrap_or_default();
    if let Some(spd) = crate::spd::section(&old, crate::spd::SECTION) {
        md = format!("{}\n{spd}", md.trim_end());
    }
    write_atomic(out, md.as_bytes())?;
    println!("wrote {} and {}", out.display(), plot.display());
    Ok(())
}

/// The paper's Table 1 on its four scenes, every method drawing the same frame.
fn table1(md: &mut String, runs: usize) -> Result<()> {
    writeln!(md, "## The paper's Table 1, reproduced\n\nThe four paper scenes at 160x100 with the paper's settings (directional light, 40x25 degree\nview, full Whitted tree). Ratio = bounding-box time / method time (the paper's \"how many\ntimes faster than the bounding box\"). Tests, inside tests and cells are per primary ray\n(eye rays alone). The first four methods trace eye rays as the paper does; the fifth walks the\nnested lattice testing each object's box before the object (inside tests: those box tests); the\nlast row is the tracer's default, where an eye ray skips every object whose window on the image (its box\nprojected through the eye) does not hold it, and scenes of up to 64 objects skip the walk too\n(`EyeRays`); its tests count only the exact tests made.\n")?;
    writeln!(md, "| scene | method | ms/frame | ratio to bbox | paper's ratio | object tests/ray | inside tests/ray | cells/ray | lattice build ms | lattice bytes |\n|---|---|---|---|---|---|---|---|---|---|")?;
    let frame = Frame::new(160, 100);
    let mut ratios = Vec::new();
    for (name, _prims, p_bbox, p_lat) in PAPER {
        let path = Path::new("scenes").join(format!("{name}.scene"));
        let text = read(&path)?;
        let mut storage = object_storage::<f64>(&text)?;
        let scene = parse_scene::<f64>(&path, &text, &mut storage, &frame)?;
        let mut times = vec![Vec::new(); METHODS.len()];
        let mut builds = vec![Vec::new(); METHODS.len()];
        let mut bytes = vec![0; METHODS.len()];
        let mut bits: Vec<Vec<u8>> = vec![Vec::new(); METHODS.len()];
        for _ in 0..runs {
            for (i, m) in METHODS.iter().enumerate() {
                let (t, b, by, _, bi) = frame_with(&scene, *m, &frame, false)?;
                times[i].push(t);
                builds[i].push(b);
                bytes[i] = by;
                bits[i] = bi;
            }
        }
        anyhow::ensure!(bits.windows(2).all(|w| w[0] == w[1]), "{name}: the methods drew different frames");
        let med: Vec<Duration> = times.into_iter().map(median).collect();
        for (i, m) in METHODS.iter().enumerate() {
            let (_, _, _, s, _) = frame_with(&scene, *m, &frame, true)?;
            let px = 160.0 * 100.0;
            let ratio = med[1].as_secs_f64() / med[i].as_secs_f64();
            let lat = matches!(m, Method::Flat | Method::Nested | Method::Boxes | Method::Windows);
            let paper = match m {
                Method::Bbox => "1.00".to_string(),
                Method::Nested => format!("{:.2}", p_bbox / p_lat),
                _ => "-".into(),
            };
            writeln!(
                md,
                "| {name} | {} | {:.2} | {ratio:.2} | {paper} | {:.2} | {:.2} | {} | {} | {} |",
                m.name(),
                med[i].as_secs_f64() * 1e3,
                s.object_tests as f64 / px,
                s.inside_tests as f64 / px,
                if lat { format!("{:.2}", s.cells_visited as f64 / px) } else { "-".into() },
                if lat { format!("{:.3}", median(builds[i].clone()).as_secs_f64() * 1e3) } else { "-".into() },
                if lat { bytes[i].to_string() } else { "-".into() },
            )?;
            if *m == Method::Nested {
                ratios.push((name, ratio, p_bbox / p_lat));
            }
        }
    }
    writeln!(
        md,
        "\nNested lattice against bounding box: {}. The paper: 2.01x to 2.70x.\n",
        ratios.iter().map(|(n, r, _)| format!("{n} {r:.2}x")).collect::<Vec<_>>().join(", ")
    )?;
    Ok(())
}

/// Named curves of (N, microseconds per ray), as the log-log plot draws them.
type Series = Vec<(String, Vec<(f64, f64)>)>;

/// Time per ray against the number of primitives, random and clustered; the plot's series.
fn scaling(md: &mut String, quick: bool, runs: usize) -> Result<Series> {
    let sizes: Vec<usize> = if quick { vec![10, 100, 1000] } else { vec![10, 100, 1_000, 10_000, 100_000] };
    writeln!(md, "## Scaling\n\nGenerated scenes (random mixes of the four primitives in a cube growing with N; \"clustered\":\n10 % spread over a stadium, 90 % packed in one composite far from them). Nearest-hit queries\nfor camera rays (a 64x40 grid; fewer for the O(N) methods at large N). Bytes: lattice storage\n(lattices, coordinate lists, cells, references); the bounding-box method keeps one box per object.\nBox tests: the bounding-box method's inside tests, and a lattice walk's test of an object's box\nbefore the object's own (the tracer's default, `Tracer::set_box_tests`).\n")?;
    writeln!(md, "| scene | N | method | us/ray | object tests/ray | box tests/ray | cells/ray | bytes | bytes/ref + bytes/cell |\n|---|---|---|---|---|---|---|---|---|")?;
    let mut series: Series = Vec::new();
    let bar = host_sim::progress::bar(2 * sizes.len(), "generated scenes");
    for clustered in [false, true] {
        for &n in &sizes {
            let mut storage = SceneStore::default();
            let scene = generated(n, clustered, &mut storage)?;
            let all_rays = camera_rays(&scene, 64, 40);
            let kind = if clustered { "clustered" } else { "random" };
            let configs: Vec<(String, Option<LatticeConfig>)> = vec![
                ("brute force".into(), None),
                ("bounding box".into(), None),
                ("lattice, uniform".into(), Some(LatticeConfig { nested: false, ..LatticeConfig::default() })),
                (
                    "lattice, adaptive".into(),
                    Some(LatticeConfig { nested: false, spacing: Spacing::Adaptive, ..LatticeConfig::default() }),
                ),
                ("lattice, nested".into(), Some(LatticeConfig::default())),
            ];
            for (label, cfg) in configs {
                if !clustered && label == "lattice, nested" {
                    continue;
                }
                let (PerRay { time, tests, boxes, cells }, bytes, per) = measure(&scene, &label, cfg, &all_rays, runs)?;
                let us = time.as_secs_f64() * 1e6;
                writeln!(
                    md,
                    "| {kind} | {n} | {label} | {us:.3} | {tests:.2} | {boxes:.2} | {} | {bytes} | {per} |",
                    if cells > 0.0 { format!("{cells:.1}") } else { "-".into() }
                )?;
                let key = format!("{kind}: {label}");
                match series.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, v)) => v.push((n as f64, us)),
                    None => series.push((key, vec![(n as f64, us)])),
                }
            }
            bar.inc(1);
            host_sim::progress::log(&bar, format_args!("  {kind} N={n} done"));
        }
    }
    scaling_summary(md, &series, &sizes)?;
    stadium_scaling(md, if quick { [100, 1000] } else { [1_000, 100_000] }, runs)?;
    Ok(series)
}

/// One method's work per eye ray on `scene` (`cfg`: a lattice's configuration, `None` for brute
/// force and bounding boxes, which answer fewer rays at large N), its bytes, and how the
/// lattice's bytes divide.
fn measure(
    scene: &lattice_rt::Scene<'_, f64>,
    label: &str,
    cfg: Option<LatticeConfig>,
    all_rays: &[lattice_rt::Ray<f64>],
    runs: usize,
) -> Result<(PerRay, usize, String)> {
    let n = scene.objects().len();
    Ok(match cfg {
        None => {
            let cap = (20_000_000 / n).clamp(50, all_rays.len());
            let rays = &all_rays[..cap];
            let a: &dyn Accelerator<f64> = if label == "brute force" { &BruteForce } else { &BoundingBox };
            let measured = per_ray(scene, a, rays, runs);
            let bytes = if label == "bounding box" { n * std::mem::size_of::<lattice_rt::Aabb<f64>>() } else { 0 };
            (PerRay { cells: 0.0, ..measured }, bytes, String::from("-"))
        }
        Some(cfg) => {
            let mut bufs = lattice_storage(scene, &cfg)?;
            let lat = build_lattice(&mut bufs, scene, &cfg)?;
            let measured = per_ray(scene, &lat, all_rays, runs);
            let w = if lat.narrow() { 2 } else { 4 };
            let other = lat.bytes() - w * (lat.ref_count() + lat.cell_count() + 1);
            (
                measured,
                lat.bytes(),
                format!("{w} x {} refs + {w} x {} cells + {other}", lat.ref_count(), lat.cell_count() + 1),
            )
        }
    })
}

/// The scaling section's sentences: the lattice against bounding boxes, time against N, the
/// clustered scenes' three lattices, and the scaling target.
fn scaling_summary(md: &mut String, series: &Series, sizes: &[usize]) -> Result<()> {
    let at = |key: &str, n: f64| {
        series.iter().find(|(k, _)| k == key).and_then(|(_, v)| v.iter().find(|p| p.0 == n)).map(|p| p.1)
    };
    writeln!(md)?;
    if let (Some(b), Some(l)) = (at("random: bounding box", 10_000.0), at("random: lattice, uniform", 10_000.0)) {
        writeln!(md, "At N = 10 000 (random): lattice {:.0}x faster per ray than the bounding-box method.", b / l)?;
    }
    if let (Some(a), Some(b)) = (at("random: lattice, uniform", 1_000.0), at("random: lattice, uniform", 100_000.0)) {
        writeln!(md, "Lattice time per ray from N = 1 000 to 100 000: x{:.2} (log N grows x1.67).", b / a)?;
    }
    if let (Some(u), Some(a), Some(nst)) = (
        at("clustered: lattice, uniform", *sizes.last().unwrap() as f64),
        at("clustered: lattice, adaptive", *sizes.last().unwrap() as f64),
        at("clustered: lattice, nested", *sizes.last().unwrap() as f64),
    ) {
        writeln!(
            md,
            "Clustered, N = {}: uniform {u:.2} us/ray, adaptive coordinate lists {a:.2}, nested sub-lattice {nst:.2}.",
            sizes.last().unwrap()
        )?;
    }
    let big = *sizes.last().unwrap() as f64;
    // The target compares 100 000 with 1 000 primitives: a quick run (1 000 at most) has no such pair.
    if let (Some(a), Some(b), true) =
        (at("clustered: lattice, nested", 1_000.0), at("clustered: lattice, nested", big), big > 1_000.0)
    {
        let met = if b / a <= SCALING_TARGET { "met" } else { "not met" };
        writeln!(md, "Scaling target (the default nested lattice, clustered): us per ray at N = {big} is {:.2}x that at N = 1 000 (target: at most {SCALING_TARGET}x, {met}). This scene's sparse tenth is spread over a stadium whose side grows as the cube root of N, so from N = 1 000 to 100 000 an eye ray crosses about 100^(1/3) = 4.6 times as many cells, and passes as many more objects (cells per ray above): the growth is the scene's, and no lattice removes it. The fixed stadium below keeps the stadium and grows only the cluster.", b / a)?;
    }
    Ok(())
}

/// The teapot in a fixed stadium ([`stadium`]: only the cluster grows, the floor, the ring of
/// boxes and the camera stay): time, object tests and cells per eye ray at two cluster sizes,
/// with the default (nested) lattice.
fn stadium_scaling(md: &mut String, sizes: [usize; 2], runs: usize) -> Result<()> {
    let mut per = Vec::new();
    for n in sizes {
        let mut storage = SceneStore::default();
        let scene = stadium(n, &mut storage)?;
        let cfg = LatticeConfig::default();
        let mut bufs = lattice_storage(&scene, &cfg)?;
        let lat = build_lattice(&mut bufs, &scene, &cfg)?;
        let m = per_ray(&scene, &lat, &camera_rays(&scene, 64, 40), runs);
        per.push((m.time.as_secs_f64() * 1e6, m.tests, m.cells));
    }
    let [(a, ta, ca), (b, tb, cb)] = [per[0], per[1]];
    writeln!(
        md,
        "The teapot in a fixed stadium (`stadium`: N loose primitives in a 2-unit cube on a 160-unit floor ringed by 40 boxes, the camera fixed; the default lattice): us per ray at N = {} is {:.2}x that at N = {} ({a:.3} -> {b:.3} us; object tests per ray {ta:.2} -> {tb:.2}, cells per ray {ca:.1} -> {cb:.1}; target: at most {SCALING_TARGET}x, {}).",
        sizes[1],
        b / a,
        sizes[0],
        if b / a <= SCALING_TARGET { "met" } else { "not met" }
    )?;
    Ok(())
}

/// How many times the time per ray at 100 000 clustered primitives may be that at 1 000.
const SCALING_TARGET: f64 = 1.2;

/// The automatic lattice resolution against a sweep of uniform ones.
fn resolution_sweep(md: &mut String, quick: bool, runs: usize) -> Result<()> {
    let n = if quick { 1000 } else { 10_000 };
    writeln!(md, "\n## Lattice resolution: automatic against a sweep\n\nRandom scene, N = {n}; uniform lists. The automatic choice aims at about 2 cells per object\n(cells per axis proportional to extent x cube root of the count, as in Cleary and Wyvill's\nanalysis and pbrt's `GridAccel`).\n")?;
    writeln!(md, "| resolution | cells | us/ray | object tests/ray | cells/ray | bytes |\n|---|---|---|---|---|---|")?;
    let mut storage = SceneStore::default();
    let scene = generated(n, false, &mut storage)?;
    let rays = camera_rays(&scene, 64, 40);
    let mut sweep: Vec<(String, LatticeConfig)> = [4u16, 8, 16, 24, 32, 48, 64]
        .iter()
        .map(|&k| {
            (
                format!("{k}^3"),
                LatticeConfig { top: Resolution::Uniform([k; 3]), nested: false, ..LatticeConfig::default() },
            )
        })
        .collect();
    sweep.push(("auto (2 per object)".into(), LatticeConfig { nested: false, ..LatticeConfig::default() }));
    sweep.push((
        "auto, adaptive lists".into(),
        LatticeConfig { nested: false, spacing: Spacing::Adaptive, ..LatticeConfig::default() },
    ));
    for (label, cfg) in sweep {
        let mut bufs = lattice_storage(&scene, &cfg)?;
        let lat = build_lattice(&mut bufs, &scene, &cfg)?;
        let m = per_ray(&scene, &lat, &rays, runs);
        writeln!(
            md,
            "| {label} | {} | {:.3} | {:.2} | {:.1} | {} |",
            lat.cell_count(),
            m.time.as_secs_f64() * 1e6,
            m.tests,
            m.cells,
            lat.bytes()
        )?;
    }
    Ok(())
}

/// A scene of the POV-Ray comparison made in the storage it is given.
type Maker = Box<dyn for<'a> Fn(&'a mut SceneStore<f64>) -> Result<Scene<'a, f64>>>;

/// The scenes of the POV-Ray comparison, by name: the paper scenes and generated scenes of 100,
/// 1 000 and 10 000 primitives (1 000 at most with `quick`), random, clustered and loosely
/// clustered, and the stadium.
pub fn versus_cases(quick: bool) -> Vec<(String, Maker)> {
    let mut cases: Vec<(String, Maker)> = Vec::new();
    for (name, ..) in PAPER {
        cases.push((
            name.to_string(),
            Box::new(move |storage: &mut SceneStore<f64>| {
                let path = Path::new("scenes").join(format!("{name}.scene"));
                let text = read(&path)?;
                *storage = object_storage::<f64>(&text)?;
                parse_scene::<f64>(&path, &text, storage, &Frame::new(crate::versus::SIZE.0, crate::versus::SIZE.1))
            }),
        ));
    }
    let sizes: &[usize] = if quick { &[100, 1000] } else { &[100, 1000, 10_000] };
    for clustered in [false, true] {
        for &n in sizes {
            let name = format!("{} {n}", if clustered { "clustered" } else { "random" });
            cases.push((name, Box::new(move |storage: &mut SceneStore<f64>| generated(n, clustered, storage))));
        }
    }
    for &n in sizes {
        cases.push((format!("loose clustered {n}"), Box::new(move |storage: &mut SceneStore<f64>| loose(n, storage))));
    }
    cases.push(("stadium 3000".into(), Box::new(|storage: &mut SceneStore<f64>| stadium(3000, storage))));
    cases
}

/// The POV-Ray section over [`versus_cases`].
fn against_povray(quick: bool, runs: usize) -> Result<String> {
    if !crate::versus::available() {
        eprintln!("povray is not installed: the POV-Ray comparison is left out (apt-get install povray)");
        return Ok("## Against POV-Ray 3.7\n\nLeft out: `povray` was not installed when this was written.\n".into());
    }
    let rows = versus_rows(&versus_cases(quick), runs, true)?;
    crate::versus::section(&rows, runs)
}

/// The command: the chosen cases' rows printed as a table.
pub fn versus_cmd(scenes: &[String], runs: usize, povray: bool) -> Result<()> {
    if povray && !crate::versus::available() {
        anyhow::bail!("povray is not installed (apt-get install povray), or pass --no-povray");
    }
    let cases: Vec<_> = versus_cases(false)
        .into_iter()
        .filter(|(name, _)| scenes.is_empty() || scenes.iter().any(|s| name.starts_with(s.as_str())))
        .collect();
    if cases.is_empty() {
        let names: Vec<String> = versus_cases(false).into_iter().map(|(n, _)| n).collect();
        anyhow::bail!("no scene of the comparison is named {}; they are: {}", scenes.join(", "), names.join(", "));
    }
    let rows = versus_rows(&cases, runs.max(1), povray)?;
    print!("{}", crate::versus::section(&rows, runs.max(1))?);
    Ok(())
}

/// Times each case in host-sim and, with `povray`, in POV-Ray (see [`crate::versus::compare`]).
pub fn versus_rows(cases: &[(String, Maker)], runs: usize, povray: bool) -> Result<Vec<crate::versus::Row>> {
    let work = Path::new("target/povray-bench");
    let cfg = LatticeConfig::default();
    let mut rows = Vec::new();
    let bar = host_sim::progress::bar(cases.len(), "against POV-Ray");
    for (name, make) in cases {
        let mut storage = SceneStore::default();
        let scene = make(&mut storage)?;
        let mut bufs = lattice_storage(&scene, &cfg)?;
        let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
        rows.extend(crate::versus::compare(name, &scene, &lattice, runs, povray.then_some(work))?);
        bar.inc(1);
        host_sim::progress::log(&bar, format_args!("  {name} done"));
    }
    Ok(rows)
}
