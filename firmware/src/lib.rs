//! The render loop shared by every board: the scenes embedded from `scenes/`, fixed-capacity
//! storage for them, and one function that parses, builds the lattice and renders a frame tile
//! by tile into any 1-bit draw target. Board binaries (`src/bin/`) only supply the target,
//! the clock and the log.
#![no_std]
#![deny(missing_docs)]

pub mod app;
/// The compiler's memory helpers for images built for size (the `compact` feature): the ARM
/// EABI's copies and fills (`__aeabi_memcpy*`, `__aeabi_memset*`, `__aeabi_memclr*`, which the
/// compiler calls to move and zero structures), each a loop of a few dozen bytes instead of
/// compiler-builtins' unrolled and specialised code (whose symbols are weak, so these take their
/// place). The results are the same; they cost more instructions (the chair's frame 6 % more).
/// The loops move each word or byte with a volatile access, so that the compiler cannot turn
/// them back into calls to themselves. (A division loop of the same kind saved 300 B more, at
/// 1.4x the frame's instructions: compiler-builtins' division stays.)
///
/// Its code has no inner attributes, so the host's tests (`tests/integration/compact_builtins.rs`) include it
/// and check it against Rust's own slice copies.
#[cfg(feature = "compact")]
pub mod builtins;
pub mod schedule;
#[cfg(feature = "slot")]
pub mod slot;
pub mod stack;
