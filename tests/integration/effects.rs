//! The effect set a scene calls for, one test per effect (a scene with it and without it), and
//! what the tracer does with it.

use crate::common;
use common::*;
use lattice_rt::scene::Object;
use lattice_rt::trace::MissingEffects;
use lattice_rt::{parse, Effects, Frame, LatticeConfig, Tracer};

fn effects_of(text: &str) -> Effects {
    let mut storage = vec![Object::<f64>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    Effects::of(&parse::<f64>(text, &mut storage, &mut parts).unwrap())
}

const LIGHT: &str = "light directional dir 0 -1 0\n";
const TWO: &str = "sphere\nbox min 2 0 0 max 3 1 1\n";

#[test]
fn shadows_need_a_light_and_two_objects() {
    assert!(effects_of(&format!("{LIGHT}{TWO}")).contains(Effects::SHADOWS));
    assert!(!effects_of(TWO).contains(Effects::SHADOWS), "no light");
    assert!(
        !effects_of(&format!("{LIGHT}sphere\n")).contains(Effects::SHADOWS),
        "a lone convex object cannot shadow itself"
    );
}

#[test]
fn reflection_needs_a_mirror_material_in_use() {
    assert!(effects_of(&format!("material m ks 0.5\nsphere material m\n{TWO}")).contains(Effects::REFLECTION));
    // Objects without a material get the first one defined, so the mirror comes second here.
    assert!(
        !effects_of(&format!("material plain\nmaterial m ks 0.5\n{TWO}")).contains(Effects::REFLECTION),
        "defined but unused"
    );
    assert!(!effects_of(TWO).contains(Effects::REFLECTION));
}

#[test]
fn refraction_needs_a_transparent_material_in_use() {
    assert!(effects_of("material g kt 0.8 ior 1.5\nsphere material g\n").contains(Effects::REFRACTION));
    assert!(!effects_of("material g kt 0\nsphere material g\n").contains(Effects::REFRACTION));
}

#[test]
fn point_lights_are_their_own_effect() {
    assert!(effects_of(&format!("light point pos 0 5 0\n{TWO}")).contains(Effects::POINT_LIGHTS));
    assert!(!effects_of(&format!("{LIGHT}{TWO}")).contains(Effects::POINT_LIGHTS));
}

#[test]
fn composites_are_their_own_effect() {
    assert!(effects_of("group g\nsphere\nend\n").contains(Effects::COMPOSITES));
    assert!(!effects_of(TWO).contains(Effects::COMPOSITES));
}

#[test]
fn the_paper_scenes_call_for_what_they_show() {
    let of = |s: &str| effects_of(&scene_text(s)).to_string();
    assert_eq!(of("chair"), "shadows, composites");
    assert_eq!(of("spheres"), "shadows, reflection");
    assert_eq!(of("whitted"), "shadows, reflection, refraction");
}

#[test]
fn a_tracer_without_refraction_refuses_glass() {
    let text = scene_text("whitted");
    let mut storage = vec![Object::<f64>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<f64>(&text, &mut storage, &mut parts).unwrap();
    let mut bufs = lattice_storage(&scene, &LatticeConfig::default());
    let lat = build_lattice(&scene, &LatticeConfig::default(), &mut bufs);
    const MATTE: u8 = Effects::SHADOWS.union(Effects::COMPOSITES).bits();
    let err = Tracer::<_, _, MATTE>::compiled(&scene, &lat).unwrap_err();
    assert_eq!(err, MissingEffects(Effects::REFLECTION | Effects::REFRACTION));
    assert_eq!(err.to_string(), "the scene needs effects this build leaves out: reflection, refraction");
}

#[test]
fn forcing_every_effect_on_changes_no_pixel_of_any_scene() {
    for s in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
        with_lattice::<f64, _>(s, [160, 100], |scene, lat| {
            let frame = Frame::new(160, 100);
            let derived = Tracer::new(scene, lat);
            let mut all = Tracer::new(scene, lat);
            all.set_effects(Effects::ALL);
            let (a, sa) = render_tracer(&derived, &frame);
            let (b, sb) = render_tracer(&all, &frame);
            assert!(a == b, "{s}: forcing all effects changed the image");
            assert!(sa.total_rays() <= sb.total_rays(), "{s}");
        });
    }
}

#[test]
fn a_one_level_cutoff_prunes_the_whitted_tree_and_barely_changes_the_frame() {
    // At 160x100, the shape of the scene's authored 40 x 25 degree view (at 128x64 the view
    // widens to 47.9 degrees across, more of the plain floor shows, and 28.7 % fewer rays).
    let ((a, sa), (b, sb)) = with_lattice::<f64, _>("whitted", [160, 100], |scene, lat| {
        let frame = Frame::new(160, 100);
        let exact = Tracer::new(scene, lat);
        let mut pruned = Tracer::new(scene, lat);
        pruned.set_cutoff(1.0 / 64.0);
        (render_tracer(&exact, &frame), render_tracer(&pruned, &frame))
    });
    let fewer = 1.0 - sb.total_rays() as f64 / sa.total_rays() as f64;
    let changed: u32 = a.iter().zip(&b).map(|(x, y)| (x ^ y).count_ones()).sum();
    assert!(fewer >= 0.30, "only {:.1} % fewer rays", 100.0 * fewer);
    assert!(changed as f64 <= 0.001 * 160.0 * 100.0, "{changed} pixels changed");
}

#[test]
fn a_frames_cutoff_is_the_tracers_and_the_larger_holds() {
    // A frame's cutoff of 2^-k renders what the tracer's own cutoff of 2^-k renders, rays
    // counted alike; of two cutoffs the larger prunes; the chair's frame (no mirror or glass,
    // and no light term below 1/128 at its camera) is the same either way.
    for s in ["whitted", "spheres", "chair"] {
        with_lattice::<f64, _>(s, [128, 64], |scene, lat| {
            let plain = Frame::new(128, 64);
            let framed = Frame { cutoff: Some(7), ..plain };
            let exact = Tracer::new(scene, lat);
            let mut own = Tracer::new(scene, lat);
            own.set_cutoff(1.0 / 128.0);
            let (a, sa) = render_tracer(&exact, &framed);
            let (b, sb) = render_tracer(&own, &plain);
            assert!(a == b && sa == sb, "{s}: the frame's cutoff and the tracer's differ");
            let mut coarser = Tracer::new(scene, lat);
            coarser.set_cutoff(1.0 / 64.0);
            let (c, sc) = render_tracer(&coarser, &plain);
            let (d, sd) = render_tracer(&coarser, &framed);
            assert!(c == d && sc == sd, "{s}: a finer frame cutoff overrode the tracer's coarser one");
            let (e, se) = render_tracer(&exact, &plain);
            if s == "chair" {
                assert!(e == a && se == sa, "chair: the cutoff changed its frame");
            } else {
                assert!(sa.total_rays() < se.total_rays(), "{s}: the frame's cutoff pruned nothing");
            }
        });
    }
}
