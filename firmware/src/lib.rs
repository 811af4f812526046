//! The render loop shared by every board: the scenes embedded from `scenes/`, fixed-capacity
//! storage for them, and one function that parses, builds the lattice and renders a frame tile
//! by tile into any 1-bit draw target. Board binaries (`src/bin/`) only supply the target,
//! the clock and the log.
#![no_std]
#![deny(missing_docs)]

pub mod app;
#[cfg(feature = "compact")]
pub mod builtins;
pub mod stack;
