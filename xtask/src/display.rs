//! `cargo xtask display`: what a person sees on the 1-bit display. Each scene is rendered as the
//! boards render it (128x64, fixed point, adaptive sampling) with every dither, with and
//! without silhouette lines and through several tone curves; each 1-bit frame is compared with
//! the reference gray image (f64, 4x4 rays per pixel) after a Gaussian low-pass that models
//! viewing distance, by mean error and SSIM. Writes `docs/display.md`, a contact sheet per
//! scene and the progressive passes of each scene.

use crate::firmware::board_frame;
use crate::tradeoff::reference;
use anyhow::{Context, Result};
use embedded_graphics::mono_font::{ascii::FONT_6X10, MonoTextStyle};
use embedded_graphics::pixelcolor::Gray8;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};
use embedded_graphics_simulator::{OutputSettingsBuilder, SimulatorDisplay};
use host_sim::load::read;
use host_sim::output::write_atomic;
use host_sim::run::{progressive_passes, render_text};
use lattice_rt::{Dither, Frame, Fx, Tone};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The dithers compared, with their report names.
const DITHERS: [(&str, Dither); 4] = [
    ("bayer", Dither::Bayer),
    ("blue noise", Dither::BlueNoise),
    ("floyd-steinberg", Dither::FloydSteinberg),
    ("atkinson", Dither::Atkinson),
];
/// Tone curves tried (exponent in tenths).
const GAMMAS: [u8; 5] = [6, 8, 10, 12, 15];
/// Low-pass widths (Gaussian sigma in display pixels) the measure is taken at.
const SIGMAS: [f64; 2] = [1.0, 2.0];

/// One option of the study.
#[derive(Clone, Copy, Debug)]
struct Look {
    dither: usize,
    outline: bool,
    gamma: u8,
}

impl Look {
    fn label(self) -> String {
        let mut s = DITHERS[self.dither].0.to_string();
        if self.outline {
            s += " + outline";
        }
        if self.gamma != 10 {
            write!(s, ", gamma {:.1}", self.gamma as f64 / 10.0).unwrap();
        }
        s
    }
    fn frame(self, w: u16, h: u16) -> Frame {
        Frame {
            dither: DITHERS[self.dither].1,
            sampling: board_frame::PANEL_SAMPLING,
            outline: self.outline,
            tone: Tone { gamma_tenths: self.gamma },
            tile: board_frame::PANEL_TILE,
            cutoff: board_frame::CUTOFF,
            ..Frame::new(w, h)
        }
    }
}

/// Separable Gaussian blur with clamped edges.
fn blur(img: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
    let r = (3.0 * sigma).ceil() as isize;
    let k: Vec<f64> = (-r..=r).map(|d| (-(d * d) as f64 / (2.0 * sigma * sigma)).exp()).collect();
    let sum: f64 = k.iter().sum();
    let pass = |src: &[f64], horizontal: bool| -> Vec<f64> {
        let mut out = vec![0.0; w * h];
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut acc = 0.0;
                for (i, d) in (-r..=r).enumerate() {
                    let (sx, sy) = if horizontal {
                        ((x + d).clamp(0, w as isize - 1), y)
                    } else {
                        (x, (y + d).clamp(0, h as isize - 1))
                    };
                    acc += k[i] * src[sy as usize * w + sx as usize];
                }
                out[y as usize * w + x as usize] = acc / sum;
            }
        }
        out
    };
    pass(&pass(img, true), false)
}

/// Mean SSIM (Wang et al. 2004: Gaussian window of sigma 1.5, K1 0.01, K2 0.03) of two images
/// with values in `0..=64`.
fn ssim(a: &[f64], b: &[f64], w: usize, h: usize) -> f64 {
    let (c1, c2) = ((0.01f64 * 64.0).powi(2), (0.03f64 * 64.0).powi(2));
    let prod = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).collect::<Vec<_>>();
    let g = |v: &[f64]| blur(v, w, h, 1.5);
    let (ma, mb) = (g(a), g(b));
    let (saa, sbb, sab) = (g(&prod(a, a)), g(&prod(b, b)), g(&prod(a, b)));
    let mut total = 0.0;
    for i in 0..w * h {
        let (va, vb, cov) = (saa[i] - ma[i] * ma[i], sbb[i] - mb[i] * mb[i], sab[i] - ma[i] * mb[i]);
        total +=
            ((2.0 * ma[i] * mb[i] + c1) * (2.0 * cov + c2)) / ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
    }
    total / (w * h) as f64
}

/// A packed 1-bit frame as values 0 or 64.
fn unpack(bits: &[u8], w: usize, h: usize) -> Vec<f64> {
    let stride = w.div_ceil(8);
    (0..w * h).map(|i| if bits[(i / w) * stride + (i % w) / 8] & (0x80 >> (i % 8)) != 0 { 64.0 } else { 0.0 }).collect()
}

/// Mean absolute error and SSIM of a 1-bit frame against the reference, both low-passed.
fn measure(bits: &[u8], reference: &[f64], w: usize, h: usize, sigma: f64) -> (f64, f64) {
    let (a, b) = (blur(&unpack(bits, w, h), w, h, sigma), blur(reference, w, h, sigma));
    let mae = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).sum::<f64>() / (w * h) as f64;
    (mae, ssim(&a, &b, w, h))
}

/// Draws 1-bit frames and gray images into one labelled gray sheet.
struct Sheet {
    display: SimulatorDisplay<Gray8>,
    cell: (u32, u32),
}

const LABEL: u32 = 12;
const GAP: u32 = 4;

impl Sheet {
    fn new(cols: u32, rows: u32, w: u32, h: u32) -> Self {
        let cell = (w + GAP, h + LABEL + GAP);
        let mut display = SimulatorDisplay::new(Size::new(cols * cell.0 + GAP, rows * cell.1 + GAP));
        display.clear(Gray8::new(96)).expect("simulator");
        Sheet { display, cell }
    }
    fn place(&mut self, col: u32, row: u32, label: &str, w: usize, values: &[f64]) {
        let (x0, y0) = ((col * self.cell.0 + GAP) as i32, (row * self.cell.1 + GAP) as i32);
        let style = MonoTextStyle::new(&FONT_6X10, Gray8::WHITE);
        Text::with_baseline(label, Point::new(x0, y0), style, Baseline::Top)
            .draw(&mut self.display)
            .expect("simulator");
        for (i, v) in values.iter().enumerate() {
            let p = Point::new(x0 + (i % w) as i32, y0 + LABEL as i32 + (i / w) as i32);
            Pixel(p, Gray8::new((v * 255.0 / 64.0).round().clamp(0.0, 255.0) as u8))
                .draw(&mut self.display)
                .expect("simulator");
        }
    }
    fn save(&self, path: &Path, scale: u32) -> Result<()> {
        let settings = OutputSettingsBuilder::new().scale(scale).build();
        let mut staged = host_sim::output::Staged::default();
        let tmp = staged.stage(path)?;
        self.display.to_grayscale_output_image(&settings).save_png(&tmp)?;
        staged.commit()
    }
}

/// Scores of one look over the scenes: (mean abs error, SSIM) per sigma, summed.
#[derive(Clone, Default)]
struct Score {
    sums: [(f64, f64); SIGMAS.len()],
    per_scene: Vec<f64>,
}

impl Score {
    fn ssim(&self, n: usize) -> f64 {
        self.sums.iter().map(|s| s.1).sum::<f64>() / (SIGMAS.len() * n.max(1)) as f64
    }
}

/// The path of `file` as a link from the report `out`.
fn link(out: &Path, file: &Path) -> String {
    let dir = out.parent().unwrap_or(Path::new(""));
    file.strip_prefix(dir).unwrap_or(file).display().to_string()
}

/// The command.
pub fn display_cmd(scenes: &[PathBuf], out: &Path, images: &Path, board: &Path) -> Result<()> {
    let mut looks = Vec::new();
    for dither in 0..DITHERS.len() {
        for outline in [false, true] {
            for gamma in GAMMAS {
                looks.push(Look { dither, outline, gamma });
            }
        }
    }
    let names: Vec<String> =
        scenes.iter().map(|p| p.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default()).collect();
    let (scores, frames, references) = score_looks(scenes, &looks)?;
    let n = scenes.len();
    let mut order: Vec<usize> = (0..looks.len()).collect();
    order.sort_by(|&a, &b| scores[b].ssim(n).total_cmp(&scores[a].ssim(n)));
    let best = looks[order[0]];
    std::fs::create_dir_all(images)?;
    let sheet_links = contact_sheets(&names, &looks, &scores, &frames, &references, best, images)?;
    let (prog_rows, strip_file) = progressive_rows(scenes, &names, &references, best, images)?;
    let mut md = report(out, &names, &looks, &scores, &order, &sheet_links, &prog_rows, &strip_file)?;
    let still = looks
        .iter()
        .position(|l| DITHERS[l.dither].1 == board_frame::STILL_DITHER && l.outline && l.gamma == 10)
        .context("the board's look is in the grid")?;
    md.push_str(&panel_section(&names, board, &references, &frames, still)?);
    md.push_str(&gray_section(scenes, &names, &references, &frames, still, out, images)?);
    write_atomic(out, md.as_bytes())?;
    println!("wrote {} (best: {}), contact sheets and passes in {}", out.display(), best.label(), images.display());
    Ok(())
}

/// The panel's size.
const PANEL: (u16, u16) = (128, 64);

/// The frames of the emulated Pico's panel (`board/<scene>.pbm`, from `cargo xtask board`)
/// scored like the looks above, beside the host's frame of the board's look (`still`): the
/// section of docs/display.md, or a line saying they are missing.
fn panel_section(
    names: &[String],
    board: &Path,
    references: &[Vec<f64>],
    frames: &[Vec<Vec<u8>>],
    still: usize,
) -> Result<String> {
    let (wu, hu) = (PANEL.0 as usize, PANEL.1 as usize);
    let mut md = String::from("\n## The Pico's panel\n\n");
    let mut rows = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let file = board.join(format!("{name}.pbm"));
        let Ok(bytes) = std::fs::read(&file) else {
            writeln!(md, "No panel frame of {name} in {} (run `cargo xtask board` first).", board.display())?;
            return Ok(md);
        };
        // A PBM's 1 is black: lit pixels are its 0 bits (128 pixels a row: no padding).
        let raster = bytes
            .get(bytes.len().saturating_sub(lattice_rt::BitFrame::bytes(PANEL.0 as u32, PANEL.1 as u32))..)
            .context("short PBM")?;
        let bits: Vec<u8> = raster.iter().map(|b| !b).collect();
        let score = |b: &[u8]| SIGMAS.map(|s| measure(b, &references[i], wu, hu, s).1);
        rows.push((name, score(&bits), score(&frames[i][still]), bits == frames[i][still]));
    }
    writeln!(md, "The frames the emulated Pico's panel showed (`cargo xtask board`: its default still, {} + outline), scored as above against", DITHERS.iter().find(|d| d.1 == board_frame::STILL_DITHER).map_or("?", |d| d.0))?;
    writeln!(md, "the same references, beside the host's frame of the same look.\n")?;
    writeln!(md, "| scene | panel SSIM (sigma 1) | panel SSIM (sigma 2) | host SSIM (sigma 1) | bit-identical |\n|---|---:|---:|---:|---|")?;
    let n = rows.len().max(1) as f64;
    let mut sums = [0.0; 3];
    for (name, panel, host, same) in &rows {
        writeln!(
            md,
            "| {name} | {:.3} | {:.3} | {:.3} | {} |",
            panel[0],
            panel[1],
            host[0],
            if *same { "yes" } else { "**no**" }
        )?;
        sums = [sums[0] + panel[0], sums[1] + panel[1], sums[2] + host[0]];
    }
    writeln!(md, "| mean | {:.3} | {:.3} | {:.3} | |", sums[0] / n, sums[1] / n, sums[2] / n)?;
    md.push('\n');
    for (name, ..) in &rows {
        write!(md, "![{name} on the Pico's panel](images/board-{name}.png) ")?;
    }
    md.push('\n');
    Ok(md)
}

/// Steps of a four-shade frame (0..=3) as levels of 64: a pixel lit in `k` of the three
/// subframes shows `64 k / 3`.
fn shade_levels(steps: &[u8]) -> Vec<f64> {
    steps.iter().map(|&k| f64::from(k) * 64.0 / 3.0).collect()
}

/// The gray mode (`--levels 4`, the firmware's `gray` feature): each scene's frame in four
/// shades, with and without silhouette lines, scored like the looks above, beside the 1-bit
/// frame of the board's still look (`still`); the section of docs/display.md and a picture of
/// each four-shade frame.
fn gray_section(
    scenes: &[PathBuf],
    names: &[String],
    references: &[Vec<f64>],
    frames: &[Vec<Vec<u8>>],
    still: usize,
    out: &Path,
    images: &Path,
) -> Result<String> {
    let (w, h) = PANEL;
    let (wu, hu) = (w as usize, h as usize);
    let score = |img: &[f64], i: usize| {
        SIGMAS.map(|s| {
            let (a, b) = (blur(img, wu, hu, s), blur(&references[i], wu, hu, s));
            ssim(&a, &b, wu, hu)
        })
    };
    let mut md = String::from("\n## Four shades (the gray mode)\n\n");
    writeln!(md, "The same frames in four shades (`host-sim render --levels 4`; the firmware's `gray` feature,")?;
    writeln!(md, "docs/board.md): Floyd-Steinberg error diffusion over black, two grays and white, a pixel of")?;
    writeln!(md, "step k lit in k of the panel's three subframes, so it shows 64 k / 3. Scored as above; the")?;
    writeln!(md, "1-bit column is the board's still frame (floyd-steinberg + outline), the gain the four-shade")?;
    writeln!(md, "frame's SSIM (sigma 1) less the 1-bit frame's.\n")?;
    writeln!(md, "| scene | 1-bit, SSIM (sigma 1) | 4 shades + outline, SSIM (sigma 1) | gain | 4 shades + outline, SSIM (sigma 2) | 4 shades, no outline (the gray mode), SSIM (sigma 1) | gain |\n|---|---:|---:|---:|---:|---:|---:|")?;
    let mut pictures = String::new();
    for (i, path) in scenes.iter().enumerate() {
        let text = read(path)?;
        let one_bit = score(&unpack(&frames[i][still], wu, hu), i)[0];
        let mut row = Vec::new();
        for outline in [true, false] {
            let frame = Frame { outline, ..board_frame::rendered(board_frame::PICO) };
            let r =
                host_sim::run::render_text_in::<Fx, embedded_graphics::pixelcolor::Gray2>(path, &text, &frame, |_| {})?;
            row.push(score(&shade_levels(&r.shades), i));
            if outline {
                let look =
                    host_sim::output::PngLook { theme: host_sim::output::Theme::OledWhite, scale: 3, grid: false };
                let file = images.join(format!("display-gray-{}.png", names[i]));
                write_atomic(&file, &host_sim::output::shades_png_bytes(w as u32, h as u32, &r.shades, 3, look)?)?;
                write!(pictures, "![{} in four shades]({}) ", names[i], link(out, &file))?;
            }
        }
        writeln!(
            md,
            "| {} | {one_bit:.3} | {:.3} | {:+.3} | {:.3} | {:.3} | {:+.3} |",
            names[i],
            row[0][0],
            row[0][0] - one_bit,
            row[0][1],
            row[1][0],
            row[1][0] - one_bit
        )?;
    }
    writeln!(md, "\n{pictures}")?;
    Ok(md)
}

/// Every look rendered on every scene and scored against the scene's reference; the scores,
/// the frames (per scene, per look) and the references.
#[allow(clippy::type_complexity)]
fn score_looks(scenes: &[PathBuf], looks: &[Look]) -> Result<(Vec<Score>, Vec<Vec<Vec<u8>>>, Vec<Vec<f64>>)> {
    let (w, h) = PANEL;
    let (wu, hu) = (w as usize, h as usize);
    let mut scores = vec![Score::default(); looks.len()];
    let mut frames: Vec<Vec<Vec<u8>>> = Vec::new();
    let mut references = Vec::new();
    let bar = host_sim::progress::bar(scenes.len(), "scenes");
    for path in scenes {
        bar.inc(1);
        let text = read(path)?;
        let reference = reference(&text, path, w, h, 4)?;
        let mut per_look = Vec::new();
        for (look, score) in looks.iter().zip(scores.iter_mut()) {
            let r = render_text::<Fx>(path, &text, &look.frame(w, h), |_| {})?;
            let mut both = 0.0;
            for (k, &sigma) in SIGMAS.iter().enumerate() {
                let (mae, s) = measure(&r.bits, &reference, wu, hu, sigma);
                score.sums[k].0 += mae;
                score.sums[k].1 += s;
                both += s / SIGMAS.len() as f64;
            }
            score.per_scene.push(both);
            per_look.push(r.bits);
        }
        frames.push(per_look);
        references.push(reference);
    }
    bar.finish_and_clear();
    Ok((scores, frames, references))
}

/// Contact sheets: rows are dithers, columns without and with the outline, at gamma 1.0 and
/// at the best look's gamma; the reference gray first. The scene names and sheet files.
fn contact_sheets(
    names: &[String],
    looks: &[Look],
    scores: &[Score],
    frames: &[Vec<Vec<u8>>],
    references: &[Vec<f64>],
    best: Look,
    images: &Path,
) -> Result<Vec<(String, PathBuf)>> {
    let (w, h) = PANEL;
    let (wu, hu) = (w as usize, h as usize);
    let mut sheet_links = Vec::new();
    for (s, name) in names.iter().enumerate() {
        let gammas: Vec<u8> = if best.gamma == 10 { vec![10] } else { vec![10, best.gamma] };
        let cols = 2 * gammas.len() as u32;
        let mut sheet = Sheet::new(cols, DITHERS.len() as u32 + 1, w as u32, h as u32);
        sheet.place(0, 0, "reference gray", wu, &references[s]);
        for d in 0..DITHERS.len() {
            for (gi, &g) in gammas.iter().enumerate() {
                for (oi, o) in [false, true].into_iter().enumerate() {
                    let i = looks
                        .iter()
                        .position(|l| l.dither == d && l.outline == o && l.gamma == g)
                        .expect("in the grid");
                    let short = ["bayer", "blue noise", "f-s", "atkinson"][d];
                    let gamma = if g == 10 { String::new() } else { format!(" g{:.1}", g as f64 / 10.0) };
                    let label = format!("{short}{}{gamma} {:.2}", if o { "+line" } else { "" }, scores[i].per_scene[s]);
                    sheet.place((gi * 2 + oi) as u32, d as u32 + 1, &label, wu, &unpack(&frames[s][i], wu, hu));
                }
            }
        }
        let file = images.join(format!("display-{name}.png"));
        sheet.save(&file, 2)?;
        sheet_links.push((name.clone(), file));
    }

    Ok(sheet_links)
}

/// Progressive passes with the best look (error diffusion cannot be split between cores, but
/// progressive passes do not need that): the report's rows and the strip of passes.
fn progressive_rows(
    scenes: &[PathBuf],
    names: &[String],
    references: &[Vec<f64>],
    best: Look,
    images: &Path,
) -> Result<(Vec<String>, PathBuf)> {
    let (w, h) = PANEL;
    let (wu, hu) = (w as usize, h as usize);
    let n = scenes.len();
    let mut prog_rows = Vec::new();
    let mut strip = Sheet::new(4, n as u32, w as u32, h as u32);
    for (s, path) in scenes.iter().enumerate() {
        let text = read(path)?;
        let frame = best.frame(w, h);
        let passes = progressive_passes::<Fx>(path, &text, &frame)?;
        let plain = render_text::<Fx>(path, &text, &frame, |_| {})?;
        let same = passes.last().is_some_and(|p| p.bits == plain.bits);
        if !same {
            anyhow::bail!("{}: the last progressive pass differs from the plain frame", names[s]);
        }
        let total: u64 = passes.iter().map(|p| p.stats.rays[0]).sum();
        let mut cells = Vec::new();
        for (k, p) in passes.iter().enumerate() {
            let (_, sim) = measure(&p.bits, &references[s], wu, hu, SIGMAS[0]);
            cells.push(format!("{} rays, SSIM {sim:.2}", p.stats.rays[0]));
            strip.place(k as u32, s as u32, &format!("{} pass {}", names[s], p.pass), wu, &unpack(&p.bits, wu, hu));
        }
        let time: Duration = passes.iter().map(|p| p.elapsed).sum();
        prog_rows.push(format!(
            "| {} | {} | {} / {} | {} | {:.2} / {:.2} |",
            names[s],
            cells.join(" | "),
            total,
            plain.stats.rays[0],
            if same { "yes" } else { "**no**" },
            time.as_secs_f64() * 1e3,
            plain.elapsed.as_secs_f64() * 1e3
        ));
    }
    let strip_file = images.join("display-progressive.png");
    strip.save(&strip_file, 2)?;

    Ok((prog_rows, strip_file))
}

/// docs/display.md.
#[allow(clippy::too_many_arguments)]
fn report(
    out: &Path,
    names: &[String],
    looks: &[Look],
    scores: &[Score],
    order: &[usize],
    sheet_links: &[(String, PathBuf)],
    prog_rows: &[String],
    strip_file: &Path,
) -> Result<String> {
    let (w, h) = PANEL;
    let n = names.len();
    let best = looks[order[0]];
    let linear = |d: usize, o: bool| {
        looks.iter().position(|l| l.dither == d && l.outline == o && l.gamma == 10).expect("in the grid")
    };
    let mut md = String::new();
    writeln!(md, "# What the display shows\n")?;
    writeln!(
        md,
        "Written by `cargo xtask display` ({n} scenes: {}). Every frame is rendered as the\nboards render it: {w}x{h}, Q16.16 fixed point, adaptive sampling in\nthe Pico panel's {}x{} tiles. Each 1-bit frame (lit pixel = 64,\ndark = 0) and the reference gray image (f64, 4x4 rays per pixel) are both low-passed by a\nGaussian of sigma 1 and 2 display pixels, a model of viewing the panel from a distance where\nsingle dots merge; the table gives the mean absolute difference of the two (levels of 64) and\ntheir SSIM (Wang et al. 2004; 1 is identical), averaged over the scenes. Ranked by SSIM averaged\nover both sigmas.\n",
        names.join(", "),
        board_frame::PANEL_TILE,
        board_frame::PANEL_TILE
    )?;
    writeln!(md, "**Best: {}** (mean SSIM {:.3}).\n", best.label(), scores[order[0]].ssim(n))?;
    writeln!(md, "| rank | look | SSIM (sigma 1) | SSIM (sigma 2) | mean abs error (sigma 1) | mean abs error (sigma 2) |\n|---|---|---|---|---|---|")?;
    for (rank, &i) in order.iter().enumerate() {
        let sc = &scores[i];
        let nf = n.max(1) as f64;
        writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.2} | {:.2} |",
            rank + 1,
            looks[i].label(),
            sc.sums[0].1 / nf,
            sc.sums[1].1 / nf,
            sc.sums[0].0 / nf,
            sc.sums[1].0 / nf
        )?;
    }
    writeln!(md, "\n## Per scene (SSIM averaged over both sigmas, tone unchanged)\n")?;
    writeln!(md, "| look | {} |\n|---|{}", names.join(" | "), "---|".repeat(n))?;
    for d in 0..DITHERS.len() {
        for o in [false, true] {
            let i = linear(d, o);
            let cells: Vec<String> = scores[i].per_scene.iter().map(|v| format!("{v:.3}")).collect();
            writeln!(md, "| {} | {} |", looks[i].label(), cells.join(" | "))?;
        }
    }
    writeln!(md, "\n## Contact sheets\n\nEach dither without and with the outline (gamma 1.0{}), under the reference; the number after\neach label is that frame's SSIM.\n", if best.gamma == 10 { String::new() } else { format!(", then gamma {:.1}", best.gamma as f64 / 10.0) })?;
    for (name, file) in sheet_links {
        writeln!(md, "### {name}\n\n![{name}]({})\n", link(out, file))?;
    }
    writeln!(md, "## Progressive preview\n\nThe best look rendered in passes (`render_pass`): pass 8 traces one ray per 8x8 block, passes 4\nand 2 add the rays of the finer blocks, pass 1 completes the frame with the adaptive sampler,\nreusing every ray traced before. Eye rays per pass and SSIM (sigma 1) of what the panel shows\nafter it; the last pass must equal the plain frame bit for bit. Host time is one run, for\nscale only; the boards' cycle cost is in docs/board.md.\n")?;
    writeln!(md, "| scene | pass 8 | pass 4 | pass 2 | pass 1 | eye rays, all passes / plain frame | last pass = plain frame | host ms, passes / plain |\n|---|---|---|---|---|---|---|---|")?;
    for r in prog_rows {
        writeln!(md, "{r}")?;
    }
    writeln!(md, "\n![progressive passes]({})", link(out, strip_file))?;
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ssim_is_one_for_equal_images_and_lower_for_noise() {
        let (w, h) = (32, 16);
        let a: Vec<f64> = (0..w * h).map(|i| ((i % w) * 2) as f64).collect();
        assert!((ssim(&a, &a, w, h) - 1.0).abs() < 1e-9);
        let b: Vec<f64> = a.iter().enumerate().map(|(i, v)| if i % 3 == 0 { 64.0 - v } else { *v }).collect();
        assert!(ssim(&a, &b, w, h) < 0.9);
    }

    #[test]
    fn blur_keeps_the_mean_of_a_flat_image() {
        let b = blur(&vec![20.0; 64], 8, 8, 2.0);
        assert!(b.iter().all(|v| (v - 20.0).abs() < 1e-9));
    }
}
