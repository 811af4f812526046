//! Per-tile culling: what the render skips because of where each object can appear (its
//! [`Region`](crate::scene::Region), worked out when the scene was validated). Every answer here
//! only removes work: a tile or a block that culling passes over gets the same picture it
//! would have got tested.
//!
//! - `tiles`: which objects can appear in a tile (a mask of the first 64, or a list per tile for
//!   larger scenes).
//! - `block`: whether two-level sampling may fill a block of pixels from its corners.

pub(crate) mod block;
#[cfg(test)]
mod tests;
pub(crate) mod tiles;
