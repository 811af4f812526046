//! The Badger 2040's e-paper (a UC8151, firmware/board/uc8151.mjs): its refresh runs while the
//! cores trace the next frame. The panels' run gives each scene's frame (trace, then the frame's
//! bytes) against the refresh's length; a run with the next-scene button pressed just after each
//! frame (so the next is traced at once, under the refresh) shows the firmware waiting on BUSY:
//! each frame's bytes reach the panel the moment the refresh before ends, so its trace was
//! finished before. A third run shows the partial refresh: a scene drawn twice, then with a
//! ball added in one corner, is refreshed whole, not at all, then in the ball's window alone.

use super::{diff_frame, m3, run_emulator, save_frame_sized, with_panel, write_uf2, BoardRun, Session, PICO_SCALAR};
use crate::firmware::board_frame::{Build, PICO};
use crate::firmware::host_frame_of;
use anyhow::{Context, Result};
use board_records::frame::Panel;
use host_sim::uf2::{build_image, kept_image, pico_built, Scenes};
use std::fmt::Write as _;

/// Frames of the pressed run.
const PRESSED_FRAMES: usize = 4;
/// How long after a frame is sent the button is pressed (the pause reads it every 20 ms), and
/// for how long.
const PRESS_AFTER_MS: f64 = 50.0;
const PRESS_MS: f64 = 40.0;
/// The most a frame's bytes may follow the end of the refresh before them when the firmware
/// was waiting on BUSY (its poll and the command's first byte take microseconds).
const WAITING_MS: f64 = 0.1;

/// The partial run's image (the scenes of [`PARTIAL_SCENES`] baked).
const PARTIAL_IMAGE: &str = "pico-uc8151-partial";
/// The partial run's scenes: the chair, the chair again (a copy by another name: an image's
/// scenes are told apart by name), and the chair with [`BALL`].
const PARTIAL_SCENES: [&str; 3] = ["chair", "chair-again", "chair-ball"];
/// The ball the partial run's third scene adds to the chair: on the floor, at the frame's
/// bottom right.
const BALL: &str = "sphere center 1.8 0.25 2.0 radius 0.25 material wood";
/// Bytes of the controller's RAM: a whole refresh's data.
const GLASS_BYTES: u64 = 296 * 128 / 8;

/// One refresh: when it started and ended, when its frame's bytes began (emulated ms), and its
/// partial window (none: the whole glass).
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Refresh {
    pub start_ms: f64,
    pub end_ms: f64,
    pub data_ms: f64,
    #[serde(default)]
    pub window: Option<Window>,
}

/// A partial refresh's window, as PTL set it: sources (the glass's rows) `hs..=he`, gates (its
/// columns) `vs..=ve`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
pub(super) struct Window {
    pub hs: u16,
    pub he: u16,
    pub vs: u16,
    pub ve: u16,
}

/// What the partial run gave: its refreshes, and each frame's bytes on the bus.
pub(super) struct PartialReport {
    refreshes: Vec<Refresh>,
    bytes: Vec<u64>,
}

/// What the e-paper's runs gave.
pub(super) struct EpaperReport {
    /// Per scene: its name, its frame's cycles in the panels' run and its refresh's length.
    scenes: Vec<(String, u64, f64)>,
    /// The pressed run's refreshes.
    pressed: Vec<Refresh>,
    /// Of the pressed run's frames after the first, those whose bytes came within
    /// [`WAITING_MS`] of the last refresh's end.
    waited: usize,
    /// The partial run.
    partial: PartialReport,
}

impl Session<'_> {
    /// The e-paper's frames from the panels' run (`panel`: the `uc8151` image's), and the
    /// pressed run's refreshes, checked: every frame refreshed, none sent during a refresh
    /// (the model fails the run), and with the button pressed each frame ready before the
    /// refresh before it ended.
    pub(super) fn epaper_runs(&mut self, panel: &BoardRun) -> Result<EpaperReport> {
        let scenes = self.scenes.clone();
        self.checks.check(panel.epaper.len() == panel.frames.len() && !panel.frames.is_empty(), || {
            format!("e-paper: {} refreshes for {} frames", panel.epaper.len(), panel.frames.len())
        });
        let rows = scenes
            .iter()
            .zip(panel.frames.iter().zip(&panel.epaper))
            .map(|(name, (f, r))| (name.clone(), f.cycles, r.end_ms - r.start_ms))
            .collect();
        // Frame k + 1 is sent when refresh k ends: a refresh and a frame's bytes apart.
        let (Some(f0), Some(r0)) = (panel.frames.first(), panel.epaper.first()) else {
            let partial = PartialReport { refreshes: Vec::new(), bytes: Vec::new() };
            return Ok(EpaperReport { scenes: rows, pressed: Vec::new(), waited: 0, partial });
        };
        let period = r0.end_ms - r0.start_ms + (f0.end_ms - r0.data_ms);
        let presses: Vec<String> = (0..PRESSED_FRAMES - 1)
            .map(|k| format!("{:.3}:{PRESS_MS}", f0.end_ms + PRESS_AFTER_MS + k as f64 * period))
            .collect();
        let mut extra = vec!["--panel", "uc8151"];
        for p in &presses {
            extra.extend(["--press", p.as_str()]);
        }
        let (run, _) = self.variant("uc8151", true, PRESSED_FRAMES, &extra)?;
        self.checks.check(run.ok, || format!("e-paper, the button pressed: the run did not finish: {}", run.reason));
        let waited = run.epaper.windows(2).filter(|w| (w[1].data_ms - w[0].end_ms).abs() <= WAITING_MS).count();
        self.checks.check(run.epaper.len() == PRESSED_FRAMES && waited == PRESSED_FRAMES - 1, || {
            format!(
                "e-paper, the button pressed: {waited} of {} frames ready when the refresh before ended",
                run.epaper.len().max(1) - 1
            )
        });
        let partial = self.partial_run()?;
        Ok(EpaperReport { scenes: rows, pressed: run.epaper, waited, partial })
    }

    /// The e-paper's image with [`PARTIAL_SCENES`] baked, run for their three frames: each
    /// frame host-sim's; the first refreshed whole, the second (the same) not at all, the
    /// third in a partial window smaller than the glass, its bytes alone sent.
    fn partial_run(&mut self) -> Result<PartialReport> {
        let dir = self.frames_dir.join("uc8151-partial");
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let chair = std::fs::read_to_string(self.scenes_dir.join("chair.scene"))?;
        let texts =
            [chair.clone(), chair.clone(), format!("{chair}\n# The partial refresh's check: a ball.\n{BALL}\n")];
        let mut paths = Vec::new();
        for (name, text) in PARTIAL_SCENES.iter().zip(texts) {
            let path = dir.join(format!("{name}.scene"));
            std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
            paths.push(path.canonicalize()?);
        }
        let names: Option<Vec<&str>> = paths.iter().map(|p| p.to_str()).collect();
        let list = names.context("the frames folder's path is not UTF-8")?.join(",");
        let elf = if self.no_build {
            kept_image(self.root, PARTIAL_IMAGE)
        } else {
            eprintln!("building the Pico image `{PARTIAL_IMAGE}` (cargo pico-build --features uc8151, scenes {list})");
            let args = ["pico-build", "--features", "uc8151"];
            build_image(self.root, PARTIAL_IMAGE, &args, (Scenes::Listed(&list), &[]), &pico_built())?
        };
        let uf2 = dir.join(format!("lattice-rt-{PARTIAL_IMAGE}.uf2"));
        write_uf2(&elf, &uf2)?;
        let frames = PARTIAL_SCENES.len();
        let run = run_emulator(self.root, &elf, &uf2, &self.bootrom, frames, true, &dir, &["--panel", "uc8151"])?;
        let what = "e-paper, partial refresh";
        self.checks.check(run.ok && run.frames.len() == frames, || {
            format!("{what}: {} of {frames} frames shown ({})", run.frames.len(), run.reason)
        });
        let build = Build { glass: Panel::Uc8151.glass(), ..PICO };
        let (w, h) = build.glass.size();
        let wants = paths.iter().map(|p| host_frame_of(p, PICO_SCALAR, build)).collect::<Result<Vec<_>>>()?;
        for ((name, want), frame) in PARTIAL_SCENES.iter().zip(&wants).zip(&run.frames) {
            save_frame_sized(&frame.pixels, (u32::from(w), u32::from(h)), &dir.join(format!("{name}.png")))?;
            self.checks.check(frame.error.is_none() && frame.pixels == *want, || {
                let why = frame.error.clone().unwrap_or_else(|| "it differs from host-sim's".into());
                format!("{what}: {name}: {why} (see {})", dir.display())
            });
        }
        let windows: Vec<Option<Window>> = run.epaper.iter().map(|r| r.window).collect();
        // The third frame's window: the gates and whole bytes of rows where it differs from the
        // second (host-sim's frames), no more.
        let changed = changed_window(&wants[1], &wants[2], (w, h))?;
        let ok = matches!(windows[..], [None, Some(win)] if Some(win) == changed);
        self.checks.check(ok, || {
            format!("{what}: refreshes {windows:?}, not the whole glass, then none (the same frame), then {changed:?}")
        });
        let bytes: Vec<u64> = run.frames.iter().map(|f| f.bus_bytes).collect();
        Ok(PartialReport { refreshes: run.epaper, bytes })
    }
}

/// The report's section on the e-paper.
pub(super) fn epaper_report(e: &EpaperReport, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## E-paper: the Badger 2040's UC8151, the trace under the refresh\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`. The UC8151 model (firmware/board/uc8151.mjs) holds BUSY low from PON until the booster is up and from DRF until the refresh's waveform has run: the VCOM LUT's frames at the PLL's frame rate (the firmware's waveform: 93 frames at 100 Hz, 930 ms); a command while BUSY is low fails the run. The firmware (`firmware/src/bin/pico/display/uc8151.rs`, feature `uc8151`) gathers the frame in RAM in the controller's gate order, sends it when it is finished (whole, or only the window of what changed: below) and starts the refresh without waiting for it: the cores trace the next frame meanwhile, and its bytes wait for BUSY. Target: a new frame's trace finishes before the refresh does.\n"
    )?;
    writeln!(md, "| scene | frame: trace and its bytes (cycles) | ms at 125 MHz | refresh (ms) | trace done first |")?;
    writeln!(md, "|---|---:|---:|---:|---|")?;
    for (name, cycles, refresh) in &e.scenes {
        let ms = *cycles as f64 / clk_hz * 1e3;
        let first = if ms < *refresh { "yes" } else { "no" };
        writeln!(md, "| {name} | {} | {ms:.0} | {refresh:.0} | {first} |", m3(*cycles))?;
    }
    let gaps: Vec<String> =
        e.pressed.windows(2).map(|w| format!("{:.1}", (w[1].data_ms - w[0].end_ms) * 1e3)).collect();
    writeln!(
        md,
        "\nWith the next-scene button pressed {PRESS_AFTER_MS:.0} ms after each frame is sent (the image as above, `run.mjs --press`), the next frame is traced at once, under the refresh: {} refreshes of {:.0} ms followed each other, and {} of the {} frames after the first had their bytes on the bus {} us after the refresh before them ended: the firmware was waiting on BUSY with the frame traced.",
        e.pressed.len(),
        e.pressed.first().map_or(0.0, |r| r.end_ms - r.start_ms),
        e.waited,
        e.pressed.len().saturating_sub(1),
        gaps.join(", ")
    )?;
    partial_report(&mut md, &e.partial)?;
    Ok(md)
}

/// The window of the pixels where two 1-bit frames of `size` (rows MSB first) differ, as PTL
/// sets one: rows widened to whole bytes of 8, the glass's columns as gates. None where they
/// are the same.
fn changed_window(a: &[u8], b: &[u8], (w, h): (u16, u16)) -> Result<Option<Window>> {
    with_panel(&diff_frame(a, b), (u32::from(w), u32::from(h)), |differs| {
        let mut window: Option<Window> = None;
        let pixels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y)));
        for (x, y) in pixels.filter(|&(x, y)| differs.get(x.into(), y.into())) {
            let win = window.get_or_insert(Window { hs: y, he: y, vs: x, ve: x });
            (win.hs, win.he) = (win.hs.min(y), win.he.max(y));
            (win.vs, win.ve) = (win.vs.min(x), win.ve.max(x));
        }
        Ok(window.map(|win| Window { hs: win.hs / 8 * 8, he: win.he / 8 * 8 + 7, ..win }))
    })
}

/// The partial run's paragraph.
fn partial_report(md: &mut String, p: &PartialReport) -> Result<()> {
    let [first, again, ball] = p.bytes[..] else { return Ok(()) };
    let window = p.refreshes.get(1).and_then(|r| r.window);
    let Some(Window { hs, he, vs, ve }) = window else { return Ok(()) };
    writeln!(
        md,
        "\nOnly what changed is refreshed. The image with the chair, the chair again and the chair with a ball added at the bottom right (`{BALL}`) baked, run for three frames: the first frame is refreshed whole ({first} bytes on the bus, the glass's {GLASS_BYTES} and the commands); the second, the same frame, is not refreshed at all ({again} bytes); the third is a partial refresh (PTIN, PTL) of gates {vs}..={ve} and rows {hs}..={he} ({ball} bytes), the glass outside that window keeping its picture. All three are host-sim's frames bit for bit."
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_changed_window_is_whole_bytes_of_rows_by_the_changed_columns() {
        // 16x16 frames, two bytes a row: pixels (3, 9) and (12, 10) differ.
        let a = vec![0u8; 32];
        let mut b = a.clone();
        b[9 * 2] |= 0x80 >> 3;
        b[10 * 2 + 1] |= 0x80 >> 4;
        assert_eq!(changed_window(&a, &b, (16, 16)).unwrap(), Some(Window { hs: 8, he: 15, vs: 3, ve: 12 }));
        assert_eq!(changed_window(&a, &a, (16, 16)).unwrap(), None);
    }
}
