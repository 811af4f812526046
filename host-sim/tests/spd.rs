//! The SPD scenes as `host-sim spd` generates them are the SPD's own programs' output, byte for
//! byte (reference files in `tests/spd/`, see its README), and read back as scenes.

use host_sim::spd::Generator;
use lattice_rt::scene::{object_count, parse_with, Object, Parts};

#[test]
fn generated_scenes_are_the_original_programs_output() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/spd");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "nff") {
            continue;
        }
        let stem = path.file_stem().unwrap().to_str().unwrap();
        let (name, size) = stem.rsplit_once('-').unwrap();
        let g = Generator::ALL.into_iter().find(|g| g.name() == name).unwrap();
        let want = std::fs::read_to_string(&path).unwrap();
        let got = g.nff(size.parse().unwrap()).unwrap();
        assert!(got == want, "{stem}: the generated NFF differs from the SPD program's");
        checked += 1;
    }
    assert_eq!(checked, 11);
}

#[test]
fn every_generator_at_its_default_size_makes_the_published_object_count_and_reads_back() {
    // The SPD's Readme and Havran's tables: objects at the default size factors.
    let published = [
        (Generator::Balls, 7382),
        (Generator::Rings, 8401),
        (Generator::Tree, 8191),
        (Generator::Lattice, 8281),
        (Generator::Jacks, 9),
        (Generator::Shells, 5761),
        (Generator::Tetra, 4096),
        (Generator::Gears, 9345),
        (Generator::Mount, 8196),
        (Generator::Teapot, 9264),
    ];
    for (g, want) in published {
        let text = g.nff(g.default_size()).unwrap();
        // NFF primitives (a polygon is one; here it is its triangles).
        let primitives = text.lines().filter(|l| ["s ", "c ", "p ", "pp "].iter().any(|w| l.starts_with(w))).count();
        assert_eq!(primitives, want, "{}", g.name());
        let n = object_count(&text);
        let mut storage = vec![Object::<f64>::default(); n];
        let mut parts = Parts::default();
        let scene = parse_with::<f64>(&text, &mut storage, &mut parts, |_| {}).unwrap();
        assert_eq!(scene.objects().len(), n, "{}", g.name());
    }
}

#[test]
fn a_size_out_of_range_is_refused_with_the_range() {
    let e = Generator::Balls.nff(0).unwrap_err().to_string();
    assert_eq!(e, "balls: the size factor must be from 1 to 7 (the SPD's default is 4)");
    assert!(Generator::Rings.nff(91).is_err());
}

/// The lattice (its world lattice and its crowded cells' lattices listing long objects only in
/// the cells their own boxes meet) finds the same hit as testing every object, ray by ray, on
/// SPD scenes: eye rays, and rays from random points in random directions.
fn lattice_agrees_with_brute_force<R: lattice_rt::Real>(text: &str, cfg: &lattice_rt::LatticeConfig) {
    use lattice_rt::accel::{Accelerator, BruteForce, Query};
    use lattice_rt::generate::Rng;
    use lattice_rt::{Ray, Vec3};
    let n = object_count(text);
    let mut storage = vec![Object::<R>::default(); n];
    let mut parts = Parts::default();
    let scene = parse_with::<R>(text, &mut storage, &mut parts, |c| c.frame = [64, 64]).unwrap();
    let mut bufs = host_sim::load::lattice_storage(&scene, cfg).unwrap();
    let lattice = host_sim::load::build_lattice(&mut bufs, &scene, cfg).unwrap();
    let (mut m1, mut m2) = (vec![0; lattice_rt::Query::mailbox_len(&scene)], vec![0; 0]);
    let (mut q1, mut q2) = (Query::new(&mut m1), Query::new(&mut m2));
    let mut rng = Rng::new(7);
    let w = scene.world();
    let mut rays: Vec<Ray<R>> =
        (0..64 * 64).map(|i| scene.camera().ray(2 * (i % 64) + 1, 2 * (i / 64) + 1, 128, 128)).collect();
    for _ in 0..4000 {
        let p = |lo: R, hi: R, r: &mut Rng| R::from_f64(r.range(lo.to_f64(), hi.to_f64()));
        let o = Vec3::new(p(w.min.x, w.max.x, &mut rng), p(w.min.y, w.max.y, &mut rng), p(w.min.z, w.max.z, &mut rng));
        let d = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        rays.push(Ray::new(o, Vec3::new(R::from_f64(d.x), R::from_f64(d.y), R::from_f64(d.z))));
    }
    for (k, ray) in rays.iter().enumerate() {
        let a = BruteForce.nearest(&scene, ray, R::ZERO, R::MAX, &mut q2).map(|h| (h.object, h.t));
        let b = lattice.nearest(&scene, ray, R::ZERO, R::MAX, &mut q1).map(|h| (h.object, h.t));
        assert_eq!(a, b, "ray {k}");
        let a = BruteForce.occluded(&scene, ray, R::ZERO, R::MAX, &mut q2).is_some();
        let b = lattice.occluded(&scene, ray, R::ZERO, R::MAX, &mut q1).is_some();
        assert_eq!(a, b, "shadow ray {k}");
    }
}

#[test]
fn the_lattice_agrees_with_brute_force_on_spd_scenes() {
    let crowded = lattice_rt::LatticeConfig { split: 4, ..Default::default() };
    for (g, size) in [
        (Generator::Rings, 2),
        (Generator::Tree, 6),
        (Generator::Balls, 2),
        (Generator::Lattice, 3),
        (Generator::Jacks, 2),
        (Generator::Tetra, 4),
        (Generator::Gears, 1),
        (Generator::Mount, 3),
        (Generator::Teapot, 3),
    ] {
        let text = g.nff(size).unwrap();
        for cfg in [lattice_rt::LatticeConfig::default(), crowded] {
            lattice_agrees_with_brute_force::<f64>(&text, &cfg);
            lattice_agrees_with_brute_force::<f32>(&text, &cfg);
            lattice_agrees_with_brute_force::<lattice_rt::Fx>(&text, &cfg);
        }
    }
}
