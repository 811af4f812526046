//! Faults on the emulated board, each at a moment taken from the clean run's frames: the
//! display losing power (run.mjs `--panel-off`: the panel stops answering, then comes back as a
//! freshly powered one, its settings and RAM lost, dark), the chip reset mid-frame (`--reset-at`,
//! the RUN pin) and core 1 stopping for good (`--hang-core1-at`, which the watchdog must turn
//! into a reset). Each run checks what the board did: every frame it reported as shown is on
//! the panel, bit-identical to host-sim's, and a good frame follows within a second of the
//! fault's end (the power's return, the reset). On the bus: the panel holding SDA low until it
//! is clocked (`--sda-stuck`, which the firmware must clear through the pins) and one byte not
//! acknowledged (`--nack-at`).

use super::{host_frame, run_emulator, PanelFrame, SceneRow, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use board_records::Record;
use std::fmt::Write as _;

/// The most time from the power's return to the next good frame (1 s: 125 M cycles).
const RECOVERY_MS: f64 = 1000.0;

/// The firmware's watchdog timeout (`firmware/src/bin/pico/guard.rs`).
const WATCHDOG_MS: f64 = 1000.0;

/// Frames each scenario runs for: the first scenes and the frames drawn again.
const FRAMES: usize = 4;

/// A fault and when (emulated milliseconds from boot).
#[derive(Clone, Copy)]
enum Fault {
    /// The display's power cut at the first time for the second's milliseconds.
    PanelOff(f64, f64),
    /// The chip reset (the RUN pin).
    Reset(f64),
    /// Core 1 stops making progress for good.
    HangCore1(f64),
    /// The firmware panics (asked through its `PANIC_REQUEST` word at this address).
    Panic(f64, u64),
    /// The panel holds SDA low until it has seen the second's falling SCL edges.
    SdaStuck(f64, u8),
    /// The panel does not acknowledge the first byte after this moment.
    Nack(f64),
}

impl Fault {
    /// The fault as run.mjs gets it: its moments to the microsecond ([`Fault::args`] writes
    /// three decimals). The checks compare the bus's events with these moments, so they must be
    /// the moments the emulator was given: a byte not acknowledged 0.3 µs after the rounded
    /// moment may come before the unrounded one.
    fn as_sent(self) -> Self {
        let us = |ms: f64| (ms * 1e3).round() / 1e3;
        match self {
            Fault::PanelOff(start, len) => Fault::PanelOff(us(start), us(len)),
            Fault::Reset(at) => Fault::Reset(us(at)),
            Fault::HangCore1(at) => Fault::HangCore1(us(at)),
            Fault::Panic(at, request) => Fault::Panic(us(at), request),
            Fault::SdaStuck(at, pulses) => Fault::SdaStuck(us(at), pulses),
            Fault::Nack(at) => Fault::Nack(us(at)),
        }
    }

    /// run.mjs's switches for it.
    fn args(self) -> Vec<String> {
        match self {
            Fault::PanelOff(start, len) => vec!["--panel-off".into(), format!("{start:.3}:{len:.3}")],
            Fault::Reset(at) => vec!["--reset-at".into(), format!("{at:.3}")],
            Fault::HangCore1(at) => vec!["--hang-core1-at".into(), format!("{at:.3}")],
            Fault::Panic(at, request) => {
                vec!["--panic-at".into(), format!("{at:.3}"), "--panic-request".into(), format!("{request:#x}")]
            }
            Fault::SdaStuck(at, pulses) => vec!["--sda-stuck".into(), format!("{at:.3}:{pulses}")],
            Fault::Nack(at) => vec!["--nack-at".into(), format!("{at:.3}")],
        }
    }
    /// When it starts.
    fn start(self) -> f64 {
        match self {
            Fault::PanelOff(start, _)
            | Fault::Reset(start)
            | Fault::HangCore1(start)
            | Fault::Panic(start, _)
            | Fault::SdaStuck(start, _)
            | Fault::Nack(start) => start,
        }
    }
}

/// One scenario: its name, what it does, and its fault, placed by the clean run's first two
/// frames.
struct Scenario {
    name: &'static str,
    what: &'static str,
    /// The fault, from the first two frames and the address of the firmware's `PANIC_REQUEST`.
    fault: fn(&PanelFrame, &PanelFrame, u64) -> Fault,
}

/// The middle of frame `f`.
fn mid(f: &PanelFrame) -> f64 {
    f.start_ms + (f.end_ms - f.start_ms) / 2.0
}

/// The scenarios: a power cut in the middle of a frame (the bus sees it), one inside the pause
/// after a frame (no transfer sees it: the board's probes do), two short ones that neither a
/// transfer nor a probe sees (the picture sent again while it stands brings it back), a long
/// one that spans the start of the next frame (its set-up waits for the panel); a reset in the
/// middle of a frame; core 1 stopping in the middle of a frame; a panic between frames; SDA
/// held low in the middle of a frame and in the pause; one byte of a frame not acknowledged.
const SCENARIOS: [Scenario; 11] = [
    Scenario {
        name: "power cut mid-frame",
        what: "the display's power, the second frame half sent, back after 300 ms",
        fault: |_, f1, _| Fault::PanelOff(mid(f1), 300.0),
    },
    Scenario {
        name: "power cut in the pause",
        what: "the display's power, 0.7 s into the pause after the first frame, for 600 ms",
        fault: |f0, _, _| Fault::PanelOff(f0.end_ms + 700.0, 600.0),
    },
    Scenario {
        name: "short power cut before a frame's first byte",
        what: "the display's power, 0.5 ms after the LED lit for the second frame (the cores trace, the bus idles), for 2.5 ms",
        fault: |_, f1, _| Fault::PanelOff(f1.start_ms + 0.5, 2.5),
    },
    Scenario {
        name: "short power cut between probes",
        what: "the display's power, 1.01 s into the pause after the first frame, for 2.5 ms",
        fault: |f0, _, _| Fault::PanelOff(f0.end_ms + 1010.0, 2.5),
    },
    Scenario {
        name: "power cut across a frame's start",
        what: "the display's power, 2 s into the pause after the first frame, for 2.5 s",
        fault: |f0, _, _| Fault::PanelOff(f0.end_ms + 2000.0, 2500.0),
    },
    Scenario {
        name: "reset mid-frame",
        what: "the RUN pin, the second frame half traced",
        fault: |_, f1, _| Fault::Reset(mid(f1)),
    },
    Scenario {
        name: "core 1 stops",
        what: "core 1 makes no more progress, the second frame half traced",
        fault: |_, f1, _| Fault::HangCore1(mid(f1)),
    },
    Scenario {
        name: "panic",
        what: "the firmware panics, 0.5 s into the pause after the first frame",
        fault: |f0, _, request| Fault::Panic(f0.end_ms + 500.0, request),
    },
    Scenario {
        name: "SDA held low mid-frame",
        what: "the panel holds SDA low, the second frame half sent, until clocked 9 times",
        fault: |_, f1, _| Fault::SdaStuck(mid(f1), 9),
    },
    Scenario {
        name: "SDA held low in the pause",
        what: "the panel holds SDA low, 0.3 s into the pause after the first frame, until clocked once",
        fault: |f0, _, _| Fault::SdaStuck(f0.end_ms + 300.0, 1),
    },
    Scenario {
        name: "one byte not acknowledged",
        what: "the panel does not acknowledge one byte, the second frame half sent",
        fault: |_, f1, _| Fault::Nack(mid(f1)),
    },
];

/// What the board reported for a frame the panel showed.
enum Outcome {
    /// Scene `.0`'s frame, shown.
    Frame(u8),
    /// A frame the display did not take.
    Failed,
    /// The line saying why the last boot panicked.
    Message,
}

/// What a scenario did, for the report.
pub(super) struct FaultRow {
    name: &'static str,
    what: &'static str,
    /// When the fault started and ended (emulated ms from boot; a stopped core ends with the
    /// watchdog's reset).
    span: (f64, Option<f64>),
    /// The resets the run saw, and why.
    resets: Vec<String>,
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
        let request = crate::elf::Elf::read(&self.elf)?.symbol_address("PANIC_REQUEST")?.unwrap_or(0);
        let dir = self.frames_dir.join("faults");
        std::fs::create_dir_all(&dir)?;
        let mut rows = Vec::new();
        for sc in &SCENARIOS {
            let fault = (sc.fault)(&f0.frame, &f1.frame, request).as_sent();
            let mut args = fault.args();
            eprintln!("fault {}: {}", sc.name, args.join(" "));
            // A power cut: when, and the panel looked at after it.
            let cut = match fault {
                Fault::PanelOff(start, len) => Some((start, start + len)),
                _ => None,
            };
            if let Some((_, back)) = cut {
                args.extend(looks(back).flat_map(|ms| ["--look-at".to_string(), format!("{ms:.3}")]));
            }
            let run = run_emulator(
                self.root,
                &self.elf,
                &self.uf2,
                &self.bootrom,
                FRAMES,
                true,
                &dir,
                &args.iter().map(String::as_str).collect::<Vec<_>>(),
            )?;
            let start = fault.start();
            let end = self.fault_end(sc.name, fault, &run);
            // A panic's reason: in the log of the next boot, and on the panel (checked below).
            let panicked =
                run.log.iter().find_map(|l| l.text.strip_prefix("the last boot panicked: ").map(str::to_string));
            if let Fault::Panic(..) = fault {
                self.checks.check(
                    panicked.as_deref().is_some_and(|w| w.starts_with("a panic the test harness asked for")),
                    || format!("{}: the next boot did not log the panic's reason ({panicked:?})", sc.name),
                );
            }
            let outcomes: Vec<Outcome> = run
                .records
                .iter()
                .filter_map(|r| match r {
                    Record::Frame(f) => Some(Outcome::Frame(f.scene)),
                    Record::Failed { .. } => Some(Outcome::Failed),
                    Record::Panicked => Some(Outcome::Message),
                    _ => None,
                })
                .collect();
            let mut ok = self.checks.check(run.ok, || format!("{}: the run did not finish: {}", sc.name, run.reason));
            let recovery_ms = self.check_frames(sc.name, &run, &outcomes, (end, cut, panicked.as_deref()), &mut ok)?;
            ok &= self.checks.check(outcomes.len() >= run.frames.len(), || {
                format!("{}: {} frames on the panel, {} reported", sc.name, run.frames.len(), outcomes.len())
            });
            ok &= self.checks.check(recovery_ms.is_some_and(|ms| ms <= RECOVERY_MS), || {
                format!(
                    "{}: the next good frame came {recovery_ms:?} ms after the fault ended (at most {RECOVERY_MS})",
                    sc.name
                )
            });
            let failed = outcomes.iter().filter(|o| matches!(o, Outcome::Failed)).count();
            let resets = run.resets.iter().map(|(why, ms)| format!("{why} at {ms:.0} ms")).collect();
            rows.push(FaultRow { name: sc.name, what: sc.what, span: (start, end), resets, failed, recovery_ms, ok });
        }
        Ok(rows)
    }

    /// When `fault` ended in `run`: the power's return, the reset; for a stopped core and a
    /// panic, the reset they cause, which must come in time (checked here, with the log's
    /// reason for a stopped core).
    fn fault_end(&mut self, name: &str, fault: Fault, run: &super::BoardRun) -> Option<f64> {
        match fault {
            Fault::PanelOff(start, len) => Some(start + len),
            Fault::Reset(at) => {
                let seen = run.resets.iter().any(|(why, ms)| why == "reset pin" && (ms - at).abs() < 1.0);
                self.checks.check(seen, || format!("{name}: no reset at {at:.1} ms"));
                Some(at)
            }
            Fault::HangCore1(at) => {
                let reset = run.resets.iter().find(|(why, _)| why == "watchdog").map(|(_, ms)| *ms);
                self.checks.check(reset.is_some_and(|ms| ms - at <= WATCHDOG_MS + 100.0), || {
                    format!("{name}: the watchdog reset {reset:?} ms, core 1 stopped at {at:.1} ms (at most {WATCHDOG_MS} ms later)")
                });
                let said = run.log.iter().any(|l| l.text.contains("the watchdog reset the board"));
                self.checks.check(said, || format!("{name}: the next boot did not log why it reset"));
                reset
            }
            Fault::Panic(at, _) => {
                let reset = run.resets.iter().find(|(why, ms)| why == "watchdog" && *ms >= at).map(|(_, ms)| *ms);
                self.checks.check(reset.is_some_and(|ms| ms - at <= 100.0), || {
                    format!("{name}: the panic at {at:.1} ms reset the board at {reset:?} ms")
                });
                reset
            }
            // The fault ends when the firmware's bus clear has clocked the panel free.
            Fault::SdaStuck(at, _) => {
                let released = run.bus.iter().find(|(what, ms)| what == "sda released" && *ms >= at).map(|(_, ms)| *ms);
                self.checks.check(released.is_some_and(|ms| ms - at <= RECOVERY_MS), || {
                    format!(
                        "{name}: SDA held low at {at:.1} ms, released {released:?} (at most {RECOVERY_MS} ms later)"
                    )
                });
                let said = run.log.iter().any(|l| l.text.contains("the bus cleared with"));
                self.checks.check(said, || format!("{name}: the firmware did not log its bus clear"));
                released
            }
            Fault::Nack(at) => {
                let nack = run.bus.iter().find(|(what, ms)| what == "nack" && *ms >= at).map(|(_, ms)| *ms);
                self.checks.check(nack.is_some(), || format!("{name}: no byte went unacknowledged after {at:.1} ms"));
                nack
            }
        }
    }

    /// Each frame of `run` against what the board reported for it (`outcomes`, in order): a
    /// frame it reported shown must be host-sim's, the panic's line must be the host's drawing
    /// of it. A frame sent while the power was `cut` may be wrong (a cut no transfer saw: a
    /// write-only bus cannot know), if the panel shows it again in time: that is the recovery
    /// check's. Returns the time from the fault's `end` to the first moment the panel showed
    /// the right picture again: the end of a good frame, or a look (`--look-at`) that shows
    /// the last frame reported.
    fn check_frames(
        &mut self,
        name: &str,
        run: &super::BoardRun,
        outcomes: &[Outcome],
        (end, cut, panicked): (Option<f64>, Option<(f64, f64)>, Option<&str>),
        ok: &mut bool,
    ) -> Result<Option<f64>> {
        let mut recovery_ms = None;
        // Each frame reported shown: when it ended, and host-sim's picture of it.
        let mut reported: Vec<(f64, Vec<u8>)> = Vec::new();
        for (k, (frame, outcome)) in run.frames.iter().zip(outcomes).enumerate() {
            let (scene, want) = match outcome {
                Outcome::Failed => continue,
                Outcome::Frame(scene) => {
                    let scene = self.scenes.get(usize::from(*scene)).cloned().unwrap_or_default();
                    let want = host_frame(&self.scenes_dir, &scene, PICO_SCALAR, PICO)?;
                    (scene, want)
                }
                // The panic's line, drawn as the host draws messages.
                Outcome::Message => {
                    let line = format!("Panicked: {}", panicked.unwrap_or_default());
                    let want = super::slot::message_frame(&line);
                    *ok &= self.checks.check(frame.error.is_none() && frame.pixels == want, || {
                        format!("{name}: the panel does not show \"{line}\"")
                    });
                    continue;
                }
            };
            let same = frame.error.is_none() && frame.pixels == want;
            let under_cut = cut.is_some_and(|(from, to)| from < frame.end_ms && to > frame.start_ms);
            *ok &= self.checks.check(same || under_cut, || {
                let why = frame.error.clone().unwrap_or_else(|| "it differs from host-sim's".into());
                format!("{name}: frame {k} ({scene}) was reported shown, but the panel: {why}")
            });
            if let Some(end) = end {
                if same && frame.end_ms > end && recovery_ms.is_none() {
                    recovery_ms = Some(frame.end_ms - end);
                }
            }
            reported.push((frame.end_ms, want));
        }
        // The looks after the fault's end that fall between frames: the panel must show the
        // last frame reported before them.
        let between = |ms: f64| !run.frames.iter().any(|f| f.start_ms <= ms && ms <= f.end_ms);
        let back = run.looks.iter().find(|(ms, pixels)| {
            let last = reported.iter().rev().find(|(at, _)| at < ms).map(|(_, want)| want);
            end.is_some_and(|end| *ms > end) && between(*ms) && last.is_some() && pixels.as_ref() == last
        });
        if let (Some(end), Some((ms, _))) = (end, back) {
            recovery_ms = Some(recovery_ms.map_or(ms - end, |r: f64| r.min(ms - end)));
        }
        Ok(recovery_ms)
    }
}

/// The moments after a power cut's end at which the panel is looked at: every 50 ms for
/// [`RECOVERY_MS`].
fn looks(end: f64) -> impl Iterator<Item = f64> {
    (1..=(RECOVERY_MS / 50.0) as u32).map(move |k| end + 50.0 * f64::from(k))
}

/// The report's section on the faults.
pub(super) fn fault_report(rows: &[FaultRow]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## Faults on the desk: power cuts, resets, a core that stops, a stuck bus\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: each fault is one run of the default image on the emulated board ({FRAMES} frames), placed by the clean run's first two frames. *Power cut*: the emulated panel stops answering (every I2C address NACKs) and comes back as a freshly powered SSD1306, its settings and RAM lost and its display off (`run.mjs --panel-off START:LEN`). *Reset*: the chip resets as the RUN pin resets it (`--reset-at`); SRAM is kept, as on silicon. *Core 1 stops*: it makes no more progress (`--hang-core1-at`). *Panic*: the firmware panics between frames (`--panic-at`, through its `PANIC_REQUEST` word, the one way the harness can reach the panic handler). *SDA held low*: the panel holds SDA low, as one whose transfer was cut off in the middle of a byte does, until it has seen the given number of falling SCL edges (`--sda-stuck START:PULSES`); the controller then sees a busy bus and sends no START (the RP2040's I2C block has no bus clear of its own). *Not acknowledged*: the panel does not acknowledge one byte (`--nack-at`).\n\nWhat the firmware does: it sets the panel up before every frame (a write-only bus cannot tell that it lost power); it draws again a frame the display did not take once the panel answers (set up again every 100 ms); while it waits between frames it asks the panel every 20 ms whether it answers, and draws the frame again when it stopped and answers again; every 400 ms of that wait, in place of a probe, it sends the picture again (the set-up without its display off, the 1 KiB of page bytes it keeps, display on: about 1,100 bytes, some 25 ms of the bus at 400 kHz), which a panel that was powered all along shows as no change and one back from a cut too short for any transfer or probe to see shows as the picture. A transfer that fails or moves no byte for 10 ms resets the I2C controller before the next one and, when SDA reads low, clears the bus: SCL pulsed through the pins until the panel lets SDA go (at most 9 times), then a STOP. The watchdog ({WATCHDOG_MS:.0} ms) is fed by core 0 after each tile it traces, between frames and while it waits for the panel, and by either core every 32 eye samples it traces (a tile of a heavy scene can take seconds), never while a core waits for the other: a core that stops resets the board once the other runs out of work, and the next boot logs why. Without a probe (the UF2 images; `cargo pico` keeps panic-probe), a panic writes its reason into RAM that a reset keeps, resets the board through the watchdog, and the next boot logs it and shows `Panicked: REASON` on the panel for 0.8 s before the scenes. Checked in each run: every frame the board reported as shown is on the panel, bit-identical to host-sim's, except one sent while the power was cut (no transfer may have failed: an I2C panel cannot be read back); within {RECOVERY_MS:.0} ms of the fault's end (the power's return, the reset) the panel shows the right picture again: a good frame ends, or, looked at every 50 ms after a power cut (`run.mjs --look-at`), between frames it shows the last frame reported; the run ends with no hard fault and no lock-up.\n"
    )?;
    writeln!(md, "| scenario | fault | starts (ms from boot) | ends (ms) | resets | frames not taken | fault's end to the right picture | passed |")?;
    writeln!(md, "|---|---|---:|---:|---|---:|---:|---|")?;
    for r in rows {
        let rec = r.recovery_ms.map_or("none".into(), |ms| format!("{ms:.0} ms"));
        let end = r.span.1.map_or("-".into(), |ms| format!("{ms:.1}"));
        let resets = if r.resets.is_empty() { "none".into() } else { r.resets.join(", ") };
        writeln!(
            md,
            "| {} | {} | {:.1} | {end} | {resets} | {} | {rec} | {} |",
            r.name,
            r.what,
            r.span.0,
            r.failed,
            if r.ok { "yes" } else { "**no**" }
        )?;
    }
    writeln!(md, "\nNot survived yet: a power cut no transfer sees during a frame that takes longer than a second (the picture is sent again only while it stands, so it comes back up to 400 ms after such a frame ends). The SPI image sees no cut at all (SPI has no acknowledge); it sends the picture again as the I2C image does. The Sharp memory LCD, the gray mode and the e-paper do not send it again (an e-paper keeps its picture without power). A panel that holds SDA low through nine clock pulses needs its power cycled: the firmware logs it and keeps trying.")?;
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::Fault;

    /// The moment the checks use is the one run.mjs reads back from the switches, to the bit (in
    /// a run that failed so, a byte went unacknowledged 0.3 µs after the rounded moment the
    /// emulator was given, and before the unrounded one the check used).
    #[test]
    fn a_fault_as_sent_is_the_moment_run_mjs_reads() {
        let faults = [
            Fault::Nack(3_135.583_4),
            Fault::Reset(0.000_6),
            Fault::SdaStuck(2_073.148_5, 9),
            Fault::PanelOff(773.147_4, 600.000_2),
        ];
        for fault in faults {
            let sent = fault.as_sent();
            let args = sent.args();
            let at: f64 = args[1].split(':').next().unwrap().parse().unwrap();
            assert_eq!(at.to_bits(), sent.start().to_bits(), "{args:?}");
            assert!((sent.start() - fault.start()).abs() <= 0.000_5, "{args:?}");
        }
    }
}
