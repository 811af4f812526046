//! The OLED controllers' page RAM as a draw target: each band of tiles sent as page bytes (a
//! byte is 8 rows of one column, LSB on top) to the controller the image drives
//! ([`super::controller::PANEL`]), addressed as it takes them. A copy of every page byte sent
//! is kept, so that the picture can be sent again ([`SetUp::refresh`]).

use super::controller::{self, Addressing, DISPLAY_OFF, DISPLAY_ON, PANEL};
use super::{flush, Band, SetUp};
use display_interface::{DataFormat, DisplayError, WriteOnlyDataCommand};
use embedded_graphics_core::pixelcolor::BinaryColor;
use firmware::app::{HEIGHT, WIDTH};

/// Columns of the panel's page RAM the image draws.
const COLUMNS: usize = WIDTH as usize;
/// Bytes of the pages the image draws: one per column of each page (1 KiB at 128x64).
const PAGE_BYTES: usize = COLUMNS * (HEIGHT as usize).div_ceil(8);

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

    /// The set-up without its display off, every page byte of the picture, then display on:
    /// a panel that was powered all along shows no change (each command sets what it already
    /// holds), one that came back from a cut shows the picture once its RAM holds it.
    fn refresh(&mut self) -> Result<(), DisplayError> {
        for command in PANEL.set_up.iter().copied().flatten().filter(|c| **c != DISPLAY_OFF && **c != DISPLAY_ON) {
            self.interface.send_commands(DataFormat::U8(command))?;
        }
        self.send((0, COLUMNS), (0, PAGE_BYTES / COLUMNS))?;
        self.interface.send_commands(DataFormat::U8(DISPLAY_ON))?;
        flush().map_err(|_| DisplayError::BusWriteError)
    }
}

/// Sends areas of a band of tiles as page bytes to the controller ([`PANEL`]), addressed as it
/// takes them, and keeps what it sent.
pub struct PageTiles<DI> {
    /// The display's bus (commands and page data).
    interface: DI,
    /// Every page byte sent, page after page, [`COLUMNS`] to a page: what the panel shows.
    shown: [u8; PAGE_BYTES],
}

impl<DI: WriteOnlyDataCommand> PageTiles<DI> {
    /// Pages on `interface`, none sent yet (the copy dark, as a panel set up shows nothing).
    pub fn new(interface: DI) -> Self {
        PageTiles { interface, shown: [0; PAGE_BYTES] }
    }

    /// Sends the kept bytes of columns `x0..x0 + w` of pages `p0..p0 + pages`.
    fn send(&mut self, (x0, w): (usize, usize), (p0, pages): (usize, usize)) -> Result<(), DisplayError> {
        let rows = |p: usize| (p * COLUMNS + x0)..(p * COLUMNS + x0 + w);
        match PANEL.addressing {
            Addressing::Window => {
                let (columns, window) = controller::window(x0 as u8, w as u8, p0 as u8, (p0 + pages - 1) as u8);
                self.interface.send_commands(DataFormat::U8(&columns))?;
                self.interface.send_commands(DataFormat::U8(&window))?;
                if w == COLUMNS {
                    // Whole pages lie together: one transfer.
                    return self.interface.send_data(DataFormat::U8(&self.shown[p0 * COLUMNS..(p0 + pages) * COLUMNS]));
                }
                for p in p0..p0 + pages {
                    self.interface.send_data(DataFormat::U8(&self.shown[rows(p)]))?;
                }
                Ok(())
            }
            Addressing::Pages => {
                for p in p0..p0 + pages {
                    self.interface.send_commands(DataFormat::U8(&controller::page_start(x0 as u8, p as u8)))?;
                    self.interface.send_data(DataFormat::U8(&self.shown[rows(p)]))?;
                }
                Ok(())
            }
        }
    }
}

impl<DI: WriteOnlyDataCommand> Band for PageTiles<DI> {
    fn band(
        &mut self,
        (x0, y0): (usize, usize),
        (w, h): (usize, usize),
        mut colors: impl Iterator<Item = BinaryColor>,
    ) -> Result<(), DisplayError> {
        // Into the kept pages (bit k of a byte = row k of its page, LSB on top), then sent
        // from there.
        for y in y0..y0 + h {
            let bit = 1u8 << (y % 8);
            for col in &mut self.shown[y / 8 * COLUMNS + x0..y / 8 * COLUMNS + x0 + w] {
                *col = if colors.next().is_some_and(|c| c.is_on()) { *col | bit } else { *col & !bit };
            }
        }
        self.send((x0, w), (y0 / 8, h.div_ceil(8)))
    }
}
