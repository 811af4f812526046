//! Kernel benchmarks (criterion): each primitive's intersection, a lattice walk, a whole tile.
//! `cargo bench --bench kernels`; regressions show as changes against the last run.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use lattice_rt::scene::Object;
use lattice_rt::shape::Shape;
use lattice_rt::{
    parse, render, Accelerator, BitFrame, Frame, Fx, HeapStorage, LatticeConfig, NoHooks, Query, Ray, Real, Scratch,
    Sizes, Tracer, Vec3,
};

fn primitives(c: &mut Criterion) {
    let r = Ray::new(Vec3::new(-5.0, 0.3, 0.2), Vec3::new(1.0, 0.05, 0.02));
    for (name, s) in [
        ("sphere", Shape::Sphere),
        ("cylinder", Shape::Cylinder),
        ("cone", Shape::Cone { top: 0.3 }),
        ("box", Shape::Box),
    ] {
        c.bench_function(&format!("intersect {name} f64"), |b| {
            b.iter(|| black_box(s).intersect(black_box(&r), 0.0, f64::MAX))
        });
    }
    let rf = Ray::new(
        Vec3::new(Fx::from_f64(-5.0), Fx::from_f64(0.3), Fx::from_f64(0.2)),
        Vec3::new(Fx::ONE, Fx::from_f64(0.05), Fx::from_f64(0.02)),
    );
    c.bench_function("intersect sphere fixed", |b| {
        b.iter(|| black_box(Shape::<Fx>::Sphere).intersect(black_box(&rf), Fx::ZERO, Fx::MAX))
    });
}

fn scene_parts<'a, R: Real>(
    text: &str,
    (st, parts): &'a mut (Vec<Object<R>>, lattice_rt::Parts<R>),
) -> lattice_rt::Scene<'a, R> {
    *st = vec![Object::default(); 64];
    parse::<R>(text, st, parts).unwrap()
}

fn walk_and_tile(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/desk.scene")).unwrap();
    let mut st = Default::default();
    let scene = scene_parts::<f64>(&text, &mut st);
    let cfg = LatticeConfig::default();
    let mut storage = HeapStorage::new(Sizes { objects: 0, ..Sizes::of(&scene, Some(&cfg), &Frame::new(8, 8)) });
    let (lat, _) = storage.view().split().1.lattice(&scene, &cfg).unwrap();
    let ray = scene.camera().ray(81, 99, 160, 100);
    c.bench_function("lattice walk (cells only), desk", |b| {
        b.iter(|| {
            let mut n = 0;
            lat.walk_cells(black_box(&ray), 0.0, f64::MAX, |_, _, _| n += 1);
            n
        })
    });
    let mut mb = vec![0; Query::mailbox_len(&scene)];
    c.bench_function("lattice nearest, desk eye ray", |b| {
        b.iter(|| {
            let mut q = Query::new(&mut mb);
            lat.nearest(&scene, black_box(&ray), 0.0, f64::MAX, &mut q)
        })
    });
    let tracer = Tracer::new(&scene, &lat);
    let frame = Frame::new(8, 8);
    c.bench_function("tile 8x8, desk, f64", |b| {
        b.iter(|| {
            let mut bits = [0u8; 8];
            let mut target = BitFrame::new(8, 8, &mut bits).unwrap();
            let mut mb = [0u32; 32];
            render(&tracer, &frame, &mut target, &mut Scratch::new(&mut mb, &mut []), &mut NoHooks).unwrap()
        })
    });
}

/// The per-test levers of the Pico's ladder in fixed point, each beside what it replaced: a
/// shadow ray towards the first light with its direction mapped afresh or taken from the scene,
/// a box face's world normal mapped or kept by the query, a product with a power of two or a
/// shift.
fn levers(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/chair.scene")).unwrap();
    let mut st = Default::default();
    let scene = scene_parts::<Fx>(&text, &mut st);
    let Some(&lattice_rt::scene::Light::Directional { to_light, .. }) = scene.lights().first() else {
        panic!("the chair has a directional light")
    };
    let seat = &scene.objects()[1];
    let ray = Ray::new(Vec3::new(Fx::from_f64(0.1), Fx::from_f64(0.05), Fx::from_f64(-0.2)), to_light);
    c.bench_function("shadow test, seat, fixed: direction mapped afresh", |b| {
        b.iter(|| black_box(seat).intersect(black_box(&ray), Fx::ZERO, Fx::MAX))
    });
    c.bench_function("shadow test, seat, fixed: first light's direction from the scene", |b| {
        b.iter(|| black_box(seat).intersect_first_light_ray(black_box(&ray), Fx::ZERO, Fx::MAX))
    });
    let up = Vec3::new(Fx::ZERO, Fx::ONE, Fx::ZERO);
    c.bench_function("world normal, floor top, fixed: mapped", |b| {
        b.iter(|| black_box(&scene.objects()[0]).world_normal(black_box(up)))
    });
    let mut mb = vec![0; Query::mailbox_len(&scene)];
    let mut w = lattice_rt::trace::Work::new(&mut mb);
    c.bench_function("world normal, floor top, fixed: kept by the tracer's work", |b| {
        b.iter(|| w.world_normal(black_box(&scene), 0, black_box(up)))
    });
    let (x, p) = (Fx::from_f64(2.71), Fx::from_f64(0.125));
    c.bench_function("fixed times 2^-3: product", |b| b.iter(|| black_box(x) * black_box(p)));
    c.bench_function("fixed times 2^-3: shift", |b| b.iter(|| black_box(x).mul_pow2(black_box(Fx::pow2(-3)))));
    // The slab test's product (an origin several units off times a reciprocal above 1) and its
    // reciprocal: both factors 1 or more, below 128.
    let (o, d) = (Fx::from_f64(5.3), Fx::from_f64(0.37));
    let inv = d.recip();
    c.bench_function("fixed product, factors 1 to 128", |b| b.iter(|| black_box(o) * black_box(inv)));
    c.bench_function("fixed reciprocal", |b| b.iter(|| black_box(d).recip()));
    // An eye ray: its direction from the pixel's factors (six products), or from the column's
    // and the row's parts a tile keeps (three sums), the same ray.
    let cam = scene.camera();
    let (u, v) = (Fx::from_f64(0.3), Fx::from_f64(-0.2));
    c.bench_function("eye ray, fixed: forward + right u + up v", |b| {
        b.iter(|| cam.ray_through(black_box(u), black_box(v)))
    });
    let (column, row) = (cam.column(u), cam.row(v));
    c.bench_function("eye ray, fixed: the column's and the row's parts kept", |b| {
        b.iter(|| cam.ray_from(black_box(column), black_box(row)))
    });
    // Floyd-Steinberg over a 16x16 tile (the Pico's), from a band's carries.
    let levels: Vec<u8> = (0..256).map(|i| ((i * 37) % 65) as u8).collect();
    let mut carries = vec![0i16; lattice_rt::dither::Carry::len(16)];
    let mut out = [embedded_graphics::pixelcolor::BinaryColor::Off; 256];
    c.bench_function("floyd-steinberg, 16x16 tile", |b| {
        b.iter(|| {
            let mut carry = lattice_rt::dither::Carry::new(&mut carries, 16).unwrap();
            carry.next_band();
            carry.tile(lattice_rt::Dither::FloydSteinberg, (0, 0), 16, 16, black_box(&levels), &mut out);
        })
    });
}

/// The chair's frame as the Pico renders it (fixed point, 16x16 tiles, Floyd-Steinberg, lines,
/// the boards' cutoff), sampled adaptively in one level and in two (the panels'): the whole
/// frame, eye rays and the sampler's fills together.
fn sampling(c: &mut Criterion) {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/chair.scene")).unwrap();
    let mut st = Default::default();
    let scene = scene_parts::<Fx>(&text, &mut st);
    let cfg = LatticeConfig::default();
    let panel = Frame {
        tile: 16,
        dither: lattice_rt::Dither::FloydSteinberg,
        outline: true,
        cutoff: Some(7),
        ..Frame::new(128, 64)
    };
    let mut storage = HeapStorage::new(Sizes { objects: 0, ..Sizes::of(&scene, Some(&cfg), &panel) });
    let (lat, _) = storage.view().split().1.lattice(&scene, &cfg).unwrap();
    let tracer = Tracer::new(&scene, &lat);
    for (name, coarse) in [("one level", false), ("two levels", true)] {
        let frame = Frame { sampling: lattice_rt::Sampling::Adaptive { contrast: 4, coarse }, ..panel };
        let mut scratch = lattice_rt::HeapScratch::new(&scene, &frame);
        c.bench_function(&format!("chair frame, fixed, the Pico's: adaptive in {name}"), |b| {
            b.iter(|| {
                let mut bits = [0u8; 128 * 64 / 8];
                let mut target = BitFrame::new(128, 64, &mut bits).unwrap();
                render(&tracer, black_box(&frame), &mut target, &mut scratch.scratch(), &mut NoHooks).unwrap()
            })
        });
    }
}

criterion_group!(benches, primitives, walk_and_tile, levers, sampling);
criterion_main!(benches);
