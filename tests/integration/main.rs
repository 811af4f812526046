//! The core's integration tests, one binary (each file a module: `cargo test --test integration
//! golden::` runs one), so the core's generic code is compiled for the tests once, not once per
//! file.

mod common;

mod accel_agree;
mod bad_input;
mod compact_builtins;
mod effects;
mod eye_window;
mod far_away;
mod golden;
mod hard_cases;
mod nff;
mod parse_errors;
mod parse_fuzz;
mod progressive;
mod sampling;
mod shares;
mod square_pixels;
mod windows_serve;
