//! The display on I2C0: a queue in RAM in front of the controller's TX FIFO, refilled by the
//! controller's TX_EMPTY interrupt on core 0 (and after each tile core 0 traces), so the bus
//! sends a band while the cores trace the next, and never waits for a tile to end.

use crate::hal;
use hal::pac;
use hal::pac::interrupt;

/// I2C0 driven through a queue in RAM ([`QUEUED`] words) in front of its 16-entry TX FIFO: a
/// transaction is queued and returns at once (it waits only while the queue is full), and the
/// queue moves into the FIFO whenever the FIFO runs low (its TX_EMPTY interrupt) and whenever
/// core 0 finishes a tile ([`Pump`]), so the bus sends a band while the cores trace the next;
/// each transaction ends with a STOP, and the controller starts
/// the next on its own when more bytes follow. (rp2040-hal's own `transaction` waits for the STOP
/// after every transaction, and a write straight to the FIFO waits while it is full: either keeps
/// core 0 from tracing while the bus is busy.) A display that does not answer aborts the
/// transfer; the abort is reported by the next transaction or [`flush`], whichever comes first.
pub struct QueuedI2c<P> {
    /// The bus, set up by the HAL (pins, clock, speed) and owned here so nothing else drives it.
    _bus: hal::I2C<pac::I2C0, P>,
    /// The one target address (set once: changing it needs the controller disabled, which would
    /// cut off a transfer under way).
    address: u8,
}

/// Words the queue holds: IC_DATA_CMD values (the byte, and the STOP bit on a transaction's
/// last). A band is its pages' column bytes (128 per page, [`BAND_PAGES`] pages) and 16 bytes of
/// addressing; the queue holds two bands' worth, so a band is queued whole while the last is
/// still on the bus. A progressive frame's first passes are traced in a fraction of the time
/// their bytes take on the bus: its queue holds all four passes' bytes (a frame is 1,152 bytes
/// in 8-row bands, fewer in higher ones), so the cores never wait for the bus and trace the later
/// passes while it sends the earlier ones (with two passes' worth, core 0 waited for room during
/// the third pass: the chair took 1.06x the still frame).
const QUEUED: usize =
    if cfg!(feature = "progressive") { 4 * 1152 + 96 } else { 2 * (BAND_PAGES * firmware::app::WIDTH as usize + 16) };

/// SSD1306 pages (8 rows each) in a band of tiles.
const BAND_PAGES: usize = super::BAND_ROWS.div_ceil(8);

/// The bytes on their way to the bus: a ring of IC_DATA_CMD words, and the abort the controller
/// reported while the queue was being moved into its FIFO.
struct Queue {
    words: [u16; QUEUED],
    head: usize,
    len: usize,
    abort: Option<u32>,
}

/// The one queue, shared by the code that draws and the interrupt that refills the FIFO.
static QUEUE: critical_section::Mutex<core::cell::RefCell<Queue>> =
    critical_section::Mutex::new(core::cell::RefCell::new(Queue { words: [0; QUEUED], head: 0, len: 0, abort: None }));

/// I2C0's registers.
fn regs() -> &'static pac::i2c0::RegisterBlock {
    // SAFETY: I2C0 belongs to the `QueuedI2c` that owns its HAL driver; only its methods,
    // `pump` and `flush` touch the registers, and each does so inside the critical section of
    // [`QUEUE`], so the two cores never interleave their writes.
    #[allow(unsafe_code)]
    unsafe {
        &*pac::I2C0::ptr()
    }
}

/// IC_INTR_MASK's TX_EMPTY bit (1: the interrupt is on).
const M_TX_EMPTY: u32 = 1 << 4;
/// TX_EMPTY is raised when this many entries or fewer wait in the 16-entry TX FIFO: at 400 kHz
/// the 4 left take 48,000 cycles, time enough for the interrupt to refill it.
const TX_THRESHOLD: u8 = 4;

/// Moves queued words into the TX FIFO while it has room (inside the queue's critical section),
/// and leaves TX_EMPTY's interrupt on while words wait in the queue, off once it is empty. An
/// abort empties the queue (the controller dropped its FIFO) and is kept for the next call that
/// can report it.
fn pump_queue(q: &mut Queue) {
    let r = regs();
    let reason = r.ic_tx_abrt_source().read().bits();
    if reason != 0 {
        // Reading IC_CLR_TX_ABRT clears the abort and releases the TX FIFO, as the HAL does.
        r.ic_clr_tx_abrt().read();
        q.abort = q.abort.or(Some(reason));
        q.len = 0;
    }
    while q.len > 0 && r.ic_status().read().tfnf().bit_is_set() {
        // SAFETY: IC_DATA_CMD takes any byte with its STOP bit (bit 9), as queued.
        #[allow(unsafe_code)]
        r.ic_data_cmd().write(|w| unsafe { w.bits(u32::from(q.words[q.head])) });
        q.head = (q.head + 1) % QUEUED;
        q.len -= 1;
    }
    // SAFETY: TX_EMPTY alone or no interrupt at all; every other source stays masked.
    #[allow(unsafe_code)]
    r.ic_intr_mask().write(|w| unsafe { w.bits(if q.len > 0 { M_TX_EMPTY } else { 0 }) });
}

/// I2C0's interrupt (TX_EMPTY, on core 0 alone): the FIFO is running low, refill it from the
/// queue.
#[interrupt]
fn I2C0_IRQ() {
    pump();
}

/// Moves what is queued into the controller's TX FIFO as far as it has room, without waiting.
pub fn pump() {
    critical_section::with(|cs| pump_queue(&mut QUEUE.borrow(cs).borrow_mut()));
}

/// The abort reported since the last call, if any.
fn take_abort() -> Result<(), hal::i2c::Error> {
    critical_section::with(|cs| {
        let mut q = QUEUE.borrow(cs).borrow_mut();
        pump_queue(&mut q);
        q.abort.take().map_or(Ok(()), |reason| Err(hal::i2c::Error::Abort(reason)))
    })
}

/// Waits until every queued byte has left the controller and the bus is idle: the frame is on
/// the panel. Reports an abort of the last transfers.
pub fn flush() -> Result<(), hal::i2c::Error> {
    loop {
        take_abort()?;
        let empty = critical_section::with(|cs| QUEUE.borrow(cs).borrow().len == 0);
        let status = regs().ic_status().read();
        if empty && status.tfe().bit_is_set() && status.activity().bit_is_clear() {
            return take_abort();
        }
    }
}

/// The render's hooks on the Pico: after each tile core 0 traces, the display's queue moves on
/// to the bus ([`pump`]) and the watchdog is fed (`guard`).
pub struct Pump;

impl lattice_rt::render::Hooks for Pump {
    fn progress(&mut self, _done: u32, _total: u32) -> bool {
        pump();
        crate::guard::feed();
        true
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
        // SAFETY: any threshold up to the FIFO's 16 entries is valid; 0 masks every interrupt.
        #[allow(unsafe_code)]
        {
            r.ic_tx_tl().write(|w| unsafe { w.tx_tl().bits(TX_THRESHOLD) });
            r.ic_intr_mask().write(|w| unsafe { w.bits(0) });
        }
        r.ic_enable().write(|w| w.enable().set_bit());
        // SAFETY: the handler only takes the queue's critical section, as every other user does.
        #[allow(unsafe_code)]
        unsafe {
            cortex_m::peripheral::NVIC::unmask(pac::Interrupt::I2C0_IRQ)
        };
        QueuedI2c { _bus: bus, address }
    }
}

impl<P> embedded_hal::i2c::ErrorType for QueuedI2c<P> {
    type Error = hal::i2c::Error;
}

impl<P> embedded_hal::i2c::I2c for QueuedI2c<P> {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
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
        /// IC_DATA_CMD's STOP bit.
        const STOP: u16 = 1 << 9;
        let mut bytes = operations.iter().flat_map(|op| match op {
            Operation::Write(b) => b.iter(),
            Operation::Read(_) => [].iter(),
        });
        // Queued in runs under one critical section each; while the queue is full, its words
        // move into the FIFO as the bus takes them.
        while left > 0 {
            critical_section::with(|cs| {
                let mut q = QUEUE.borrow(cs).borrow_mut();
                pump_queue(&mut q);
                while q.len < QUEUED && left > 0 {
                    let Some(&byte) = bytes.next() else { break };
                    left -= 1;
                    let tail = (q.head + q.len) % QUEUED;
                    q.words[tail] = u16::from(byte) | if left == 0 { STOP } else { 0 };
                    q.len += 1;
                }
            });
            take_abort()?;
        }
        Ok(())
    }
}

/// An I2C module resets itself at power-on: nothing to pulse.
pub fn reset<DI, D>(
    _display: &mut ssd1306::Ssd1306<DI, ssd1306::prelude::DisplaySize128x64, ssd1306::mode::BasicMode>,
    _line: &mut crate::wiring::Reset,
    _delay: &mut D,
) {
}
