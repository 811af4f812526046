//! The board's buttons (GP14 to ground, `Wiring::NEXT`; the Thumby's A button; and the
//! camera-turn button, `Wiring::TURN`): pressed in the pause after the first scene (run.mjs
//! `--press`, `--press-turn`), the next frame must start within a probe of the press and be
//! bit-identical to host-sim's (the next scene's, or the same scene's turned a step), and the
//! frames after it follow in order.

use super::{host_frame, run_emulator, run_variant_image, variant_uf2, BoardRun, SceneRow, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use board_records::frame::{rendered, Build, TURN_STEPS};
use lattice_rt::Fx;
use std::fmt::Write as _;
use std::path::Path;

/// The most time from the press to the next frame's start: the pause's probe (20 ms) and the
/// panel's set-up, with room to spare.
pub(super) const RESPONSE_MS: f64 = 50.0;

/// When, after the first frame's end, the button is pressed (half a second into its 3 s pause).
pub(super) const PRESS_AFTER_MS: f64 = 500.0;

/// What the button run did, for the report.
pub(super) struct ButtonRow {
    /// Which button.
    what: &'static str,
    /// When the button was pressed, and when the next frame started (ms from boot).
    press_ms: f64,
    next_start_ms: Option<f64>,
    /// The frames after the press bit-identical to their scenes' host-sim frames, of those run.
    same: usize,
    checked: usize,
}

/// An image whose button is pressed: its ELF and UF2 files, the frame it renders, the run's
/// switches (its panel), which button, and what the report calls it.
pub(super) struct Pressed<'a> {
    pub elf: &'a Path,
    pub uf2: &'a Path,
    pub build: Build,
    pub extra: &'a [&'a str],
    pub press: Buttons,
    pub what: &'static str,
}

/// The buttons a run presses, at one moment.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Buttons {
    /// The next-scene button: the scenes in turn.
    Next,
    /// The camera-turn button: the first scene, that scene turned a step, the second scene.
    Turn,
    /// Both at one probe: the first scene, the second (the next-scene button is taken first),
    /// that scene turned (the turn taken at the next pause's first probe).
    Both,
}

impl Session<'_> {
    /// The default image with the button pressed in the first pause.
    pub(super) fn button_run(&mut self, clean: &[SceneRow]) -> Result<Option<ButtonRow>> {
        let Some(f0) = clean.first() else {
            self.checks.fail("the button needs the clean run's first frame".into());
            return Ok(None);
        };
        let (elf, uf2) = (self.elf.clone(), self.uf2.clone());
        let image = Pressed {
            elf: &elf,
            uf2: &uf2,
            build: PICO,
            extra: &[],
            press: Buttons::Next,
            what: "GP14 (a push button to ground)",
        };
        self.press_run(&image, f0.frame.end_ms, "button").map(Some)
    }

    /// The `parse` image (whose camera turns) with both buttons pressed at one moment in the
    /// first pause: neither press may be lost.
    pub(super) fn both_buttons_run(&mut self) -> Result<Option<ButtonRow>> {
        self.variant_press_run("parse", &[], PICO, (Buttons::Both, "GP14 and GP15 at once, `parse`"), "both-buttons")
    }

    /// The image with `features` (run with the switches `extra`, drawing frames as `build`
    /// says) run for its first frame, then again with `press` made after it: [`Self::press_run`],
    /// its frames in the folder `name`.
    pub(super) fn variant_press_run(
        &mut self,
        features: &str,
        extra: &[&str],
        build: Build,
        (press, what): (Buttons, &'static str),
        name: &str,
    ) -> Result<Option<ButtonRow>> {
        let (run, dir) = self.variant(features, true, 1, extra)?;
        let Some(first) = run.frames.first() else {
            self.checks.fail(format!("{features}: no frame shown ({})", run.reason));
            return Ok(None);
        };
        let (elf, uf2) = (run_variant_image(self.root, features), dir.join(variant_uf2(features)));
        let image = Pressed { elf: &elf, uf2: &uf2, build, extra, press, what };
        self.press_run(&image, first.end_ms, name).map(Some)
    }

    /// `image` with its button pressed [`PRESS_AFTER_MS`] after its first frame ended at
    /// `first_end_ms`; its frames in the folder `name`. The next-scene button's frames are the
    /// scenes in turn; the camera-turn button's the first scene, the first scene turned a step
    /// ([`TURN_STEPS`]), then the second scene from its own camera (after the pause); both
    /// buttons' the first scene, the second, then the second turned a step.
    pub(super) fn press_run(&mut self, image: &Pressed<'_>, first_end_ms: f64, name: &str) -> Result<ButtonRow> {
        let press_ms = first_end_ms + PRESS_AFTER_MS;
        let dir = self.frames_dir.join(name);
        std::fs::create_dir_all(&dir)?;
        let frames = 3.min(self.scenes.len() + usize::from(image.press != Buttons::Next));
        eprintln!("{name}: the button pressed at {press_ms:.1} ms");
        let press = format!("{press_ms:.3}");
        let which: &[(&str, &str)] = match image.press {
            Buttons::Next => &[("--press", "next")],
            Buttons::Turn => &[("--press-turn", "turn")],
            Buttons::Both => &[("--press", "next"), ("--press-turn", "turn")],
        };
        let mut args: Vec<&str> = which.iter().flat_map(|&(switch, _)| [switch, press.as_str()]).collect();
        args.extend(image.extra);
        let run = run_emulator(self.root, image.elf, image.uf2, &self.bootrom, frames, true, &dir, &args)?;
        self.checks.check(run.ok, || format!("{name}: the run did not finish: {}", run.reason));
        let seen = which.iter().all(|&(_, w)| run.presses.iter().filter(|p| p.0 == w).count() == 1);
        self.checks.check(seen && run.presses.len() == which.len(), || {
            format!("{name}: {} presses seen, {} made", run.presses.len(), which.len())
        });
        let next_start_ms = self.check_response(name, press_ms, &run);
        // Each frame's scene and turn.
        let (first, rest) = self.scenes.split_at(1.min(self.scenes.len()));
        let shots: Vec<(&String, u32)> = match image.press {
            Buttons::Next => self.scenes.iter().map(|s| (s, 0)).collect(),
            Buttons::Turn => first.iter().flat_map(|s| [(s, 0), (s, 1)]).chain(rest.iter().map(|s| (s, 0))).collect(),
            Buttons::Both => {
                first.iter().map(|s| (s, 0)).chain(rest.iter().take(1).flat_map(|s| [(s, 0), (s, 1)])).collect()
            }
        };
        let mut same = 0;
        for (k, (frame, (scene, step))) in run.frames.iter().zip(shots).enumerate() {
            let want = if step == 0 {
                host_frame(&self.scenes_dir, scene, PICO_SCALAR, image.build)?
            } else {
                let path = self.scenes_dir.join(format!("{scene}.scene"));
                let turn = f64::from(step) / f64::from(TURN_STEPS);
                host_sim::orbit::turned_frame::<Fx>(&path, &host_sim::load::read(&path)?, turn, &rendered(image.build))?
            };
            let ok = frame.error.is_none() && frame.pixels == want;
            same += usize::from(ok);
            self.checks
                .check(ok, || format!("{name}: frame {k} is not {scene}'s frame (turned {step}) as host-sim draws it"));
        }
        Ok(ButtonRow { what: image.what, press_ms, next_start_ms, same, checked: run.frames.len() })
    }

    /// Checks that `run`'s second frame, the one after a press at `press_ms`, started within
    /// [`RESPONSE_MS`] of it; when it started.
    pub(super) fn check_response(&mut self, name: &str, press_ms: f64, run: &BoardRun) -> Option<f64> {
        let next_start_ms = run.frames.get(1).map(|f| f.start_ms);
        self.checks.check(next_start_ms.is_some_and(|s| s >= press_ms && s - press_ms <= RESPONSE_MS), || {
            format!("{name}: pressed at {press_ms:.1} ms, the next frame started at {next_start_ms:?} ms (at most {RESPONSE_MS} ms later)")
        });
        next_start_ms
    }
}

/// The report's section on the buttons: the board's, the Thumby's A and B, the Badger's camera turn.
pub(super) fn button_report(rows: &[ButtonRow]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## The buttons: the next scene, the camera turned\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: a push button from GP14 to ground (`Wiring::NEXT`, pulled up inside; the Thumby's A button on GP27 in the `thumby` image) ends the 3 s pause between scenes, so the next scene is drawn at once; the firmware reads it at every probe of the pause (20 ms). The emulated board presses it {PRESS_AFTER_MS:.0} ms into the pause after the first frame (`run.mjs --press`); the next frame must start within {RESPONSE_MS:.0} ms and every frame must be its scene's, bit-identical to host-sim's. A second button, from GP15 (`Wiring::TURN`; the Thumby's B on GP24), draws the scene again from an eighth of a circle further round; it works where the scene is set up on the board (the `slot` and `parse` images, `thumby,parse` on the Thumby, `uc8151,parse,code-in-flash` on the Badger, whose default image bakes its scenes: parsing at 296x128 fits the RP2040's RAM only with the code in flash), and *The scene slot* above and the Thumby's B and the Badger's rows below press it (the first scene, then that scene turned, then the next scene after the pause, each bit-identical to host-sim's). Both pressed at one probe (the `parse` image's row), the next-scene button is taken first and the turn at the next pause's first probe, so neither is lost: the first scene, the second, the second turned. The Badger 2040's buttons close to 3V3: its image reads them with pull-downs, and the emulated board's buttons read what the pad's pull gives a released pin, so an image that pulled them the wrong way would see a button held down (the e-paper's run below presses its button C).\n"
    )?;
    writeln!(md, "| button | pressed at | the next frame started after | frames bit-identical to host-sim |")?;
    writeln!(md, "|---|---:|---:|---:|")?;
    for r in rows {
        let response = r.next_start_ms.map_or("none".into(), |s| format!("{:.1} ms", s - r.press_ms));
        writeln!(md, "| {} | {:.1} ms | {response} | {} of {} |", r.what, r.press_ms, r.same, r.checked)?;
    }
    Ok(md)
}
