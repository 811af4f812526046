//! host-sim as a library: loading scenes, rendering them on the host, writing images, and the
//! command line's vocabulary, shared by the `host-sim` binary and `cargo xtask` (the project's
//! checks and studies, which render the same frames to compare against).

pub mod cli;
pub mod load;
pub mod orbit;
pub mod output;
pub mod pov;
pub mod progress;
pub mod report;
pub mod run;
pub mod shared;
pub mod spd;
pub mod stdout;
pub mod uf2;
