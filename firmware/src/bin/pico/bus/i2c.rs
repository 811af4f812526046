//! The display on I2C0: a queue in RAM in front of the controller's TX FIFO, refilled by the
//! controller's TX_EMPTY interrupt on core 0 (and after each tile core 0 traces), so the bus
//! sends a band while the cores trace the next, and never waits for a tile to end. A transfer
//! that fails (no acknowledge, arbitration lost, a bus that stops moving) leaves the controller
//! reset and the bus cleared ([`super::clear`]) before the next one.

use crate::hal;
use crate::wiring::Wiring;
use core::sync::atomic::{AtomicBool, Ordering};
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
    /// The controller's settings as set up, written again after it is reset ([`Self::recover`]).
    settings: Settings,
}

/// What went wrong on the display's bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BusError {
    /// The controller aborted the transfer: IC_TX_ABRT_SOURCE's bits (no acknowledge of the
    /// address or of a byte, arbitration lost).
    Abort(u32),
    /// The bus moved no byte for [`STALL_US`]: a START the controller cannot send (a device
    /// holds SDA low, so the bus looks busy) or a transfer that never ends.
    Stalled,
    /// A transaction this queue does not take: a read, an empty write, another address.
    Unsupported,
}

impl embedded_hal::i2c::Error for BusError {
    fn kind(&self) -> embedded_hal::i2c::ErrorKind {
        use embedded_hal::i2c::{ErrorKind, NoAcknowledgeSource};
        match *self {
            BusError::Abort(r) if r & ABRT_ADDR_NOACK != 0 => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address),
            BusError::Abort(r) if r & ABRT_TXDATA_NOACK != 0 => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Data),
            BusError::Abort(r) if r & ABRT_ARB_LOST != 0 => ErrorKind::ArbitrationLoss,
            _ => ErrorKind::Other,
        }
    }
}

/// IC_TX_ABRT_SOURCE: an address not acknowledged (7-bit, either 10-bit byte).
const ABRT_ADDR_NOACK: u32 = 0b111;
/// IC_TX_ABRT_SOURCE: a data byte not acknowledged.
const ABRT_TXDATA_NOACK: u32 = 1 << 3;
/// IC_TX_ABRT_SOURCE: arbitration lost (SDA low where the controller let it go high).
const ABRT_ARB_LOST: u32 = 1 << 12;

/// How long the bus may move no byte while bytes wait before the transfer counts as failed: a
/// byte takes 22.5 µs at 400 kHz, so 10 ms is hundreds of bytes' time.
const STALL_US: u32 = 10_000;

/// Set when a transfer failed: the next transaction resets the controller and clears the bus
/// first ([`QueuedI2c::recover`]).
static FAILED: AtomicBool = AtomicBool::new(false);

/// A failure, noted for the next transaction's recovery.
fn failed(e: BusError) -> BusError {
    FAILED.store(true, Ordering::Relaxed);
    e
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
fn take_abort() -> Result<(), BusError> {
    critical_section::with(|cs| {
        let mut q = QUEUE.borrow(cs).borrow_mut();
        pump_queue(&mut q);
        q.abort.take().map_or(Ok(()), |reason| Err(failed(BusError::Abort(reason))))
    })
}

/// Watches a wait on the bus: how much waits (queued words, FIFO entries, a transfer under way)
/// and since when that has not changed.
struct Progress {
    waiting: u32,
    since: u32,
}

impl Progress {
    /// What waits now, and the timer's microseconds.
    fn now() -> (u32, u32) {
        let queued = critical_section::with(|cs| QUEUE.borrow(cs).borrow().len) as u32;
        let r = regs();
        let active = u32::from(r.ic_status().read().activity().bit_is_set());
        (queued + r.ic_txflr().read().bits() + active, crate::sleep::micros())
    }

    fn start() -> Self {
        let (waiting, since) = Self::now();
        Progress { waiting, since }
    }

    /// `Stalled` when nothing has moved for [`STALL_US`]; else whether anything still waits.
    fn check(&mut self) -> Result<bool, BusError> {
        let (waiting, now) = Self::now();
        if waiting != self.waiting {
            *self = Progress { waiting, since: now };
        } else if waiting > 0 && now.wrapping_sub(self.since) > STALL_US {
            return Err(failed(BusError::Stalled));
        }
        Ok(waiting > 0)
    }
}

/// Waits until every queued byte has left the controller and the bus is idle: the frame is on
/// the panel. Reports an abort of the last transfers, or a bus that stopped moving.
pub fn flush() -> Result<(), BusError> {
    let mut progress = Progress::start();
    loop {
        take_abort()?;
        if !progress.check()? {
            return take_abort();
        }
    }
}

/// The render's hooks on the Pico: after each tile core 0 traces, the display's queue moves on
/// to the bus ([`pump`]) and the watchdog is fed (`guard`); its eye samples count as progress
/// ([`crate::guard::alive`]).
pub struct Pump;

impl lattice_rt::render::Hooks for Pump {
    fn progress(&mut self, _done: u32, _total: u32) -> bool {
        pump();
        crate::guard::feed();
        true
    }
    #[inline(always)]
    fn sampled(&mut self) {
        crate::guard::alive();
    }
}

/// The controller's registers the HAL and [`QueuedI2c::new`] set: IC_CON, the SCL counts,
/// the spike filter, the SDA hold time, IC_TAR and IC_TX_TL.
#[derive(Clone, Copy)]
struct Settings([u32; 7]);

impl Settings {
    /// The registers as they are.
    fn read() -> Self {
        let r = regs();
        Settings([
            r.ic_con().read().bits(),
            r.ic_fs_scl_hcnt().read().bits(),
            r.ic_fs_scl_lcnt().read().bits(),
            r.ic_fs_spklen().read().bits(),
            r.ic_sda_hold().read().bits(),
            r.ic_tar().read().bits(),
            r.ic_tx_tl().read().bits(),
        ])
    }

    /// The registers written back (the controller disabled, as they must be written).
    fn write(self) {
        let r = regs();
        let [con, hcnt, lcnt, spklen, hold, tar, tl] = self.0;
        // SAFETY: each value was read from the same register after the HAL set it.
        #[allow(unsafe_code)]
        unsafe {
            r.ic_con().write(|w| w.bits(con));
            r.ic_fs_scl_hcnt().write(|w| w.bits(hcnt));
            r.ic_fs_scl_lcnt().write(|w| w.bits(lcnt));
            r.ic_fs_spklen().write(|w| w.bits(spklen));
            r.ic_sda_hold().write(|w| w.bits(hold));
            r.ic_tar().write(|w| w.bits(tar));
            r.ic_tx_tl().write(|w| w.bits(tl));
            r.ic_intr_mask().write(|w| w.bits(0));
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
        // SAFETY: any threshold up to the FIFO's 16 entries is valid; 0 masks every interrupt.
        #[allow(unsafe_code)]
        {
            r.ic_tx_tl().write(|w| unsafe { w.tx_tl().bits(TX_THRESHOLD) });
            r.ic_intr_mask().write(|w| unsafe { w.bits(0) });
        }
        let settings = Settings::read();
        r.ic_enable().write(|w| w.enable().set_bit());
        // SAFETY: the handler only takes the queue's critical section, as every other user does.
        #[allow(unsafe_code)]
        unsafe {
            cortex_m::peripheral::NVIC::unmask(pac::Interrupt::I2C0_IRQ)
        };
        QueuedI2c { _bus: bus, address, settings }
    }

    /// After a failed transfer: the controller reset (whatever it was waiting for is dropped,
    /// a START it could not send included) and set up again, the queue emptied, and the bus
    /// cleared if a device holds SDA low (a transfer cut off in the middle of a byte). A device
    /// that keeps SDA low through the clear is logged; the next transfer then fails again.
    fn recover(&mut self) {
        critical_section::with(|cs| {
            let mut q = QUEUE.borrow(cs).borrow_mut();
            // SAFETY: RESETS' I2C0 bit, set and cleared by this driver alone once the HAL set it up.
            #[allow(unsafe_code)]
            let resets = unsafe { &*pac::RESETS::ptr() };
            resets.reset().modify(|_, w| w.i2c0().set_bit());
            if super::clear::sda_held(Wiring::SDA) {
                match super::clear::clear(Wiring::SDA, Wiring::SCL) {
                    Some(pulses) => {
                        defmt::warn!("the display held SDA low: the bus cleared with {} clock pulses", pulses)
                    }
                    None => defmt::error!("the display holds SDA low through 9 clock pulses: its power needs cycling"),
                }
            }
            resets.reset().modify(|_, w| w.i2c0().clear_bit());
            while resets.reset_done().read().i2c0().bit_is_clear() {}
            self.settings.write();
            regs().ic_enable().write(|w| w.enable().set_bit());
            (q.head, q.len, q.abort) = (0, 0, None);
        });
    }
}

impl<P> embedded_hal::i2c::ErrorType for QueuedI2c<P> {
    type Error = BusError;
}

impl<P> embedded_hal::i2c::I2c for QueuedI2c<P> {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        use embedded_hal::i2c::Operation;
        if address != self.address {
            return Err(BusError::Unsupported);
        }
        take_abort()?;
        // Core 0 alone sends (and fails): a load and a store need no atomic swap (which the
        // Cortex-M0+ lacks).
        if FAILED.load(Ordering::Relaxed) {
            FAILED.store(false, Ordering::Relaxed);
            self.recover();
        }
        let mut left: usize = 0;
        for op in operations.iter() {
            match op {
                Operation::Write(bytes) => left += bytes.len(),
                Operation::Read(_) => return Err(BusError::Unsupported),
            }
        }
        if left == 0 {
            return Err(BusError::Unsupported);
        }
        /// IC_DATA_CMD's STOP bit.
        const STOP: u16 = 1 << 9;
        let mut bytes = operations.iter().flat_map(|op| match op {
            Operation::Write(b) => b.iter(),
            Operation::Read(_) => [].iter(),
        });
        // Queued in runs under one critical section each; while the queue is full, its words
        // move into the FIFO as the bus takes them.
        let mut progress = Progress::start();
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
            progress.check()?;
        }
        Ok(())
    }
}

/// An I2C module resets itself at power-on: nothing to pulse.
pub fn reset<D>(_line: &mut crate::wiring::Reset, _delay: &mut D) {}
