//! The frame every board renders: the firmware renders it, its `build.rs` sizes the storage
//! for it, and the host renders it to check the board's frames bit for bit.

use lattice_rt::render::Sampling;
use lattice_rt::{Dither, EyeRays, Frame, Tone};

/// Display width (SSD1306 128x64).
pub const WIDTH: u16 = 128;
/// Display height.
pub const HEIGHT: u16 = 64;

/// How the boards spend eye rays: adaptive sub-sampling (every second pixel traced, the rest
/// filled where the traced pixels around agree to 4 levels of 64; its error is in
/// docs/accuracy.md). The firmware's `exact-sampling` feature traces one ray per pixel instead
/// (`app::RENDERED`).
pub const SAMPLING: Sampling = Sampling::Adaptive { contrast: 4 };

/// The frame every board renders: 128x64, 8x8 tiles (one SSD1306 page high), blue-noise
/// ordered dither: of the dithers whose tiles the two cores can share out, the one that scores
/// best in `cargo xtask display` (docs/display.md; error diffusion scores higher but carries error
/// from tile to tile, so one core would have to render every tile). No silhouette lines: they
/// cost about a fifth more cycles (the firmware's `outline` feature draws them).
pub const FRAME: Frame = Frame {
    width: WIDTH,
    height: HEIGHT,
    tile: 8,
    dither: Dither::BlueNoise,
    sampling: SAMPLING,
    rows: (0, u16::MAX),
    tone: Tone::LINEAR,
    outline: false,
};

/// Frames per turn of the camera in orbit mode (the firmware's `orbit` feature, `host-sim orbit`).
pub const ORBIT_FRAMES: u32 = 36;

/// How a frame is traced: the real-time levers that can be switched at run time, so one image
/// measures them one by one (the `ladder` feature) with every frame still checked against
/// host-sim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tuning {
    /// How eye rays find their hit (`None`: the scene's default, `EyeRays::for_scene`).
    pub eye_rays: Option<EyeRays>,
    /// Shadow rays try the object that last hid their light first.
    pub shadow_coherence: bool,
    /// Eye rays per pixel.
    pub sampling: Sampling,
}

/// What the boards run: every lever on.
pub const TUNING: Tuning = Tuning { eye_rays: None, shadow_coherence: true, sampling: SAMPLING };

/// The ladder of the real-time work, from the paper's method to what the boards run, one lever
/// added per rung (docs/board.md, written by `cargo xtask board` from the `ladder` image).
pub const LADDER: [(&str, Tuning); 5] = [
    ("the paper's nested lattice, one ray per pixel", Tuning { eye_rays: Some(EyeRays::Plain), shadow_coherence: false, sampling: Sampling::Center }),
    ("+ shadow rays try the last occluder first", Tuning { eye_rays: Some(EyeRays::Plain), shadow_coherence: true, sampling: Sampling::Center }),
    ("+ eye windows: the walk skips objects whose window misses the eye ray", Tuning { eye_rays: Some(EyeRays::Accelerator), shadow_coherence: true, sampling: Sampling::Center }),
    ("+ eye rays and first-light shadow rays by windows alone, no walk", Tuning { eye_rays: Some(EyeRays::Windows), shadow_coherence: true, sampling: Sampling::Center }),
    ("+ adaptive sub-sampling (the boards' default)", TUNING),
];

/// Tile shares a frame is rendered in (`Share`): one per RP2040 core. Where only one core runs
/// (the emulator), core 0 renders both, one after the other, and logs each share's time.
pub const SHARES: u8 = 2;
