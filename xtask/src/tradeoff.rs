//! `cargo xtask tradeoff`: what accuracy costs in time. Varies one knob at a time from a default
//! (f64, the scene's depth, no cutoff, one ray per pixel, Bayer), measures the error against a
//! reference (f64, 4x4 rays per pixel) and the cost, and writes `docs/accuracy.md` and a plot.

use anyhow::Result;
use host_sim::load::read;
use host_sim::output::write_atomic;
use host_sim::run::render_text;
use host_sim::shared::median;
use host_sim::shared::plot_link;
use lattice_rt::dither::Ditherer;
use lattice_rt::{Dither, F32Micro, F32MicroNewton, Frame, Fx, Real, Sampling};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// One point of the study.
#[derive(Clone, Debug)]
struct Config {
    knob: &'static str,
    label: String,
    scalar: &'static str,
    depth: Option<u8>,
    cutoff: f64,
    sampling: Sampling,
    dither: Dither,
    /// Tile side: adaptive sampling traces each tile's last row and column too.
    tile: u8,
}

fn configs() -> Vec<Config> {
    let base = Config {
        knob: "default",
        label: "f64, 1 ray/pixel, bayer".into(),
        scalar: "f64",
        depth: None,
        cutoff: 0.0,
        sampling: Sampling::Center,
        dither: Dither::Bayer,
        tile: Frame::new(1, 1).tile,
    };
    let mut v = vec![base.clone()];
    for s in ["f32", "f32-micromath", "f32-micromath-newton", "fixed"] {
        v.push(Config { knob: "scalar", label: s.into(), scalar: s, ..base.clone() });
    }
    for d in 0..=4u8 {
        v.push(Config { knob: "depth", label: format!("depth {d}"), depth: Some(d), ..base.clone() });
    }
    for (c, l) in [
        (1.0 / 256.0, "1/256"),
        (boards_cutoff(), BOARDS_CUTOFF),
        (1.0 / 64.0, "1/64 (one level)"),
        (1.0 / 16.0, "1/16"),
    ] {
        v.push(Config { knob: "cutoff", label: format!("cutoff {l}"), cutoff: c, ..base.clone() });
    }
    for n in [8u8, 4, 2] {
        v.push(Config {
            knob: "sampling",
            label: format!("pattern {n}x{n} (1 ray per block)"),
            dither: Dither::Pattern(n),
            ..base.clone()
        });
    }
    v.push(Config { knob: "sampling", label: "4 rays/pixel".into(), sampling: Sampling::Grid2x2, ..base.clone() });
    v.push(Config {
        knob: "sampling",
        label: "edges only: 4 rays at object edges".into(),
        sampling: Sampling::Edges { contrast: u8::MAX },
        ..base.clone()
    });
    for c in [16u8, 24] {
        v.push(Config {
            knob: "sampling",
            label: format!("edges + contrast >= {c}: 4 rays there"),
            sampling: Sampling::Edges { contrast: c },
            ..base.clone()
        });
    }
    for c in [2u8, 4, 8] {
        v.push(Config {
            knob: "sampling",
            label: format!("adaptive, contrast <= {c}: every 2nd pixel traced, the rest filled"),
            sampling: Sampling::Adaptive { contrast: c, coarse: false },
            ..base.clone()
        });
    }
    v.push(Config {
        knob: "sampling",
        label: PICO_ONE_LEVEL.into(),
        sampling: board_records::frame::SAMPLING,
        tile: board_records::frame::PANEL_TILE,
        ..base.clone()
    });
    v.push(Config {
        knob: "sampling",
        label: PICO_ADAPTIVE.into(),
        sampling: board_records::frame::PANEL_SAMPLING,
        tile: board_records::frame::PANEL_TILE,
        ..base.clone()
    });
    v.push(Config { knob: "dither", label: "floyd-steinberg".into(), dither: Dither::FloydSteinberg, ..base.clone() });
    v.push(Config { knob: "dither", label: "atkinson".into(), dither: Dither::Atkinson, ..base.clone() });
    v
}

/// The label of the boards' cutoff ([`board_records::frame::CUTOFF`]).
const BOARDS_CUTOFF: &str = "1/128 (half a level: the boards' frames)";

/// The boards' cutoff as a weight (0 with none).
fn boards_cutoff() -> f64 {
    board_records::frame::CUTOFF.map_or(0.0, |k| 0.5f64.powi(i32::from(k)))
}

/// The label of adaptive sampling in the Pico's 16x16 tiles (the QEMU boards' frames have 8x8).
const PICO_ADAPTIVE: &str = "adaptive in two levels in 16x16 tiles (the Pico's frame), contrast <= 4";
/// The row of one-level adaptive sampling in the Pico's tiles.
const PICO_ONE_LEVEL: &str = "adaptive in one level in 16x16 tiles, contrast <= 4";

/// One render's outcome.
struct Shot {
    gray: Vec<u8>,
    bits: Vec<u8>,
    rays: u64,
    time: Duration,
}

fn shoot_in<R: Real>(text: &str, path: &Path, c: &Config, w: u16, h: u16) -> Result<Shot> {
    let frame = Frame { dither: c.dither, sampling: c.sampling, tile: c.tile, ..Frame::new(w, h) };
    let r = render_text::<R>(path, text, &frame, |t| {
        if let Some(d) = c.depth {
            t.set_max_depth(d).expect("the study stays within MAX_DEPTH");
        }
        t.set_cutoff(R::from_f64(c.cutoff));
    })?;
    Ok(Shot { gray: r.gray, bits: r.bits, rays: r.stats.total_rays(), time: r.elapsed })
}

fn shoot(text: &str, path: &Path, c: &Config, w: u16, h: u16) -> Result<Shot> {
    match c.scalar {
        "f32" => shoot_in::<f32>(text, path, c, w, h),
        "f32-micromath" => shoot_in::<F32Micro>(text, path, c, w, h),
        "f32-micromath-newton" => shoot_in::<F32MicroNewton>(text, path, c, w, h),
        "fixed" => shoot_in::<Fx>(text, path, c, w, h),
        _ => shoot_in::<f64>(text, path, c, w, h),
    }
}

/// Gray levels (0..=64, as reals) of `n x n` f64 rays per pixel, averaged.
pub fn reference(text: &str, path: &Path, w: u16, h: u16, n: usize) -> Result<Vec<f64>> {
    host_sim::run::with_tracer::<f64, _>(
        path,
        text,
        &Frame::new(w, h),
        |_| {},
        |tracer| {
            let scene = tracer.scene();
            let mut mb = vec![0u32; lattice_rt::Query::mailbox_len(scene)];
            let mut q = lattice_rt::trace::Work::new(&mut mb);
            let (ws, hs) = (2 * n * w as usize, 2 * n * h as usize);
            let mut out = Vec::with_capacity(w as usize * h as usize);
            for y in 0..h as usize {
                for x in 0..w as usize {
                    let mut sum = 0.0;
                    for j in 0..n {
                        for i in 0..n {
                            let ray = scene.camera().ray(
                                (2 * n * x + 2 * i + 1) as i32,
                                (2 * n * y + 2 * j + 1) as i32,
                                ws as i32,
                                hs as i32,
                            );
                            sum += tracer.radiance(ray, &mut q);
                        }
                    }
                    out.push(sum / (n * n) as f64 * 64.0);
                }
            }
            Ok(out)
        },
    )
}

/// The reference dithered the way a configuration dithers (ordered per pixel, or error
/// diffusion in the renderer's tile order with its carries).
fn dither_reference(levels: &[u8], w: usize, h: usize, d: Dither) -> Vec<bool> {
    let mut out = vec![false; w * h];
    let mut store = vec![0i16; Ditherer::rows_len(d, w)];
    let mut dither = Ditherer::new(d, w, &mut store).expect("sized");
    let t = 8;
    for ty in (0..h).step_by(t) {
        dither.next_band();
        for tx in (0..w).step_by(t) {
            let (tw, th) = (t.min(w - tx), t.min(h - ty));
            let tile: Vec<u8> = (0..th)
                .flat_map(|y| (0..tw).map(move |x| (y, x)))
                .map(|(y, x)| levels[(ty + y) * w + tx + x])
                .collect();
            let mut bits = vec![embedded_graphics::pixelcolor::BinaryColor::Off; tw * th];
            dither.tile(tx, ty, tw, th, &tile, &mut bits);
            for (k, b) in bits.iter().enumerate() {
                out[(ty + k / tw) * w + tx + k % tw] = b.is_on();
            }
        }
    }
    out
}

fn bit(bits: &[u8], w: usize, i: usize) -> bool {
    let stride = w.div_ceil(8);
    let (x, y) = (i % w, i / w);
    bits[y * stride + x / 8] & (0x80 >> (x % 8)) != 0
}

/// Error of one configuration over all scenes.
#[derive(Default, Clone)]
struct Tally {
    pixels: usize,
    dither_diff: usize,
    abs_sum: f64,
    sq_sum: f64,
    max_abs: f64,
    rays: u64,
    time: Duration,
    same_settings_diff: usize,
}

/// The command.
pub fn tradeoff_cmd(
    scenes: &[PathBuf],
    size: (u16, u16),
    runs: usize,
    out: &Path,
    plot: &Path,
    firmware_csv: &Path,
) -> Result<()> {
    let configs = configs();
    let (tallies, per_scene) = measure(scenes, &configs, size, runs)?;
    let names: Vec<String> =
        scenes.iter().filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().to_string())).collect();
    let instr = firmware_instructions(firmware_csv, &names, size);
    let mut md = String::new();
    let points = knob_table(&mut md, &configs, &tallies, &instr, &names, size, runs)?;
    scalar_section(&mut md, &names, &per_scene)?;
    targets_section(&mut md, &configs, &tallies, &names, &per_scene)?;
    writeln!(md, "\n![error against cost]({})", plot_link(out, plot))?;
    let title = "Error against cost, one knob at a time";
    crate::plot::scatter(
        plot,
        title,
        "host ms per frame (median, mean over scenes)",
        "mean abs gray error (levels of 64)",
        &points,
    )?;
    write_atomic(out, md.as_bytes())?;
    println!("wrote {} and {}", out.display(), plot.display());
    Ok(())
}

/// Dithered pixels of each scalar's frame that differ from the f64 frame with the same
/// settings, per scene and scalar: (differing, all).
type PerScene = BTreeMap<(String, &'static str), (usize, usize)>;

/// Renders every scene with every configuration (interleaved, `runs` times) against a 16-ray
/// f64 reference; the error and cost tallies per configuration.
fn measure(scenes: &[PathBuf], configs: &[Config], (w, h): (u16, u16), runs: usize) -> Result<(Vec<Tally>, PerScene)> {
    let mut tallies = vec![Tally::default(); configs.len()];
    let mut per_scene: BTreeMap<(String, &'static str), (usize, usize)> = BTreeMap::new();
    let bar = host_sim::progress::bar(scenes.len(), "scenes");
    for path in scenes {
        let name = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
        bar.inc(1);
        host_sim::progress::log(&bar, format_args!("  {name}: reference (16 rays/pixel, f64)"));
        let text = read(path)?;
        let reference = reference(&text, path, w, h, 4)?;
        let ref_levels: Vec<u8> = reference.iter().map(|v| v.round().clamp(0.0, 64.0) as u8).collect();
        // Interleave configurations so drift on a shared machine hits all alike.
        let mut times = vec![Vec::new(); configs.len()];
        let mut shots: Vec<Option<Shot>> = (0..configs.len()).map(|_| None).collect();
        for _ in 0..runs.max(1) {
            for (i, c) in configs.iter().enumerate() {
                let s = shoot(&text, path, c, w, h)?;
                times[i].push(s.time);
                shots[i] = Some(s);
            }
        }
        let default_bits = shots[0].as_ref().map(|s| s.bits.clone()).unwrap_or_default();
        for (i, c) in configs.iter().enumerate() {
            let s = shots[i].take().expect("rendered");
            let dref = dither_reference(&ref_levels, w as usize, h as usize, c.dither);
            let t = &mut tallies[i];
            let npx = w as usize * h as usize;
            t.pixels += npx;
            let mut differ = 0;
            for p in 0..npx {
                if bit(&s.bits, w as usize, p) != dref[p] {
                    differ += 1;
                }
                let e = (s.gray[p] as f64 - reference[p]).abs();
                t.abs_sum += e;
                t.sq_sum += e * e;
                t.max_abs = t.max_abs.max(e);
            }
            t.dither_diff += differ;
            t.rays += s.rays;
            t.time += median(times[i].clone());
            if c.knob == "scalar" || c.knob == "default" {
                let same =
                    (0..npx).filter(|&p| bit(&s.bits, w as usize, p) != bit(&default_bits, w as usize, p)).count();
                t.same_settings_diff += same;
                per_scene.insert((name.clone(), c.scalar), (same, npx));
            }
        }
    }
    Ok((tallies, per_scene))
}

/// Instructions per frame from the firmware report (`docs/firmware.csv`), summed over the
/// scenes studied, by scalar and board (empty unless the size is the boards' 128x64).
fn firmware_instructions(firmware_csv: &Path, names: &[String], (w, h): (u16, u16)) -> BTreeMap<(String, String), u64> {
    let mut instr: BTreeMap<(String, String), u64> = BTreeMap::new();
    let csv = std::fs::read_to_string(firmware_csv).unwrap_or_default();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        // Only the plain build of each scalar and board (not the effect-study variants).
        let plain = f.get(5).is_some_and(|v| *v == format!("qemu-{}-{}", f[2], f[1]));
        if plain && names.contains(&f[0].to_string()) && w == 128 && h == 64 {
            *instr.entry((f[1].to_string(), f[2].to_string())).or_default() += f[3].parse::<u64>().unwrap_or(0);
        }
    }
    instr
}

/// The main table: one row per knob setting; the points of the plot.
fn knob_table(
    md: &mut String,
    configs: &[Config],
    tallies: &[Tally],
    instr: &BTreeMap<(String, String), u64>,
    names: &[String],
    (w, h): (u16, u16),
    runs: usize,
) -> Result<Vec<(String, &'static str, f64, f64)>> {
    writeln!(md, "# What accuracy costs\n")?;
    writeln!(
        md,
        "Written by `cargo xtask tradeoff` ({} scenes: {}; {w}x{h}; host time is the\nmedian of {} interleaved runs per scene, averaged over the scenes). Reference: f64, 4x4 rays per\npixel. One knob varies at a time from the default row (f64, each scene's depth, no cutoff).\n",
        names.len(),
        names.join(", "),
        runs.max(1)
    )?;
    writeln!(md, "Error diffusion (Floyd-Steinberg, Atkinson) is chaotic: a change of one level anywhere moves\nthe dots that follow, so its dithered-pixel figure against the reference is large by nature;\ncompare its gray error, which is the same as the default's.\n")?;
    writeln!(md, "Error columns compare with the reference: share of 1-bit display pixels that differ after\ndithering (the reference dithered the same way), mean and max absolute gray error in levels\n(of 64), PSNR of the gray image. Cortex-M columns: instructions per frame summed over the\nscenes, from `docs/firmware.csv` (`cargo xtask firmware`, QEMU `-icount shift=0`).\n")?;
    writeln!(md, "| knob | setting | dithered px differ | mean abs gray | max abs gray | PSNR dB | host ms/frame | rays/frame | M0 Minstr | M4F Minstr |\n|---|---|---|---|---|---|---|---|---|---|")?;
    let scenes_n = names.len().max(1) as f64;
    let mut points = Vec::new();
    for (c, t) in configs.iter().zip(tallies) {
        let mse = t.sq_sum / t.pixels.max(1) as f64;
        let psnr = if mse > 0.0 { 10.0 * (64.0f64 * 64.0 / mse).log10() } else { f64::INFINITY };
        let ms = t.time.as_secs_f64() * 1e3 / scenes_n;
        let (m0, m4) = if c.knob == "scalar" || c.knob == "default" {
            let s = if c.scalar == "f64" { "" } else { c.scalar };
            let get = |b: &str| {
                instr.get(&(s.to_string(), b.to_string())).map(|v| format!("{:.0}", *v as f64 / 1e6 / scenes_n))
            };
            (get("m0").unwrap_or_else(|| "-".into()), get("m4f").unwrap_or_else(|| "-".into()))
        } else {
            ("-".into(), "-".into())
        };
        let pct = 100.0 * t.dither_diff as f64 / t.pixels.max(1) as f64;
        let mean = t.abs_sum / t.pixels.max(1) as f64;
        writeln!(
            md,
            "| {} | {} | {pct:.2} % | {mean:.3} | {:.1} | {psnr:.1} | {ms:.2} | {:.0} | {m0} | {m4} |",
            c.knob,
            c.label,
            t.max_abs,
            t.rays as f64 / scenes_n
        )?;
        points.push((c.label.clone(), c.knob, ms, mean));
    }
    if instr.is_empty() {
        writeln!(
            md,
            "\n(No `docs/firmware.csv` at {w}x{h}: run `cargo xtask firmware` first for the Cortex-M columns.)"
        )?;
    }
    writeln!(md, "\nCortex-M columns are per scene on average (the f64 row has no firmware build).\n")?;
    Ok(points)
}

/// Each scalar against f64 at the same settings, per scene.
fn scalar_section(md: &mut String, names: &[String], per_scene: &PerScene) -> Result<()> {
    writeln!(md, "## Each scalar against f64 at the same settings\n\nShare of dithered pixels that differ from the f64 frame rendered with the same settings\n(1 ray per pixel, Bayer): the error the scalar alone adds.\n")?;
    writeln!(md, "| scene | f32 | f32-micromath | f32-micromath-newton | fixed |\n|---|---|---|---|---|")?;
    for n in names {
        let cell = |s: &'static str| {
            per_scene
                .get(&(n.clone(), s))
                .map_or("-".into(), |(d, p)| format!("{:.3} %", 100.0 * *d as f64 / *p as f64))
        };
        writeln!(
            md,
            "| {n} | {} | {} | {} | {} |",
            cell("f32"),
            cell("f32-micromath"),
            cell("f32-micromath-newton"),
            cell("fixed")
        )?;
    }
    Ok(())
}

/// The targets: the scalars' worst scenes, anti-aliasing and adaptive sub-sampling.
fn targets_section(
    md: &mut String,
    configs: &[Config],
    tallies: &[Tally],
    names: &[String],
    per_scene: &PerScene,
) -> Result<()> {
    let worst = |s: &'static str| {
        names
            .iter()
            .filter_map(|n| per_scene.get(&(n.clone(), s)))
            .map(|(d, p)| 100.0 * *d as f64 / *p as f64)
            .fold(0.0, f64::max)
    };
    let find = |label: &str| configs.iter().position(|c| c.label.starts_with(label)).map(|i| &tallies[i]);
    writeln!(md, "\n## Targets\n")?;
    writeln!(
        md,
        "- fixed point vs f64: worst scene {:.3} % of dithered pixels differ (target at most 0.5 %).",
        worst("fixed")
    )?;
    writeln!(md, "- f32 + libm vs f64: worst scene {:.3} % (target at most 0.05 %).", worst("f32"))?;
    if let (Some(one), Some(four)) = (find("f64, 1 ray"), find("4 rays")) {
        let err = |t: &Tally| t.abs_sum / t.pixels.max(1) as f64;
        writeln!(md, "- anti-aliasing (target: the 4-ray error at under 1.6x the cost of 1 ray/pixel). 4 rays/pixel: mean gray error {:.3} (1 ray/pixel: {:.3}) at {:.2}x the host time.", err(four), err(one), four.time.as_secs_f64() / one.time.as_secs_f64())?;
        for label in ["edges only", "edges + contrast >= 16", "edges + contrast >= 24"] {
            if let Some(e) = find(label) {
                writeln!(
                    md,
                    "  - {label}: error {:.3} ({:+.0} % of the 4-ray error) at {:.2}x the host time ({:.2}x the rays).",
                    err(e),
                    100.0 * (err(e) / err(four) - 1.0),
                    e.time.as_secs_f64() / one.time.as_secs_f64(),
                    e.rays as f64 / one.rays as f64
                )?;
            }
        }
    }
    let cutoff = format!("cutoff {BOARDS_CUTOFF}");
    let boards = [
        (format!("the boards' contribution cutoff, {BOARDS_CUTOFF}"), cutoff.as_str(), "without"),
        (
            "adaptive sub-sampling (the QEMU boards' default, contrast 4) in their 8x8 tiles".into(),
            "adaptive, contrast <= 4",
            "with one ray per pixel",
        ),
        (
            "adaptive sub-sampling in one level (contrast 4) in the Pico's 16x16 tiles".into(),
            PICO_ONE_LEVEL,
            "with one ray per pixel",
        ),
        (
            "adaptive sub-sampling in two levels (the panels' default, contrast 4) in the Pico's 16x16 tiles".into(),
            PICO_ADAPTIVE,
            "with one ray per pixel",
        ),
    ];
    for (what, label, against) in boards {
        if let (Some(one), Some(a)) = (find("f64, 1 ray"), find(label)) {
            let err = |t: &Tally| t.abs_sum / t.pixels.max(1) as f64;
            writeln!(
                md,
                "- {what}: mean gray error {:.3} against {:.3} {against} ({:+.1} %), at {:.2}x the host time and {:.2}x the rays.",
                err(a),
                err(one),
                100.0 * (err(a) / err(one) - 1.0),
                a.time.as_secs_f64() / one.time.as_secs_f64(),
                a.rays as f64 / one.rays as f64
            )?;
        }
    }
    Ok(())
}
