#![doc = include_str!("../README.md")]
#![no_std]
#![deny(missing_docs, missing_debug_implementations, unsafe_code, rustdoc::broken_intra_doc_links)]
// Matrix and lattice code indexes rows and axes as the maths does; `!(a < b)` is deliberate
// wherever a NaN must fail a test.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]
#![deny(trivial_casts, trivial_numeric_casts, unused_qualifications, missing_copy_implementations)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(test)]
extern crate std;

// In the order the data flows: numbers, geometry, the scene (text in, validated scene out),
// the lattice over it, the storage that holds both and the loading that fills it, then tracing, sampling, dithering and the
// tile loop that writes a display.
mod bounds;
pub mod scalar;
pub use scalar::{F32Micro, F32MicroNewton, Real};
pub mod fixed;
pub use fixed::Fx;
pub mod math;
pub use math::{Aabb, Affine, Linear, Ray, Vec3};
pub mod camera;
pub mod shape;
pub use shape::{Shape, ShapeHit};
pub mod cull;
pub mod scene;
pub use scene::text::{parse, ParseError};
pub use scene::{Parts, Scene, SceneBuilder, SceneError};
pub mod accel;
#[cfg(any(test, feature = "generate"))]
pub mod generate;
pub use accel::{Accelerator, BoundingBox, BruteForce, Hit, Query, Stats};
pub mod lattice;
pub use lattice::{Lattice, LatticeConfig, LatticeStorage};
pub mod load;
pub mod storage;
pub use load::{LoadError, Loaded};
pub mod bake;
pub use bake::Baked;
pub use storage::{Buffers, Sizes, Storage, StorageView};
#[cfg(feature = "alloc")]
pub use storage::{HeapScratch, HeapStorage};
pub mod trace;
pub use trace::{Effects, EyeRays, Tracer};
pub mod dither;
pub mod sample;
pub use dither::{Dither, Tone};
pub mod outline;
pub mod render;
pub use render::{
    dither_band, dither_tiles, render, render_pass, render_share, trace_pass, trace_share, Frame, Hooks, KeptTile,
    NoHooks, Sampling, Scratch, Share, Traced,
};
pub mod bitframe;
pub use bitframe::BitFrame;
