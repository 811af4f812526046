//! Sampling modes: edge-only anti-aliasing spends rays only near edges and leaves every other
//! pixel exactly as one ray per pixel draws it.

use crate::common;
use common::*;
use lattice_rt::render::Hooks;
use lattice_rt::scene::Object;
use lattice_rt::{parse, render, BitFrame, Frame, HeapScratch, LatticeConfig, Sampling, Tracer};

struct Gray(Vec<u8>, usize);
impl Hooks for Gray {
    fn gray_tile(&mut self, x: u16, y: u16, w: u16, h: u16, levels: &[u8]) {
        for r in 0..h as usize {
            for c in 0..w as usize {
                self.0[(y as usize + r) * self.1 + x as usize + c] = levels[r * w as usize + c];
            }
        }
    }
}

/// The spheres scene rendered at 128x64 with `sampling`, `hooks` called: the render's statistics.
fn render_spheres(sampling: Sampling, hooks: &mut impl Hooks) -> lattice_rt::Stats {
    let text = scene_text("spheres");
    let mut storage = vec![Object::<f64>::default(); 16];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<f64>(&text, &mut storage, &mut parts).unwrap();
    let mut bufs = lattice_storage(&scene, &LatticeConfig::default());
    let lat = build_lattice(&scene, &LatticeConfig::default(), &mut bufs);
    let frame = Frame { sampling, ..Frame::new(128, 64) };
    let mut bits = vec![0u8; BitFrame::bytes(128, 64)];
    let mut target = BitFrame::new(128, 64, &mut bits).unwrap();
    let mut scratch = HeapScratch::new(&scene, &frame);
    render(&Tracer::new(&scene, &lat), &frame, &mut target, &mut scratch.scratch(), hooks).unwrap()
}

fn gray(sampling: Sampling) -> (Vec<u8>, u64) {
    let mut hooks = Gray(vec![0; 128 * 64], 128);
    let stats = render_spheres(sampling, &mut hooks);
    (hooks.0, stats.rays[0])
}

#[test]
fn edge_sampling_refines_only_near_edges() {
    let (one, rays1) = gray(Sampling::Center);
    let (four, rays4) = gray(Sampling::Grid2x2);
    let (edges, rays_e) = gray(Sampling::Edges { contrast: u8::MAX });
    assert_eq!(rays1, 128 * 64);
    assert_eq!(rays4, 4 * 128 * 64);
    assert!(rays_e > rays1 && rays_e < rays1 + (rays4 - rays1) / 4, "edge rays {rays_e}");
    // Every refined pixel took exactly four extra rays and now shows the 4-ray value.
    let refined = (0..one.len()).filter(|&i| edges[i] != one[i]).count() as u64;
    assert!(refined <= (rays_e - rays1) / 4);
    for i in 0..one.len() {
        assert!(edges[i] == one[i] || edges[i] == four[i], "pixel {i}: {} not {} or {}", edges[i], one[i], four[i]);
    }
}

#[test]
fn contrast_also_refines_shadow_edges() {
    let (_, plain) = gray(Sampling::Edges { contrast: u8::MAX });
    let (_, contrast) = gray(Sampling::Edges { contrast: 16 });
    assert!(contrast > plain, "contrast {contrast} vs object edges {plain}");
}

/// Counts the render's calls: eye samples and tiles.
#[derive(Default)]
struct Calls {
    sampled: u64,
    tiles: u32,
    /// Eye samples before the first tile was done: a tile reports its samples as it traces.
    before_first_tile: u64,
}
impl Hooks for Calls {
    fn sampled(&mut self) {
        self.sampled += 1;
    }
    fn progress(&mut self, done: u32, _total: u32) -> bool {
        if self.tiles == 0 {
            self.before_first_tile = self.sampled;
        }
        self.tiles = done;
        true
    }
}

#[test]
fn every_eye_sample_is_reported_as_it_is_traced() {
    // `Hooks::sampled` paces a board's watchdog inside tiles that take seconds: it comes once
    // per eye ray the statistics count, in every sampling mode, and within the tile.
    let adaptive = Sampling::Adaptive { contrast: 16, coarse: true };
    for sampling in [Sampling::Center, Sampling::Grid2x2, Sampling::Edges { contrast: 16 }, adaptive] {
        let mut calls = Calls::default();
        let stats = render_spheres(sampling, &mut calls);
        assert_eq!(calls.sampled, stats.rays[0], "{sampling:?}: eye samples reported against eye rays traced");
        assert!(calls.tiles > 1 && calls.before_first_tile > 0, "{sampling:?}: {} tiles", calls.tiles);
        assert!(calls.before_first_tile < calls.sampled, "{sampling:?}: every sample came in the first tile");
    }
}
