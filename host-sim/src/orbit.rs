//! `host-sim orbit`: the camera circles a scene and the 1-bit frames, as the display shows
//! them, become an animated GIF.

use crate::load::{build_lattice, lattice_storage, object_storage, read};
use crate::output::write_atomic;
use crate::progress;
use anyhow::{anyhow, bail, Context, Result};
use board_records::frame as board_frame;
use lattice_rt::scene::{parse_with, CameraDesc};
use lattice_rt::{BitFrame, Frame, LatticeConfig, Real, Tracer};
use std::borrow::Cow;
use std::path::Path;

/// Frames per second the GIF plays at (the real-time target of the boards).
pub const FPS: u16 = 10;

/// The frames of `frames` evenly spaced turns around the scene in scalar `R`, rendered with
/// `frame` (1-bit packed rows as `bits`, gray levels as `gray`); frame 0 is the scene's own
/// camera.
pub fn orbit_renders<R: Real>(
    path: &Path,
    text: &str,
    frames: u32,
    frame: &Frame,
) -> Result<Vec<crate::run::Rendered>> {
    let mut storage = object_storage::<R>(text)?;
    let bar = progress::bar(frames as usize, "orbit frames");
    let mut out = Vec::new();
    for i in 0..frames {
        let turn = i as f64 / frames as f64;
        let rendered = render_turned::<R>(text, turn, frame, &mut storage)
            .map_err(|e| anyhow!("{}: frame {i} of the orbit: {e:#}", path.display()))?;
        out.push(rendered);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// The 1-bit frame (packed rows) of the scene at `path` in scalar `R` with its camera turned
/// `turn` of a circle around the point it looks at, as the board's camera-turn button draws it.
pub fn turned_frame<R: Real>(path: &Path, text: &str, turn: f64, frame: &Frame) -> Result<Vec<u8>> {
    let mut storage = object_storage::<R>(text)?;
    let rendered = render_turned::<R>(text, turn, frame, &mut storage)
        .map_err(|e| anyhow!("{}: turned {turn} of a circle: {e:#}", path.display()))?;
    Ok(rendered.bits)
}

/// One frame of the scene `text` with its camera turned `turn` of a circle, parsed into `storage`.
fn render_turned<R: Real>(
    text: &str,
    turn: f64,
    frame: &Frame,
    storage: &mut crate::load::SceneStore<R>,
) -> Result<crate::run::Rendered> {
    // Turned, then fitted to the frame's shape, as the board sets its camera up.
    let fitted = |c: &mut CameraDesc| *c = CameraDesc { frame: frame.size(), ..c.orbit(turn) };
    let scene = parse_with::<R>(text, &mut storage.objects, &mut storage.parts, fitted).map_err(|e| anyhow!("{e}"))?;
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg)?;
    let lattice = build_lattice(&mut bufs, &scene, &cfg)?;
    crate::run::render_band(&Tracer::new(&scene, &lattice), frame, false)
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
            let pixels: Vec<u8> = (0..h as u32)
                .flat_map(|y| (0..w as u32).map(move |x| (x, y)))
                .map(|(x, y)| view.get(x, y) as u8)
                .collect();
            let f = gif::Frame {
                width: w,
                height: h,
                delay: 100 / FPS,
                buffer: Cow::Owned(pixels),
                ..gif::Frame::default()
            };
            enc.write_frame(&f).context("GIF frame")?;
        }
    }
    Ok(bytes)
}

/// `host-sim orbit SCENE -o OUT.gif`: `frames` frames of the Pico's orbit mode (128x64, its
/// sampling, blue noise with silhouette lines) in fixed point, as a Pico shows them.
pub fn orbit_cmd(scene: &Path, out: &Path, frames: u32) -> Result<()> {
    if frames == 0 || frames > 3600 {
        bail!("--frames must be from 1 to 3600");
    }
    let text = read(scene)?;
    let frame = board_frame::rendered(board_frame::Build { orbit: true, ..board_frame::PICO });
    let bits = orbit_frames::<lattice_rt::Fx>(scene, &text, frames, &frame)?;
    write_atomic(out, &gif_bytes(&bits, frame.width, frame.height)?)?;
    crate::say!(
        "wrote {} ({frames} frames at {FPS} fps, {}x{}, as the Pico renders them)",
        out.display(),
        frame.width,
        frame.height
    )?;
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
