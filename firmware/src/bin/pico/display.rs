//! The SSD1306 as the render loop's draw target: 8-row tiles or whole bands sent as page bytes (no
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
        if y0 < 0 || x0 < 0 || y0 % 8 != 0 || h > 8 || x0 as usize + w > WIDTH as usize {
            return Err(display_interface::DisplayError::OutOfBoundsError);
        }
        // One byte per column, bit k = row k of the page (LSB on top).
        let mut cols = [0u8; WIDTH as usize];
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

/// I2C0 driven through its 16-entry TX FIFO: a transaction is queued (a write waits only while
/// the FIFO is full) and the controller sends it while the core goes on tracing; each ends with
/// a STOP, and the controller starts the next on its own when more bytes follow. rp2040-hal's
/// own `transaction` waits for the STOP after every transaction, which on a 400 kHz bus keeps
/// core 0 waiting about 60,000 cycles per tile. A display that does not answer aborts the
/// transfer; the abort is reported by the next transaction or [`flush`], whichever comes first.
pub struct QueuedI2c<P> {
    /// The bus, set up by the HAL (pins, clock, speed) and owned here so nothing else drives it.
    _bus: hal::I2C<pac::I2C0, P>,
    /// The one target address (set once: changing it needs the controller disabled, which would
    /// cut off a transfer under way).
    address: u8,
}

/// I2C0's registers.
fn regs() -> &'static pac::i2c0::RegisterBlock {
    // SAFETY: I2C0 belongs to the `QueuedI2c` that owns its HAL driver; only its methods and
    // `flush` touch the registers, and the two cores call those one at a time (each tile is
    // drawn under the board's critical section, `app::Shared`; `flush` runs once core 1 is done).
    #[allow(unsafe_code)]
    unsafe {
        &*pac::I2C0::ptr()
    }
}

/// The abort the controller reported since the last call, if any (reading IC_CLR_TX_ABRT clears
/// it and releases the TX FIFO, as the HAL does after an abort it noticed).
fn take_abort() -> Result<(), hal::i2c::Error> {
    let reason = regs().ic_tx_abrt_source().read().bits();
    if reason != 0 {
        regs().ic_clr_tx_abrt().read();
        return Err(hal::i2c::Error::Abort(reason));
    }
    Ok(())
}

/// Waits until every queued byte has left the controller and the bus is idle: the frame is on
/// the panel. Reports an abort of the last transfers.
pub fn flush() -> Result<(), hal::i2c::Error> {
    loop {
        take_abort()?;
        let status = regs().ic_status().read();
        if status.tfe().bit_is_set() && status.activity().bit_is_clear() {
            return take_abort();
        }
    }
}

impl<P> QueuedI2c<P> {
    /// Takes the HAL's bus and sets its one target `address` (7 bits).
    pub fn new(bus: hal::I2C<pac::I2C0, P>, address: u8) -> Self {
        let r = regs();
        r.ic_enable().write(|w| w.enable().clear_bit());
        r.ic_con().modify(|_, w| w.ic_10bitaddr_master().clear_bit());
        // SAFETY: any 7-bit address is a valid IC_TAR value.
        #[allow(unsafe_code)]
        r.ic_tar().write(|w| unsafe { w.ic_tar().bits(u16::from(address)) });
        r.ic_enable().write(|w| w.enable().set_bit());
        QueuedI2c { _bus: bus, address }
    }
}

impl<P> embedded_hal::i2c::ErrorType for QueuedI2c<P> {
    type Error = hal::i2c::Error;
}

impl<P> embedded_hal::i2c::I2c for QueuedI2c<P> {
    fn transaction(&mut self, address: u8, operations: &mut [embedded_hal::i2c::Operation<'_>]) -> Result<(), Self::Error> {
        use embedded_hal::i2c::Operation;
        if address != self.address {
            return Err(hal::i2c::Error::AddressOutOfRange(u16::from(address)));
        }
        take_abort()?;
        let mut left: usize = 0;
        for op in operations.iter() {
            match op {
                Operation::Write(bytes) => left += bytes.len(),
                Operation::Read(_) => return Err(hal::i2c::Error::InvalidReadBufferLength),
            }
        }
        if left == 0 {
            return Err(hal::i2c::Error::InvalidWriteBufferLength);
        }
        let r = regs();
        for op in operations.iter() {
            let Operation::Write(bytes) = op else { continue };
            for &byte in bytes.iter() {
                while r.ic_status().read().tfnf().bit_is_clear() {
                    take_abort()?;
                }
                left -= 1;
                // SAFETY: DAT takes any byte; STOP on the transaction's last byte.
                #[allow(unsafe_code)]
                r.ic_data_cmd().write(|w| unsafe { w.stop().bit(left == 0).dat().bits(byte) });
            }
        }
        Ok(())
    }
}
