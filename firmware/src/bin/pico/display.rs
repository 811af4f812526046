//! The SSD1306 as the render loop's draw target: whole 8-row tiles sent as page bytes (no
//! framebuffer), over an I2C bus that reports a display that does not answer.

use crate::hal;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use firmware::app::{HEIGHT, WIDTH};
use hal::pac;
use ssd1306::mode::BasicMode;
use ssd1306::prelude::*;

/// Draws whole 8-row tiles by sending SSD1306 page bytes; nothing else is supported (there is
/// no framebuffer to merge single pixels into), and anything else is refused with an error.
pub struct PageTiles<DI> {
    /// The display, in its basic mode (commands and raw page data).
    pub display: ssd1306::Ssd1306<DI, DisplaySize128x64, BasicMode>,
}

impl<DI: WriteOnlyDataCommand> OriginDimensions for PageTiles<DI> {
    fn size(&self) -> Size {
        Size::new(WIDTH as u32, HEIGHT as u32)
    }
}

impl<DI: WriteOnlyDataCommand> DrawTarget for PageTiles<DI> {
    type Color = BinaryColor;
    type Error = display_interface::DisplayError;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, _pixels: I) -> Result<(), Self::Error> {
        Err(display_interface::DisplayError::OutOfBoundsError)
    }

    fn fill_contiguous<I: IntoIterator<Item = BinaryColor>>(&mut self, area: &Rectangle, colors: I) -> Result<(), Self::Error> {
        let (x0, y0) = (area.top_left.x, area.top_left.y);
        let (w, h) = (area.size.width as usize, area.size.height as usize);
        if y0 < 0 || x0 < 0 || y0 % 8 != 0 || h > 8 || w > 16 || x0 as usize + w > WIDTH as usize {
            return Err(display_interface::DisplayError::OutOfBoundsError);
        }
        // One byte per column, bit k = row k of the page (LSB on top).
        let mut cols = [0u8; 16];
        let mut colors = colors.into_iter();
        for bit in (0..h).map(|y| 1u8 << y) {
            for col in cols[..w].iter_mut() {
                if colors.next().is_some_and(|c| c.is_on()) {
                    *col |= bit;
                }
            }
        }
        // `set_draw_area` takes pixel coordinates (it divides rows by 8 into pages itself).
        let (x1, y1) = ((x0 as usize + w) as u8, (y0 as usize + h) as u8);
        self.display.set_draw_area((x0 as u8, y0 as u8), (x1, y1))?;
        self.display.draw(&cols[..w])
    }
}

/// I2C0 that reports a device that does not answer. rp2040-hal 0.12 checks the controller's
/// abort flags only while a write waits for room in the 16-byte TX FIFO, so a shorter write to
/// an address nobody acknowledges (every SSD1306 command is one) returns `Ok` and the display
/// seems to be there. This reads the abort source after each transaction, as the hardware
/// leaves it once the STOP has gone out.
pub struct CheckedI2c<P>(pub hal::I2C<pac::I2C0, P>);

impl<P> embedded_hal::i2c::ErrorType for CheckedI2c<P> {
    type Error = hal::i2c::Error;
}

impl<P> embedded_hal::i2c::I2c for CheckedI2c<P>
where
    hal::I2C<pac::I2C0, P>: embedded_hal::i2c::I2c<Error = hal::i2c::Error>,
{
    fn transaction(&mut self, address: u8, operations: &mut [embedded_hal::i2c::Operation<'_>]) -> Result<(), Self::Error> {
        self.0.transaction(address, operations)?;
        // SAFETY: I2C0 belongs to `self.0`, and no transaction is under way; reading
        // IC_TX_ABRT_SOURCE has no side effect, reading IC_CLR_TX_ABRT clears the abort (and
        // releases the TX FIFO) exactly as the HAL itself does after an abort it noticed.
        #[allow(unsafe_code)]
        let regs = unsafe { &*pac::I2C0::ptr() };
        let reason = regs.ic_tx_abrt_source().read().bits();
        if reason != 0 {
            regs.ic_clr_tx_abrt().read();
            return Err(hal::i2c::Error::Abort(reason));
        }
        Ok(())
    }
}
