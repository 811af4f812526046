//! A draw target of your own: the core renders into anything that implements
//! embedded-graphics' `DrawTarget<Color = BinaryColor>`, tile by tile, each tile in one
//! `fill_contiguous` call. Here the target is a text canvas, and the frame is the paper's chair
//! at 128x64 with Floyd-Steinberg error diffusion and silhouette lines.
//!
//! `cargo run --example custom_target`

use embedded_graphics::{pixelcolor::BinaryColor, prelude::*, primitives::Rectangle};
use lattice_rt::{render, Dither, Frame, LatticeConfig, Loaded, NoHooks, Storage, Tracer};

/// A canvas of characters, `#` for a lit pixel.
struct TextCanvas {
    size: Size,
    lit: Vec<bool>,
    /// `fill_contiguous` calls: one per tile.
    fills: usize,
}

impl OriginDimensions for TextCanvas {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for TextCanvas {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            if let (Ok(x), Ok(y)) = (u32::try_from(p.x), u32::try_from(p.y)) {
                if x < self.size.width && y < self.size.height {
                    self.lit[(y * self.size.width + x) as usize] = c.is_on();
                }
            }
        }
        Ok(())
    }

    /// The render hands over a whole tile at once: a driver would send it in one transfer.
    fn fill_contiguous<I: IntoIterator<Item = BinaryColor>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        self.fills += 1;
        self.draw_iter(area.points().zip(colors).map(|(p, c)| Pixel(p, c)))
    }
}

fn main() {
    let text = include_str!("../scenes/chair.scene");
    // The chair's five boxes and its lattice; 1,024 rows of dither carries for 128 pixels.
    let mut storage = Storage::<f32, 16, 4, 128, 2048, 1024>::new();
    let Loaded { scene, lattice, mut scratch } =
        storage.view().load(text, &LatticeConfig::default()).expect("the chair fits the storage");
    let tracer = Tracer::new(&scene, &lattice);
    let frame = Frame { dither: Dither::FloydSteinberg, outline: true, ..Frame::new(128, 64) };
    let mut canvas = TextCanvas { size: Size::new(128, 64), lit: vec![false; 128 * 64], fills: 0 };
    render(&tracer, &frame, &mut canvas, &mut scratch, &mut NoHooks).expect("rendered");
    for row in canvas.lit.chunks(128) {
        println!("{}", row.iter().map(|&on| if on { '#' } else { ' ' }).collect::<String>());
    }
    println!("{} tiles, each drawn in one fill_contiguous call", canvas.fills);
}
