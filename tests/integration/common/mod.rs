//! Helpers shared by the integration tests: parse a scene, build an accelerator, render.
#![allow(dead_code)]

use lattice_rt::scene::Object;
use lattice_rt::{
    render, Accelerator, BitFrame, BoundingBox, BruteForce, Frame, HeapScratch, HeapStorage, Lattice, LatticeConfig,
    NoHooks, Real, Scene, Sizes, Stats, Tracer,
};

/// The accelerators under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accel {
    Lattice,
    Bbox,
    Brute,
}

pub const ACCELS: [Accel; 3] = [Accel::Lattice, Accel::Bbox, Accel::Brute];

/// Reads a scene file from `scenes/`.
pub fn scene_text(name: &str) -> String {
    let path = format!("{}/scenes/{name}.scene", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Heap storage for the lattice of `scene` with `cfg` (and a render's scratch).
pub fn lattice_storage<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> HeapStorage<R> {
    HeapStorage::new(Sizes { objects: 0, ..Sizes::of(scene, Some(cfg), &Frame::new(1, 1)) })
}

/// Builds the lattice with `cfg` in storage from [`lattice_storage`] with the same `cfg`.
pub fn build_lattice<'a, R: Real>(
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
    st: &'a mut HeapStorage<R>,
) -> Lattice<'a, R> {
    st.view().split().1.lattice(scene, cfg).expect("lattice fits").0
}

/// Renders with a tracer already set up; returns the PBM bytes and the statistics.
pub fn render_tracer<R: Real, A: Accelerator<R> + ?Sized>(t: &Tracer<'_, '_, R, A>, frame: &Frame) -> (Vec<u8>, Stats) {
    let mut bits = vec![0u8; BitFrame::bytes(frame.width as u32, frame.height as u32)];
    let mut target = BitFrame::new(frame.width as u32, frame.height as u32, &mut bits).unwrap();
    let mut scratch = HeapScratch::new(t.scene(), frame);
    let stats = render(t, frame, &mut target, &mut scratch.scratch(), &mut NoHooks).expect("render");
    let mut pbm = Vec::new();
    target.write_pbm(|b| pbm.extend_from_slice(b));
    (pbm, stats)
}

/// Parses `text` in `R` with its view fitted to frames of `shape` (width and height).
pub fn parse_for<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut lattice_rt::Parts<R>,
    shape: [u32; 2],
) -> Result<Scene<'a, R>, lattice_rt::ParseError<'t>> {
    lattice_rt::scene::text::parse_with::<R>(text, storage, parts, |c| c.frame = shape)
}

/// Calls `f` with scene `name` (from `scenes/`), parsed in `R` with its view fitted to frames
/// of `shape`, and its lattice built with the default configuration.
pub fn with_lattice<R: Real, T>(name: &str, shape: [u32; 2], f: impl FnOnce(&Scene<'_, R>, &Lattice<'_, R>) -> T) -> T {
    let text = scene_text(name);
    let mut storage = vec![Object::<R>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse_for::<R>(&text, &mut storage, &mut parts, shape).unwrap();
    let mut bufs = lattice_storage(&scene, &LatticeConfig::default());
    let lat = build_lattice(&scene, &LatticeConfig::default(), &mut bufs);
    f(&scene, &lat)
}

/// Parses `text` and renders it with one accelerator and the scene's own settings.
pub fn render_text<R: Real>(text: &str, accel: Accel, frame: &Frame) -> (Vec<u8>, Stats) {
    let mut storage = vec![Object::<R>::default(); text.lines().count()];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse_for::<R>(text, &mut storage, &mut parts, frame.size()).unwrap_or_else(|e| panic!("{e}"));
    let mut st = lattice_storage(&scene, &LatticeConfig::default());
    let lat = build_lattice(&scene, &LatticeConfig::default(), &mut st);
    let a: &dyn Accelerator<R> = match accel {
        Accel::Lattice => &lat,
        Accel::Bbox => &BoundingBox,
        Accel::Brute => &BruteForce,
    };
    render_tracer(&Tracer::new(&scene, a), frame)
}

/// Compares a PBM with the checked-in golden file; on mismatch writes the actual image and an
/// XOR diff under `target/golden/` and panics with their paths. `UPDATE_GOLDEN=1` rewrites.
pub fn assert_golden(name: &str, pbm: &[u8]) {
    let root = env!("CARGO_MANIFEST_DIR");
    let golden = format!("{root}/tests/golden/{name}.pbm");
    if std::env::var("UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
        std::fs::write(&golden, pbm).unwrap();
        return;
    }
    let want =
        std::fs::read(&golden).unwrap_or_else(|e| panic!("{golden}: {e}; run with UPDATE_GOLDEN=1 to create it"));
    if want == pbm {
        return;
    }
    let out = format!("{root}/target/golden");
    std::fs::create_dir_all(&out).unwrap();
    let actual = format!("{out}/{name}-actual.pbm");
    let diff = format!("{out}/{name}-diff.pbm");
    std::fs::write(&actual, pbm).unwrap();
    let head_len = pbm.iter().enumerate().filter(|(_, &b)| b == b'\n').nth(1).map_or(0, |(i, _)| i + 1);
    let mut d = pbm[..head_len].to_vec();
    let differing: usize = if want.len() == pbm.len() {
        let body: Vec<u8> = pbm[head_len..].iter().zip(&want[head_len..]).map(|(a, b)| !(a ^ b)).collect();
        let n = body.iter().map(|b| (!b).count_ones() as usize).sum();
        d.extend(body);
        std::fs::write(&diff, &d).unwrap();
        n
    } else {
        usize::MAX
    };
    panic!(
        "{name}: image differs from {golden} in {differing} pixels; actual: {actual}, diff (black = differs): {diff}"
    );
}

/// Gray levels (0..=64) of a frame rendered with a tracer.
pub fn gray_of<R: Real, A: Accelerator<R> + ?Sized>(t: &Tracer<'_, '_, R, A>, frame: &Frame) -> Vec<u8> {
    struct G(Vec<u8>, usize);
    impl lattice_rt::Hooks for G {
        fn gray_tile(&mut self, x: u16, y: u16, w: u16, h: u16, levels: &[u8]) {
            for r in 0..h as usize {
                for c in 0..w as usize {
                    self.0[(y as usize + r) * self.1 + x as usize + c] = levels[r * w as usize + c];
                }
            }
        }
    }
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut bits = vec![0u8; BitFrame::bytes(w as u32, h as u32)];
    let mut target = BitFrame::new(w as u32, h as u32, &mut bits).unwrap();
    let mut scratch = HeapScratch::new(t.scene(), frame);
    let mut g = G(vec![0; w * h], w);
    render(t, frame, &mut target, &mut scratch.scratch(), &mut g).expect("render");
    g.0
}

/// Share of pixels more than one gray level (of 64) apart.
pub fn share_off(a: &[u8], b: &[u8]) -> f64 {
    a.iter().zip(b).filter(|(x, y)| x.abs_diff(**y) > 1).count() as f64 / a.len() as f64
}
