//! The scene slot in flash (`board_records::slot`): the text a user wrote beside the prebuilt
//! `slot` image, read where the flash is mapped (XIP), and the message the panel shows when
//! there is no scene to show.

use board_records::slot::{self, SlotError};
use core::fmt::{self, Write};

/// The scene text in the slot, or why there is none.
pub fn text() -> Result<&'static str, SlotError> {
    // SAFETY: the flash is mapped read-only at 0x10000000 for as long as the board runs, the
    // slot lies within it (1 MiB in, 64 KiB of a 2 MiB flash), and nothing writes the flash
    // while the image runs; `u8` has no invalid values.
    let bytes = unsafe { core::slice::from_raw_parts(slot::ADDRESS as *const u8, slot::SIZE) };
    slot::read(bytes)
}

/// A message of at most 160 bytes, formatted without allocation (longer text is cut).
#[derive(Clone)]
pub struct Message {
    bytes: [u8; 160],
    len: usize,
}

impl Message {
    /// `what` formatted.
    pub fn of(what: impl fmt::Display) -> Message {
        let mut m = Message { bytes: [0; 160], len: 0 };
        let _ = write!(m, "{what}");
        m
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        // Whole characters only are appended (`write_str` cuts at a character boundary).
        core::str::from_utf8(&self.bytes[..self.len]).unwrap_or("")
    }
}

impl Write for Message {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let room = self.bytes.len() - self.len;
        let mut n = s.len().min(room);
        while !s.is_char_boundary(n) {
            n -= 1;
        }
        self.bytes[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        Ok(())
    }
}
