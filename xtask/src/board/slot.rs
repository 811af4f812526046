//! The scene slot on the emulated Pico: the prebuilt `slot` image with a user's scene written
//! beside it (as `host-sim uf2 --scene` and the playground write it) shows that scene's frame,
//! bit-identical to host-sim's; an empty slot, a corrupt one, a scene too big for the image and
//! a scene with a mistake each show their message on the panel (drawn as the host draws it,
//! `board_records::message`) and in the log, never a fault.

use super::button::{PRESS_AFTER_MS, RESPONSE_MS};
use super::{build_pico_with, run_emulator, save_frame, Session, PANEL};
use anyhow::{Context, Result};
use board_records::frame::{ORBIT_FRAMES, TURN_STEPS};
use board_records::slot::{self, SlotError};
use host_sim::uf2::{kept_image, write_uf2};
use lattice_rt::{BitFrame, Fx};
use std::fmt::Write as _;
use std::path::Path;

/// A scene no built-in image holds: the spheres from another eye, with a cone and one angle of
/// view (what a user writes).
const USER_SCENE: &str = "camera eye 2.5 2.2 -6 look 0 0.7 0 fov 50\nlight directional dir -0.5 -1 0.7\nmaterial shiny ka 0.15 kd 0.6 ks 0.3\nsphere center -0.9 0.8 0 radius 0.8 material shiny\ncone base 1.1 0 0.3 radius 0.6 height 1.5\nbox min -4 -0.1 -3 max 4 0 5\n";

/// What the panel must show.
enum Expect {
    /// The frame host-sim renders of this text with the Pico's settings.
    Frame(&'static str),
    /// This message (as the firmware words it, cut to the 160 bytes it keeps).
    Message(String),
    /// The frame host-sim renders of this text with the camera turned a step
    /// (`TURN_STEPS`), after the camera-turn button is pressed in the pause after the first.
    Turned(&'static str),
}

/// One case: its name, what it is, the UF2 file's bytes and what the panel must show.
struct Case {
    name: &'static str,
    what: &'static str,
    uf2: Vec<u8>,
    expect: Expect,
}

/// What a case did, for the report.
pub(super) struct SlotRow {
    name: &'static str,
    what: &'static str,
    shown: String,
    cycles: Option<u64>,
    same: bool,
}

/// The message the firmware shows for a scene the core refused: its `AppError::Parse` words.
fn refused(text: &str) -> String {
    let mut objects = vec![lattice_rt::scene::Object::<Fx>::default(); slot::ROOM.objects];
    let mut parts = lattice_rt::Parts::default();
    match lattice_rt::parse::<Fx>(text, &mut objects, &mut parts) {
        Err(e) => format!("scene: {e}"),
        Ok(_) => "the scene was accepted".into(),
    }
}

/// `text` cut as the firmware's 160-byte message cuts it (at a character boundary).
fn cut(text: &str) -> String {
    let mut n = text.len().min(160);
    while !text.is_char_boundary(n) {
        n -= 1;
    }
    text[..n].to_string()
}

/// The panel's bits of `message` as the board draws it.
pub(super) fn message_frame(message: &str) -> Vec<u8> {
    let mut bits = vec![0u8; BitFrame::bytes(PANEL.0, PANEL.1)];
    let mut frame = BitFrame::new(PANEL.0, PANEL.1, &mut bits).expect("sized");
    let Ok(()) = board_records::message::draw(&mut frame, PANEL.0, PANEL.1, message);
    bits
}

/// The slot cases: the user's scene, the slot image alone, the user's file corrupted, and two
/// scenes written past the host's check (too many objects, a misspelt attribute), each with
/// what the board must show.
fn cases(image: &[u8]) -> Result<[Case; 6]> {
    let too_big: String = std::iter::once("camera eye 0 4 -30\n".to_string())
        .chain((0..70).map(|i| format!("sphere center {} {} 0 radius 0.4\n", i % 10 - 5, i / 10)))
        .collect();
    let mistake = "camera eye 0 1 -6\nsphere raduis 1\n";
    let user = slot::with::scene(image, USER_SCENE).map_err(|e| anyhow::anyhow!("the user's scene: {e}"))?;
    // The user's file with the first byte of its scene changed after it was written: the
    // slot's first block carries the header, then the text.
    let mut corrupt = user.clone();
    let first_slot_block = corrupt.len() / slot::uf2::BLOCK - slot::uf2::slot_blocks(USER_SCENE.as_bytes());
    corrupt[first_slot_block * slot::uf2::BLOCK + 32 + slot::HEADER] ^= 0x20;
    let (stored, mut damaged) = (slot::checksum(USER_SCENE.as_bytes()), USER_SCENE.as_bytes().to_vec());
    damaged[0] ^= 0x20;
    Ok([
        Case {
            name: "user",
            what: "a scene of the user's (`host-sim uf2 --scene`)",
            uf2: user.clone(),
            expect: Expect::Frame(USER_SCENE),
        },
        Case {
            name: "turned",
            what: "the user's scene, the camera-turn button (GP15) pressed after its first frame",
            uf2: user,
            expect: Expect::Turned(USER_SCENE),
        },
        Case {
            name: "empty",
            what: "the slot image alone (nothing in its slot)",
            uf2: image.to_vec(),
            expect: Expect::Message(SlotError::Empty.to_string()),
        },
        Case {
            name: "corrupt",
            what: "the user's file with a byte of its scene changed",
            uf2: corrupt,
            expect: Expect::Message(SlotError::Corrupt { stored, computed: slot::checksum(&damaged) }.to_string()),
        },
        Case {
            name: "too-big",
            what: "70 spheres (room for 64), written past the host's check",
            uf2: slot::with::unchecked(image, &too_big).map_err(anyhow::Error::msg)?,
            expect: Expect::Message(refused(&too_big)),
        },
        Case {
            name: "mistake",
            what: "a misspelt attribute, written past the host's check",
            uf2: slot::with::unchecked(image, mistake).map_err(anyhow::Error::msg)?,
            expect: Expect::Message(refused(mistake)),
        },
    ])
}

impl Session<'_> {
    /// Builds the slot image (unless `no_build`), writes each case's UF2 file and runs it for
    /// one frame, checking the panel and the log.
    pub(super) fn slot_runs(&mut self) -> Result<Vec<SlotRow>> {
        let elf =
            if self.no_build { kept_image(self.root, "pico-slot") } else { build_pico_with(self.root, "slot", true)? };
        let dir = self.frames_dir.join("slot");
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let base = dir.join("lattice-rt-pico-slot.uf2");
        write_uf2(&elf, &base)?;
        let image = std::fs::read(&base).with_context(|| format!("cannot read {}", base.display()))?;
        let cases = cases(&image)?;
        let mut rows = Vec::new();
        // When the user's frame ended: the turned case presses its button in the pause after.
        let mut first_end_ms = None;
        for case in cases {
            let (row, end_ms) = self.slot_case(&elf, &dir, case, first_end_ms)?;
            first_end_ms = first_end_ms.or(end_ms);
            rows.push(row);
        }
        Ok(rows)
    }

    /// Runs one case's UF2 file for a frame (or the attempt and the message, or the frame and
    /// the turned frame, its button pressed [`PRESS_AFTER_MS`] after `first_end_ms`) and checks
    /// the panel and the log; its row, and when its first panel ended.
    fn slot_case(
        &mut self,
        elf: &Path,
        dir: &Path,
        case: Case,
        first_end_ms: Option<f64>,
    ) -> Result<(SlotRow, Option<f64>)> {
        let case_dir = dir.join(case.name);
        std::fs::create_dir_all(&case_dir).with_context(|| format!("cannot create {}", case_dir.display()))?;
        let file = case_dir.join(format!("lattice-rt-pico-slot-{}.uf2", case.name));
        host_sim::output::write_atomic(&file, &case.uf2)?;
        eprintln!("running the slot image: {} ({})", case.name, case.what);
        // A scene the board refuses lights the LED for its attempt (a blank "frame" to the
        // runner) before the message: two LED cycles, the message the last.
        let frames = if matches!(case.expect, Expect::Frame(_)) { 1 } else { 2 };
        let press_ms = first_end_ms.unwrap_or(0.0) + PRESS_AFTER_MS;
        let press = format!("{press_ms:.3}");
        let args: &[&str] = if matches!(case.expect, Expect::Turned(_)) { &["--press-turn", &press] } else { &[] };
        let run = run_emulator(self.root, elf, &file, &self.bootrom, frames, true, &case_dir, args)?;
        let frame = board_records::frame::rendered(board_records::frame::PICO);
        let (want, shown) = match &case.expect {
            Expect::Frame(text) => (
                host_sim::run::render_text::<Fx>(Path::new("slot"), text, &frame, |_| {})?.bits,
                "the scene's frame".to_string(),
            ),
            Expect::Turned(text) => {
                let turn = 1.0 / f64::from(TURN_STEPS);
                (
                    host_sim::orbit::turned_frame::<Fx>(Path::new("slot"), text, turn, &frame)?,
                    format!("the scene's frame, the camera turned 1/{TURN_STEPS} of a circle"),
                )
            }
            Expect::Message(m) => (message_frame(&cut(m)), format!("\"{}\"", cut(m))),
        };
        if matches!(case.expect, Expect::Turned(_)) {
            self.checks.check(first_end_ms.is_some(), || "slot turned: the user's frame did not end".into());
            self.check_response("slot turned", press_ms, &run);
        }
        let frame = run.frames.last();
        let same = frame.is_some_and(|f| f.pixels == want);
        if let Some(f) = frame {
            save_frame(&f.pixels, &case_dir.join("panel.png"))?;
        }
        let name = case.name;
        self.checks.check(run.ok && run.frames.len() == frames, || {
            format!("slot {name}: the board showed {} of {frames} panels ({})", run.frames.len(), run.reason)
        });
        self.checks
            .check(same, || format!("slot {name}: the panel is not {shown} (see {}/panel.png)", case_dir.display()));
        let errors: Vec<&str> = run.log.iter().filter(|l| l.level == "ERROR").map(|l| l.text.as_str()).collect();
        match &case.expect {
            Expect::Frame(_) | Expect::Turned(_) => {
                self.checks.check(errors.is_empty(), || format!("slot {name}: the device logged errors: {errors:?}"))
            }
            Expect::Message(m) => self.checks.check(errors.iter().any(|e| e.contains(&cut(m))), || {
                format!("slot {name}: the log does not say `{m}`: {errors:?}")
            }),
        };
        let first_end_ms = run.frames.first().map(|f| f.end_ms);
        Ok((SlotRow { name, what: case.what, shown, cycles: frame.map(|f| f.cycles), same }, first_end_ms))
    }
}

/// The report's section on the scene slot.
pub(super) fn slot_report(rows: &[SlotRow]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## The scene slot: a user's scene with no toolchain\n")?;
    writeln!(
        md,
        "The `slot` image (`host-sim uf2 --features slot`, built once) holds no scene: it reads scene text from the slot at 1 MiB into the flash (`board_records::slot`: a magic, the length, a CRC-32, the text), parses it on the board and shows it. `host-sim uf2 --scene FILE` (and the playground's page) writes a scene beside the prebuilt image, checking it first as the Pico will read it; nothing is compiled. The image keeps its code in flash (the parser, the lattice builder and every effect would leave too little SRAM for the scene's room of {} objects). Each case below is one UF2 file run on the emulated Pico, its panel compared bit for bit with what the host draws (the frame, or the message in `board_records::message`'s font), and its log read for the message.\n",
        slot::ROOM.objects
    )?;
    writeln!(
        md,
        "| case | UF2 file | the panel shows | cycles to the panel | bit-identical |\n|---|---|---|---:|---|"
    )?;
    for r in rows {
        let cycles = r.cycles.map_or("-".into(), |c| format!("{:.1} M", c as f64 / 1e6));
        writeln!(
            md,
            "| {} | {} | {} | {cycles} | {} |",
            r.name,
            r.what,
            r.shown.replace('|', "\\|"),
            if r.same { "yes" } else { "**no**" }
        )?;
    }
    writeln!(md, "\nCycles are those of the panel checked: for the scene, from the LED going on to its going out (the scene parsed, its lattice built, the frame traced and sent); for a message, its drawing and sending (a refused scene's attempt comes first, then the message; the empty and corrupt slots show theirs at once, again every 3 s). The turned case presses the camera-turn button (GP15 to ground, `Wiring::TURN`; `run.mjs --press-turn`) {PRESS_AFTER_MS:.0} ms into the pause after the user's first frame: the next frame must start within {RESPONSE_MS:.0} ms and show the scene from 1/{TURN_STEPS} of a circle further round (`host-sim orbit` draws the same frame as its frame {} of {}); each press turns it a step further, and the next-scene button brings back the scene's own camera.", ORBIT_FRAMES / TURN_STEPS, ORBIT_FRAMES)?;
    Ok(md)
}
