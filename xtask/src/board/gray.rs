//! The gray mode (the firmware's `gray` feature) on the emulated board: the panel's model knows
//! its own refresh (firmware/board/ssd1306.mjs: the row scan timed from its clock and
//! pre-charge registers), and run.mjs `--scan` reports every refresh as its rows were driven.
//! Each refresh must show one subframe whole: the low or the high plane of one scene's
//! four-shade frame, as host-sim renders it (`--levels 4`); none may show rows of two (tearing).
//! Each scene's refreshes must run low, high, high, cycle after cycle, so what the eye sees
//! (each pixel's lit share of a cycle) is host-sim's frame, for at least [`HELD`] refreshes. A
//! panel whose oscillator runs 3 % fast tears an image that assumes the typical clock and must
//! not tear one calibrated for it (`FIRMWARE_GRAY_ROW_NS`).

use super::{build_image, m3, pico_built, run_emulator, write_uf2, BoardRun, Session, PICO};
use anyhow::Result;
use board_records::frame::{rendered, Build, Glass, Panel};
use host_sim::uf2::Scenes;
use std::fmt::Write as _;
use std::path::Path;

/// Refreshes each scene's picture must hold without a fault (the 100).
const HELD: u64 = 100;
/// How fast the emulated panel's oscillator runs in the calibration runs, in percent.
const OSC_ERROR: f64 = 3.0;
/// The typical row period the firmware assumes (firmware/src/bin/pico/display/gray.rs).
const ROW_NS: f64 = 100_000.0;

/// One scene's four-shade frame as host-sim renders it for the gray image: each pixel's step,
/// and its two planes packed as the panel model packs a picture (rows MSB first).
struct Shades {
    steps: Vec<u8>,
    planes: [Vec<u8>; 2],
    width: usize,
}

impl Shades {
    fn of(scenes: &Path, name: &str, glass: Glass) -> Result<Shades> {
        let frame = rendered(Build { gray: true, glass, ..PICO });
        let path = scenes.join(format!("{name}.scene"));
        let r = host_sim::run::render_text_in::<lattice_rt::Fx, embedded_graphics::pixelcolor::Gray2>(
            &path,
            &host_sim::load::read(&path)?,
            &frame,
            |_| {},
        )?;
        let (w, h) = (frame.width as usize, frame.height as usize);
        let stride = w.div_ceil(8);
        let mut planes = [vec![0u8; stride * h], vec![0u8; stride * h]];
        for (i, &k) in r.shades.iter().enumerate() {
            for (bit, plane) in planes.iter_mut().enumerate() {
                if k >> bit & 1 != 0 {
                    plane[(i / w) * stride + (i % w) / 8] |= 0x80 >> (i % w % 8);
                }
            }
        }
        Ok(Shades { steps: r.shades, planes, width: w })
    }
}

/// What a refresh showed: nothing yet, a plane of a scene's frame, or neither (torn).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Showed {
    Blank,
    Plane(usize, usize),
    Torn,
}

/// What the refreshes of one run showed, checked.
#[derive(Default)]
pub(super) struct Scan {
    /// Refreshes in all, and those that showed no whole subframe.
    refreshes: u64,
    torn: u64,
    /// Refreshes out of the low, high, high order of a cycle.
    out_of_order: u64,
    /// Per scene shown (in order): the scene, refreshes held, and whether its first whole
    /// cycle, as the panel's refreshes show it, is host-sim's frame.
    held: Vec<(usize, u64, bool)>,
    /// The first scene's picture as the eye sees it (steps from the panel's own refreshes).
    perceived: Vec<u8>,
}

/// The refreshes of `run` against the scenes' frames `want`.
fn scan(run: &BoardRun, want: &[Shades]) -> Scan {
    let label = |pixels: &[u8]| {
        if pixels.iter().all(|&b| b == 0) {
            return Showed::Blank;
        }
        for (k, s) in want.iter().enumerate() {
            if let Some(p) = s.planes.iter().position(|p| p == pixels) {
                return Showed::Plane(k, p);
            }
        }
        Showed::Torn
    };
    let labels: Vec<Showed> = run.images.iter().map(|p| label(p)).collect();
    let mut out = Scan { refreshes: run.refreshes, ..Scan::default() };
    let mut changes = run.refresh_changes.iter().peekable();
    let (mut now, mut run_of) = (Showed::Blank, None::<(usize, u64, Vec<usize>)>);
    for i in 0..run.refreshes {
        while let Some(&&(at, id)) = changes.peek() {
            if at > i {
                break;
            }
            now = labels.get(id).copied().unwrap_or(Showed::Torn);
            changes.next();
        }
        match now {
            Showed::Blank => {}
            Showed::Torn => out.torn += 1,
            Showed::Plane(k, plane) => {
                if run_of.as_ref().is_none_or(|(scene, ..)| *scene != k) {
                    if let Some(done) = run_of.take() {
                        out.held.push(finish(done, want, run));
                    }
                    run_of = Some((k, 0, Vec::new()));
                }
                let (_, n, first) = run_of.as_mut().expect("set above");
                if [0, 1, 1][(*n % 3) as usize] != plane {
                    out.out_of_order += 1;
                }
                if first.len() < 3 {
                    first.push(current_image(run, i));
                }
                *n += 1;
            }
        }
    }
    if let Some(done) = run_of.take() {
        out.held.push(finish(done, want, run));
    }
    if let Some(&(k, ..)) = out.held.first() {
        out.perceived = perceive(run, k, want).unwrap_or_default();
    }
    out
}

/// The picture refresh `i` showed.
fn current_image(run: &BoardRun, i: u64) -> usize {
    run.refresh_changes.iter().take_while(|(at, _)| *at <= i).last().map_or(0, |&(_, id)| id)
}

/// A scene's run of refreshes: the scene, how many, and whether its first cycle's pictures sum
/// to host-sim's steps.
fn finish((k, n, first): (usize, u64, Vec<usize>), want: &[Shades], run: &BoardRun) -> (usize, u64, bool) {
    (k, n, first.len() == 3 && steps_of(run, &first, &want[k]) == want[k].steps)
}

/// Each pixel's lit count over the pictures `ids` (a cycle: its step as the eye sees it), on
/// the glass of `like`.
fn steps_of(run: &BoardRun, ids: &[usize], like: &Shades) -> Vec<u8> {
    let w = like.width;
    let stride = w.div_ceil(8);
    (0..like.steps.len())
        .map(|i| {
            ids.iter()
                .filter(|&&id| {
                    run.images.get(id).is_some_and(|p| {
                        p.get((i / w) * stride + (i % w) / 8).is_some_and(|b| b & (0x80 >> (i % w % 8)) != 0)
                    })
                })
                .count() as u8
        })
        .collect()
}

/// Scene `k`'s first whole cycle as the panel showed it, as steps.
fn perceive(run: &BoardRun, k: usize, want: &[Shades]) -> Option<Vec<u8>> {
    let lo = run.images.iter().position(|p| *p == want[k].planes[0])?;
    let hi = run.images.iter().position(|p| *p == want[k].planes[1])?;
    Some(steps_of(run, &[lo, hi, hi], &want[k]))
}

/// The gray section's figures.
pub(super) struct GrayReport {
    scan: Scan,
    /// Per scene: its frame's cycles and the refresh interrupt's microseconds in it.
    frames: Vec<(String, u64, u64)>,
    /// The panel 3 % fast: the typical image's scan, the calibrated image's.
    fast: Option<(Scan, Scan)>,
    /// The Thumby's image: its scan and its chair's cycles.
    thumby: (Scan, u64),
    clk_hz: f64,
}

impl Session<'_> {
    /// The gray image on every scene, then a fast panel with the typical and the calibrated
    /// image.
    pub(super) fn gray_runs(&mut self) -> Result<GrayReport> {
        let want = self.shades(Glass::Oled128x64)?;
        // One frame more than the scenes: every scene's pause is then scanned whole.
        let (run, dir) = self.variant("gray", true, self.scenes.len() + 1, &["--scan"])?;
        self.checks.check(run.ok, || format!("gray: the run did not finish: {}", run.reason));
        let shares: Vec<u64> = run
            .log
            .iter()
            .filter_map(|l| l.text.strip_prefix("the gray refresh took ")?.split(' ').next()?.parse().ok())
            .collect();
        let frames = self
            .scenes
            .iter()
            .zip(&run.frames)
            .enumerate()
            .map(|(i, (n, f))| (n.clone(), f.cycles, shares.get(i).copied().unwrap_or(0)))
            .collect();
        let checked = scan(&run, &want);
        self.check_scan("gray", &checked, self.scenes.len());
        if let Some(shown) = want.first().filter(|_| !checked.perceived.is_empty()) {
            self.checks
                .check(checked.perceived == shown.steps, || "gray: the perceived chair is not host-sim's".into());
        }
        save_shades(&checked.perceived, Glass::Oled128x64, &dir.join("perceived.png"))?;
        let fast = self.fast_panel_runs(&want)?;
        let thumby = self.thumby_run()?;
        Ok(GrayReport { scan: checked, frames, fast: Some(fast), thumby, clk_hz: run.clk_sys_hz })
    }

    /// Every scene's four-shade frame on `glass`, as host-sim renders it for the gray image.
    fn shades(&self, glass: Glass) -> Result<Vec<Shades>> {
        self.scenes.iter().map(|n| Shades::of(&self.scenes_dir, n, glass)).collect()
    }

    /// The gray mode on the Thumby (its 72x40 panel on SPI on its own pins, the `thumby,gray`
    /// image): every scene's refreshes checked as the 128x64 panel's are; the chair's first
    /// cycle and the run's first frame's cycles.
    fn thumby_run(&mut self) -> Result<(Scan, u64)> {
        let want = self.shades(Glass::Oled72x40)?;
        let args = ["--scan", "--panel", Panel::Thumby.name()];
        let (run, dir) = self.variant("thumby,gray", true, self.scenes.len() + 1, &args)?;
        self.checks.check(run.ok, || format!("gray on the Thumby: the run did not finish: {}", run.reason));
        let checked = scan(&run, &want);
        self.check_scan("gray on the Thumby", &checked, self.scenes.len());
        save_shades(&checked.perceived, Glass::Oled72x40, &dir.join("perceived.png"))?;
        Ok((checked, run.frames.first().map_or(0, |f| f.cycles)))
    }

    /// The checks of one scan: no torn refresh, every cycle in order, `scenes` scenes each held
    /// for [`HELD`] refreshes (the last run may be cut off by the run's end) with its cycle
    /// host-sim's frame.
    fn check_scan(&mut self, what: &str, s: &Scan, scenes: usize) {
        self.checks.check(s.torn == 0, || {
            format!("{what}: {} of {} refreshes torn (rows of two subframes)", s.torn, s.refreshes)
        });
        self.checks.check(s.out_of_order == 0, || {
            format!("{what}: {} refreshes out of the low, high, high order", s.out_of_order)
        });
        self.checks.check(s.held.len() >= scenes, || format!("{what}: {} scenes shown of {scenes}", s.held.len()));
        for (i, &(k, n, same)) in s.held.iter().enumerate().take(scenes) {
            self.checks.check(n >= HELD, || format!("{what}: scene {k} held {n} refreshes, not {HELD}"));
            self.checks
                .check(same, || format!("{what}: scene {k} (shown {}th): its cycle is not host-sim's frame", i + 1));
        }
    }

    /// The panel's oscillator 3 % fast: the typical image tears; the image calibrated for it
    /// (`FIRMWARE_GRAY_ROW_NS`) holds its picture.
    fn fast_panel_runs(&mut self, want: &[Shades]) -> Result<(Scan, Scan)> {
        let fast = format!("{OSC_ERROR}");
        let args = ["--scan", "--osc-error", fast.as_str()];
        let (typical, _) = self.variant("gray", true, 2, &args)?;
        let typical = scan(&typical, want);
        self.checks.check(typical.torn > 0, || {
            "gray: a panel 3 % fast did not tear the uncalibrated image (the check cannot fail?)".into()
        });
        let row_ns = (ROW_NS / (1.0 + OSC_ERROR / 100.0)).round() as u64;
        let elf = if self.no_build {
            host_sim::uf2::kept_image(self.root, "pico-gray-calibrated")
        } else {
            let row_ns = row_ns.to_string();
            build_image(
                self.root,
                "pico-gray-calibrated",
                &["pico-build", "--features", "gray"],
                (Scenes::Inherited, &[("FIRMWARE_GRAY_ROW_NS", &row_ns)]),
                &pico_built(),
            )?
        };
        let dir = self.frames_dir.join("gray-calibrated");
        std::fs::create_dir_all(&dir)?;
        let uf2 = dir.join("lattice-rt-pico-gray-calibrated.uf2");
        write_uf2(&elf, &uf2)?;
        eprintln!("running {} on a panel {OSC_ERROR} % fast (FIRMWARE_GRAY_ROW_NS={row_ns})", uf2.display());
        let run = run_emulator(self.root, &elf, &uf2, &self.bootrom, 2, true, &dir, &args)?;
        let calibrated = scan(&run, want);
        self.check_scan("gray, calibrated for a panel 3 % fast", &calibrated, 1);
        Ok((typical, calibrated))
    }
}

/// Saves steps 0..=3 of `glass` as a PNG in the panel's white, 4x.
pub(super) fn save_shades(steps: &[u8], glass: Glass, path: &Path) -> Result<()> {
    if steps.is_empty() {
        return Ok(());
    }
    let (w, h) = glass.size();
    let look = host_sim::output::PngLook { theme: host_sim::output::Theme::OledWhite, scale: 4, grid: false };
    let png = host_sim::output::shades_png_bytes(u32::from(w), u32::from(h), steps, 3, look)?;
    host_sim::output::write_atomic(path, &png)
}

/// The report's section on the gray mode; the perceived chair saved as `picture`.
pub(super) fn gray_report(g: &GrayReport, spi_chair: Option<u64>, picture: &Path) -> Result<String> {
    save_shades(&g.scan.perceived, Glass::Oled128x64, picture)?;
    let thumby_picture = picture.with_file_name("board-gray-chair-72x40.png");
    save_shades(&g.thumby.0.perceived, Glass::Oled72x40, &thumby_picture)?;
    let mut md = String::new();
    writeln!(md, "\n## Four shades: the gray mode\n")?;
    writeln!(md, "Written by `cargo xtask board`: the image with the `gray` feature (SSD1306 128x64 on SPI) runs every scene with the panel's refresh emulated (firmware/board/ssd1306.mjs: each row driven for D x (phase 1 + phase 2 + 50) clocks of its oscillator, 530 kHz at the setting 0xF0, the rows in turn; `run.mjs --scan` reports each refresh as its rows were driven). Every refresh must show one subframe whole, the low or high plane of a scene's four-shade frame as host-sim renders it (`host-sim render --board pico --levels 4`), never rows of two (tearing); each scene's refreshes must run low, high, high, so the eye, which sums each pixel's lit share over a cycle, sees host-sim's frame; each scene must hold for {HELD} refreshes or more.\n")?;
    let s = &g.scan;
    writeln!(md, "| scene | refreshes held | cycle = host-sim's 4-shade frame | frame cycles | refresh's share of core 0 | frame cycles less the refresh's share |\n|---|---:|---|---:|---:|---:|")?;
    for (i, (name, cycles, refresh_us)) in g.frames.iter().enumerate() {
        let (held, same) = s.held.get(i).map_or((0, false), |&(_, n, same)| (n, same));
        let share = (*refresh_us as f64 * g.clk_hz / 1e6) as u64;
        writeln!(
            md,
            "| {name} | {held} | {} | {} | {} | {} |",
            if same { "yes" } else { "**no**" },
            m3(*cycles),
            m3(share),
            m3(cycles.saturating_sub(share))
        )?;
    }
    writeln!(md, "\nRefreshes in the run: {}, torn: {}, out of order: {}.", s.refreshes, s.torn, s.out_of_order)?;
    if let (Some(spi), Some((_, chair, _))) = (spi_chair, g.frames.first()) {
        writeln!(md, "The chair's frame with the gray refresh running takes {} cycles, {:.2}x the 1-bit SPI image's {} (the `spi` lever above; target at most 1.2x).", m3(*chair), *chair as f64 / spi as f64, m3(spi))?;
    }
    if let Some((typical, calibrated)) = &g.fast {
        writeln!(md, "\n**A panel whose oscillator runs {OSC_ERROR} % fast** (`run.mjs --osc-error {OSC_ERROR}`): the image that assumes the typical clock tears {} of {} refreshes; the image built with `FIRMWARE_GRAY_ROW_NS={}` (the row period measured for that panel) tears {} of {}, and holds the chair {} refreshes.", typical.torn, typical.refreshes, (ROW_NS / (1.0 + OSC_ERROR / 100.0)).round(), calibrated.torn, calibrated.refreshes, calibrated.held.first().map_or(0, |h| h.1))?;
    }
    let (t, cycles) = &g.thumby;
    writeln!(md, "\n**The Thumby** (its SSD1306 72x40 on SPI on its own pins, `uf2 --panel thumby --features gray`, 40 rows a refresh, 4 ms): {} scenes each held at least {} refreshes, their cycles host-sim's frames: {}; {} refreshes, {} torn, {} out of order; the chair's frame {} cycles.", t.held.len().min(g.frames.len()), t.held.iter().take(g.frames.len()).map(|h| h.1).min().unwrap_or(0), if t.held.iter().take(g.frames.len()).all(|h| h.2) { "all" } else { "**not all**" }, t.refreshes, t.torn, t.out_of_order, m3(*cycles))?;
    let name = |p: &Path| p.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string();
    writeln!(md, "\nThe chair as the eye sees it on the emulated panels (each pixel's lit share of a cycle, from the panel's own refreshes), 128x64 and the Thumby's 72x40:\n\n![the chair in four shades on the emulated panel](images/{}) ![the chair in four shades on the 72x40 panel](images/{})", name(picture), name(&thumby_picture))?;
    Ok(md)
}
