#![doc = include_str!("../README.md")]
#![no_std]
#![deny(missing_docs, missing_debug_implementations, unsafe_code, rustdoc::broken_intra_doc_links)]
// Matrix and lattice code indexes rows and axes as the maths does; `!(a < b)` is deliberate
// wherever a NaN must fail a test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]
#![deny(trivial_casts, trivial_numeric_casts, unused_qualifications, missing_copy_implementations)]

#[cfg(test)]
extern crate std;
#[cfg(feature = "alloc")]
extern crate alloc;

pub mod math;
pub mod scalar;
pub mod scene;
pub mod shape;

pub use math::{Aabb, Affine, Ray, Vec3};
pub use scalar::{F32Micro, F32MicroNewton, Real};
pub use scene::{Scene, SceneBuilder, SceneError};
pub use shape::Shape;
pub mod accel;
pub mod lattice;
pub use accel::{Accelerator, BoundingBox, BruteForce, Hit, Query, Stats};
pub use lattice::{Lattice, LatticeConfig, LatticeStorage};
pub mod trace;
pub use trace::{Effects, Tracer};
pub mod dither;
pub use dither::Dither;
pub mod sample;
pub mod render;
pub use render::{render, Frame, Hooks, NoHooks, Sampling};
pub mod parse;
pub use parse::{parse, ParseError};
pub mod storage;
pub use storage::{Loaded, Scratch, Sizes, Storage, StorageView};
#[cfg(feature = "alloc")]
pub use storage::{HeapScratch, HeapStorage};
pub mod bitframe;
pub use bitframe::BitFrame;
#[cfg(any(test, feature = "generate"))]
pub mod generate;
pub mod fixed;
pub use fixed::Fx;
