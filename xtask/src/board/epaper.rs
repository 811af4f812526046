//! The Badger 2040's e-paper (a UC8151, firmware/board/uc8151.mjs): its refresh runs while the
//! cores trace the next frame. The panels' run gives each scene's frame (trace, then the frame's
//! bytes) against the refresh's length; the image with `orbit`, whose frames follow each other
//! with no pause, shows the firmware waiting on BUSY: each frame's bytes reach the panel the
//! moment the last refresh ends, so its trace was finished before.

use super::{m3, BoardRun, Session};
use anyhow::Result;
use std::fmt::Write as _;

/// Frames of the orbit run.
const ORBIT_FRAMES: usize = 4;
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
    /// The orbit run's refreshes.
    orbit: Vec<Refresh>,
    /// Of the orbit's frames after the first, those whose bytes came within [`WAITING_MS`] of
    /// the last refresh's end.
    waited: usize,
}

impl Session<'_> {
    /// The e-paper's frames from the panels' run (`panel`: the `uc8151` image's), and the
    /// orbit image's refreshes, checked: every frame refreshed, none sent during a refresh
    /// (the model fails the run), and in the orbit each frame ready before the refresh ended.
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
        let (run, _) = self.variant("uc8151,orbit", false, ORBIT_FRAMES, &["--panel", "uc8151"])?;
        self.checks.check(run.ok, || format!("e-paper orbit: the run did not finish: {}", run.reason));
        let waited = run.epaper.windows(2).filter(|w| (w[1].data_ms - w[0].end_ms).abs() <= WAITING_MS).count();
        self.checks.check(run.epaper.len() >= 2 && waited == run.epaper.len() - 1, || {
            format!(
                "e-paper orbit: {waited} of {} frames ready when the refresh before ended",
                run.epaper.len().max(1) - 1
            )
        });
        Ok(EpaperReport { scenes: rows, orbit: run.epaper, waited })
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
    let gaps: Vec<String> = e.orbit.windows(2).map(|w| format!("{:.3}", (w[1].data_ms - w[0].end_ms) * 1e3)).collect();
    writeln!(
        md,
        "\nThe orbit image (`uc8151,orbit`, the {} turning, no pause between frames): {} refreshes of {:.0} ms back to back; {} of the {} frames after the first had their bytes on the bus {} us after the refresh before them ended, so the firmware was waiting on BUSY with the frame traced.",
        e.scenes.first().map_or("", |s| s.0.as_str()),
        e.orbit.len(),
        e.orbit.first().map_or(0.0, |r| r.end_ms - r.start_ms),
        e.waited,
        e.orbit.len().saturating_sub(1),
        gaps.join(", ")
    )?;
    Ok(md)
}
