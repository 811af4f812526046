//! A packed 1-bit frame over caller storage, as an `embedded_graphics` draw target.
//!
//! Rows are packed MSB first and padded to whole bytes, which is exactly the raster of a
//! binary PBM (`P4`) file, so tests, host-sim and the emulated firmware can all emit the same
//! bytes. The renderer never needs it; it is one possible [`DrawTarget`].

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::Pixel;

/// A 1-bit frame; `On` pixels are stored as 1 (PBM black).
#[derive(Debug)]
pub struct BitFrame<'b> {
    width: u32,
    height: u32,
    bits: &'b mut [u8],
}

impl<'b> BitFrame<'b> {
    /// Bytes needed for a `width x height` frame.
    pub const fn bytes(width: u32, height: u32) -> usize {
        (width as usize).div_ceil(8) * height as usize
    }
    /// A cleared frame over `bits`, or `None` if `bits` is shorter than [`BitFrame::bytes`].
    pub fn new(width: u32, height: u32, bits: &'b mut [u8]) -> Option<Self> {
        let bits = bits.get_mut(..Self::bytes(width, height))?;
        bits.iter_mut().for_each(|b| *b = 0);
        Some(BitFrame { width, height, bits })
    }
    /// The packed rows (the raster of a `P4` PBM).
    pub fn raster(&self) -> &[u8] {
        self.bits
    }
    /// Whether the pixel at `(x, y)` is on.
    pub fn get(&self, x: u32, y: u32) -> bool {
        let stride = (self.width as usize).div_ceil(8);
        self.bits[y as usize * stride + x as usize / 8] & (0x80 >> (x % 8)) != 0
    }
}

impl OriginDimensions for BitFrame<'_> {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for BitFrame<'_> {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        let stride = (self.width as usize).div_ceil(8);
        for Pixel(p, c) in pixels {
            if p.x < 0 || p.y < 0 || p.x as u32 >= self.width || p.y as u32 >= self.height {
                continue;
            }
            let (i, m) = (p.y as usize * stride + p.x as usize / 8, 0x80u8 >> (p.x % 8));
            if c.is_on() {
                self.bits[i] |= m;
            } else {
                self.bits[i] &= !m;
            }
        }
        Ok(())
    }
}
