//! `cargo xtask motion`: how each dither flickers while the camera orbits the scenes
//! (docs/motion.md).

use anyhow::{bail, Result};
use board_records::frame as board_frame;
use host_sim::load::read;
use host_sim::orbit::orbit_renders;
use host_sim::output::write_atomic;
use lattice_rt::Frame;
use std::path::Path;

/// Flicker of one dither in motion: between consecutive frames of an orbit, the share of
/// display pixels that change and the mean gray change (of 64 levels) that caused it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Flicker {
    /// Mean share of the 1-bit pixels that change from one frame to the next.
    pub flipped: f64,
    /// Mean absolute change of a pixel's gray level (0..=64) from one frame to the next.
    pub gray_change: f64,
}

/// [`Flicker`] over consecutive frames.
pub fn flicker(renders: &[host_sim::run::Rendered]) -> Flicker {
    let pairs = renders.windows(2).count().max(1) as f64;
    let mut f = Flicker::default();
    for w in renders.windows(2) {
        let bits: u32 = w[0].bits.iter().zip(&w[1].bits).map(|(a, b)| (a ^ b).count_ones()).sum();
        let px = w[0].gray.len().max(1) as f64;
        f.flipped += bits as f64 / px / pairs;
        f.gray_change += w[0].gray.iter().zip(&w[1].gray).map(|(a, b)| a.abs_diff(*b) as f64).sum::<f64>() / px / pairs;
    }
    f
}

/// `cargo xtask motion`: flicker of every dither along each scene's orbit, as docs/motion.md.
pub fn motion_cmd(scenes: &[std::path::PathBuf], frames: u32, out: &Path) -> Result<()> {
    use lattice_rt::Dither;
    use std::fmt::Write as _;
    if !(2..=3600).contains(&frames) {
        bail!("--frames must be from 2 to 3600");
    }
    let dithers = [
        ("bayer", Dither::Bayer),
        ("blue noise", Dither::BlueNoise),
        ("pattern 4x4", Dither::Pattern(4)),
        ("floyd-steinberg", Dither::FloydSteinberg),
        ("atkinson", Dither::Atkinson),
    ];
    let mut md = String::new();
    writeln!(md, "# Dithers in motion\n")?;
    writeln!(md, "Written by `cargo xtask motion` ({frames} frames per turn of the orbit that")?;
    writeln!(md, "`host-sim orbit` draws; 128x64, fixed point, the boards' sampling). Between consecutive frames:")?;
    writeln!(md, "the share of display pixels that change (*flipped*), the mean gray change that caused it (levels")?;
    writeln!(md, "of 64), and their ratio, *flicker*: pixels flipped per level of gray change. A dither that")?;
    writeln!(md, "flips many pixels for little change shimmers on the panel while the camera moves.\n")?;
    writeln!(md, "| scene | dither | flipped | gray change | flicker |\n|---|---|---:|---:|---:|")?;
    let mut sums = vec![(0.0, 0.0); dithers.len()];
    for path in scenes {
        let text = read(path)?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        for (i, (label, d)) in dithers.iter().enumerate() {
            let frame = Frame { dither: *d, ..board_frame::FRAME };
            let f = flicker(&orbit_renders::<lattice_rt::Fx>(path, &text, frames, &frame)?);
            let ratio = f.flipped / f.gray_change.max(1e-9);
            writeln!(
                md,
                "| {name} | {label} | {:.2} % | {:.2} | {:.2} % |",
                100.0 * f.flipped,
                f.gray_change,
                100.0 * ratio
            )?;
            sums[i].0 += f.flipped / scenes.len() as f64;
            sums[i].1 += f.gray_change / scenes.len() as f64;
        }
    }
    writeln!(md, "\nMean over the scenes:\n\n| dither | flipped | gray change | flicker |\n|---|---:|---:|---:|")?;
    for ((label, _), (fl, g)) in dithers.iter().zip(&sums) {
        writeln!(md, "| {label} | {:.2} % | {g:.2} | {:.2} % |", 100.0 * fl, 100.0 * fl / g.max(1e-9))?;
    }
    write_atomic(out, md.as_bytes())?;
    println!("wrote {}", out.display());
    Ok(())
}
