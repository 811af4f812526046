//! Pixels are square: a sphere straight ahead is as wide as it is tall at every frame shape,
//! whichever form of field of view the scene gives (first-look.md measured 1.25 at 128x64 and
//! 0.605 at 200x200 before views were fitted to frames).

use crate::common;
use common::*;
use lattice_rt::scene::Object;
use lattice_rt::{Frame, LatticeConfig, Tracer};

/// Width over height of the pixels where a sphere straight ahead shows, at `w x h`.
fn sphere_aspect(fov: &str, w: u16, h: u16) -> f64 {
    let text = format!("camera eye 0 0 -10 fov {fov}\nambient 1\nsphere radius 1\n");
    let frame = Frame::new(w, h);
    let mut storage = vec![Object::<f64>::default(); 4];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse_for::<f64>(&text, &mut storage, &mut parts, frame.size()).unwrap();
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    let gray = gray_of(&Tracer::new(&scene, &lat), &frame);
    let (w, h) = (w as usize, h as usize);
    let cols = (0..w).filter(|&x| (0..h).any(|y| gray[y * w + x] > 0)).count();
    let rows = (0..h).filter(|&y| (0..w).any(|x| gray[y * w + x] > 0)).count();
    cols as f64 / rows as f64
}

#[test]
fn a_sphere_is_round_at_every_frame_shape() {
    for fov in ["40 25", "25 40", "30", "90 10"] {
        for (w, h) in [(128, 64), (200, 200), (160, 100), (400, 240), (72, 40), (64, 128)] {
            let aspect = sphere_aspect(fov, w, h);
            // Within a pixel on either side of a sphere at least 10 pixels across.
            assert!(
                (aspect - 1.0).abs() < 0.1,
                "fov {fov} at {w}x{h}: the sphere is {aspect:.3} times wider than tall"
            );
        }
    }
}

#[test]
fn a_frame_of_another_shape_is_refused_not_stretched() {
    let text = "camera eye 0 0 -10\nsphere radius 1\n";
    let mut storage = vec![Object::<f64>::default(); 4];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse_for::<f64>(text, &mut storage, &mut parts, [128, 64]).unwrap();
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    let frame = Frame::new(200, 200);
    let mut bits = vec![0u8; lattice_rt::BitFrame::bytes(200, 200)];
    let mut target = lattice_rt::BitFrame::new(200, 200, &mut bits).unwrap();
    let mut scratch = lattice_rt::HeapScratch::new(&scene, &frame);
    let err = lattice_rt::render(
        &Tracer::new(&scene, &lat),
        &frame,
        &mut target,
        &mut scratch.scratch(),
        &mut lattice_rt::NoHooks,
    )
    .unwrap_err();
    assert_eq!(err.to_string(), "the scene's view was fitted to frames of shape 2:1, not 200x200 (pixels would not be square): load the scene for this frame");
    // The same shape at another size renders.
    let half = Frame::new(64, 32);
    let mut bits = vec![0u8; lattice_rt::BitFrame::bytes(64, 32)];
    let mut target = lattice_rt::BitFrame::new(64, 32, &mut bits).unwrap();
    let mut scratch = lattice_rt::HeapScratch::new(&scene, &half);
    assert!(lattice_rt::render(
        &Tracer::new(&scene, &lat),
        &half,
        &mut target,
        &mut scratch.scratch(),
        &mut lattice_rt::NoHooks
    )
    .is_ok());
}
