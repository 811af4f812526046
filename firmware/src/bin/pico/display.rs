//! The panel as the render loop's draw target: whole bands of tiles sent as page bytes (no
//! framebuffer) to the controller the image drives ([`controller`]: SSD1306, SH1106, SSD1309),
//! over I2C ([`i2c`]: a queue the bus drains while the cores trace, and a display
//! that does not answer reported) or, with the `spi` feature, 4-wire SPI ([`spi`]). Each gives
//! the render loop the same two things: [`Pump`], its hooks, and [`flush`], the wait until the
//! frame is on the panel.

#[cfg(not(feature = "spi"))]
mod bus_clear;
pub mod controller;
#[cfg(not(feature = "spi"))]
mod i2c;
#[cfg(not(feature = "spi"))]
pub use i2c::{flush, reset, Pump, QueuedI2c};
#[cfg(feature = "spi")]
mod spi;
#[cfg(feature = "spi")]
pub use spi::{flush, reset, Pump};

use controller::{Addressing, PANEL};
use display_interface::{DataFormat, DisplayError, WriteOnlyDataCommand};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::BinaryColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use firmware::app::{HEIGHT, RENDERED, WIDTH};

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
}

impl<DI: WriteOnlyDataCommand> SetUp for PageTiles<DI> {
    fn set_up(&mut self) -> Result<(), DisplayError> {
        for command in PANEL.set_up.iter().copied().flatten() {
            self.interface.send_commands(DataFormat::U8(command))?;
        }
        flush().map_err(|_| DisplayError::BusWriteError)
    }

    fn answers(&mut self) -> bool {
        self.interface.send_commands(DataFormat::U8(controller::PROBE)).is_ok() && flush().is_ok()
    }
}

/// The most rows drawn at once: a band of tiles.
const BAND_ROWS: usize = RENDERED.tile as usize;

/// Draws areas that start on a page and are at most a band high ([`BAND_ROWS`]) by sending
/// page bytes to the controller ([`PANEL`]); nothing else is supported (there is no framebuffer
/// to merge single pixels into), and anything else is refused with an error.
pub struct PageTiles<DI> {
    /// The display's bus (commands and page data).
    pub interface: DI,
}

impl<DI: WriteOnlyDataCommand> OriginDimensions for PageTiles<DI> {
    fn size(&self) -> Size {
        Size::new(WIDTH as u32, HEIGHT as u32)
    }
}

impl<DI: WriteOnlyDataCommand> DrawTarget for PageTiles<DI> {
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
        if y0 < 0 || x0 < 0 || y0 % 8 != 0 || h > BAND_ROWS || x0 as usize + w > WIDTH as usize {
            return Err(DisplayError::OutOfBoundsError);
        }
        // One byte per column of each page, the pages one after the other (the SSD1306's
        // horizontal addressing fills a draw area that way); bit k = row k of its page (LSB on
        // top).
        let mut pages = [0u8; WIDTH as usize * BAND_ROWS.div_ceil(8)];
        let mut colors = colors.into_iter();
        for y in 0..h {
            let (page, bit) = (&mut pages[y / 8 * w..(y / 8 + 1) * w], 1u8 << (y % 8));
            for col in page.iter_mut() {
                if colors.next().is_some_and(|c| c.is_on()) {
                    *col |= bit;
                }
            }
        }
        let (pages, w) = (&pages[..h.div_ceil(8) * w], w as u8);
        let (x0, p0) = (x0 as u8, (y0 / 8) as u8);
        match PANEL.addressing {
            Addressing::Window => {
                let (columns, rows) = controller::window(x0, w, p0, p0 + h.div_ceil(8) as u8 - 1);
                self.interface.send_commands(DataFormat::U8(&columns))?;
                self.interface.send_commands(DataFormat::U8(&rows))?;
                self.interface.send_data(DataFormat::U8(pages))
            }
            Addressing::Pages => {
                for (k, page) in pages.chunks(usize::from(w)).enumerate() {
                    self.interface.send_commands(DataFormat::U8(&controller::page_start(x0, p0 + k as u8)))?;
                    self.interface.send_data(DataFormat::U8(page))?;
                }
                Ok(())
            }
        }
    }
}
