//! `cargo xtask memory`: the memory-time frontier. Each scene's lattice is built within byte
//! budgets from 64 B to 1 MiB (`LatticeConfig::budget`), and its time, object tests and cells
//! per ray are set against the bytes it took; the bounding-box method and brute force are the
//! end that keeps no lattice. Writes `docs/memory.md` and two plots.

use crate::bench::{camera_rays, generated};
use anyhow::{ensure, Result};
use host_sim::load::{build_lattice, lattice_storage, object_storage, parse_scene, read, SceneStore};
use host_sim::output::write_atomic;
use host_sim::shared::{median, plot_link, PAPER_SCENES};
use lattice_rt::lattice::Choice;
use lattice_rt::{Accelerator, BoundingBox, BruteForce, Lattice, LatticeConfig, Query, Ray, Scene};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The smallest and largest budget of the sweep, which doubles from one to the other.
const BUDGETS: (usize, usize) = (64, 1 << 20);
/// Eye rays per scene: a grid of this many columns and rows.
const RAYS: (i32, i32) = (64, 40);

/// Options of the study.
#[derive(Clone, Debug)]
pub struct MemoryArgs {
    /// Timed runs per measurement (the median is used).
    pub runs: usize,
    /// Generated scenes of at most 1 000 primitives.
    pub quick: bool,
    /// Report to write.
    pub out: PathBuf,
    /// Plot of time per ray against lattice bytes.
    pub plot: PathBuf,
    /// Plot of object tests per ray against lattice bytes.
    pub tests_plot: PathBuf,
}

/// One way to answer the rays: an accelerator and the bytes it keeps.
struct Method<'a> {
    label: String,
    accel: Box<dyn Accelerator<f64> + 'a>,
    bytes: usize,
}

/// What one method measured: median time per ray, object tests and cells per ray.
#[derive(Clone, Copy, Debug)]
struct Measured {
    time: Duration,
    tests: f64,
    cells: f64,
}

impl Measured {
    fn us(&self) -> f64 {
        self.time.as_secs_f64() * 1e6
    }
}

/// Times every method on the rays, interleaved in each run so drift on a shared machine hits
/// all alike; the answers must agree with the first method's.
fn measure(scene: &Scene<'_, f64>, methods: &[Method<'_>], rays: &[Ray<f64>], runs: usize) -> Result<Vec<Measured>> {
    let mut mb = vec![0; Query::mailbox_len(scene)];
    let mut times = vec![Vec::new(); methods.len()];
    let mut work = vec![(0.0, 0.0); methods.len()];
    let mut answers: Vec<Vec<Option<(usize, f64)>>> = vec![Vec::new(); methods.len()];
    for _ in 0..runs.max(1) {
        for (i, m) in methods.iter().enumerate() {
            let mut q = Query::new(&mut mb);
            let mut hits = Vec::with_capacity(rays.len());
            let t0 = Instant::now();
            for r in rays {
                hits.push(m.accel.nearest(scene, r, 0.0, f64::MAX, &mut q).map(|h| (h.object as usize, h.t)));
            }
            times[i].push(t0.elapsed() / rays.len().max(1) as u32);
            let n = rays.len().max(1) as f64;
            work[i] = (q.stats.object_tests as f64 / n, q.stats.cells_visited as f64 / n);
            answers[i] = hits;
        }
    }
    for (m, a) in methods.iter().zip(&answers).skip(1) {
        ensure!(*a == answers[0], "{} found other hits than {}", m.label, methods[0].label);
    }
    Ok(times.into_iter().zip(work).map(|(t, (tests, cells))| Measured { time: median(t), tests, cells }).collect())
}

/// A scene of the study and how its name reads in the report.
struct Subject {
    name: String,
    objects: SceneStore<f64>,
    source: Source,
}

enum Source {
    File(PathBuf, String),
    Generated(usize, bool),
}

fn subjects(quick: bool) -> Result<Vec<Subject>> {
    let mut v = Vec::new();
    for name in PAPER_SCENES {
        let path = Path::new("scenes").join(format!("{name}.scene"));
        let text = read(&path)?;
        v.push(Subject {
            name: name.to_string(),
            objects: object_storage::<f64>(&text)?,
            source: Source::File(path, text),
        });
    }
    let sizes: &[usize] = if quick { &[100, 1000] } else { &[100, 1000, 10_000] };
    for clustered in [false, true] {
        for &n in sizes {
            let kind = if clustered { "clustered" } else { "uniform" };
            v.push(Subject {
                name: format!("{kind} {n}"),
                objects: SceneStore::default(),
                source: Source::Generated(n, clustered),
            });
        }
    }
    Ok(v)
}

/// The budgets of the sweep, doubling, and a quarter of the automatic lattice's bytes.
fn budgets(quarter: usize) -> Vec<usize> {
    let mut b: Vec<usize> = std::iter::successors(Some(BUDGETS.0), |&x| (x < BUDGETS.1).then_some(x * 2)).collect();
    b.push(quarter);
    b.sort_unstable();
    b.dedup();
    b
}

/// One row of a scene's sweep.
struct Row {
    budget: usize,
    /// The lattice chosen, or `None` when not one cell per lattice fits (bounding boxes).
    choice: Option<Choice>,
    /// Index of the method that answers at this budget.
    method: usize,
}

/// What a budget gives: the lattice built within it (or bounding boxes) and the fastest
/// method that keeps at most that many bytes (brute force and bounding boxes keep none).
struct AtBudget {
    budget: usize,
    built: usize,
    ratio: f64,
    best: String,
    best_ratio: f64,
}

/// Per scene: the automatic lattice, what a quarter of its bytes gives, the plotted points.
struct Summary {
    name: String,
    auto: Choice,
    auto_wide_bytes: usize,
    /// At a quarter of the automatic lattice's bytes with 16-bit indices, then with 32-bit.
    quarters: [AtBudget; 2],
    time_points: Vec<(f64, f64)>,
    test_points: Vec<(f64, f64)>,
}

/// Sweeps one scene; appends its section to `md`.
fn sweep(scene: &Scene<'_, f64>, name: &str, runs: usize, md: &mut String) -> Result<Summary> {
    let auto_cfg = LatticeConfig::default();
    let auto = Lattice::choose(scene, &auto_cfg);
    let auto_wide_bytes = Lattice::choose(scene, &LatticeConfig { index16: false, ..auto_cfg }).bytes;
    let quarter = auto.bytes / 4;
    let mut budgets = budgets(quarter);
    budgets.push(auto_wide_bytes / 4);
    budgets.sort_unstable();
    budgets.dedup();
    let (choices, rows) = lattices_within(scene, auto, &budgets);
    let mut storages = Vec::new();
    for c in &choices {
        storages.push(lattice_storage(scene, &c.cfg)?);
    }
    let mut methods: Vec<Method<'_>> = vec![
        Method { label: "brute force".into(), accel: Box::new(BruteForce), bytes: 0 },
        Method { label: "bounding boxes".into(), accel: Box::new(BoundingBox), bytes: 0 },
    ];
    for (st, c) in storages.iter_mut().zip(&choices) {
        let lat = build_lattice(st, scene, &c.cfg)?;
        ensure!(lat.bytes() == c.bytes, "{name}: built {} bytes, chose {}", lat.bytes(), c.bytes);
        methods.push(Method { label: c.to_string(), bytes: c.bytes, accel: Box::new(lat) });
    }
    let rays = camera_rays(scene, RAYS.0, RAYS.1);
    let m = measure(scene, &methods, &rays, runs)?;
    let auto_m = m[2];
    writeln!(md, "### {name}\n")?;
    writeln!(
        md,
        "{} objects, {} composites. Automatic lattice: {auto}.\n",
        scene.objects().len(),
        scene.composites().len()
    )?;
    writeln!(md, "| budget (bytes) | lattice built | bytes | us/ray | x automatic | object tests/ray | cells/ray |\n|---:|---|---:|---:|---:|---:|---:|")?;
    let (time_points, test_points) = sweep_rows(md, &m, &methods, &rows, [quarter, auto_wide_bytes / 4])?;
    writeln!(md)?;
    let at = |budget: usize| {
        let r = rows.iter().find(|r| r.budget == budget).expect("the quarter budgets are swept");
        let best = (0..methods.len())
            .filter(|&i| methods[i].bytes <= budget)
            .min_by_key(|&i| m[i].time)
            .expect("brute force keeps no bytes");
        AtBudget {
            budget,
            built: methods[r.method].bytes,
            ratio: m[r.method].us() / auto_m.us(),
            best: if best < 2 { methods[best].label.clone() } else { short(&choices[best - 2]) },
            best_ratio: m[best].us() / auto_m.us(),
        }
    };
    let quarters = [at(quarter), at(auto_wide_bytes / 4)];
    Ok(Summary { name: name.into(), auto, auto_wide_bytes, quarters, time_points, test_points })
}

/// The sweep's table rows: brute force and bounding boxes, then the lattice built within each
/// budget (`marks`: the budgets of a quarter of the automatic lattice, with 16- and 32-bit
/// indices), each against the automatic lattice (method 2). Returns the points of the time and
/// the tests plotted against the budget.
#[allow(clippy::type_complexity)]
fn sweep_rows(
    md: &mut String,
    m: &[Measured],
    methods: &[Method<'_>],
    rows: &[Row],
    [quarter, wide_quarter]: [usize; 2],
) -> Result<(Vec<(f64, f64)>, Vec<(f64, f64)>)> {
    let auto_m = m[2];
    for (i, label) in [(0, "brute force"), (1, "bounding boxes")] {
        let x = m[i];
        writeln!(md, "| 0 | none: {label} | 0 | {:.3} | {:.2} | {:.2} | - |", x.us(), x.us() / auto_m.us(), x.tests)?;
    }
    let (mut time_points, mut test_points) = (Vec::new(), Vec::new());
    for r in rows {
        let x = m[r.method];
        let what = match &r.choice {
            None => "none fits: bounding boxes".to_string(),
            Some(c) => short(c),
        };
        let bytes = methods[r.method].bytes;
        let mark = if r.budget == quarter {
            " (a quarter of automatic)"
        } else if r.budget == wide_quarter {
            " (a quarter of automatic with 32-bit indices)"
        } else {
            ""
        };
        writeln!(
            md,
            "| {}{mark} | {what} | {bytes} | {:.3} | {:.2} | {:.2} | {} |",
            r.budget,
            x.us(),
            x.us() / auto_m.us(),
            x.tests,
            if r.choice.is_some() { format!("{:.1}", x.cells) } else { "-".into() }
        )?;
        time_points.push((r.budget as f64, x.us() / auto_m.us()));
        test_points.push((r.budget as f64, x.tests));
    }
    Ok((time_points, test_points))
}

/// The lattice `Lattice::choose` picks within each budget: every distinct lattice of the sweep
/// (the automatic one first), and one row per budget with the method index it uses (1:
/// bounding boxes when none fits, 2 + i: the i-th distinct lattice).
fn lattices_within(scene: &Scene<'_, f64>, auto: Choice, budgets: &[usize]) -> (Vec<Choice>, Vec<Row>) {
    let mut choices: Vec<Choice> = vec![auto];
    let mut rows = Vec::new();
    for &budget in budgets {
        let c = Lattice::choose(scene, &LatticeConfig { budget: Some(budget), ..LatticeConfig::default() });
        let choice = c.fits.then_some(c);
        let method = match choice {
            None => 1,
            Some(c) => match choices.iter().position(|k| k.cfg == c.cfg) {
                Some(i) => 2 + i,
                None => {
                    choices.push(c);
                    1 + choices.len()
                }
            },
        };
        rows.push(Row { budget, choice, method });
    }
    (choices, rows)
}

/// A lattice in a few words: world cells, sub-lattices, index width.
fn short(c: &Choice) -> String {
    let [x, y, z] = c.world;
    let subs = c.sizes.lattices - 1;
    let shape = if subs > 0 {
        format!(" + {subs} sub")
    } else if !c.cfg.nested {
        " flat".into()
    } else {
        String::new()
    };
    format!("{x}x{y}x{z}{shape}, {}-bit", if c.sizes.narrow { 16 } else { 32 })
}

/// The board's side of the study: written by `cargo xtask board`, shown here (docs/images).
const BOARD_SECTION: &str = "
## On the board: the sphereflake from the Pico's flash

The same question on the board: `cargo xtask board` bakes the SPD's sphereflake (`balls`, sizes 1
to 4: 12 to 7,383 objects) into the Pico's flash, objects and lattice read through the 16 KiB XIP
cache, and runs each image on the emulated board: the image's flash and static RAM against
cycles per frame and XIP misses per ray (figures: docs/board.md, *The Standard Procedural
Databases from flash*).

![flash, RAM, cycles and XIP misses per ray of the sphereflake on the Pico](images/board-spd-balls.svg)
";

/// The command.
pub fn memory_cmd(a: &MemoryArgs) -> Result<()> {
    let runs = if a.quick { 1 } else { a.runs.max(1) };
    let mut subjects = subjects(a.quick)?;
    let mut sections = String::new();
    let mut summaries = Vec::new();
    let bar = host_sim::progress::bar(subjects.len(), "memory sweep");
    for s in subjects.iter_mut() {
        let t0 = Instant::now();
        let summary = match &s.source {
            Source::File(path, text) => {
                let scene = parse_scene::<f64>(
                    path,
                    text,
                    &mut s.objects,
                    &lattice_rt::Frame::new(RAYS.0 as u16, RAYS.1 as u16),
                )?;
                sweep(&scene, &s.name, runs, &mut sections)?
            }
            Source::Generated(n, clustered) => {
                let scene = generated(*n, *clustered, &mut s.objects)?;
                sweep(&scene, &s.name, runs, &mut sections)?
            }
        };
        bar.inc(1);
        host_sim::progress::log(&bar, format_args!("  {} done in {:.1} s", s.name, t0.elapsed().as_secs_f64()));
        summaries.push(summary);
    }
    drop(bar);
    let mut md = String::new();
    writeln!(
        md,
        "# Memory: the lattice within a byte budget\n\nWritten by `cargo xtask memory{}` on the host (f64, one core). Each\nscene's lattice is built within budgets from {} B to {} KiB, doubling, and at a quarter of\nits automatic lattice's bytes (`LatticeConfig::budget`: the densest lattice that fits, its\ncells per item scaled down in steps of 3/4, sub-lattices tried before a flat lattice, 16-bit\nindices whenever they fit). Where not one cell per lattice fits, the tracer keeps no lattice\nand uses bounding boxes. Per ray: nearest-hit queries of {}x{} eye rays, median time of {runs}\nruns with every method interleaved in each run; all methods find the same hits.\n",
        if a.quick { " --quick" } else { "" },
        BUDGETS.0,
        BUDGETS.1 >> 10,
        RAYS.0,
        RAYS.1
    )?;
    writeln!(md, "![time per ray against lattice bytes]({})\n", plot_link(&a.out, &a.plot))?;
    let met = quarter_section(&mut md, &summaries)?;
    let n = summaries.len();
    grid_section(&mut md, &summaries)?;
    md.push_str(BOARD_SECTION);
    writeln!(md, "\n## Every budget\n\nx automatic: time per ray over the automatic lattice's. The zero-byte rows keep no lattice.\n\n![object tests per ray against lattice bytes]({})\n", plot_link(&a.out, &a.tests_plot))?;
    md.push_str(&sections);
    let series = |f: fn(&Summary) -> &Vec<(f64, f64)>| {
        summaries.iter().map(|s| (s.name.clone(), f(s).clone())).collect::<Vec<_>>()
    };
    crate::plot::loglog(
        &a.plot,
        "Time per ray against lattice budget",
        "budget (bytes)",
        "time per ray / automatic lattice's",
        &series(|s| &s.time_points),
    )?;
    crate::plot::loglog(
        &a.tests_plot,
        "Object tests per ray against lattice budget",
        "budget (bytes)",
        "object tests per ray",
        &series(|s| &s.test_points),
    )?;
    write_atomic(&a.out, md.as_bytes())?;
    println!(
        "within 1.3x of the automatic lattice's time at a quarter of its bytes: lattice {} of {n}, best method {} of {n}; at a quarter of the 32-bit automatic: {} of {n}",
        met[0], met[1], met[2]
    );
    println!("wrote {}, {} and {}", a.out.display(), a.plot.display(), a.tests_plot.display());
    Ok(())
}

/// The budgets at a quarter of the automatic lattice's bytes against the 1.3x target; how many
/// scenes met it: the lattice built, the best method, the quarter of the 32-bit lattice.
fn quarter_section(md: &mut String, summaries: &[Summary]) -> Result<[usize; 3]> {
    writeln!(
        md,
        "## At a quarter of the automatic lattice's bytes\n\nTarget: at most 1.3x the automatic lattice's time per ray. The automatic lattice now has\n16-bit indices; the issue set the target when it had 32-bit ones, so both quarters are shown.\n\"Lattice\": what `LatticeConfig::budget` builds within the quarter (bounding boxes when no\nlattice fits); \"best\": the fastest method that keeps at most that many bytes.\n"
    )?;
    writeln!(md, "| scene | automatic bytes | quarter | lattice bytes | lattice x automatic | best within it | best x automatic | quarter of 32-bit automatic | lattice bytes | lattice x automatic |\n|---|---:|---:|---:|---:|---|---:|---:|---:|---:|")?;
    let mut met = [0, 0, 0];
    for s in summaries {
        let [q, w] = &s.quarters;
        met[0] += usize::from(q.ratio <= 1.3);
        met[1] += usize::from(q.best_ratio <= 1.3);
        met[2] += usize::from(w.ratio <= 1.3);
        let mark = |r: f64| if r <= 1.3 { format!("{r:.2}") } else { format!("**{r:.2}**") };
        writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            s.name,
            s.auto.bytes,
            q.budget,
            q.built,
            mark(q.ratio),
            q.best,
            mark(q.best_ratio),
            w.budget,
            w.built,
            mark(w.ratio)
        )?;
    }
    let n = summaries.len();
    writeln!(
        md,
        "\nWithin 1.3x at a quarter of the automatic bytes: the lattice built in {} of {n} scenes, the best\nmethod in {} of {n}; at a quarter of the 32-bit automatic lattice's bytes, the lattice in {} of {n}.\n",
        met[0], met[1], met[2]
    )?;
    Ok(met)
}

/// Bytes per reference and per cell of each automatic lattice, against a compact grid.
fn grid_section(md: &mut String, summaries: &[Summary]) -> Result<()> {
    writeln!(md, "## Bytes per reference and per cell, against compact grids\n\nA compact grid (Lagae and Dutre 2008) keeps one 32-bit index per cell (plus one) and one per\nreference. The lattice keeps the same two arrays, 16-bit when they fit, plus its coordinate\nlists and one header per lattice (bounds, cells per axis, where its lists and cells start).\n")?;
    writeln!(md, "| scene | cells | references | lattice bytes | with 32-bit indices | compact grid, same cells | bytes/reference | bytes/cell |\n|---|---:|---:|---:|---:|---:|---:|---:|")?;
    for s in summaries {
        let (cells, refs) = (s.auto.sizes.cells - 1, s.auto.sizes.refs);
        writeln!(
            md,
            "| {} | {cells} | {refs} | {} | {} | {} | {:.2} | {:.2} |",
            s.name,
            s.auto.bytes,
            s.auto_wide_bytes,
            4 * (cells + 1 + refs),
            s.auto.bytes as f64 / refs.max(1) as f64,
            s.auto.bytes as f64 / cells.max(1) as f64
        )?;
    }
    Ok(())
}
