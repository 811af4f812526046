//! Scene text in, a validated scene or an error out: never a panic, and every error names a
//! line and column inside the text. Valid scenes are also built into a lattice and traced for
//! a few rays in every scalar, so validation is checked against what the tracer needs.
#![no_main]

use lattice_rt::lattice::SubLattice;
use lattice_rt::scene::Object;
use lattice_rt::{parse, Accelerator, BruteForce, Fx, Lattice, LatticeConfig, LatticeStorage, Query, Real};
use libfuzzer_sys::fuzz_target;

fn check<R: Real>(text: &str) {
    let mut storage = vec![Object::<R>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    match parse::<R>(text, &mut storage, &mut parts) {
        Err(e) => {
            // Lines as the parser counts them: ended by `\n`, `\r\n` or a lone `\r` (old Mac
            // files), so the last one is after the last ending.
            let lines = text.replace("\r\n", "\n").matches(['\n', '\r']).count() as u32 + 1;
            assert!(e.line >= 1 && e.line <= lines && e.col >= 1, "{e}");
        }
        Ok(scene) => {
            let cfg = LatticeConfig::default();
            let sizes = Lattice::plan(&scene, &cfg);
            if sizes.words() > 1 << 20 {
                return;
            }
            let (mut g, mut c, mut w) =
                (vec![SubLattice::EMPTY; sizes.lattices], vec![R::ZERO; sizes.coords], vec![0; sizes.words()]);
            let lat = Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut c, words: &mut w })
                .unwrap();
            let mut mb = vec![0; Query::mailbox_len(&scene)];
            let mut q = Query::new(&mut mb);
            for (x, y) in [(1, 1), (7, 3), (15, 9)] {
                let ray = scene.camera().ray(x, y, 16, 10);
                let a = lat.nearest(&scene, &ray, R::ZERO, R::MAX, &mut q);
                let b = BruteForce.nearest(&scene, &ray, R::ZERO, R::MAX, &mut q);
                assert_eq!(a, b);
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        check::<f64>(text);
        check::<f32>(text);
        check::<Fx>(text);
    }
});
