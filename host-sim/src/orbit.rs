//! `host-sim orbit`: the camera circles a scene and the 1-bit frames, as the display shows
//! them, become an animated GIF.

use crate::firmware::board_frame;
use crate::load::{build_lattice, lattice_storage, object_storage, read};
use crate::output::write_atomic;
use crate::progress;
use anyhow::{anyhow, bail, Context, Result};
use lattice_rt::scene::text::parse_with;
use lattice_rt::{BitFrame, Frame, LatticeConfig, Real, Tracer};
use std::borrow::Cow;
use std::path::Path;

/// Frames per second the GIF plays at (the real-time target of the boards).
pub const FPS: u16 = 10;

/// The frames of `frames` evenly spaced turns around the scene in scalar `R`, rendered with
/// `frame` (1-bit packed rows as `bits`, gray levels as `gray`); frame 0 is the scene's own
/// camera.
pub fn orbit_renders<R: Real>(path: &Path, text: &str, frames: u32, frame: &Frame) -> Result<Vec<crate::run::Rendered>> {
    let mut storage = object_storage::<R>(text)?;
    let bar = progress::bar(frames as usize, "orbit frames");
    let mut out = Vec::new();
    for i in 0..frames {
        let turn = i as f64 / frames as f64;
        let scene = parse_with::<R>(text, &mut storage, |c| *c = c.orbit(turn))
            .map_err(|e| anyhow!("{}: frame {i} of the orbit: {e}", path.display()))?;
        let cfg = LatticeConfig::default();
        let mut bufs = lattice_storage(&scene, &cfg)?;
        let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
        out.push(crate::run::render_band(&Tracer::new(&scene, &lattice), frame, false)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// The 1-bit frames (packed rows, see `BitFrame`) of [`orbit_renders`].
pub fn orbit_frames<R: Real>(path: &Path, text: &str, frames: u32, frame: &Frame) -> Result<Vec<Vec<u8>>> {
    Ok(orbit_renders::<R>(path, text, frames, frame)?.into_iter().map(|r| r.bits).collect())
}

/// The GIF of packed 1-bit frames `w x h`: lit pixels white on black, looping, at [`FPS`].
pub fn gif_bytes(frames: &[Vec<u8>], w: u16, h: u16) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut bytes, w, h, &[0, 0, 0, 255, 255, 255]).context("GIF encoder")?;
        enc.set_repeat(gif::Repeat::Infinite).context("GIF encoder")?;
        for bits in frames {
            let mut raster = bits.clone();
            let view = BitFrame::wrap(w as u32, h as u32, &mut raster).context("frame size")?;
            let pixels: Vec<u8> = (0..h as u32).flat_map(|y| (0..w as u32).map(move |x| (x, y))).map(|(x, y)| view.get(x, y) as u8).collect();
            let f = gif::Frame { width: w, height: h, delay: 100 / FPS, buffer: Cow::Owned(pixels), ..gif::Frame::default() };
            enc.write_frame(&f).context("GIF frame")?;
        }
    }
    Ok(bytes)
}

/// `host-sim orbit SCENE -o OUT.gif`: `frames` frames of the boards' frame (128x64, their
/// sampling and dither) in fixed point, as a Pico shows them.
pub fn orbit_cmd(scene: &Path, out: &Path, frames: u32) -> Result<()> {
    if frames == 0 || frames > 3600 {
        bail!("--frames must be from 1 to 3600");
    }
    let text = read(scene)?;
    let frame = board_frame::FRAME;
    let bits = orbit_frames::<lattice_rt::Fx>(scene, &text, frames, &frame)?;
    write_atomic(out, &gif_bytes(&bits, frame.width, frame.height)?)?;
    println!("wrote {} ({frames} frames at {FPS} fps, {}x{}, as the Pico renders them)", out.display(), frame.width, frame.height);
    Ok(())
}

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
pub fn flicker(renders: &[crate::run::Rendered]) -> Flicker {
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

/// `host-sim motion`: flicker of every dither along each scene's orbit, as docs/motion.md.
pub fn motion_cmd(scenes: &[std::path::PathBuf], frames: u32, out: &Path) -> Result<()> {
    use lattice_rt::Dither;
    use std::fmt::Write as _;
    if !(2..=3600).contains(&frames) {
        bail!("--frames must be from 2 to 3600");
    }
    let dithers = [("bayer", Dither::Bayer), ("blue noise", Dither::BlueNoise), ("pattern 4x4", Dither::Pattern(4)), ("floyd-steinberg", Dither::FloydSteinberg), ("atkinson", Dither::Atkinson)];
    let mut md = String::new();
    writeln!(md, "# Dithers in motion\n")?;
    writeln!(md, "Written by `cargo run --release -p host-sim -- motion` ({frames} frames per turn of the orbit that")?;
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
            writeln!(md, "| {name} | {label} | {:.2} % | {:.2} | {:.2} % |", 100.0 * f.flipped, f.gray_change, 100.0 * ratio)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_orbit_frame_is_the_scene_and_the_gif_holds_every_frame() {
        let path = std::path::PathBuf::from(format!("{}/../scenes/chair.scene", env!("CARGO_MANIFEST_DIR")));
        let text = read(&path).unwrap();
        let frame = Frame::new(64, 32);
        let frames = orbit_frames::<f64>(&path, &text, 4, &frame).unwrap();
        let still = crate::run::render_text::<f64>(&path, &text, &frame, |_| {}).unwrap();
        assert_eq!(frames[0], still.bits, "turn 0 is the scene's own camera");
        assert!(frames.windows(2).all(|w| w[0] != w[1]), "the camera moves");
        let bytes = gif_bytes(&frames, 64, 32).unwrap();
        let mut dec = gif::DecodeOptions::new().read_info(&bytes[..]).unwrap();
        let mut n = 0;
        while let Some(f) = dec.read_next_frame().unwrap() {
            assert_eq!((f.width, f.height, f.delay), (64, 32, 100 / FPS));
            n += 1;
        }
        assert_eq!(n, 4);
    }
}
