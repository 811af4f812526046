//! Culling: where on the image, and across a light, each object can appear, and what the
//! render and the tracer skip because of it. Every answer here only removes work: a ray, a
//! tile or a block that culling passes over gets the same picture it would have got tested.
//!
//! Rooms, from the leaf up:
//! - [`region`]: the regions an object holds (eye window, eye hull, shadow window: one
//!   [`Region`]) and their tests against a window position or rectangle. A leaf on the numbers.
//! - `build`: an object's region from the camera, the first light and the object, through the
//!   eye's `projection` (the hull's own builder, `hull`, only with the `eye-hulls` feature).
//! - `tiles`: which objects can appear in a tile (a mask of the first 64, or a list per tile for
//!   larger scenes).
//! - `block`: whether two-level sampling may fill a block of pixels from its corners.

pub(crate) mod block;
pub(crate) mod build;
#[cfg(feature = "eye-hulls")]
mod hull;
mod projection;
pub mod region;
#[cfg(test)]
mod tests;
pub(crate) mod tiles;

pub use region::{
    Culled, EyeHull, EyeWindow, HullEdge, Region, ShadowWindow, EYE_MARGIN, HULL_EDGES, NO_HULL, WHOLE_PLANE,
};

/// Calls `f` with each object of a mask (bit `i`: object `i`, of the first 64) that a scene of
/// `n` objects has, lowest first, until `f` answers true; returns whether it did. The mask is
/// taken by halves of 32 bits (a Cortex-M0+ counts and shifts 64-bit values in library calls),
/// each cut to the objects there are; two plain loops, which the tracer's eye rays run faster
/// than an iterator's state.
#[inline(always)]
pub(crate) fn any_object(mask: u64, n: usize, mut f: impl FnMut(usize) -> bool) -> bool {
    let below = |n: usize| if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    for (half, base) in [(mask as u32, 0), ((mask >> 32) as u32, 32)] {
        let mut left = half & below(n.saturating_sub(base));
        while left != 0 {
            let i = base + left.trailing_zeros() as usize;
            left &= left - 1;
            if f(i) {
                return true;
            }
        }
    }
    false
}
