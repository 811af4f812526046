//! The Badger 2040's e-paper (a UC8151, firmware/board/uc8151.mjs): its refresh runs while the
//! cores trace the next frame. The panels' run gives each scene's frame (trace, then the frame's
//! bytes) against the refresh's length; a run with the next-scene button pressed just after each
//! frame (so the next is traced at once, under the refresh) shows the firmware waiting on BUSY:
//! each frame's bytes reach the panel the moment the refresh before ends, so its trace was
//! finished before.

use super::{m3, BoardRun, Session};
use anyhow::Result;
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

/// One refresh: when it started and ended, and when its frame's bytes began (emulated ms).
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Refresh {
    pub start_ms: f64,
    pub end_ms: f64,
    pub data_ms: f64,
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
            return Ok(EpaperReport { scenes: rows, pressed: Vec::new(), waited: 0 });
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
        Ok(EpaperReport { scenes: rows, pressed: run.epaper, waited })
    }
}

/// The report's section on the e-paper.
pub(super) fn epaper_report(e: &EpaperReport, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## E-paper: the Badger 2040's UC8151, the trace under the refresh\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`. The UC8151 model (firmware/board/uc8151.mjs) holds BUSY low from PON until the booster is up and from DRF until the refresh's waveform has run: the VCOM LUT's frames at the PLL's frame rate (the firmware's waveform: 93 frames at 100 Hz, 930 ms); a command while BUSY is low fails the run. The firmware (`firmware/src/bin/pico/display/uc8151.rs`, feature `uc8151`) gathers the frame in RAM in the controller's gate order, sends it whole when it is finished and starts the refresh without waiting for it: the cores trace the next frame meanwhile, and its bytes wait for BUSY. Target: a new frame's trace finishes before the refresh does.\n"
    )?;
    writeln!(
        md,
        "| scene | frame: trace and 4,736 bytes (cycles) | ms at 125 MHz | refresh (ms) | trace done first |"
    )?;
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
    Ok(md)
}
