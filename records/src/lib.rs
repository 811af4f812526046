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

/// Cells per object of the lattice a Pico or Pico 2 image bakes for a scene (world and
/// sub-lattices, `Resolution::Auto`), where it fits the flash the objects leave: four times
/// host-sim's default of 2. From flash through the XIP cache, a finer lattice's extra cells
/// cost less than the box tests of fuller cells: on the emulated Pico, the SPD's rings at size
/// 5 take 246.3 M cycles at 2 cells per object, 237.6 M at 4 and 231.1 M at 8; the sphereflake
/// (balls) at size 3 138.9, 137.1 and 137.2 M, and 143.6 M at 16.
pub const BAKED_DENSITY: f64 = 8.0;
