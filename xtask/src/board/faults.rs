//! The display losing power on the emulated board (run.mjs `--panel-off`): the panel stops
//! answering, then comes back as a freshly powered one (its settings and RAM lost, dark). Each
//! scenario cuts the power at a moment taken from the clean run's frames, for a while, and
//! checks what the board did: every frame it reported as shown is on the panel, bit-identical
//! to host-sim's, and a good frame follows within a second of the power's return.

use super::{host_frame, run_emulator, PanelFrame, SceneRow, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use board_records::Record;
use std::fmt::Write as _;

/// The most time from the power's return to the next good frame (1 s: 125 M cycles).
const RECOVERY_MS: f64 = 1000.0;

/// Frames each scenario runs for: the first scenes and the frames drawn again.
const FRAMES: usize = 4;

/// One scenario: its name, what it does, and when it cuts the power (from boot, in emulated
/// milliseconds) and for how long, from the clean run's first two frames.
struct Scenario {
    name: &'static str,
    what: &'static str,
    cut: fn(&PanelFrame, &PanelFrame) -> (f64, f64),
}

/// The scenarios: a cut in the middle of a frame (the bus sees it), one inside the pause after
/// a frame (no transfer sees it: the board's probes do), and a long one that spans the start of
/// the next frame (its set-up waits for the panel).
const SCENARIOS: [Scenario; 3] = [
    Scenario {
        name: "mid-frame",
        what: "the second frame half sent, power back after 300 ms",
        cut: |_, f1| (f1.start_ms + (f1.end_ms - f1.start_ms) / 2.0, 300.0),
    },
    Scenario {
        name: "in the pause",
        what: "0.7 s into the pause after the first frame, for 600 ms",
        cut: |f0, _| (f0.end_ms + 700.0, 600.0),
    },
    Scenario {
        name: "across a frame's start",
        what: "2 s into the pause after the first frame, for 2.5 s",
        cut: |f0, _| (f0.end_ms + 2000.0, 2500.0),
    },
];

/// What a scenario did, for the report.
pub(super) struct FaultRow {
    name: &'static str,
    what: &'static str,
    cut: (f64, f64),
    /// Frames the board reported as not taken by the display.
    failed: usize,
    /// Milliseconds from the power's return to the end of the next good frame.
    recovery_ms: Option<f64>,
    ok: bool,
}

impl Session<'_> {
    /// Runs every scenario on the default image; `clean` is the run without faults.
    pub(super) fn fault_runs(&mut self, clean: &[SceneRow]) -> Result<Vec<FaultRow>> {
        let (Some(f0), Some(f1)) = (clean.first(), clean.get(1)) else {
            self.checks.fail("the power cuts need the clean run's first two frames".into());
            return Ok(Vec::new());
        };
        let dir = self.frames_dir.join("faults");
        std::fs::create_dir_all(&dir)?;
        let mut rows = Vec::new();
        for sc in &SCENARIOS {
            let (start, len) = (sc.cut)(&f0.frame, &f1.frame);
            eprintln!("power cut {}: at {start:.1} ms for {len:.0} ms", sc.name);
            let arg = format!("{start:.3}:{len:.3}");
            let run = run_emulator(
                self.root,
                &self.elf,
                &self.uf2,
                &self.bootrom,
                FRAMES,
                true,
                &dir,
                &["--panel-off", &arg],
            )?;
            let outcomes: Vec<Option<u8>> = run
                .records
                .iter()
                .filter_map(|r| match r {
                    Record::Frame(f) => Some(Some(f.scene)),
                    Record::Failed { .. } => Some(None),
                    _ => None,
                })
                .collect();
            let mut ok =
                self.checks.check(run.ok, || format!("power cut {}: the run did not finish: {}", sc.name, run.reason));
            let mut recovery_ms = None;
            for (k, (frame, outcome)) in run.frames.iter().zip(&outcomes).enumerate() {
                let Some(scene) = outcome else { continue };
                let name = self.scenes.get(usize::from(*scene)).cloned().unwrap_or_default();
                let want = host_frame(&self.scenes_dir, &name, PICO_SCALAR, PICO)?;
                let same = frame.error.is_none() && frame.pixels == want;
                ok &= self.checks.check(same, || {
                    let why = frame.error.clone().unwrap_or_else(|| "it differs from host-sim's".into());
                    format!("power cut {}: frame {k} ({name}) was reported shown, but the panel: {why}", sc.name)
                });
                if same && frame.end_ms > start + len && recovery_ms.is_none() {
                    recovery_ms = Some(frame.end_ms - (start + len));
                }
            }
            ok &= self.checks.check(outcomes.len() >= run.frames.len(), || {
                format!("power cut {}: {} frames on the panel, {} reported", sc.name, run.frames.len(), outcomes.len())
            });
            ok &= self.checks.check(recovery_ms.is_some_and(|ms| ms <= RECOVERY_MS), || {
                format!(
                    "power cut {}: the next good frame came {recovery_ms:?} ms after the power (at most {RECOVERY_MS})",
                    sc.name
                )
            });
            let failed = outcomes.iter().filter(|o| o.is_none()).count();
            rows.push(FaultRow { name: sc.name, what: sc.what, cut: (start, len), failed, recovery_ms, ok });
        }
        Ok(rows)
    }
}

/// The report's section on the power cuts.
pub(super) fn fault_report(rows: &[FaultRow]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## The display losing power\n")?;
    writeln!(
        md,
        "A loose wire: the emulated panel stops answering (every I2C address NACKs) and comes back as a freshly powered SSD1306, its settings and RAM lost and its display off (`run.mjs --panel-off START:LEN`). The firmware sets the panel up before every frame (a write-only bus cannot tell that it lost power), draws again a frame the display did not take once it answers (set up again every 100 ms), and asks the panel every 20 ms while it waits between frames whether it answers, drawing the frame again when it stopped and answers again. Each run: {FRAMES} frames of the default image; every frame the board reported as shown must be on the panel, bit-identical to host-sim's, and a good frame must end within {RECOVERY_MS:.0} ms of the power's return.\n"
    )?;
    writeln!(md, "| scenario | power cut | from boot (ms) | length (ms) | frames not taken | power back to the next good frame | passed |")?;
    writeln!(md, "|---|---|---:|---:|---:|---:|---|")?;
    for r in rows {
        let rec = r.recovery_ms.map_or("none".into(), |ms| format!("{ms:.0} ms"));
        writeln!(
            md,
            "| {} | {} | {:.1} | {:.0} | {} | {rec} | {} |",
            r.name,
            r.what,
            r.cut.0,
            r.cut.1,
            r.failed,
            if r.ok { "yes" } else { "**no**" }
        )?;
    }
    writeln!(md, "\nNot survived yet: a cut shorter than the gaps between one frame's transfers (the bus idles while the cores trace) that ends before the frame's last byte. No transfer fails, the board reports the frame shown, and the panel stays dark until the next frame sets it up: an SSD1306 on I2C cannot be read back. The SPI image sees no cut at all (SPI has no acknowledge); its frames still set the panel up, so the next frame after the power's return is good.")?;
    Ok(md)
}
