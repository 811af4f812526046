//! The board's button (GP14 to ground, `Wiring::NEXT`): pressed in the pause after the first
//! scene (run.mjs `--press`), the next scene's frame must start within a probe of the press and
//! be bit-identical to host-sim's, and the scenes after it follow in order.

use super::{host_frame, run_emulator, SceneRow, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use std::fmt::Write as _;

/// The most time from the press to the next frame's start: the pause's probe (20 ms) and the
/// panel's set-up, with room to spare.
const RESPONSE_MS: f64 = 50.0;

/// When, after the first frame's end, the button is pressed (half a second into its 3 s pause).
const PRESS_AFTER_MS: f64 = 500.0;

/// What the button run did, for the report.
pub(super) struct ButtonRow {
    /// When the button was pressed, and when the next frame started (ms from boot).
    press_ms: f64,
    next_start_ms: Option<f64>,
    /// The frames after the press bit-identical to their scenes' host-sim frames, of those run.
    same: usize,
    checked: usize,
}

impl Session<'_> {
    /// The default image with the button pressed in the first pause.
    pub(super) fn button_run(&mut self, clean: &[SceneRow]) -> Result<Option<ButtonRow>> {
        let Some(f0) = clean.first() else {
            self.checks.fail("the button needs the clean run's first frame".into());
            return Ok(None);
        };
        let press_ms = f0.frame.end_ms + PRESS_AFTER_MS;
        let dir = self.frames_dir.join("button");
        std::fs::create_dir_all(&dir)?;
        let frames = 3.min(self.scenes.len());
        eprintln!("the button pressed at {press_ms:.1} ms");
        let press = format!("{press_ms:.3}");
        let run =
            run_emulator(self.root, &self.elf, &self.uf2, &self.bootrom, frames, true, &dir, &["--press", &press])?;
        self.checks.check(run.ok, || format!("button: the run did not finish: {}", run.reason));
        self.checks.check(run.presses.len() == 1, || format!("button: {} presses seen, 1 made", run.presses.len()));
        let next_start_ms = run.frames.get(1).map(|f| f.start_ms);
        self.checks.check(next_start_ms.is_some_and(|s| s >= press_ms && s - press_ms <= RESPONSE_MS), || {
            format!("button: pressed at {press_ms:.1} ms, the next frame started at {next_start_ms:?} ms (at most {RESPONSE_MS} ms later)")
        });
        let mut same = 0;
        for (k, (frame, name)) in run.frames.iter().zip(&self.scenes).enumerate() {
            let want = host_frame(&self.scenes_dir, name, PICO_SCALAR, PICO)?;
            let ok = frame.error.is_none() && frame.pixels == want;
            same += usize::from(ok);
            self.checks.check(ok, || format!("button: frame {k} is not {name}'s frame as host-sim draws it"));
        }
        Ok(Some(ButtonRow { press_ms, next_start_ms, same, checked: run.frames.len() }))
    }
}

/// The report's section on the button.
pub(super) fn button_report(row: Option<&ButtonRow>) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## The button: the next scene\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: a push button from GP14 to ground (`Wiring::NEXT`, pulled up inside) ends the 3 s pause between scenes, so the next scene is drawn at once; the firmware reads it at every probe of the pause (20 ms). The emulated board presses it {PRESS_AFTER_MS:.0} ms into the pause after the first frame (`run.mjs --press`); the next frame must start within {RESPONSE_MS:.0} ms and every frame must be its scene's, bit-identical to host-sim's.\n"
    )?;
    if let Some(r) = row {
        let response = r.next_start_ms.map_or("none".into(), |s| format!("{:.1} ms", s - r.press_ms));
        writeln!(md, "| pressed at | the next frame started after | frames bit-identical to host-sim |")?;
        writeln!(md, "|---:|---:|---:|")?;
        writeln!(md, "| {:.1} ms | {response} | {} of {} |", r.press_ms, r.same, r.checked)?;
    }
    Ok(md)
}
