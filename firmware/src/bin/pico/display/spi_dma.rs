//! Bytes to SPI0 by DMA, paced by SPI0's TX requests, while the cores go on: the gray mode's
//! pages (`gray`). The chip select and data/command lines are the caller's.
//!
//! The Sharp memory LCD's line writes (`display/sharp.rs`) do the same with their own copy of
//! these few register writes: built on this module, the 400x240 chair took 62.635 M cycles
//! instead of 62.460 M (the code's layout in SRAM, not its instructions, which are the same),
//! over its 62.5 M target.

use crate::hal;

/// TREQ_SEL: SPI0's TX requests.
const DREQ_SPI0_TX: u8 = 16;

/// Takes the DMA block out of reset and turns SPI0's TX requests on.
pub fn enable() {
    // SAFETY: RESETS' DMA bit (only these channels use the DMA) and SPI0's DMA control, which
    // the HAL's SPI driver leaves alone.
    #[allow(unsafe_code)]
    unsafe {
        let resets = &*hal::pac::RESETS::ptr();
        resets.reset().modify(|_, w| w.dma().clear_bit());
        while resets.reset_done().read().dma().bit_is_clear() {}
        (*hal::pac::SPI0::ptr()).sspdmacr().modify(|_, w| w.txdmae().set_bit());
    }
}

/// Starts channel `ch` sending the `len` bytes at `from` to SPI0.
///
/// # Safety
/// The bytes must stay as they are, and in place, until [`finish`] on `ch` has returned.
#[allow(unsafe_code)]
pub unsafe fn start(ch: usize, from: *const u8, len: usize) {
    core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    let c = (*hal::pac::DMA::ptr()).ch(ch);
    c.ch_read_addr().write(|w| w.bits(from as u32));
    c.ch_write_addr().write(|w| w.bits((*hal::pac::SPI0::ptr()).sspdr().as_ptr() as u32));
    c.ch_trans_count().write(|w| w.bits(len as u32));
    c.ch_ctrl_trig().write(|w| {
        w.data_size().size_byte().incr_read().set_bit().treq_sel().bits(DREQ_SPI0_TX);
        w.chain_to().bits(ch as u8).en().set_bit()
    });
}

/// Waits until channel `ch` has sent its last byte and the bus is idle, then empties SPI0's
/// receive FIFO (the DMA only sends) and clears its overrun flag.
pub fn finish(ch: usize) {
    // SAFETY: reads of the channel's and SPI0's status, and of SPI0's data register (what it
    // received, which nothing wants), and a write of its interrupt clear register.
    #[allow(unsafe_code)]
    unsafe {
        let (dma, spi) = (&*hal::pac::DMA::ptr(), &*hal::pac::SPI0::ptr());
        while dma.ch(ch).ch_ctrl_trig().read().busy().bit_is_set() {}
        while spi.sspsr().read().bsy().bit_is_set() {}
        while spi.sspsr().read().rne().bit_is_set() {
            spi.sspdr().read();
        }
        spi.sspicr().write(|w| w.roric().clear_bit_by_one());
    }
    core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
}
