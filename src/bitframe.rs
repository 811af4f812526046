//! A packed 1-bit frame over caller storage, as an `embedded_graphics` draw target.
//!
//! Rows are packed MSB first and padded to whole bytes, which is exactly the raster of a
//! binary PBM (`P4`) file, so tests, host-sim and the emulated firmware can all emit the same
//! bytes. The renderer never needs it; it is one possible [`DrawTarget`].

use crate::bounds::{at_mut, span_mut};
use crate::dither::Shade;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::{PointsIter, Rectangle};
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
        let f = Self::wrap(width, height, bits)?;
        f.bits.iter_mut().for_each(|b| *b = 0);
        Some(f)
    }
    /// A frame over a raster that already holds an image (rows packed as [`BitFrame::raster`]
    /// gives them), or `None` if `bits` is shorter than [`BitFrame::bytes`].
    pub fn wrap(width: u32, height: u32, bits: &'b mut [u8]) -> Option<Self> {
        let bits = bits.get_mut(..Self::bytes(width, height))?;
        Some(BitFrame { width, height, bits })
    }
    /// The packed rows (the raster of a `P4` PBM).
    pub fn raster(&self) -> &[u8] {
        self.bits
    }
    /// Emits the frame as a binary PBM (`P4`) in pieces, lit pixels white (PBM 0), without
    /// allocating: the same bytes on the host and over semihosting.
    pub fn write_pbm(&self, mut sink: impl FnMut(&[u8])) {
        let mut head = [0u8; 32];
        let n = pbm_header(self.width, self.height, &mut head);
        sink(&head[..n]);
        for chunk in self.bits.chunks(64) {
            let mut inv = [0u8; 64];
            for (d, s) in inv.iter_mut().zip(chunk) {
                *d = !s;
            }
            sink(&inv[..chunk.len()]);
        }
    }
    /// Whether the pixel at `(x, y)` is on.
    pub fn get(&self, x: u32, y: u32) -> bool {
        let stride = (self.width as usize).div_ceil(8);
        self.bits[y as usize * stride + x as usize / 8] & (0x80 >> (x % 8)) != 0
    }
}

/// Writes `P4\n<w> <h>\n` into `out` and returns its length.
fn pbm_header(w: u32, h: u32, out: &mut [u8; 32]) -> usize {
    let mut n = 0;
    let mut put = |b: u8| {
        out[n] = b;
        n += 1;
    };
    b"P4\n".iter().for_each(|&b| put(b));
    for (v, end) in [(w, b' '), (h, b'\n')] {
        let mut digits = [0u8; 10];
        let (mut k, mut v) = (0, v);
        loop {
            digits[k] = b'0' + (v % 10) as u8;
            k += 1;
            v /= 10;
            if v == 0 {
                break;
            }
        }
        digits[..k].iter().rev().for_each(|&d| put(d));
        put(end);
    }
    n
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
            let byte = at_mut(self.bits, i);
            if c.is_on() {
                *byte |= m;
            } else {
                *byte &= !m;
            }
        }
        Ok(())
    }

    /// A whole rectangle inside the frame (a tile) goes row by row with no per-pixel bounds
    /// checks; one reaching outside goes pixel by pixel through [`DrawTarget::draw_iter`].
    fn fill_contiguous<I: IntoIterator<Item = BinaryColor>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let (x0, y0) = (area.top_left.x, area.top_left.y);
        let (w, h) = (area.size.width, area.size.height);
        let inside = x0 >= 0
            && y0 >= 0
            && (x0 as u32).checked_add(w).is_some_and(|x1| x1 <= self.width)
            && (y0 as u32).checked_add(h).is_some_and(|y1| y1 <= self.height);
        if !inside {
            return self.draw_iter(area.points().zip(colors).map(|(p, c)| Pixel(p, c)));
        }
        let stride = (self.width as usize).div_ceil(8);
        let mut colors = colors.into_iter();
        let (x0, x1) = (x0 as usize, x0 as usize + w as usize);
        for y in y0 as usize..y0 as usize + h as usize {
            let row = span_mut(self.bits, y * stride..(y + 1) * stride);
            let mut x = x0;
            while x < x1 {
                if x % 8 == 0 && x1 - x >= 8 {
                    // A whole byte of the row: its eight pixels packed, then stored at once.
                    let mut byte = 0u8;
                    for k in 0..8 {
                        let Some(c) = colors.next() else {
                            // Fewer colors than pixels: the first `k` pixels alone are drawn.
                            if k > 0 {
                                let keep = 0xFFu8 >> k;
                                let b = at_mut(row, x / 8);
                                *b = (*b & keep) | (byte << (8 - k) & !keep);
                            }
                            return Ok(());
                        };
                        byte = byte << 1 | u8::from(c.is_on());
                    }
                    *at_mut(row, x / 8) = byte;
                    x += 8;
                    continue;
                }
                let Some(c) = colors.next() else { return Ok(()) };
                let m = 0x80u8 >> (x % 8);
                let byte = at_mut(row, x / 8);
                if c.is_on() {
                    *byte |= m;
                } else {
                    *byte &= !m;
                }
                x += 1;
            }
        }
        Ok(())
    }
}

/// A frame of shades over caller storage, one byte a pixel, row-major: each pixel's step
/// ([`Shade::step`]: `0..=C::STEPS`), as an `embedded_graphics` draw target of `C`. What the
/// gray mode's four shades ([`embedded_graphics_core::pixelcolor::Gray2`]) are drawn into on
/// a host; a 1-bit frame drawn into it holds 0 and 1.
#[derive(Debug)]
pub struct ShadeFrame<'s, C> {
    width: u32,
    height: u32,
    steps: &'s mut [u8],
    shade: core::marker::PhantomData<C>,
}

impl<'s, C: Shade> ShadeFrame<'s, C> {
    /// A dark frame over `steps`, or `None` if it is shorter than `width * height`.
    pub fn new(width: u32, height: u32, steps: &'s mut [u8]) -> Option<Self> {
        let steps = steps.get_mut(..width as usize * height as usize)?;
        steps.iter_mut().for_each(|k| *k = 0);
        Some(ShadeFrame { width, height, steps, shade: core::marker::PhantomData })
    }

    /// Draws into `frame` which pixels are lit at all (a step above 0), in any subframe.
    pub fn lit(&self, frame: &mut BitFrame<'_>) {
        let w = self.width.max(1) as usize;
        let pixels = self
            .steps
            .iter()
            .enumerate()
            .map(|(i, &k)| Pixel(Point::new((i % w) as i32, (i / w) as i32), BinaryColor::from(k > 0)));
        let Ok(()) = frame.draw_iter(pixels);
    }
}

impl<C> OriginDimensions for ShadeFrame<'_, C> {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl<C: Shade> DrawTarget for ShadeFrame<'_, C> {
    type Color = C;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<C>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && (p.x as u32) < self.width && (p.y as u32) < self.height {
                *at_mut(self.steps, p.y as usize * self.width as usize + p.x as usize) = c.step();
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics_core::geometry::Point;

    /// Filling a rectangle, inside the frame or reaching out of it, sets the bits that drawing
    /// its pixels one by one sets.
    #[test]
    fn fill_contiguous_is_draw_iter() {
        for (x, y, w, h) in [
            (0, 0, 8, 8),
            (8, 16, 8, 8),
            (3, 5, 7, 3),
            (20, 10, 8, 8),
            (-3, -2, 6, 5),
            (0, 0, 21, 13),
            (0, 0, 0, 4),
            (8, 1, 13, 4),
            (16, 0, 5, 2),
            (5, 3, 16, 2),
        ] {
            let area = Rectangle::new(Point::new(x, y), Size::new(w, h));
            let colors = (0..w * h).map(|i| BinaryColor::from((i * 7 + i / 3) % 5 < 2));
            let (mut a, mut b) = ([0x5au8; 3 * 13], [0x5au8; 3 * 13]);
            let mut fa = BitFrame::wrap(21, 13, &mut a).unwrap();
            fa.fill_contiguous(&area, colors.clone()).unwrap();
            let mut fb = BitFrame::wrap(21, 13, &mut b).unwrap();
            fb.draw_iter(area.points().zip(colors).map(|(p, c)| Pixel(p, c))).unwrap();
            assert_eq!(a, b, "area ({x}, {y}) {w}x{h}");
        }
    }

    /// With fewer colors than the area has pixels, the pixels they reach are drawn and the rest
    /// keep their bits, as drawing them one by one does.
    #[test]
    fn fill_contiguous_with_fewer_colors_draws_what_they_reach() {
        for n in [0u32, 3, 8, 11, 16, 20] {
            let area = Rectangle::new(Point::new(8, 2), Size::new(13, 3));
            let colors = (0..n).map(|i| BinaryColor::from(i % 3 == 0));
            let (mut a, mut b) = ([0x5au8; 3 * 13], [0x5au8; 3 * 13]);
            BitFrame::wrap(21, 13, &mut a).unwrap().fill_contiguous(&area, colors.clone()).unwrap();
            BitFrame::wrap(21, 13, &mut b)
                .unwrap()
                .draw_iter(area.points().zip(colors).map(|(p, c)| Pixel(p, c)))
                .unwrap();
            assert_eq!(a, b, "{n} colors");
        }
    }

    #[test]
    fn a_shade_frame_keeps_each_pixels_step_and_lights_the_nonzero_ones() {
        use embedded_graphics_core::pixelcolor::Gray2;
        let mut steps = [9u8; 6];
        let mut f = ShadeFrame::<Gray2>::new(3, 2, &mut steps).unwrap();
        let px = |x, y, k| Pixel(Point::new(x, y), Gray2::new(k));
        f.draw_iter([px(0, 0, 3), px(2, 1, 1), px(1, 0, 2), px(5, 5, 3), px(-1, 0, 3)]).unwrap();
        let mut bits = [0u8; 2];
        f.lit(&mut BitFrame::new(3, 2, &mut bits).unwrap());
        assert_eq!(steps, [3, 2, 0, 0, 0, 1], "outside pixels dropped, the rest cleared");
        assert_eq!(bits, [0b1100_0000, 0b0010_0000]);
        assert!(ShadeFrame::<Gray2>::new(4, 2, &mut [0; 7]).is_none());
    }
}
