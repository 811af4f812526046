//! The commands: render, stats and the default gallery job.

use crate::shared::{median, PAPER_SCENES};
use crate::load::{object_storage, parse_scene, read, build_lattice, lattice_storage};
use crate::output::{write_gray_png, write_pbm, write_pgm, write_png, Theme};
use crate::cli::{Accel, RenderArgs, StatsArgs};
use anyhow::{anyhow, Context, Result};
use lattice_rt::render::{Hooks, RenderError};
use lattice_rt::trace::{Effects, EyeRays};
use lattice_rt::{
    render, Accelerator, BitFrame, BoundingBox, BruteForce, Frame, HeapScratch, Lattice, LatticeConfig, Real, Scene, Stats,
    Tracer,
};
use std::path::Path;
use std::time::{Duration, Instant};

/// A finished render on the host.
pub struct Rendered {
    /// Packed 1-bit frame (see `BitFrame`).
    pub bits: Vec<u8>,
    /// Gray levels 0..=64, row-major.
    pub gray: Vec<u8>,
    /// Work counted by the core.
    pub stats: Stats,
    /// Wall time of the render.
    pub elapsed: Duration,
}

/// Collects gray tiles into a full image and shows progress on long renders.
struct HostHooks {
    width: usize,
    gray: Vec<u8>,
    start: Instant,
    progress: bool,
    /// Shown once a render has taken 0.7 s.
    bar: Option<indicatif::ProgressBar>,
}

impl Hooks for HostHooks {
    fn gray_tile(&mut self, x: u16, y: u16, w: u16, h: u16, levels: &[u8]) {
        for row in 0..h as usize {
            let dst = (y as usize + row) * self.width + x as usize;
            self.gray[dst..dst + w as usize].copy_from_slice(&levels[row * w as usize..(row + 1) * w as usize]);
        }
    }
    fn progress(&mut self, done: u32, total: u32) -> bool {
        if self.progress && self.bar.is_none() && self.start.elapsed() > Duration::from_millis(700) {
            self.bar = Some(crate::progress::bar(total as usize, "rendering tiles"));
        }
        if let Some(b) = &self.bar {
            b.set_position(done as u64);
            if done == total {
                b.finish_and_clear();
            }
        }
        true
    }
}

/// Renders a frame with one accelerator into host buffers: bands of tile rows in parallel on
/// all cores when the frame allows it ([`Frame::bands_independent`]), serially otherwise.
pub fn render_with<R: Real, A: Accelerator<R> + ?Sized + Sync>(
    tracer: &Tracer<'_, '_, R, A>,
    frame: &Frame,
    progress: bool,
) -> Result<Rendered> {
    let start = Instant::now();
    let tiles_y = (frame.height as usize).div_ceil(frame.tile.max(1) as usize);
    let threads = rayon::current_num_threads().min(tiles_y).max(1);
    if !frame.bands_independent() || threads == 1 {
        let mut r = render_band(tracer, frame, progress)?;
        r.elapsed = start.elapsed();
        return Ok(r);
    }
    use rayon::prelude::*;
    let per = tiles_y.div_ceil(threads);
    let bands: Vec<Result<Rendered>> = (0..threads)
        .into_par_iter()
        .map(|i| {
            let rows = ((i * per) as u16, ((i + 1) * per).min(tiles_y) as u16);
            render_band(tracer, &Frame { rows, ..*frame }, false)
        })
        .collect();
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut out = Rendered { bits: vec![0; BitFrame::bytes(w as u32, h as u32)], gray: vec![0; w * h], stats: Stats::default(), elapsed: Duration::ZERO };
    for band in bands {
        let band = band?;
        out.bits.iter_mut().zip(&band.bits).for_each(|(a, b)| *a |= b);
        out.gray.iter_mut().zip(&band.gray).for_each(|(a, b)| *a |= b);
        out.stats.add(&band.stats);
    }
    out.elapsed = start.elapsed();
    Ok(out)
}

/// Renders the frame's band of tile rows on this thread (pixels outside it stay 0).
/// Timing measurements use this: one core, so methods and modes compare fairly.
pub fn render_band<R: Real, A: Accelerator<R> + ?Sized>(tracer: &Tracer<'_, '_, R, A>, frame: &Frame, progress: bool) -> Result<Rendered> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut bits = vec![0u8; BitFrame::bytes(w as u32, h as u32)];
    let mut target = BitFrame::new(w as u32, h as u32, &mut bits).expect("sized above");
    let mut scratch = HeapScratch::new(tracer.scene(), frame);
    let mut hooks = HostHooks { width: w, gray: vec![0; w * h], start: Instant::now(), progress, bar: None };
    let start = Instant::now();
    let stats = render(tracer, frame, &mut target, &mut scratch.scratch(), &mut hooks).map_err(|e| match e {
        RenderError::Draw(never) => match never {},
        other => anyhow!("{other}"),
    })?;
    let elapsed = start.elapsed();
    Ok(Rendered { bits, gray: hooks.gray, stats, elapsed })
}


/// Parses scene text, builds its default lattice and hands `work` a tracer on it, after `tune`
/// has adjusted the tracer (depth, cutoff, effects, eye rays).
pub fn with_tracer<R: Real, T>(
    path: &Path,
    text: &str,
    frame: &Frame,
    tune: impl FnOnce(&mut lattice_rt::Tracer<'_, '_, R, lattice_rt::Lattice<'_, R>>),
    work: impl FnOnce(&lattice_rt::Tracer<'_, '_, R, lattice_rt::Lattice<'_, R>>) -> Result<T>,
) -> Result<T> {
    let mut storage = object_storage::<R>(text)?;
    let scene = parse_scene::<R>(path, text, &mut storage, frame)?;
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg)?;
    let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
    let mut tracer = lattice_rt::Tracer::new(&scene, &lattice);
    tune(&mut tracer);
    work(&tracer)
}

/// Parses scene text, builds its default lattice and renders `frame` on one core, after
/// `tune` has adjusted the tracer (depth, cutoff, effects).
pub fn render_text<R: Real>(
    path: &Path,
    text: &str,
    frame: &lattice_rt::Frame,
    tune: impl FnOnce(&mut lattice_rt::Tracer<'_, '_, R, lattice_rt::Lattice<'_, R>>),
) -> Result<Rendered> {
    with_tracer(path, text, frame, tune, |tracer| render_band(tracer, frame, false))
}

/// One pass of a progressive frame as the panel shows it once the pass is drawn.
pub struct Pass {
    /// The pass: 8, 4, 2 or 1 (the finished frame).
    pub pass: u8,
    /// Packed 1-bit frame.
    pub bits: Vec<u8>,
    /// Work counted by the core in this pass alone.
    pub stats: Stats,
    /// Wall time of the pass.
    pub elapsed: Duration,
}

/// The passes of a progressive frame (8, 4, 2, 1; `render_pass`) of scene text with its default
/// lattice, in scalar `R`.
pub fn progressive_passes<R: Real>(path: &Path, text: &str, frame: &Frame) -> Result<Vec<Pass>> {
    with_tracer::<R, _>(path, text, frame, |_| {}, |tracer| {
        let (w, h) = (frame.width as u32, frame.height as u32);
        let mut scratch = HeapScratch::new(tracer.scene(), frame);
        let mut traced = vec![lattice_rt::Traced::default(); frame.traced_len(lattice_rt::Share::ALL)];
        let mut out = Vec::new();
        for pass in [8u8, 4, 2, 1] {
            let mut bits = vec![0u8; BitFrame::bytes(w, h)];
            let mut target = BitFrame::new(w, h, &mut bits).expect("sized");
            let start = Instant::now();
            let stats = lattice_rt::render_pass(tracer, frame, lattice_rt::Share::ALL, pass, &mut traced, &mut target, &mut scratch.scratch(), &mut lattice_rt::NoHooks)
                .map_err(|e| match e {
                    RenderError::Draw(never) => match never {},
                    other => anyhow!("{other}"),
                })?;
            out.push(Pass { pass, bits, stats, elapsed: start.elapsed() });
        }
        Ok(out)
    })
}

/// Renders with the accelerator chosen by `accel` (building the lattice when needed).
pub fn render_accel<R: Real>(
    scene: &Scene<'_, R>,
    accel: Accel,
    cfg: &LatticeConfig,
    frame: &Frame,
    tune: impl Fn(&mut Tracer<'_, '_, R, dyn Accelerator<R> + Sync + '_>),
    progress: bool,
    parallel: bool,
) -> Result<Rendered> {
    let mut bufs;
    let lattice;
    let a: &(dyn Accelerator<R> + Sync) = match accel {
        Accel::Lattice => {
            bufs = lattice_storage(scene, cfg)?;
            lattice = build_lattice(&mut bufs, scene, cfg)?;
            &lattice
        }
        Accel::Bbox => &BoundingBox,
        Accel::Brute => &BruteForce,
    };
    let mut tracer = Tracer::new(scene, a);
    tune(&mut tracer);
    if parallel {
        render_with(&tracer, frame, progress)
    } else {
        render_band(&tracer, frame, progress)
    }
}

fn print_stats(label: &str, s: &Stats, elapsed: Duration) {
    println!(
        "{label}: {:.1} ms, rays {} (primary {}, shadow {}, reflection {}, refraction {}), object tests {} ({:.2}/ray), inside tests {}, cells {}",
        elapsed.as_secs_f64() * 1e3,
        s.total_rays(),
        s.rays[0],
        s.rays[1],
        s.rays[2],
        s.rays[3],
        s.object_tests,
        s.object_tests as f64 / s.total_rays().max(1) as f64,
        s.inside_tests,
        s.cells_visited,
    );
}

/// `host-sim render`.
pub fn render_cmd<R: Real>(a: &RenderArgs) -> Result<()> {
    crate::output::check_png_size(a.size.0 as u32, a.size.1 as u32, a.scale)?;
    let text = read(&a.scene)?;
    let frame = Frame {
        tile: a.tile,
        dither: a.dither.mode(),
        sampling: a.sampling.mode(),
        outline: !a.no_outline,
        tone: lattice_rt::Tone { gamma_tenths: a.gamma },
        cutoff: a.cutoff,
        ..Frame::new(a.size.0, a.size.1)
    };
    let mut storage = object_storage::<R>(&text)?;
    let scene = parse_scene::<R>(&a.scene, &text, &mut storage, &frame)?;
    let mut out = render_accel(&scene, a.accel, &crate::cli::lattice_config(a.cells, a.budget), &frame, |_| {}, true, true).map_err(|e| {
        // Only render chooses its method: say how to trace without a lattice.
        if a.budget.is_some() && e.to_string().starts_with("no lattice fits") {
            anyhow!("{e}, or render with --accel bbox (no lattice)")
        } else {
            e
        }
    })?;
    let frame_bits = BitFrame::wrap(frame.width as u32, frame.height as u32, &mut out.bits).expect("sized by render");
    // Every output under a temporary name first: if one cannot be written, none is left.
    let mut staged = crate::output::Staged::default();
    crate::output::write_png_look(&frame_bits, &staged.stage(&a.output)?, crate::output::PngLook { theme: a.theme, scale: a.scale, grid: a.grid }).with_context(|| format!("cannot write {}", a.output.display()))?;
    if let Some(p) = &a.pbm {
        write_pbm(&frame_bits, &staged.stage(p)?).with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &a.gray {
        write_pgm(frame.width as u32, frame.height as u32, &out.gray, &staged.stage(p)?).with_context(|| format!("cannot write {}", p.display()))?;
    }
    staged.commit()?;
    for p in [Some(&a.output), a.pbm.as_ref(), a.gray.as_ref()].into_iter().flatten() {
        println!("wrote {}", p.display());
    }
    print_stats(&format!("{} {} {}", a.scene.display(), R::NAME, a.accel.name()), &out.stats, out.elapsed);
    Ok(())
}



/// `host-sim stats`.
pub fn stats_cmd<R: Real>(a: &StatsArgs) -> Result<()> {
    let text = read(&a.scene)?;
    let frame = Frame::new(a.size.0, a.size.1);
    let mut storage = object_storage::<R>(&text)?;
    let scene = parse_scene::<R>(&a.scene, &text, &mut storage, &frame)?;
    let cfg = crate::cli::lattice_config(a.cells, a.budget);
    let mut bufs = lattice_storage(&scene, &cfg)?;
    let t0 = Instant::now();
    let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
    let build = t0.elapsed();
    let fx = Effects::of(&scene);
    println!("scene {} ({})", a.scene.display(), R::NAME);
    println!(
        "  objects {}, composites {}, materials {}, lights {}, depth {}",
        scene.objects().len(),
        scene.composites().len(),
        scene.materials().len(),
        scene.lights().len(),
        scene.max_depth()
    );
    println!("  effects: {fx}");
    for (i, g) in lattice.lattices().iter().enumerate() {
        let name = if i == 0 { "world lattice".to_string() } else { format!("sub-lattice {}", i - 1) };
        println!("  {name}: {} x {} x {} cells", g.n[0], g.n[1], g.n[2]);
    }
    if cfg.budget.is_some() {
        println!("  within {} bytes: {}", a.budget.unwrap_or(0), Lattice::choose(&scene, &cfg));
    }
    println!(
        "  lattice: {} cells, {} references, {} bytes, built in {:.3} ms",
        lattice.cell_count(),
        lattice.ref_count(),
        lattice.bytes(),
        build.as_secs_f64() * 1e3
    );
    per_accelerator(&scene, &cfg, frame, a.runs)
}


/// Work per primary ray and full-render time of each accelerator on `scene`, printed.
fn per_accelerator<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, frame: Frame, runs: usize) -> Result<()> {
    let pixels = frame.width as f64 * frame.height as f64;
    // Primary rays only: the paper's per-ray figures.
    let primary_only = |t: &mut Tracer<'_, '_, R, dyn Accelerator<R> + Sync + '_>| {
        t.set_max_depth(0).expect("depth 0 is always valid");
        t.set_effects(Effects::NONE);
    };
    println!("  per eye ray at {}x{}, each method answering every eye ray as in the paper's Table 1:", frame.width, frame.height);
    let accels = [Accel::Brute, Accel::Bbox, Accel::Lattice];
    for acc in accels {
        let plain = |t: &mut Tracer<'_, '_, R, dyn Accelerator<R> + Sync + '_>| {
            primary_only(t);
            t.set_eye_rays(EyeRays::Plain);
        };
        let r = render_accel(scene, acc, cfg, &frame, plain, false, false)?;
        println!(
            "    {:8} object tests {:6.3}, bounding-box (inside) tests {:6.2}, cells visited {:6.2}",
            acc.name(),
            r.stats.object_tests as f64 / pixels,
            r.stats.inside_tests as f64 / pixels,
            r.stats.cells_visited as f64 / pixels
        );
    }
    let defaults = render_accel(scene, Accel::Lattice, cfg, &frame, primary_only, false, false)?;
    let how = match Tracer::new(scene, &BruteForce).eye_rays() {
        EyeRays::Windows => "every object's window on the image (its box projected through the eye) is tested and only the objects whose window holds the ray are intersected: no cell is walked, whichever method is chosen",
        EyeRays::Accelerator => "the lattice is walked, skipping objects whose window on the image misses the ray",
        EyeRays::Plain => "the method chosen answers them",
    };
    println!(
        "    tracer's default: object tests {:6.3}, cells visited {:6.2}: {how}",
        defaults.stats.object_tests as f64 / pixels,
        defaults.stats.cells_visited as f64 / pixels,
    );
    // Full renders, interleaved so drift on a shared machine hits all methods alike.
    let mut times: Vec<Vec<Duration>> = vec![Vec::new(); accels.len()];
    let mut last = Vec::new();
    for _ in 0..runs.max(1) {
        last.clear();
        for (i, acc) in accels.iter().enumerate() {
            let r = render_accel(scene, *acc, cfg, &frame, |_| {}, false, false)?;
            times[i].push(r.elapsed);
            last.push(r);
        }
    }
    let med: Vec<Duration> = times.into_iter().map(median).collect();
    println!(
        "  full render at {}x{} with the tracer's defaults (eye rays, and shadow rays towards a directional first light, answered by windows where the scene allows: the methods differ only in the rays left to them), median of {} interleaved runs:",
        frame.width,
        frame.height,
        runs.max(1)
    );
    for (i, acc) in accels.iter().enumerate() {
        let s = &last[i].stats;
        println!(
            "    {:8} {:9.2} ms  rays {:7}  object tests {:9}  ({:.2}/ray)",
            acc.name(),
            med[i].as_secs_f64() * 1e3,
            s.total_rays(),
            s.object_tests,
            s.object_tests as f64 / s.total_rays().max(1) as f64
        );
    }
    let same = last.windows(2).all(|w| w[0].bits == w[1].bits);
    println!(
        "  lattice/bbox time ratio {:.3} (lattice {:.2}x faster); images identical across accelerators: {same}",
        med[2].as_secs_f64() / med[1].as_secs_f64(),
        med[1].as_secs_f64() / med[2].as_secs_f64()
    );
    Ok(())
}

/// The default job: the paper's scenes at 160x100 and 128x64.
pub fn gallery(out: &Path, scenes: &Path) -> Result<()> {
    for name in PAPER_SCENES {
        let path = scenes.join(format!("{name}.scene"));
        let text = read(&path)?;
        for (w, h) in [(160u16, 100u16), (128, 64)] {
            let frame = Frame::new(w, h);
            let mut storage = object_storage::<f64>(&text)?;
            let scene = parse_scene::<f64>(&path, &text, &mut storage, &frame)?;
            let mut r = render_accel(&scene, Accel::Lattice, &LatticeConfig::default(), &frame, |_| {}, true, true)?;
            let f = BitFrame::wrap(w as u32, h as u32, &mut r.bits).expect("sized by render");
            let png = out.join(format!("{name}-{w}x{h}.png"));
            write_png(&f, &png, Theme::Paper, 3)?;
            write_pbm(&f, &out.join(format!("{name}-{w}x{h}.pbm")))?;
            write_gray_png(w as u32, h as u32, &r.gray, &out.join(format!("{name}-{w}x{h}-gray.png")), 2)?;
            print_stats(&format!("{}", png.display()), &r.stats, r.elapsed);
        }
    }
    println!("wrote the paper's four scenes to {}/", out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{build_lattice, lattice_storage};
    use lattice_rt::Dither;

    #[test]
    fn parallel_bands_equal_the_serial_render() {
        for name in ["chair", "whitted"] {
            let path = std::path::PathBuf::from(format!("{}/../scenes/{name}.scene", env!("CARGO_MANIFEST_DIR")));
            let text = read(&path).unwrap();
            let mut storage = object_storage::<f64>(&text).unwrap();
            let scene = parse_scene::<f64>(&path, &text, &mut storage, &Frame::new(160, 100)).unwrap();
            let cfg = LatticeConfig::default();
            let mut bufs = lattice_storage(&scene, &cfg).expect("lattice fits");
            let lat = build_lattice(&mut bufs, &scene, &cfg).unwrap();
            let t = Tracer::new(&scene, &lat);
            for dither in [Dither::Bayer, Dither::Pattern(4)] {
                let frame = Frame { dither, ..Frame::new(160, 100) };
                let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
                let par = pool.install(|| render_with(&t, &frame, false)).unwrap();
                let ser = render_band(&t, &frame, false).unwrap();
                assert!(par.bits == ser.bits && par.gray == ser.gray, "{name} {dither:?}");
                assert_eq!(par.stats, ser.stats, "{name}");
            }
        }
    }
}
