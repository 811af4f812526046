//! The frame every board renders (also read by `build.rs`, which sizes the storage for it).

use lattice_rt::render::Sampling;
use lattice_rt::{Dither, Frame};

/// Display width (SSD1306 128x64).
pub const WIDTH: u16 = 128;
/// Display height.
pub const HEIGHT: u16 = 64;

/// The frame every board renders: 128x64, 8x8 tiles (one SSD1306 page high), Bayer dither.
pub const FRAME: Frame = Frame {
    width: WIDTH,
    height: HEIGHT,
    tile: 8,
    dither: Dither::Bayer,
    sampling: Sampling::Center,
    rows: (0, u16::MAX),
};
