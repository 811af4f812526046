//! Golden 1-bit images of the paper's scenes and the Whitted showcase in f64 and f32, and the
//! three accelerators drawing identical frames.

use crate::common;
use common::*;
use lattice_rt::{Dither, Frame, Real};

const SCENES: [&str; 5] = ["chair", "desk", "polyhedron", "spheres", "whitted"];

fn golden_for<R: Real>() {
    let frame = Frame::new(128, 64);
    for s in SCENES {
        let (pbm, _) = render_text::<R>(&scene_text(s), Accel::Lattice, &frame);
        assert_golden(&format!("{s}-128x64-{}", R::NAME), &pbm);
    }
}

#[test]
fn paper_scenes_match_golden_images_in_f64() {
    golden_for::<f64>();
}

#[test]
fn paper_scenes_match_golden_images_in_f32() {
    golden_for::<f32>();
}

#[test]
fn paper_scenes_match_golden_images_in_fixed_point() {
    golden_for::<lattice_rt::Fx>();
}

fn identical_for<R: Real>(frame: &Frame) {
    for s in SCENES {
        let text = scene_text(s);
        let images: Vec<_> = ACCELS.iter().map(|&a| render_text::<R>(&text, a, frame).0).collect();
        assert!(images[0] == images[1], "{s} ({}): lattice and bbox images differ", R::NAME);
        assert!(images[0] == images[2], "{s} ({}): lattice and brute-force images differ", R::NAME);
    }
}

#[test]
fn all_accelerators_draw_identical_frames() {
    let frame = Frame { dither: Dither::FloydSteinberg, ..Frame::new(160, 100) };
    identical_for::<f64>(&frame);
    identical_for::<f32>(&frame);
    identical_for::<lattice_rt::Fx>(&frame);
}

#[test]
fn error_diffusion_in_tiles_keeps_the_mean_gray() {
    // Tile-order Floyd-Steinberg keeps the overall brightness of the Bayer rendering.
    let text = scene_text("spheres");
    let count = |d| {
        let f = Frame { dither: d, ..Frame::new(160, 100) };
        let (pbm, _) = render_text::<f64>(&text, Accel::Lattice, &f);
        pbm[pbm.len() - 2000..].iter().map(|b| b.count_ones()).sum::<u32>() as f64
    };
    let (bayer, fs) = (count(Dither::Bayer), count(Dither::FloydSteinberg));
    assert!((bayer - fs).abs() / bayer < 0.03, "bayer {bayer} vs floyd-steinberg {fs} white pixels");
}

/// Error diffusion bit for bit: the Pico's panel frame (Floyd-Steinberg with silhouette lines,
/// adaptive sampling in two levels, branches below half a gray step not traced) in fixed point, the same at a size whose edge tiles are partial, and
/// Atkinson's kernel.
#[test]
fn error_diffused_frames_match_golden_images() {
    let panel = Frame {
        dither: Dither::FloydSteinberg,
        sampling: lattice_rt::render::Sampling::Adaptive { contrast: 4, coarse: true },
        outline: true,
        cutoff: Some(7),
        ..Frame::new(128, 64)
    };
    for s in SCENES {
        let (pbm, _) = render_text::<lattice_rt::Fx>(&scene_text(s), Accel::Lattice, &panel);
        assert_golden(&format!("{s}-panel-fixed"), &pbm);
    }
    for (s, frame) in [
        ("chair", Frame { width: 100, height: 60, cutoff: None, ..panel }),
        ("whitted", Frame { dither: Dither::Atkinson, width: 100, height: 60, cutoff: None, ..panel }),
    ] {
        let (pbm, _) = render_text::<f64>(&scene_text(s), Accel::Lattice, &frame);
        assert_golden(&format!("{s}-100x60-{:?}-f64", frame.dither).to_lowercase(), &pbm);
    }
}
