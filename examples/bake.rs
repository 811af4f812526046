//! The build-script half of a baked scene: parses a scene and builds its lattice on the host,
//! then writes both as Rust `static` tables (`lattice_rt::bake::source`), which firmware
//! includes so that it links no parser and keeps neither objects nor lattice in RAM. The
//! tables of `examples/baked/sphere.rs` are this example's output (CI checks they still are):
//!
//! `cargo run --example bake --features bake > examples/baked/sphere.rs`

use lattice_rt::{bake, LatticeConfig, Loaded, Storage};

fn main() {
    let text = include_str!("baked/sphere.scene");
    let mut storage = Storage::<f32, 4, 2, 64, 512, 0>::new();
    let Loaded { scene, lattice, .. } =
        storage.view().load(text, &LatticeConfig::default()).expect("the scene fits the storage");
    println!("// Written by `cargo run --example bake --features bake` from examples/baked/sphere.scene.");
    print!("{}", bake::source("SPHERE", "f32", &scene, Some(&lattice)));
}
