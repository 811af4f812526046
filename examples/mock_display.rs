//! The smallest complete use of the core: a scene in text, fixed-size storage, a render into
//! embedded-graphics' `MockDisplay` (as a display driver's test would use it), printed.
//!
//! `cargo run --example mock_display`

use embedded_graphics::{mock_display::MockDisplay, pixelcolor::BinaryColor, prelude::*};
use lattice_rt::{render, Frame, LatticeConfig, Loaded, NoHooks, Storage, Tracer};

/// A sphere lit from the upper left; the view is fitted to a 2:1 frame (square pixels).
const SCENE: &str = "camera eye 0 0 -4\nlight directional dir -1 -1 1\nsphere radius 1\n";

fn main() {
    // Capacities: objects, lattices, coordinates, words (cells, references, mailbox), dither rows.
    let mut storage = Storage::<f32, 4, 1, 16, 64, 0>::new();
    let Loaded { scene, lattice, mut scratch } =
        storage.view().load(SCENE, &LatticeConfig::default()).expect("the scene fits the storage");
    let tracer = Tracer::new(&scene, &lattice);
    let mut display = MockDisplay::<BinaryColor>::new();
    let stats = render(&tracer, &Frame::new(64, 32), &mut display, &mut scratch, &mut NoHooks).expect("rendered");
    for y in 0..32 {
        let row: String = (0..64)
            .map(|x| if display.get_pixel(Point::new(x, y)) == Some(BinaryColor::On) { '#' } else { '.' })
            .collect();
        println!("{row}");
    }
    println!("{} eye rays, {} object tests", stats.rays[0], stats.object_tests);
}
