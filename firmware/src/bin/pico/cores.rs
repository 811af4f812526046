//! Both cores: core 1 is started once at boot and then runs each job core 0 hands it through
//! the SIO FIFO. There is one path: a board always has core 1, and so does the emulated one
//! (`cargo xtask board` runs core 1 and requires its tile share to be bit-identical too).

use crate::hal;
use firmware::app::Cores;
use hal::pac;

/// Core 1's stack. rp2040-hal guards its lowest 32 bytes with core 1's MPU, so an overflow
/// faults instead of corrupting memory.
static CORE1_STACK: hal::multicore::Stack<CORE1_STACK_WORDS> = hal::multicore::Stack::new();

/// Core 1's stack in words: 32 KiB where the scenes are baked. Its tile jobs need 6 KiB at
/// most (5,984 bytes at 296x128 over the five scenes, as the emulated board found it).
#[cfg(baked_scenes)]
const CORE1_STACK_WORDS: usize = 8192;
/// Core 1's stack in words: 10 KiB where the scenes are parsed on the board (`parse`, `slot`,
/// `orbit`), whose storage lives on core 0's stack and needs the rest (flip-link gives core 0
/// what the statics and the code copied to SRAM leave): with 32 KiB here the `parse` image of
/// the five scenes overflowed core 0's stack at boot, and with 16 KiB it did again once the
/// core's code in SRAM grew by 4 KiB (core 0 reaches 31,936 bytes in it; core 1 only traces).
#[cfg(not(baked_scenes))]
const CORE1_STACK_WORDS: usize = 2560;

/// Core 1: runs each job core 0 sends through the SIO FIFO and answers when it is done.
fn core1_main() {
    // SAFETY: core 1 uses only the SIO FIFO's core-1 side, which no other code on core 1 touches.
    #[allow(unsafe_code)]
    let pac = unsafe { pac::Peripherals::steal() };
    let mut sio = hal::Sio::new(pac.SIO);
    loop {
        let job = sio.fifo.read_blocking() as usize as *mut &mut (dyn FnMut() + Send);
        // SAFETY: core 0 sent the address of a job it keeps alive, and does not touch, until
        // this core answers below (`TwoCores::join`).
        #[allow(unsafe_code)]
        unsafe {
            (*job)()
        };
        sio.fifo.write_blocking(1);
    }
}

/// Both cores: core 1 runs the other piece of work (see [`core1_main`]).
pub struct TwoCores {
    fifo: hal::sio::SioFifo,
}

impl TwoCores {
    /// Starts core 1 (rp2040-hal's launch handshake through the FIFO). A core that does not
    /// start is a broken board: the firmware stops with the reason in the log.
    pub fn start(psm: &mut pac::PSM, ppb: &mut pac::PPB, mut fifo: hal::sio::SioFifo) -> Self {
        let mut mc = hal::multicore::Multicore::new(psm, ppb, &mut fifo);
        let cores = mc.cores();
        match CORE1_STACK.take().map(|stack| cores[1].spawn(stack, core1_main)) {
            Some(Ok(())) => TwoCores { fifo },
            Some(Err(e)) => defmt::panic!("core 1 did not start: {}", e),
            None => defmt::panic!("core 1's stack is taken"),
        }
    }
}

impl Cores for TwoCores {
    fn join(&mut self, there: &mut (dyn FnMut() + Send), here: &mut dyn FnMut()) {
        let mut job: &mut (dyn FnMut() + Send) = there;
        // Core 1 gets the address of `job` (a pointer to the closure and its vtable); both live
        // on this stack until core 1's answer has come back.
        self.fifo.write_blocking(&mut job as *mut &mut (dyn FnMut() + Send) as usize as u32);
        here();
        let _ = self.fifo.read_blocking();
    }
}
