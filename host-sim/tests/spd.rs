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
    assert_eq!(checked, 7);
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
    ];
    for (g, want) in published {
        let text = g.nff(g.default_size()).unwrap();
        // NFF primitives (a polygon is one; it becomes two triangles here).
        let primitives =
            text.lines().filter(|l| l.starts_with("s ") || l.starts_with("c ") || l.starts_with("p ")).count();
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
