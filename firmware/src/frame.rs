//! The frame every board renders (also read by `build.rs`, which sizes the storage for it).

use lattice_rt::render::Sampling;
use lattice_rt::{Dither, Frame};

/// Display width (SSD1306 128x64).
pub const WIDTH: u16 = 128;
/// Display height.
pub const HEIGHT: u16 = 64;

/// How the boards spend eye rays: adaptive sub-sampling (every second pixel traced, the rest
/// filled where the traced pixels around agree to 4 levels of 64; its error is in
/// docs/accuracy.md). The firmware's `exact-sampling` feature traces one ray per pixel instead
/// (`app::RENDERED`).
pub const SAMPLING: Sampling = Sampling::Adaptive { contrast: 4 };

/// The frame every board renders: 128x64, 8x8 tiles (one SSD1306 page high), Bayer dither.
pub const FRAME: Frame = Frame {
    width: WIDTH,
    height: HEIGHT,
    tile: 8,
    dither: Dither::Bayer,
    sampling: SAMPLING,
    rows: (0, u16::MAX),
};

/// Frames per turn of the camera in orbit mode (the firmware's `orbit` feature, `host-sim orbit`).
pub const ORBIT_FRAMES: u32 = 36;
