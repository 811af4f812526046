//! The firmware half of a baked scene: the tables `examples/bake.rs` wrote, included as
//! `static`s (in flash on a board), traced with no parse, no set-up and no lattice build. The
//! mailbox and the rows are all the memory the render writes.
//!
//! `cargo run --example baked_scene`

use lattice_rt::{render, BitFrame, Frame, NoHooks, Scratch, Tracer};

mod baked {
    use lattice_rt::bake::prelude::*;
    include!("baked/sphere.rs");
}

fn main() {
    let baked = &baked::SPHERE;
    let tracer = Tracer::new(&baked.scene, &baked.lattice);
    // One mailbox entry per object and per composite; no rows for Bayer dithering.
    let (mut mailbox, mut rows) = ([0u32; 4], [0i16; 0]);
    let mut scratch = Scratch::new(&mut mailbox, &mut rows);
    let mut bytes = [0u8; 128 / 8 * 64];
    let mut frame = BitFrame::new(128, 64, &mut bytes).expect("room for 128x64");
    render(&tracer, &Frame::new(128, 64), &mut frame, &mut scratch, &mut NoHooks).expect("rendered");
    // A binary PBM on stdout: `cargo run --example baked_scene > sphere.pbm`.
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    write!(out, "P4\n128 64\n").and_then(|()| out.write_all(&bytes)).expect("stdout");
}
