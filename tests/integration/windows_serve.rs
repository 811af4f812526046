//! `EyeRays::serve_every_ray`: where it holds, a frame never asks its accelerator (the
//! windows answer every eye and shadow ray, or the scene is so small that every other ray tests
//! each object), so brute force in place of the lattice gives the
//! same frame; a build whose scenes all qualify links no walk (the firmware's `windows_only`).

use crate::common;
use common::*;
use lattice_rt::accel::{Hit, Query};
use lattice_rt::render::Sampling;
use lattice_rt::scene::Object;
use lattice_rt::{Accelerator, BruteForce, Dither, EyeRays, Frame, Fx, LatticeConfig, Ray, Real, Scene, Tracer};
use std::sync::atomic::{AtomicU32, Ordering};

/// The lattice, counting the rays it is asked about.
struct Counting<'l, R: Real> {
    lattice: &'l dyn Accelerator<R>,
    asked: AtomicU32,
}

impl<R: Real> Accelerator<R> for Counting<'_, R> {
    fn name(&self) -> &'static str {
        "counting"
    }
    fn nearest(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<Hit<R>> {
        self.asked.fetch_add(1, Ordering::Relaxed);
        self.lattice.nearest(s, ray, t0, t1, q)
    }
    fn occluded(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<u32> {
        self.asked.fetch_add(1, Ordering::Relaxed);
        self.lattice.occluded(s, ray, t0, t1, q)
    }
}

/// The frames checked: the Pico's still (16x16 tiles, adaptive sampling, error diffusion,
/// lines: hit-only apron rays too) and one ray per pixel with four at edges.
fn frames() -> [Frame; 2] {
    [
        Frame {
            tile: 16,
            sampling: Sampling::Adaptive { contrast: 4, coarse: true },
            dither: Dither::FloydSteinberg,
            outline: true,
            ..Frame::new(128, 64)
        },
        Frame { sampling: Sampling::Edges { contrast: 16 }, ..Frame::new(96, 60) },
    ]
}

/// Whether `text` qualifies, and for each frame the rays its lattice was asked about and
/// whether brute force in its place drew the same frame.
fn check<R: Real>(text: &str) -> (bool, Vec<(u32, bool)>) {
    let mut serves = true;
    let runs = frames()
        .iter()
        .map(|frame| {
            let mut storage = vec![Object::<R>::default(); text.lines().count()];
            let mut parts = lattice_rt::Parts::default();
            let scene = parse_for::<R>(text, &mut storage, &mut parts, frame.size()).unwrap_or_else(|e| panic!("{e}"));
            let mut st = lattice_storage(&scene, &LatticeConfig::default());
            let lattice = build_lattice(&scene, &LatticeConfig::default(), &mut st);
            serves &= EyeRays::serve_every_ray(&scene);
            let counting = Counting { lattice: &lattice, asked: AtomicU32::new(0) };
            let (with_lattice, _) = render_tracer(&Tracer::new(&scene, &counting), frame);
            let (with_brute, _) = render_tracer(&Tracer::new(&scene, &BruteForce), frame);
            (counting.asked.into_inner(), with_lattice == with_brute)
        })
        .collect();
    (serves, runs)
}

#[test]
fn scenes_the_windows_serve_never_ask_the_accelerator() {
    // The matte paper scenes qualify (one directional light, no mirror); spheres has a mirror
    // but three objects, which its mirror rays test without the walk; the Whitted scene has 38
    // objects, mirrors and glass.
    for (name, expected) in
        [("chair", true), ("desk", true), ("polyhedron", true), ("spheres", true), ("whitted", false)]
    {
        let text = scene_text(name);
        for (scalar, (serves, runs)) in [("f64", check::<f64>(&text)), ("fixed", check::<Fx>(&text))] {
            assert_eq!(serves, expected, "{name} ({scalar})");
            for (i, (asked, same)) in runs.into_iter().enumerate() {
                if serves {
                    assert_eq!(asked, 0, "{name} ({scalar}), frame {i}: the lattice was asked about {asked} rays");
                    assert!(same, "{name} ({scalar}), frame {i}: brute force drew another frame");
                } else {
                    assert!(
                        asked > 0,
                        "{name} ({scalar}), frame {i}: a scene with secondary rays asks its accelerator"
                    );
                }
            }
        }
    }
}

#[test]
fn a_second_light_or_a_point_light_needs_the_accelerator() {
    let base = scene_text("chair");
    let second = format!("{base}\nlight directional dir 0.3 -1 0.2 intensity 0.4\n");
    let point = base.replace("light directional dir -0.5 -1 0.6 intensity 1.1", "light point pos 2 5 -3 intensity 1.1");
    assert_ne!(point, base, "the chair's light line changed: update this test");
    for text in [second, point] {
        let (serves, runs) = check::<f64>(&text);
        assert!(!serves);
        assert!(
            runs.iter().all(|&(asked, _)| asked > 0),
            "shadow rays towards a second or point light walk the lattice"
        );
    }
}
