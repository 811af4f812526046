//! The commands: render, stats and the default gallery job.

use crate::cli::{Accel, RenderArgs, StatsArgs};
use crate::load::{build_lattice, lattice_storage, object_storage, parse_scene, read};
use crate::output::{write_gray_png, write_pbm, write_pgm};
use crate::report::{print_json, LatticeSize, MethodRender, MethodWork, RenderReport, StatsReport, Work};
use crate::shared::median;
use anyhow::{anyhow, bail, Context, Result};
use embedded_graphics::pixelcolor::{BinaryColor, Gray2};
use lattice_rt::dither::Shade;
use lattice_rt::render::{Hooks, RenderError};
use lattice_rt::trace::EyeRays;
use lattice_rt::Effects;
use lattice_rt::{
    render, Accelerator, BitFrame, BoundingBox, BruteForce, Frame, HeapScratch, Lattice, LatticeConfig, Real, Scene,
    ShadeFrame, Stats, Tracer,
};
use std::path::Path;
use std::time::{Duration, Instant};

/// A finished render on the host.
pub struct Rendered {
    /// Packed 1-bit frame (see `BitFrame`): the pixels lit in any subframe.
    pub bits: Vec<u8>,
    /// Each pixel's shade, row-major: its step, `0..=C::STEPS` of the `Shade` it was rendered
    /// in (1: the 1-bit frame; 3: the gray mode's four shades).
    pub shades: Vec<u8>,
    /// Gray levels 0..=64, row-major.
    pub gray: Vec<u8>,
    /// Work counted by the core.
    pub stats: Stats,
    /// Wall time of the render.
    pub elapsed: Duration,
    /// The size of the lattice it traced with, when [`render_accel`] built one.
    pub lattice: Option<LatticeSize>,
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
    render_with_in::<R, A, BinaryColor>(tracer, frame, progress)
}

/// [`render_with`] in the shades of `C` (a [`Gray2`] frame: the gray mode's).
pub fn render_with_in<R: Real, A: Accelerator<R> + ?Sized + Sync, C: Shade>(
    tracer: &Tracer<'_, '_, R, A>,
    frame: &Frame,
    progress: bool,
) -> Result<Rendered> {
    let start = Instant::now();
    let tiles_y = (frame.height as usize).div_ceil(frame.tile.max(1) as usize);
    let threads = rayon::current_num_threads().min(tiles_y).max(1);
    if !frame.bands_independent() || threads == 1 {
        let mut r = render_band_in::<R, A, C>(tracer, frame, progress)?;
        r.elapsed = start.elapsed();
        return Ok(r);
    }
    use rayon::prelude::*;
    let per = tiles_y.div_ceil(threads);
    let bands: Vec<Result<Rendered>> = (0..threads)
        .into_par_iter()
        .map(|i| {
            let rows = ((i * per) as u16, ((i + 1) * per).min(tiles_y) as u16);
            render_band_in::<R, A, C>(tracer, &Frame { rows, ..*frame }, false)
        })
        .collect();
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut out = Rendered {
        bits: vec![0; BitFrame::bytes(w as u32, h as u32)],
        shades: vec![0; w * h],
        gray: vec![0; w * h],
        stats: Stats::default(),
        elapsed: Duration::ZERO,
        lattice: None,
    };
    for band in bands {
        let band = band?;
        out.bits.iter_mut().zip(&band.bits).for_each(|(a, b)| *a |= b);
        out.gray.iter_mut().zip(&band.gray).for_each(|(a, b)| *a |= b);
        out.shades.iter_mut().zip(&band.shades).for_each(|(a, b)| *a |= b);
        out.stats.add(&band.stats);
    }
    out.elapsed = start.elapsed();
    Ok(out)
}

/// Renders the frame's band of tile rows on this thread (pixels outside it stay 0).
/// Timing measurements use this: one core, so methods and modes compare fairly.
pub fn render_band<R: Real, A: Accelerator<R> + ?Sized>(
    tracer: &Tracer<'_, '_, R, A>,
    frame: &Frame,
    progress: bool,
) -> Result<Rendered> {
    render_band_in::<R, A, BinaryColor>(tracer, frame, progress)
}

/// [`render_band`] in the shades of `C`.
pub fn render_band_in<R: Real, A: Accelerator<R> + ?Sized, C: Shade>(
    tracer: &Tracer<'_, '_, R, A>,
    frame: &Frame,
    progress: bool,
) -> Result<Rendered> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut steps = vec![0u8; w * h];
    let mut target = ShadeFrame::<C>::new(w as u32, h as u32, &mut steps).expect("sized above");
    let mut scratch = HeapScratch::new(tracer.scene(), frame);
    let mut hooks = HostHooks { width: w, gray: vec![0; w * h], start: Instant::now(), progress, bar: None };
    let start = Instant::now();
    let stats = render(tracer, frame, &mut target, &mut scratch.scratch(), &mut hooks).map_err(|e| match e {
        RenderError::Draw(never) => match never {},
        other => anyhow!("{other}"),
    })?;
    let elapsed = start.elapsed();
    let mut bits = vec![0u8; BitFrame::bytes(w as u32, h as u32)];
    target.lit(&mut BitFrame::new(w as u32, h as u32, &mut bits).expect("sized"));
    Ok(Rendered { bits, shades: steps, gray: hooks.gray, stats, elapsed, lattice: None })
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

/// [`render_text`] in the shades of `C` (`Gray2`: the gray mode's frame).
pub fn render_text_in<R: Real, C: Shade>(
    path: &Path,
    text: &str,
    frame: &lattice_rt::Frame,
    tune: impl FnOnce(&mut lattice_rt::Tracer<'_, '_, R, lattice_rt::Lattice<'_, R>>),
) -> Result<Rendered> {
    with_tracer(path, text, frame, tune, |tracer| render_band_in::<R, _, C>(tracer, frame, false))
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
    with_tracer::<R, _>(
        path,
        text,
        frame,
        |_| {},
        |tracer| {
            let (w, h) = (frame.width as u32, frame.height as u32);
            let mut scratch = HeapScratch::new(tracer.scene(), frame);
            let mut traced = vec![lattice_rt::Traced::default(); frame.traced_len(lattice_rt::Share::ALL)];
            let mut out = Vec::new();
            for pass in [8u8, 4, 2, 1] {
                let mut bits = vec![0u8; BitFrame::bytes(w, h)];
                let mut target = BitFrame::new(w, h, &mut bits).expect("sized");
                let start = Instant::now();
                let stats = lattice_rt::render_pass(
                    tracer,
                    frame,
                    lattice_rt::Share::ALL,
                    pass,
                    &mut traced,
                    &mut target,
                    &mut scratch.scratch(),
                    &mut lattice_rt::NoHooks,
                )
                .map_err(|e| match e {
                    RenderError::Draw(never) => match never {},
                    other => anyhow!("{other}"),
                })?;
                out.push(Pass { pass, bits, stats, elapsed: start.elapsed() });
            }
            Ok(out)
        },
    )
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
    render_accel_in::<R, BinaryColor>(scene, accel, cfg, frame, tune, progress, parallel)
}

/// [`render_accel`] in the shades of `C`.
pub fn render_accel_in<R: Real, C: Shade>(
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
    let mut size = None;
    let a: &(dyn Accelerator<R> + Sync) = match accel {
        Accel::Lattice => {
            bufs = lattice_storage(scene, cfg)?;
            lattice = build_lattice(&mut bufs, scene, cfg)?;
            size = Some(LatticeSize::of(&lattice));
            &lattice
        }
        Accel::Bbox => &BoundingBox,
        Accel::Brute => &BruteForce,
    };
    let mut tracer = Tracer::new(scene, a);
    tune(&mut tracer);
    let mut out = if parallel {
        render_with_in::<R, _, C>(&tracer, frame, progress)
    } else {
        render_band_in::<R, _, C>(&tracer, frame, progress)
    }?;
    out.lattice = size;
    Ok(out)
}

/// One line of what a render counted.
fn stats_line(label: &str, s: &Stats, elapsed: Duration) -> String {
    format!(
        "{label}: {:.1} ms, rays {} (primary {}, shadow {}, reflection {}, refraction {}), object tests {} ({:.2}/ray), inside tests {}, cells walked {}",
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
    )
}

/// `host-sim render`.
pub fn render_cmd<R: Real>(a: &RenderArgs) -> Result<()> {
    crate::output::check_png_size(a.size.0 as u32, a.size.1 as u32, a.scale)?;
    let files = outputs(a)?;
    let text = read(&a.scene)?;
    let frame = a.frame();
    let mut storage = object_storage::<R>(&text)?;
    let scene = parse_scene::<R>(&a.scene, &text, &mut storage, &frame)?;
    let cfg = crate::cli::lattice_config(a.cells, a.budget);
    let rendered = if a.levels == 4 {
        render_accel_in::<R, Gray2>(&scene, a.accel, &cfg, &frame, |_| {}, true, true)
    } else {
        render_accel(&scene, a.accel, &cfg, &frame, |_| {}, true, true)
    };
    let mut out = rendered.map_err(|e| {
        // Only render chooses its method: say how to trace without a lattice.
        match e.downcast_ref::<crate::load::BudgetTooSmall>() {
            Some(b) => anyhow!("{b}, or render with --accel bbox (no lattice)"),
            None => e,
        }
    })?;
    let frame_bits = BitFrame::wrap(frame.width as u32, frame.height as u32, &mut out.bits).expect("sized by render");
    let look = crate::output::PngLook { theme: a.theme, scale: a.scale, grid: a.grid };
    let (w, h) = (frame.width as u32, frame.height as u32);
    // Every output under a temporary name first: if one cannot be written, none is left.
    let mut staged = crate::output::Staged::default();
    let mut stdout = None;
    for &(path, kind) in &files {
        let png = || -> Result<Vec<u8>> {
            match a.levels {
                4 => crate::output::shades_png_bytes(w, h, &out.shades, 3, look),
                _ => crate::output::png_bytes(&frame_bits, look),
            }
        };
        if path == Path::new("-") {
            stdout = Some(png()?);
            continue;
        }
        let tmp = staged.stage(path)?;
        match kind {
            Output::Png => png().and_then(|bytes| std::fs::write(&tmp, bytes).map_err(Into::into)),
            Output::Pbm => write_pbm(&frame_bits, &tmp),
            Output::Pgm => write_pgm(w, h, &out.gray, &tmp),
            Output::GrayPng => write_gray_png(w, h, &out.gray, &tmp, a.scale),
        }
        .with_context(|| format!("cannot write {}", path.display()))?;
    }
    staged.commit()?;
    if let Some(png) = stdout {
        crate::stdout::bytes(&png).context("cannot write the PNG to standard output")?;
    }
    // With the picture or JSON on standard output, the messages go to standard error.
    let quiet = a.output == Path::new("-") || a.json;
    let say = |line: String| {
        if quiet {
            eprintln!("{line}");
            Ok(())
        } else {
            crate::say!("{line}")
        }
    };
    for (p, _) in files.iter().filter(|(p, _)| *p != Path::new("-")) {
        say(format!("wrote {}", p.display()))?;
    }
    if a.json {
        let report = RenderReport {
            scene: a.scene.display().to_string(),
            scalar: R::NAME,
            accel: a.accel.name(),
            width: frame.width,
            height: frame.height,
            lattice: out.lattice,
            work: Work::of(&out.stats, out.elapsed),
        };
        return print_json(&report);
    }
    say(stats_line(&format!("{} {} {}", a.scene.display(), R::NAME, a.accel.name()), &out.stats, out.elapsed))?;
    Ok(())
}

/// What a file written by `render` holds, by the option and the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Output {
    /// The 1-bit frame in the PNG's theme.
    Png,
    /// The 1-bit frame as binary PBM.
    Pbm,
    /// The gray levels (0..=64) as PGM.
    Pgm,
    /// The gray levels as a gray PNG.
    GrayPng,
}

/// The files `render` writes with what each holds: the extension names the format, and one
/// that is not the option's is refused before anything is rendered (`-o -`: PNG to standard
/// output).
fn outputs(a: &RenderArgs) -> Result<Vec<(&Path, Output)>> {
    let ext = |p: &Path| p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    let mut out = Vec::new();
    out.push((
        a.output.as_path(),
        match ext(&a.output).as_str() {
            _ if a.output == Path::new("-") => Output::Png,
            "png" => Output::Png,
            "pbm" => Output::Pbm,
            "pgm" => Output::Pgm,
            _ => bail!("-o {}: the extension names the format: .png (the frame in --theme), .pbm (the 1-bit frame) or .pgm (gray levels); - writes a PNG to standard output", a.output.display()),
        },
    ));
    if a.levels == 4 && (out[0].1 == Output::Pbm || a.pbm.is_some()) {
        bail!("--levels 4: a PBM holds one bit per pixel; write the four shades as PNG (-o FILE.png)");
    }
    if let Some(p) = &a.pbm {
        if ext(p) != "pbm" {
            bail!("--pbm {}: writes a PBM file, so its name must end in .pbm (-o FILE.png writes a PNG)", p.display());
        }
        out.push((p.as_path(), Output::Pbm));
    }
    if let Some(p) = &a.gray {
        out.push((
            p.as_path(),
            match ext(p).as_str() {
                "pgm" => Output::Pgm,
                "png" => Output::GrayPng,
                _ => bail!(
                    "--gray {}: writes the gray levels as .pgm or as a gray .png; give a name ending in one of them",
                    p.display()
                ),
            },
        ));
    }
    if a.json && a.output == Path::new("-") {
        bail!("--json and -o - both write to standard output: write the PNG to a file");
    }
    Ok(out)
}

/// `host-sim stats`.
pub fn stats_cmd<R: Real>(a: &StatsArgs) -> Result<()> {
    if a.spd {
        return spd_stats::<R>(a);
    }
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
    let (per_eye_ray, full_render, identical) = per_accelerator(&scene, &cfg, frame, a.runs)?;
    let report = StatsReport {
        scene: a.scene.display().to_string(),
        scalar: R::NAME,
        width: frame.width,
        height: frame.height,
        objects: scene.objects().len(),
        composites: scene.composites().len(),
        materials: scene.materials().len(),
        lights: scene.lights().len(),
        depth: scene.max_depth(),
        effects: fx.names().collect(),
        lattice: LatticeSize::of(&lattice),
        build_ms: build.as_secs_f64() * 1e3,
        per_eye_ray,
        full_render,
        identical,
    };
    if a.json {
        return print_json(&report);
    }
    print_stats(&report, &scene, &cfg, a)?;
    Ok(())
}

/// `stats`'s report as text: the scene, its lattice, the work per eye ray and the full render.
fn print_stats<R: Real>(r: &StatsReport, scene: &Scene<'_, R>, cfg: &LatticeConfig, a: &StatsArgs) -> Result<()> {
    let fx = Effects::of(scene);
    crate::say!("scene {} ({})", r.scene, r.scalar)?;
    crate::say!(
        "  objects {}, composites {}, materials {}, lights {}, depth {}",
        r.objects,
        r.composites,
        r.materials,
        r.lights,
        r.depth
    )?;
    crate::say!("  effects: {fx}")?;
    for (i, n) in r.lattice.lattices.iter().enumerate() {
        let name = if i == 0 { "world lattice".to_string() } else { format!("sub-lattice {}", i - 1) };
        crate::say!("  {name}: {} x {} x {} cells", n[0], n[1], n[2])?;
    }
    if cfg.budget.is_some() {
        crate::say!("  within {} bytes: {}", a.budget.unwrap_or(0), Lattice::choose(scene, cfg))?;
    }
    crate::say!(
        "  lattice: {} cells, {} references, {} bytes, built in {:.3} ms",
        r.lattice.cells,
        r.lattice.references,
        r.lattice.bytes,
        r.build_ms
    )?;
    crate::say!(
        "  per eye ray at {}x{}, each method answering every eye ray as in the paper's Table 1:",
        r.width,
        r.height
    )?;
    for m in &r.per_eye_ray {
        if m.method == "default" {
            let how = match Tracer::new(scene, &BruteForce).eye_rays() {
                EyeRays::Windows => "every object's window on the image (its box projected through the eye) is tested and only the objects whose window holds the ray are intersected: no cell is walked, whichever method is chosen",
                EyeRays::Accelerator => "the lattice is walked, skipping objects whose window on the image misses the ray",
                EyeRays::Plain => "the method chosen answers them",
            };
            crate::say!(
                "    tracer's default: object tests {:6.3}, cells visited {:6.2}: {how}",
                m.object_tests_per_eye_ray,
                m.cells_per_eye_ray
            )?;
        } else {
            crate::say!(
                "    {:8} object tests {:6.3}, bounding-box (inside) tests {:6.2}, cells visited {:6.2}",
                m.method,
                m.object_tests_per_eye_ray,
                m.inside_tests_per_eye_ray,
                m.cells_per_eye_ray
            )?;
        }
    }
    crate::say!(
        "  full render at {}x{} with the tracer's defaults (eye rays, and shadow rays towards a directional first light, answered by windows where the scene allows: the methods differ only in the rays left to them), median of {} interleaved runs:",
        r.width,
        r.height,
        a.runs.max(1)
    )?;
    for m in &r.full_render {
        let w = &m.work;
        crate::say!(
            "    {:8} {:9.2} ms  rays {:7}  object tests {:9}  ({:.2}/ray)",
            m.method,
            m.median_ms,
            w.rays.total,
            w.object_tests,
            w.object_tests as f64 / w.rays.total.max(1) as f64
        )?;
    }
    let (bbox, lat) = (r.full_render[1].median_ms, r.full_render[2].median_ms);
    crate::say!(
        "  lattice/bbox time ratio {:.3} (lattice {:.2}x faster); images identical across accelerators: {}",
        lat / bbox,
        bbox / lat,
        r.identical
    )?;
    Ok(())
}

/// Work per eye ray of each accelerator (answering every eye ray, then the tracer's default),
/// each accelerator's full render (median time of `runs` interleaved), and whether their
/// frames are identical.
fn per_accelerator<R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    frame: Frame,
    runs: usize,
) -> Result<(Vec<MethodWork>, Vec<MethodRender>, bool)> {
    let pixels = frame.width as f64 * frame.height as f64;
    // Primary rays only: the paper's per-ray figures.
    let primary_only = |t: &mut Tracer<'_, '_, R, dyn Accelerator<R> + Sync + '_>| {
        t.set_max_depth(0).expect("depth 0 is always valid");
        t.set_effects(Effects::NONE);
    };
    let per = |method: &'static str, s: &Stats| MethodWork {
        method,
        object_tests_per_eye_ray: s.object_tests as f64 / pixels,
        inside_tests_per_eye_ray: s.inside_tests as f64 / pixels,
        cells_per_eye_ray: s.cells_visited as f64 / pixels,
    };
    let accels = [Accel::Brute, Accel::Bbox, Accel::Lattice];
    let mut per_eye_ray = Vec::new();
    for acc in accels {
        let plain = |t: &mut Tracer<'_, '_, R, dyn Accelerator<R> + Sync + '_>| {
            primary_only(t);
            t.set_eye_rays(EyeRays::Plain);
        };
        per_eye_ray.push(per(acc.name(), &render_accel(scene, acc, cfg, &frame, plain, false, false)?.stats));
    }
    per_eye_ray
        .push(per("default", &render_accel(scene, Accel::Lattice, cfg, &frame, primary_only, false, false)?.stats));
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
    let identical = last.windows(2).all(|w| w[0].bits == w[1].bits);
    let full = accels
        .iter()
        .zip(times)
        .zip(&last)
        .map(|((acc, t), r)| MethodRender {
            method: acc.name(),
            median_ms: median(t).as_secs_f64() * 1e3,
            work: Work::of(&r.stats, r.elapsed),
        })
        .collect();
    Ok((per_eye_ray, full, identical))
}

/// `render`'s options alone, parsed from a command line (what the gallery runs).
#[derive(clap::Parser, Debug)]
struct RenderLine {
    #[command(flatten)]
    args: RenderArgs,
}

/// The sizes the gallery renders: `render`'s default (the panel's 128x64) and the paper's 160x100.
pub const GALLERY_SIZES: [&str; 2] = ["128x64", "160x100"];

/// The default job and `gallery`: every scene file in `scenes` (sorted by name) rendered by
/// `render` with its default settings at each of [`GALLERY_SIZES`], into `out` as
/// `NAME-WxH.png`, `.pbm` and `-gray.png`; the command that draws each is printed.
pub fn gallery(out: &Path, scenes: &Path) -> Result<()> {
    let mut files: Vec<_> = std::fs::read_dir(scenes)
        .with_context(|| format!("cannot read the scene folder {}", scenes.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "scene"))
        .collect();
    files.sort();
    if files.is_empty() {
        bail!("{}: no .scene files to render", scenes.display());
    }
    for path in &files {
        let name = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
        for size in GALLERY_SIZES {
            let at = |suffix: &str| out.join(format!("{name}-{size}{suffix}")).display().to_string();
            let line = [
                "render".to_string(),
                path.display().to_string(),
                "--size".into(),
                size.into(),
                "-o".into(),
                at(".png"),
                "--pbm".into(),
                at(".pbm"),
                "--gray".into(),
                at("-gray.png"),
            ];
            crate::say!("host-sim {}", line[..].join(" "))?;
            let RenderLine { args } = <RenderLine as clap::Parser>::try_parse_from(&line)?;
            render_cmd::<f64>(&args)?;
        }
    }
    crate::say!("wrote {} scenes to {}/ (each as `render` draws it by default)", files.len(), out.display())?;
    Ok(())
}

/// `stats --spd`: the SPD protocol's counts ([`crate::spd::protocol`]) with the lattice alone
/// and with the tracer's defaults.
fn spd_stats<R: Real>(a: &StatsArgs) -> Result<()> {
    use crate::spd::protocol::{count, Setup, RESOLUTION};
    let text = read(&a.scene)?;
    let frame = Frame::new(RESOLUTION, RESOLUTION);
    let mut storage = object_storage::<R>(&text)?;
    let scene = parse_scene::<R>(&a.scene, &text, &mut storage, &frame)?;
    let cfg = crate::cli::lattice_config(a.cells, a.budget);
    let mut bufs = lattice_storage(&scene, &cfg)?;
    let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
    let counts = [Setup::AsHavran, Setup::Defaults].map(|s| count(&scene, &lattice, s));
    let report = crate::report::SpdReport {
        scene: a.scene.display().to_string(),
        scalar: R::NAME,
        objects: scene.objects().len(),
        lattice: LatticeSize::of(&lattice),
        counts: counts.to_vec(),
    };
    if a.json {
        return print_json(&report);
    }
    crate::say!(
        "scene {} ({}): {} objects, SPD protocol (513x513 eye rays at the pixel corners, depth 5)",
        report.scene,
        R::NAME,
        report.objects
    )?;
    crate::say!(
        "  lattice: {} cells, {} references, {} bytes",
        report.lattice.cells,
        report.lattice.references,
        report.lattice.bytes
    )?;
    for (name, v) in counts[0].invariants.named() {
        crate::say!("  {name:<24}{v:>10}")?;
    }
    for c in &counts {
        crate::say!(
            "  {:?}: {:.2} object tests per ray, {:.2} cell steps per ray, {:.0} ms",
            c.setup,
            c.tests_per_ray,
            c.steps_per_ray,
            c.ms
        )?;
    }
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
