//! The panels beside the SSD1306 128x64: each image built for its panel (the firmware's
//! `sh1106`, `ssd1309`, `ssd1306-128x32` or `ssd1306-72x40` feature) runs with that panel emulated in
//! place of the SSD1306 (run.mjs `--panel`), on I2C at 1 MHz and on SPI, and every scene's
//! frame must be bit-identical to host-sim's at the glass's size. The models follow their
//! datasheets (firmware/board/sh1106.mjs, ssd1309.mjs, ssd1306.mjs's glasses): a command the
//! controller does not have fails the run.

use super::button::{ButtonRow, Buttons, Pressed};
use super::{host_frame, m3, run_variant_image, save_frame_sized, variant_uf2, BoardRun, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use board_records::frame::{Build, Panel};
use std::fmt::Write as _;

/// An image checked: its panel (whose feature, glass and emulated model it takes), the bus
/// feature it adds (`i2c-1mhz`, `spi`; none: the panel's own default) and what the module is.
type Image = (Panel, Option<&'static str>, &'static str);

/// The images checked.
const PANELS: [Image; 10] = [
    (Panel::Sh1106, Some("i2c-1mhz"), "SH1106 (1.3\" 128x64), I2C at 1 MHz"),
    (Panel::Sh1106, Some("spi"), "SH1106 (1.3\" 128x64), SPI at 10 MHz"),
    (Panel::Ssd1309, Some("i2c-1mhz"), "SSD1309 (2.42\" 128x64), I2C at 1 MHz"),
    (Panel::Ssd1309, Some("spi"), "SSD1309 (2.42\" 128x64), SPI at 10 MHz"),
    (Panel::Ssd1306x32, None, "SSD1306 (0.91\" 128x32), I2C at 400 kHz"),
    (Panel::Ssd1306x40, Some("spi"), "SSD1306 (0.42\" 72x40, the Thumby's), SPI at 10 MHz"),
    (Panel::Sharp400x240, None, "Sharp memory LCD LS027B7DH01 (2.7\" 400x240), SPI at 2 MHz"),
    (Panel::Sharp128x128, None, "Sharp memory LCD LS013B7DH03 (1.28\" 128x128), SPI at 1 MHz"),
    (Panel::Uc8151, None, "UC8151 e-paper (2.9\" 296x128, the Badger 2040's), SPI at 10 MHz"),
    (Panel::Thumby, None, "the Thumby's SSD1306 (0.42\" 72x40; CS GP16, DC GP17, RES GP20), SPI at 10 MHz"),
];

/// An image's firmware features: its panel's, then its bus's.
fn features((panel, bus, _): Image) -> String {
    panel.feature().into_iter().chain(bus).collect::<Vec<_>>().join(",")
}

/// What one panel's run did, for the report.
pub(super) struct PanelRow {
    panel: Panel,
    what: &'static str,
    features: String,
    /// Frames bit-identical to host-sim's, of the scenes run.
    same: usize,
    scenes: usize,
    /// The first scene's frame: cycles, and bytes on the bus.
    first: Option<(u64, u64)>,
    /// The glass's width and height.
    size: (u16, u16),
    /// The first scene's frame as the panel showed it.
    picture: Vec<u8>,
}

impl PanelRow {
    /// The file its picture is saved as, in docs/images.
    fn picture_name(&self) -> String {
        format!("board-panel-{}.png", self.features.replace(',', "-"))
    }
}

/// Saves each panel's first frame into `images` (docs/images), as the report shows them.
pub(super) fn save_pictures(rows: &[PanelRow], images: &std::path::Path) -> Result<()> {
    for r in rows {
        let (w, h) = r.size;
        save_frame_sized(&r.picture, (u32::from(w), u32::from(h)), &images.join(r.picture_name()))?;
    }
    Ok(())
}

impl Session<'_> {
    /// Every panel's image on every embedded scene; with the e-paper's run, for its refreshes,
    /// and the boards' buttons pressed: the Thumby's A on its image, its B on `thumby,parse`,
    /// the Badger's camera-turn button on `uc8151,parse,code-in-flash`.
    pub(super) fn panel_runs(&mut self) -> Result<(Vec<PanelRow>, Option<BoardRun>, Vec<ButtonRow>)> {
        let (mut rows, mut epaper, mut pressed) = (Vec::new(), None, Vec::new());
        for image in PANELS {
            let (panel, _, what) = image;
            let (features, glass) = (features(image), panel.glass());
            let build = Build { glass, ..PICO };
            let (w, h) = glass.size();
            let (run, dir) = self.variant(&features, true, self.scenes.len(), &["--panel", panel.name()])?;
            self.checks.check(run.ok, || format!("{what}: the run did not finish: {}", run.reason));
            let mut same = 0;
            for (name, frame) in self.scenes.clone().iter().zip(&run.frames) {
                let want = host_frame(&self.scenes_dir, name, PICO_SCALAR, build)?;
                save_frame_sized(&frame.pixels, (u32::from(w), u32::from(h)), &dir.join(format!("{name}.png")))?;
                let ok = frame.error.is_none() && frame.pixels == want;
                same += usize::from(ok);
                self.checks.check(ok, || {
                    let why = frame.error.clone().unwrap_or_else(|| "it differs from host-sim's".into());
                    format!("{what}: {name}: {why} (see {}/{name}.png)", dir.display())
                });
            }
            self.checks.check(run.frames.len() == self.scenes.len(), || {
                format!("{what}: {} frames shown of {}", run.frames.len(), self.scenes.len())
            });
            let first = run.frames.first().map(|f| (f.cycles, f.bus_bytes));
            let picture = run.frames.first().map(|f| f.pixels.clone()).unwrap_or_default();
            rows.push(PanelRow {
                panel,
                what,
                features: features.clone(),
                same,
                scenes: self.scenes.len(),
                first,
                size: (w, h),
                picture,
            });
            if panel == Panel::Thumby {
                if let Some(first) = run.frames.first() {
                    let (elf, uf2) = (run_variant_image(self.root, &features), dir.join(variant_uf2(&features)));
                    let extra = ["--panel", panel.name()];
                    let image = Pressed {
                        elf: &elf,
                        uf2: &uf2,
                        build,
                        extra: &extra,
                        press: Buttons::Next,
                        what: "the Thumby's A (GP27)",
                    };
                    pressed.push(self.press_run(&image, first.end_ms, "thumby-button")?);
                    pressed.extend(self.turn_run(
                        panel,
                        "thumby,parse",
                        build,
                        "the Thumby's B (GP24), `thumby,parse`",
                    )?);
                }
            }
            if panel == Panel::Uc8151 {
                epaper = Some(run);
                let what = "the Badger's up button (GP15), `uc8151,parse,code-in-flash`";
                pressed.extend(self.turn_run(panel, "uc8151,parse,code-in-flash", build, what)?);
            }
        }
        Ok((rows, epaper, pressed))
    }

    /// A board's image that sets its scenes up on the board (`features`: the Thumby's
    /// `thumby,parse`, the Badger's `uc8151,parse,code-in-flash`), its camera-turn button
    /// pressed after the first frame: that scene again, turned a step.
    fn turn_run(
        &mut self,
        panel: Panel,
        features: &str,
        build: Build,
        what: &'static str,
    ) -> Result<Option<ButtonRow>> {
        let name = format!("{}-turn", panel.name());
        self.variant_press_run(features, &["--panel", panel.name()], build, (Buttons::Turn, what), &name)
    }
}

/// The report's section on the panels.
pub(super) fn panel_report(rows: &[PanelRow], first: &str, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## Other panels: SH1106, SSD1309, 128x32, 72x40, the Thumby's, Sharp memory LCDs and e-paper\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: each image is built for its panel's controller (`cargo pico-build --features ...`) and runs on the emulated board with that controller on the bus in place of the SSD1306 (`run.mjs --panel`), every scene's frame checked against host-sim's. The SH1106 model (firmware/board/sh1106.mjs) has the SH1106's 132 columns of RAM, page addressing only and the glass on columns 2 to 129; the SSD1309 model (ssd1309.mjs) has no charge pump command and a command lock; the smaller SSD1306 modules show part of the controller's RAM (128x32: 32 multiplexed rows, COM pins in sequence; 72x40: columns 28 to 99 and 40 rows) and the frame is traced at the glass's size. The Thumby's image drives the same 72x40 SSD1306 on the Thumby's own pins (CS GP16, DC GP17, RES GP20), its A button (GP27) the next-scene button (*The button* above). The Sharp memory LCD model (sharp.mjs) takes line writes with its chip select active high, the mode and addresses LSB first, a dummy byte after each line and one after the last, holds noise after power-on until cleared or written, and fails the run when VCOM is left uninverted for more than a second. A command a controller does not have fails the run. The firmware sends each controller its own set-up and addresses the SH1106 page by page (`firmware/src/bin/pico/display/controller.rs`); it gathers a band of tiles for the Sharp LCD and sends its lines by DMA while the cores trace on (`display/sharp.rs`), and on frames of more than 32 tiles keeps three bands of tiles between trace and dither, not the whole frame (a 400x240 frame: 75 of 375 tiles). Target for the Sharp LCD at 400x240: the {first} in at most 62.5 M cycles (2 frames per second).\n"
    )?;
    writeln!(md, "| panel and bus | features | pixels | frames bit-identical to host-sim | {first}: cycles | fps at 125 MHz | bytes on the bus |")?;
    writeln!(md, "|---|---|---|---:|---:|---:|---:|")?;
    for r in rows {
        let (cycles, mut fps, bytes) = r.first.map_or(("-".into(), "-".into(), "-".into()), |(c, b)| {
            (m3(c), format!("{:.2}", clk_hz / c as f64), b.to_string())
        });
        // The e-paper's rate is the trace's: the panel changes its picture at most once a
        // refresh, whose length the e-paper section gives.
        if r.panel == Panel::Uc8151 && r.first.is_some() {
            fps.push_str(" traced; shown at most one per refresh (*E-paper* below)");
        }
        let (w, h) = r.size;
        writeln!(
            md,
            "| {} | `{}` | {w}x{h} | {} of {} | {cycles} | {fps} | {bytes} |",
            r.what, r.features, r.same, r.scenes
        )?;
    }
    writeln!(
        md,
        "\nThe {first} as each panel showed it (its pixels as they are, 4x; the Sharp LCD's white pixels drawn lit):\n"
    )?;
    for r in rows {
        writeln!(md, "![{}](images/{})", r.what.replace('"', "''"), r.picture_name())?;
    }
    Ok(md)
}
