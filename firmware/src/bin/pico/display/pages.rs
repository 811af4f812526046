//! The OLED controllers' page RAM as a draw target: each band of tiles sent as page bytes (a
//! byte is 8 rows of one column, LSB on top) to the controller the image drives
//! ([`super::controller::PANEL`]), addressed as it takes them.

use super::controller::{self, Addressing, PANEL};
use super::{flush, Band, SetUp};
use crate::bus::BAND_ROWS;
use display_interface::{DataFormat, DisplayError, WriteOnlyDataCommand};
use embedded_graphics_core::pixelcolor::BinaryColor;
use firmware::app::WIDTH;

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

/// Sends areas of a band of tiles as page bytes to the controller ([`PANEL`]), addressed as it
/// takes them.
pub struct PageTiles<DI> {
    /// The display's bus (commands and page data).
    pub interface: DI,
}

impl<DI: WriteOnlyDataCommand> Band for PageTiles<DI> {
    fn band(
        &mut self,
        (x0, y0): (usize, usize),
        (w, h): (usize, usize),
        mut colors: impl Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError> {
        // One byte per column of each page, the pages one after the other (the SSD1306's
        // horizontal addressing fills a draw area that way); bit k = row k of its page (LSB on
        // top).
        let mut pages = [0u8; WIDTH as usize * BAND_ROWS.div_ceil(8)];
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
