//! The contract between the firmware and the host: the frame every board renders
//! ([`frame`]), and what a board reports ([`Record`]), written by the firmware into a
//! [`Channel`] in its RAM and read back by the host as the same types: no log line is parsed
//! as text. The defmt log stays for people; records are for `cargo xtask board`.
#![no_std]
#![deny(missing_docs)]
#[cfg(feature = "alloc")]
extern crate alloc;

pub mod frame;
pub mod message;
mod record;
pub mod slot;

pub use record::{Channel, FrameDone, Record, CHANNEL_BYTES, CHANNEL_MAGIC};
