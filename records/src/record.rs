//! What a board reports, and the channel it reports through.
//!
//! A record is encoded with postcard and framed by COBS (each ends in a zero byte) into a ring
//! buffer in the board's RAM, [`Channel`], laid out like an RTT up channel: the host (the
//! emulated board's runner, or a probe) finds it by its symbol, copies what lies between its read
//! and write offsets and moves the read offset on. When the host does not keep up (or there is
//! none, on a board without a probe) a record that does not fit is dropped and counted, never
//! waited for.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicU32, Ordering};
use serde::{Deserialize, Serialize};

/// One frame on the panel, as the board measured it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameDone {
    /// Index of the scene in the image's list.
    pub scene: u8,
    /// Microseconds from the LED going on to the frame on the panel.
    pub us: u64,
    /// Microseconds from the LED going on to the first tile: the scene's set-up (with run-time
    /// parsing, the parse and the lattice build) and the tracer's.
    pub setup_us: u64,
    /// Microseconds each core spent on its tile share (core 0, core 1).
    pub share_us: [u64; 2],
    /// Rays traced by kind: eye, shadow, reflection, refraction.
    pub rays: [u64; 4],
    /// Object tests.
    pub object_tests: u64,
    /// Lattice cells visited.
    pub cells: u64,
    /// Bytes of the scene's lattice.
    pub lattice_bytes: u32,
    /// Deepest stack use so far on core 0, in bytes.
    pub stack: u32,
}

/// What a board reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Record {
    /// The firmware is up: how many scenes it shows, at what clock and bus speed.
    Started {
        /// Scenes embedded.
        scenes: u8,
        /// clk_sys in MHz.
        clk_mhz: u16,
        /// The display bus in kHz.
        bus_khz: u16,
    },
    /// A frame of a scene is on the panel.
    Frame(FrameDone),
    /// A frame of the ladder image (rung `rung` of `frame::LADDER`) is on the panel.
    Rung {
        /// The rung.
        rung: u8,
        /// The frame.
        frame: FrameDone,
    },
    /// An orbit around scene `scene` ended: `frames` frames in `us` microseconds.
    Orbit {
        /// Index of the scene.
        scene: u8,
        /// Frames shown.
        frames: u32,
        /// Microseconds for all of them.
        us: u64,
        /// Deepest stack use so far on core 0, in bytes.
        stack: u32,
    },
    /// Scene `scene` could not be shown (the log says why).
    Failed {
        /// Index of the scene.
        scene: u8,
    },
    /// The last boot ended in a panic: its reason is on the panel (drawn by [`crate::message`])
    /// and in the log.
    Panicked,
}

/// Bytes of a [`Channel`]'s ring buffer.
pub const CHANNEL_BYTES: usize = 1024;
/// The first bytes of a [`Channel`], by which a host checks it found one.
pub const CHANNEL_MAGIC: [u8; 8] = *b"LRT-RECS";
/// Most bytes one encoded record takes.
const MAX_RECORD: usize = 96;

/// The ring buffer a board writes records into (one writer: core 0). Layout (`repr(C)`, all
/// little-endian words): magic, size, write offset, read offset (the host's), records dropped,
/// then the buffer.
#[repr(C)]
pub struct Channel {
    magic: [u8; 8],
    size: u32,
    write: AtomicU32,
    read: AtomicU32,
    dropped: AtomicU32,
    buf: UnsafeCell<[u8; CHANNEL_BYTES]>,
}

// SAFETY: one core writes the buffer (`send` takes care of the offsets with atomics); the host
// reads it from outside the program.
unsafe impl Sync for Channel {}

impl Channel {
    /// An empty channel.
    pub const fn new() -> Self {
        Channel {
            magic: CHANNEL_MAGIC,
            size: CHANNEL_BYTES as u32,
            write: AtomicU32::new(0),
            read: AtomicU32::new(0),
            dropped: AtomicU32::new(0),
            buf: UnsafeCell::new([0; CHANNEL_BYTES]),
        }
    }

    /// Appends `record`, or drops it (and counts it) when the host has not made room.
    pub fn send(&self, record: &Record) {
        let mut bytes = [0u8; MAX_RECORD];
        let Ok(encoded) = postcard::to_slice_cobs(record, &mut bytes) else {
            self.drop_one();
            return;
        };
        let n = encoded.len();
        let write = self.write.load(Ordering::Relaxed) as usize;
        let read = self.read.load(Ordering::Acquire) as usize;
        let free = (read + CHANNEL_BYTES - write - 1) % CHANNEL_BYTES;
        if n > free {
            self.drop_one();
            return;
        }
        let buf = self.buf.get() as *mut u8;
        for (i, &b) in encoded.iter().enumerate() {
            // SAFETY: the offset is below CHANNEL_BYTES, and the bytes between the write and
            // the read offset belong to the writer until the write offset moves past them.
            #[allow(unsafe_code)]
            unsafe {
                buf.add((write + i) % CHANNEL_BYTES).write_volatile(b)
            };
        }
        self.write.store(((write + n) % CHANNEL_BYTES) as u32, Ordering::Release);
    }
}

impl Channel {
    /// Counts a dropped record (load and store: the Cortex-M0+ has no atomic add, and there is
    /// one writer).
    fn drop_one(&self) {
        self.dropped.store(self.dropped.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
    }
}

impl Default for Channel {
    fn default() -> Self {
        Self::new()
    }
}

impl Record {
    /// Decodes one record from its frame, the bytes a [`Channel`] holds up to and including a
    /// zero; `None` when they are not a record.
    pub fn decode(frame: &mut [u8]) -> Option<Record> {
        postcard::from_bytes_cobs(frame).ok()
    }
}
