//! Random and mutated scene text, in every scalar: never a panic, every error names a line and
//! column inside the text, and every scene that is accepted traces the same with the lattice as
//! with brute force. (The coverage-guided fuzzer is `fuzz/`, run with `cargo +nightly fuzz`.)

use crate::common;
use common::*;
use lattice_rt::scene::Object;
use lattice_rt::{parse, Accelerator, BruteForce, Fx, LatticeConfig, Query, Real};
use proptest::prelude::*;

const WORDS: [&str; 30] = [
    "sphere",
    "box",
    "cone",
    "cylinder",
    "group",
    "end",
    "camera",
    "light",
    "material",
    "translate",
    "rotate",
    "scale",
    "shear",
    "radius",
    "min",
    "max",
    "top",
    "NaN",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "1e-300",
    "-0",
    "0",
    "x",
    "#",
    "\n",
    "ior",
    "99999999999999999999",
];

fn check<R: Real>(text: &str) -> Result<(), TestCaseError> {
    let mut storage = vec![Object::<R>::default(); lattice_rt::object_count(text).clamp(48, 512)];
    let mut parts = lattice_rt::Parts::default();
    match parse::<R>(text, &mut storage, &mut parts) {
        Err(e) => {
            let lines = text.lines().count().max(1) as u32;
            prop_assert!(e.line >= 1 && e.line <= lines + 1 && e.col >= 1, "{}: bad position in {e}", R::NAME);
            prop_assert!(!e.to_string().is_empty());
        }
        Ok(scene) => {
            let cfg = LatticeConfig::default();
            let sizes = lattice_rt::Lattice::plan(&scene, &cfg);
            if sizes.cells > 1 << 18 || sizes.refs > 1 << 18 {
                return Ok(());
            }
            let mut bufs = lattice_storage(&scene, &cfg);
            let lat = build_lattice(&scene, &cfg, &mut bufs);
            let mut mb = vec![0; Query::mailbox_len(&scene)];
            let mut q = Query::new(&mut mb);
            for (x, y) in [(1, 1), (7, 3), (15, 9), (9, 5)] {
                let ray = scene.camera().ray(x, y, 16, 10);
                let a = lat.nearest(&scene, &ray, R::ZERO, R::MAX, &mut q);
                let b = BruteForce.nearest(&scene, &ray, R::ZERO, R::MAX, &mut q);
                prop_assert_eq!(a, b, "{}", R::NAME);
            }
        }
    }
    Ok(())
}

/// NFF's words and a few numbers, for random NFF text.
const NFF_WORDS: [&str; 24] = [
    "v",
    "from",
    "at",
    "up",
    "angle",
    "hither",
    "resolution",
    "b",
    "l",
    "f",
    "c",
    "s",
    "p",
    "pp",
    "#",
    "\n",
    "0",
    "1",
    "-1",
    "0.5",
    "3",
    "1e300",
    "nan",
    "-0",
];

/// Small NFF scenes to mutate: the SPD's jacks and rings at size 1 (as its programs write them)
/// and every entity in a few lines.
fn nff_scene(pick: usize) -> String {
    match pick {
        0 => include_str!("../../host-sim/tests/spd/rings-1.nff").to_string(),
        1 => "v\nfrom 0 -10 2\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\nresolution 64 64\nb 0.2 0.4 0.6\nl 5 -5 5\nl -5 -5 5 1 0.5 0.5\nf 1 0 0 0.8 0.2 30 0 1\ns 0 0 1 1\nc 2 0 0 0.5 2 0 2 0.5\nc -2 0 0 0.8 -2 0 1.5 0.2\np 4\n-5 -5 0\n5 -5 0\n5 5 0\n-5 5 0\nf 0.5 0.5 0.5 0.5 0.5 0 0.5 1.5\npp 3\n0 3 0 0 0 1\n1 3 0 0 0 1\n0 4 0 0 0 1\n".to_string(),
        _ => include_str!("../../host-sim/tests/spd/tree-2.nff").to_string(),
    }
}

fn mutate(base: &str, ops: &[(u8, usize, usize)]) -> String {
    let mut s: Vec<char> = base.chars().collect();
    for &(op, a, b) in ops {
        let n = s.len().max(1);
        let (i, j) = (a % n, b % n);
        match op % 4 {
            0 => {
                let (lo, hi) = (i.min(j), i.max(j).min(i.min(j) + 12));
                s.drain(lo..hi.min(s.len()));
            }
            1 => {
                let w = format!(" {} ", WORDS[b % WORDS.len()]);
                let at = i.min(s.len());
                s.splice(at..at, w.chars());
            }
            2 => {
                // Replace a number-looking run with an extreme value.
                let at = (i..s.len()).find(|&k| s[k].is_ascii_digit()).unwrap_or(0);
                let end = (at..s.len()).find(|&k| !(s[k].is_ascii_digit() || s[k] == '.')).unwrap_or(s.len());
                let w = WORDS[17 + b % 8];
                s.splice(at..end, w.chars());
            }
            _ => {
                // Duplicate a line.
                let text: String = s.iter().collect();
                let lines: Vec<&str> = text.lines().collect();
                if !lines.is_empty() {
                    let l = lines[j % lines.len()].to_string();
                    let mut out = text.clone();
                    out.push('\n');
                    out.push_str(&l);
                    s = out.chars().collect();
                }
            }
        }
    }
    s.into_iter().collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenes_never_panic(pick in 0usize..5, ops in prop::collection::vec((any::<u8>(), any::<usize>(), any::<usize>()), 1..6)) {
        let base = scene_text(["chair", "desk", "polyhedron", "spheres", "whitted"][pick]);
        let text = mutate(&base, &ops);
        check::<f64>(&text)?;
        check::<f32>(&text)?;
        check::<Fx>(&text)?;
    }

    #[test]
    fn mutated_nff_never_panics(pick in 0usize..3, ops in prop::collection::vec((any::<u8>(), any::<usize>(), any::<usize>()), 1..6)) {
        let text = mutate(&nff_scene(pick), &ops);
        check::<f64>(&text)?;
        check::<f32>(&text)?;
        check::<Fx>(&text)?;
    }

    #[test]
    fn random_nff_never_panics(words in prop::collection::vec(0usize..24, 0..60)) {
        let text: String = words.iter().map(|&w| NFF_WORDS[w]).collect::<Vec<_>>().join(" ");
        check::<f64>(&text)?;
        check::<Fx>(&text)?;
    }

    #[test]
    fn random_text_never_panics(text in "[a-z0-9 .#\\-\\n]{0,200}") {
        check::<f64>(&text)?;
        check::<f32>(&text)?;
        check::<Fx>(&text)?;
    }

    #[test]
    fn random_statements_never_panic(words in prop::collection::vec(0usize..30, 0..40)) {
        let text: String = words.iter().map(|&w| WORDS[w]).collect::<Vec<_>>().join(" ");
        check::<f64>(&text)?;
        check::<Fx>(&text)?;
    }
}
