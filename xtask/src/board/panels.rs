//! The panels beside the SSD1306: each image built for its controller (the firmware's `sh1106`
//! or `ssd1309` feature) runs with the emulated controller in place of the SSD1306 (run.mjs
//! `--panel`), on I2C at 1 MHz and on SPI, and every scene's frame must be bit-identical to
//! host-sim's. The models follow their datasheets (firmware/board/sh1106.mjs, ssd1309.mjs):
//! a command the controller does not have fails the run.

use super::{host_frame, m, save_frame, Session, PICO, PICO_SCALAR};
use anyhow::Result;
use std::fmt::Write as _;

/// The images checked: their features, the emulated controller, what the module is.
const PANELS: [(&str, &str, &str); 4] = [
    ("sh1106,i2c-1mhz", "sh1106", "SH1106 (1.3\" 128x64), I2C at 1 MHz"),
    ("sh1106,spi", "sh1106", "SH1106 (1.3\" 128x64), SPI at 10 MHz"),
    ("ssd1309,i2c-1mhz", "ssd1309", "SSD1309 (2.42\" 128x64), I2C at 1 MHz"),
    ("ssd1309,spi", "ssd1309", "SSD1309 (2.42\" 128x64), SPI at 10 MHz"),
];

/// What one panel's run did, for the report.
pub(super) struct PanelRow {
    what: &'static str,
    features: &'static str,
    /// Frames bit-identical to host-sim's, of the scenes run.
    same: usize,
    scenes: usize,
    /// The first scene's frame: cycles, and bytes on the bus.
    first: Option<(u64, u64)>,
}

impl Session<'_> {
    /// Every panel's image on every embedded scene.
    pub(super) fn panel_runs(&mut self) -> Result<Vec<PanelRow>> {
        let mut rows = Vec::new();
        for (features, panel, what) in PANELS {
            let (run, dir) = self.variant(features, true, self.scenes.len(), &["--panel", panel])?;
            self.checks.check(run.ok, || format!("{what}: the run did not finish: {}", run.reason));
            let mut same = 0;
            for (name, frame) in self.scenes.clone().iter().zip(&run.frames) {
                let want = host_frame(&self.scenes_dir, name, PICO_SCALAR, PICO)?;
                save_frame(&frame.pixels, &dir.join(format!("{name}.png")))?;
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
            rows.push(PanelRow { what, features, same, scenes: self.scenes.len(), first });
        }
        Ok(rows)
    }
}

/// The report's section on the panels.
pub(super) fn panel_report(rows: &[PanelRow], first: &str, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## Other panels: SH1106 and SSD1309\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: each image is built for its panel's controller (`cargo pico-build --features ...`) and runs on the emulated board with that controller on the bus in place of the SSD1306 (`run.mjs --panel`), every scene's frame checked against host-sim's. The SH1106 model (firmware/board/sh1106.mjs) has the SH1106's 132 columns of RAM, page addressing only and the glass on columns 2 to 129; the SSD1309 model (ssd1309.mjs) has no charge pump command and a command lock; a command either controller does not have fails the run. The firmware sends each controller its own set-up and addresses the SH1106 page by page (`firmware/src/bin/pico/display/controller.rs`).\n"
    )?;
    writeln!(md, "| panel and bus | features | frames bit-identical to host-sim | {first}: cycles | fps at 125 MHz | bytes on the bus |")?;
    writeln!(md, "|---|---|---:|---:|---:|---:|")?;
    for r in rows {
        let (cycles, fps, bytes) = r.first.map_or(("-".into(), "-".into(), "-".into()), |(c, b)| {
            (m(c), format!("{:.2}", clk_hz / c as f64), b.to_string())
        });
        writeln!(md, "| {} | `{}` | {} of {} | {cycles} | {fps} | {bytes} |", r.what, r.features, r.same, r.scenes)?;
    }
    Ok(md)
}
