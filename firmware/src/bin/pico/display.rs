//! The panel as the render loop's draw target, with no framebuffer: whole bands of tiles sent
//! as page bytes to an OLED controller ([`pages`], the controller the image drives from
//! [`controller`]: SSD1306, SH1106, SSD1309) over I2C ([`i2c`]: a queue the bus drains while the
//! cores trace, and a display that does not answer reported) or 4-wire SPI ([`spi`], the `spi`
//! feature), or as line writes to a Sharp memory LCD on SPI ([`sharp`], the `sharp-*`
//! features), or as a whole frame to the Badger 2040's e-paper ([`uc8151`]). Each bus gives the
//! render loop the same two things: [`Pump`], its hooks, and [`flush`], the wait until the
//! frame is on the panel.

#[cfg(not(any(feature = "sharp", feature = "uc8151")))]
pub mod controller;
pub use crate::bus::{flush, reset, Pump};
#[cfg(not(any(feature = "sharp", feature = "gray", feature = "uc8151")))]
mod pages;
#[cfg(not(any(feature = "sharp", feature = "gray", feature = "uc8151")))]
pub use pages::PageTiles;
#[cfg(feature = "gray")]
pub mod gray;
#[cfg(feature = "sharp")]
pub mod sharp;
#[cfg(feature = "gray")]
mod spi_dma;
#[cfg(feature = "uc8151")]
pub mod uc8151;

use display_interface::DisplayError;
#[cfg(not(feature = "gray"))]
use {
    embedded_graphics_core::draw_target::DrawTarget,
    embedded_graphics_core::geometry::{OriginDimensions, Size},
    embedded_graphics_core::pixelcolor::BinaryColor,
    embedded_graphics_core::primitives::Rectangle,
    embedded_graphics_core::Pixel,
    firmware::app::{HEIGHT, WIDTH},
};

#[cfg(not(feature = "gray"))]
use crate::bus::BAND_ROWS;

/// The panel's name in the log.
#[cfg(not(any(feature = "sharp", feature = "uc8151")))]
pub const NAME: &str = controller::PANEL.name;
/// The panel's name in the log.
#[cfg(feature = "uc8151")]
pub const NAME: &str = "UC8151 e-paper";
/// The panel's name in the log.
#[cfg(feature = "sharp")]
pub const NAME: &str = "Sharp memory LCD";

/// A panel the modes set up before every frame: a panel that lost power (a loose wire) comes
/// back dark, with its settings lost, and a write-only bus cannot tell, so no frame may count
/// on an earlier set-up.
pub trait SetUp {
    /// Sends the panel's whole set-up (display off, its configuration, charge pump, display on)
    /// and waits until it has left the bus; an error when the panel does not answer.
    fn set_up(&mut self) -> Result<(), DisplayError>;
    /// Whether the panel answers a command that changes nothing it shows (normal, not inverted,
    /// display): a probe while the board waits between frames.
    fn answers(&mut self) -> bool;
    /// Sends the picture shown again, with the set-up that shows it but without turning the
    /// display off first: a panel that lost power for a moment no transfer saw (it comes back
    /// dark, its settings lost) shows the picture again, and one that did not changes nothing.
    /// The modes call it at a steady rate while a picture stands. Panels that keep their
    /// picture without power have nothing to do.
    fn refresh(&mut self) -> Result<(), DisplayError> {
        Ok(())
    }
    /// Waits until everything drawn is on the panel: the bus's own wait ([`flush`]) unless the
    /// panel has its own.
    fn flush(&mut self) -> Result<(), DisplayError> {
        flush().map_err(|_| DisplayError::BusWriteError)
    }
}

/// A panel that takes an area of one band of tiles at a time: at most [`BAND_ROWS`] rows from a
/// row that is a multiple of 8, within the frame, its pixels row by row.
#[cfg(not(feature = "gray"))]
pub trait Band {
    /// Sends `colors` (row by row) for the area of size `size` (width, height) at `at` (x, y).
    fn band(
        &mut self,
        at: (usize, usize),
        size: (usize, usize),
        colors: impl Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError>;
}

/// A [`Band`] panel as the render loop's draw target: the areas it takes are passed on; nothing
/// else is supported (there is no framebuffer to merge single pixels into), and anything else is
/// refused with an error.
#[cfg(not(feature = "gray"))]
pub struct Bands<T>(pub T);

#[cfg(not(feature = "gray"))]
impl<T: SetUp> SetUp for Bands<T> {
    fn set_up(&mut self) -> Result<(), DisplayError> {
        self.0.set_up()
    }

    fn answers(&mut self) -> bool {
        self.0.answers()
    }

    fn refresh(&mut self) -> Result<(), DisplayError> {
        self.0.refresh()
    }

    fn flush(&mut self) -> Result<(), DisplayError> {
        self.0.flush()
    }
}

#[cfg(not(feature = "gray"))]
impl<T> OriginDimensions for Bands<T> {
    fn size(&self) -> Size {
        Size::new(WIDTH as u32, HEIGHT as u32)
    }
}

#[cfg(not(feature = "gray"))]
impl<T: Band> DrawTarget for Bands<T> {
    type Color = BinaryColor;
    type Error = DisplayError;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, _pixels: I) -> Result<(), Self::Error> {
        Err(DisplayError::OutOfBoundsError)
    }

    fn fill_contiguous<I: IntoIterator<Item = BinaryColor>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let (x0, y0) = (area.top_left.x, area.top_left.y);
        let (w, h) = (area.size.width as usize, area.size.height as usize);
        if w == 0 || h == 0 {
            return Ok(());
        }
        let inside = x0 >= 0 && y0 >= 0 && x0 as usize + w <= WIDTH as usize && y0 as usize + h <= HEIGHT as usize;
        if !inside || y0 % 8 != 0 || h > BAND_ROWS {
            return Err(DisplayError::OutOfBoundsError);
        }
        self.0.band((x0 as usize, y0 as usize), (w, h), colors.into_iter())
    }
}
