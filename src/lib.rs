#![doc = include_str!("../README.md")]
#![no_std]
#![deny(missing_docs, missing_debug_implementations, unsafe_code, rustdoc::broken_intra_doc_links)]

#[cfg(test)]
extern crate std;

pub mod math;
pub mod scalar;
pub mod scene;
pub mod shape;

pub use math::{Aabb, Affine, Ray, Vec3};
pub use scalar::Real;
pub use scene::{Scene, SceneBuilder, SceneError};
pub use shape::Shape;
