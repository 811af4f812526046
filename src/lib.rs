//! A `no_std`, allocation-free Whitted ray tracer built on the lattice-structured space
//! subdivision of a 1988 paper, for microcontrollers with a small monochrome display.
//!
//! Spheres, cylinders, cones, boxes and composites of them; ambient and diffuse light, shadows,
//! mirror reflection and refraction (the paper's eq. 1). The world is cut into a lattice of cells
//! (per-axis coordinate lists, a nested lattice per composite) and a ray steps from cell to
//! neighbouring cell by index arithmetic. The frame is rendered tile by tile into any
//! [`embedded-graphics`](embedded_graphics_core) draw target and dithered to 1 bit, so no
//! frame buffer is needed. All memory comes from the caller, in capacities fixed at compile
//! time ([`Storage`]) or, with the `alloc` feature, on the heap (`HeapStorage`). The tracer is
//! written once over a scalar trait ([`Real`]): `f64`, `f32`, or Q16.16 fixed point ([`Fx`])
//! for cores without a floating-point unit.
//!
//! # Example
//!
//! ```
//! use embedded_graphics::{mock_display::MockDisplay, pixelcolor::BinaryColor};
//! use lattice_rt::{render, Frame, LatticeConfig, Loaded, NoHooks, Storage, Tracer};
//!
//! // The view is fitted to the frame's shape (square pixels): 2:1 unless the camera says otherwise.
//! let text = "camera eye 0 0 -4\nlight directional dir -1 -1 1\nsphere radius 1\n";
//! // Capacities: objects, lattices, coordinates, words (cells, references, mailbox), dither rows.
//! let mut storage = Storage::<f32, 4, 1, 16, 64, 0>::new();
//! let Loaded { scene, lattice, mut scratch } = storage.view().load(text, &LatticeConfig::default()).expect("fits");
//! let tracer = Tracer::new(&scene, &lattice);
//! let mut display = MockDisplay::<BinaryColor>::new();
//! render(&tracer, &Frame::new(64, 32), &mut display, &mut scratch, &mut NoHooks).expect("rendered");
//! assert_eq!(display.affected_area().size.height, 32); // every row drawn: a lit sphere on black
//! ```
//!
//! More in the repository's `examples/`: a draw target of your own, and a scene baked into
//! `static` tables at build time (what firmware does, so it links no parser).
//!
//! # Where things are
//!
//! In the order data flows: [`scene`] (the scene format, [`parse`], validation into the
//! tracer's scalar, where each object can appear), [`camera`], [`lattice`] and the other [`accel`]erators, [`trace`] (the intersection tree, without recursion),
//! [`sample`], [`outline`] and [`dither`], and [`render`](mod@render) (the tile loop, progressive passes,
//! two-core bands). [`storage`] and [`load`] hold and fill the memory; [`bake`] writes a scene
//! as static tables. The repository's `ARCHITECTURE.md` draws the whole.
//!
//! # Features
//!
//! Default: `spheres`, `cones` (the shapes beyond boxes and cylinders), `edge-sampling`,
//! `coarse-sampling` and `eye-hulls` (the real-time levers), `diffusion` (error-diffusion
//! dithers), `tile-lists` (scenes of more than 64 objects), `budget` (a lattice that fits a
//! byte budget), `hit-counts` (rays that hit, in [`Stats`]). Each can be left out to make a
//! smaller image; a build without one refuses what needs it with a typed error. Optional:
//! `alloc` (heap storage), `bake` (writing static tables), `generate` (seeded random scenes),
//! `defmt` (firmware logging of the error types), `tile8` and `compact` (the smallest boards).
//!
//! The crate needs Rust 1.87 or newer.
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
// the lattice over it, the storage that holds both and the loading that fills it, then tracing,
// sampling, dithering and the
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
pub mod scene;
pub use scene::text::ParseError;
pub use scene::{object_count, parse};
pub use scene::{Effects, Parts, Scene, SceneBuilder, SceneError};
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
#[cfg(feature = "alloc")]
pub use render::HeapScratch;
#[cfg(feature = "alloc")]
pub use storage::HeapStorage;
pub use storage::{Buffers, Sizes, Storage, StorageView};
pub mod trace;
pub use trace::{EyeRays, Tracer};
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
pub use bitframe::{BitFrame, ShadeFrame};
