//! Hard cases stay numerically stable. Every case runs in every scalar (f64, f32, Q16.16 fixed
//! point) and, where rays are answered, in every accelerator (lattice, bounding box, brute
//! force), and asserts the right behaviour. docs/robustness.md lists the remedies.

use crate::common;
use common::*;
use lattice_rt::lattice::Resolution;
use lattice_rt::scene::Object;
use lattice_rt::shape::{Shape, ShapeHit};
use lattice_rt::trace::{facing, refract};
use lattice_rt::{
    parse, Accelerator, BoundingBox, BruteForce, Effects, Frame, Fx, LatticeConfig, Query, Ray, Real, Scene, Tracer,
    Vec3,
};

/// Runs a generic case body in every scalar.
macro_rules! every_scalar {
    ($($name:ident => $body:ident;)*) => {$(
        #[test]
        fn $name() {
            $body::<f64>();
            $body::<f32>();
            $body::<Fx>();
        }
    )*};
}

fn scene_in<'a, R: Real>(text: &str, st: &'a mut (Vec<Object<R>>, lattice_rt::Parts<R>)) -> Scene<'a, R> {
    scene_for(text, st, lattice_rt::scene::DEFAULT_FRAME)
}

/// [`scene_in`] with the view fitted to frames of `shape`.
fn scene_for<'a, R: Real>(
    text: &str,
    (storage, parts): &'a mut (Vec<Object<R>>, lattice_rt::Parts<R>),
    shape: [u32; 2],
) -> Scene<'a, R> {
    *storage = vec![Object::default(); text.lines().count().max(1)];
    parse_for::<R>(text, storage, parts, shape).unwrap_or_else(|e| panic!("{} : {e}", R::NAME))
}

/// Calls `f` with each accelerator over the scene (a lattice with `cfg`).
fn with_accels<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig, mut f: impl FnMut(&str, &dyn Accelerator<R>)) {
    let mut bufs = lattice_storage(scene, cfg);
    let lat = build_lattice(scene, cfg, &mut bufs);
    f("lattice", &lat);
    f("bbox", &BoundingBox);
    f("brute", &BruteForce);
}

fn v<R: Real>(x: f64, y: f64, z: f64) -> Vec3<R> {
    Vec3::new(R::from_f64(x), R::from_f64(y), R::from_f64(z))
}

/// Gray levels of a frame rendered with every accelerator; asserts they agree and returns them.
fn gray_all<R: Real>(scene: &Scene<'_, R>, frame: &Frame, shadows: bool) -> Vec<u8> {
    let mut out: Option<Vec<u8>> = None;
    with_accels(scene, &LatticeConfig::default(), |name, a| {
        let mut t = Tracer::new(scene, a);
        if !shadows {
            t.set_effects(t.effects() - Effects::SHADOWS);
        }
        let g = gray_of(&t, frame);
        match &out {
            None => out = Some(g),
            Some(o) => assert!(*o == g, "{}: {name} differs from lattice", R::NAME),
        }
    });
    out.unwrap()
}

// 1. Shadow rays leaving a surface: no acne. Two objects that cannot shadow each other's lit
// side: the frame with shadow rays must equal the frame without them, pixel for pixel.
fn no_self_shadow_acne<R: Real>() {
    let text = "camera eye 0 3 -8 look 0 0.5 0\nlight directional dir 1 -1 1\nsphere center -1.5 1 0 radius 1\nbox min 1 0 -1 max 3 1.5 1\n";
    let mut st = Default::default();
    let frame = Frame::new(96, 64);
    let scene = scene_for::<R>(text, &mut st, frame.size());
    assert_eq!(gray_all(&scene, &frame, true), gray_all(&scene, &frame, false), "{}: acne", R::NAME);
}

/// Rays that leave a primitive's surface from outside, towards where its outward normal points
/// (shadow rays to lights in front, mirror rays), miss that primitive: the tracer relies on it
/// to leave the primitive untested ([`lattice_rt::accel::Filter::leaving`]; every primitive is
/// convex). This checks it against the tests themselves, rounding and offset included.
fn leaving_rays_miss_their_object<R: Real>() {
    let text = "camera eye 0 3 -8 look 0 0.5 0\nlight directional dir 1 -1 1\n\
        sphere center -2 1 0 radius 1\n\
        box min 1 0 -1 max 3 1.5 1 rotate y 30\n\
        cylinder base -0.5 0 2 radius 0.6 height 2 rotate x 20\n\
        cone base 1 0 3 radius 0.8 height 1.5 top 0.3 rotate z 15 scale 1 1.5 1\n\
        cone base -3 0 3 radius 0.5 height 1 rotate y 40\n";
    let mut st = Default::default();
    let scene = scene_in::<R>(text, &mut st);
    let cam = scene.camera();
    let dirs =
        [(1.0, 1.0, -1.0), (-0.6, 1.0, 0.5), (0.0, 1.0, 0.0), (0.3, 0.2, -1.0), (1.0, 0.05, 0.0), (-1.0, 0.3, 0.7)];
    let mut checked = 0;
    for (i, o) in scene.objects().iter().enumerate() {
        for y in 0..48 {
            for x in 0..64 {
                let eye = cam.ray(2 * x + 1, 2 * y + 1, 128, 96);
                let Some(hit) = o.intersect(&eye, R::ZERO, R::MAX) else { continue };
                let n = o.world_normal(hit.normal);
                if facing(eye.dir, n).entering {
                    let p = o.surface_point(hit.point, hit.normal);
                    let from = p + n * R::offset(p.max_abs(), o.size());
                    let mirror = eye.dir.normalize() + n * (-(eye.dir.normalize().dot(n)) * R::from_f64(2.0));
                    for d in dirs
                        .iter()
                        .map(|&(a, b, c)| Vec3::new(R::from_f64(a), R::from_f64(b), R::from_f64(c)).normalize())
                        .chain([mirror])
                    {
                        if d.dot(n) > R::ZERO {
                            checked += 1;
                            let again = o.intersect(&Ray::new(from, d), R::ZERO, R::MAX);
                            assert!(
                                again.is_none(),
                                "{}: object {i}, pixel ({x}, {y}), direction {d:?}: hit again at {:?}",
                                R::NAME,
                                again.map(|h| h.t)
                            );
                        }
                    }
                }
            }
        }
    }
    assert!(checked > 5000, "{}: only {checked} rays checked", R::NAME);
}

// 2. The whole scene far from the origin: the same picture within a stated tolerance.
fn far_from_the_origin<R: Real>() {
    let base = scene_text("spheres");
    let shift = match R::NAME {
        "fixed" => 1000.0,
        "f32" => 1.0e4,
        _ => 1.0e5,
    };
    let moved = translate_scene(&base, shift);
    let (mut s1, mut s2) = Default::default();
    let (a, b) = (scene_in::<R>(&base, &mut s1), scene_in::<R>(&moved, &mut s2));
    let frame = Frame::new(128, 64);
    let (ga, gb) = (gray_all(&a, &frame, true), gray_all(&b, &frame, true));
    let off = ga.iter().zip(&gb).filter(|(x, y)| x.abs_diff(**y) > 1).count();
    // Tolerance: at most 1 % of the pixels more than one gray level off.
    assert!(off * 100 <= ga.len(), "{}: {off} pixels off by more than a level", R::NAME);
}

/// The scene text with every coordinate moved by `d` along x, y and z.
fn translate_scene(text: &str, d: f64) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split('#').next().unwrap().split_whitespace().collect();
        let mut i = 0;
        let mut line_out = Vec::new();
        while i < words.len() {
            line_out.push(words[i].to_string());
            if matches!(words[i], "eye" | "look" | "center" | "min" | "max" | "base" | "pos") && words[0] != "light"
                || words[i] == "pos"
            {
                for k in 1..=3 {
                    let x: f64 = words[i + k].parse().unwrap();
                    line_out.push(format!("{}", x + d));
                }
                i += 3;
            }
            i += 1;
        }
        out.push_str(&line_out.join(" "));
        out.push('\n');
    }
    out
}

// 3. A small sphere far away: its silhouette within half a pixel of f64, or the scene refused.
fn small_far_sphere<R: Real>() {
    let text = "camera eye 0 0 -200 look 0 0 0 fov 1 1\nsphere radius 0.5\n";
    // The world size of a pixel at the sphere.
    let pixel = 2.0 * (0.5f64.to_radians()).tan() * 200.0 / 64.0;
    silhouette_as_f64::<R>(text, 1, (Vec3::new(0.0, 0.0, 0.0), 0.5), pixel, true);
}

// 3b. A small sphere in a scene thousands of times its size (in fixed point, the world box
// reaches 400000 in its own coordinates, so its rays are moved to near it before they are
// mapped): its silhouette within half a pixel of f64 all the same.
fn small_sphere_in_a_large_scene<R: Real>() {
    let text = "camera eye 1 0 -0.2 look 1 0 0 fov 10 10\nbox min -4000 -4000 100 max 4000 4000 200\n\
                sphere center 1 0 0 radius 0.01\n";
    let pixel = 2.0 * (5f64.to_radians()).tan() * 0.2 / 64.0;
    let centre = Vec3::new(1.0, 0.0, 0.0);
    silhouette_as_f64::<R>(text, 2, (centre, 0.01), pixel, false);
    // Rays from thousands of units away (as from the big box towards a light), aimed across
    // the sphere: hit as the same ray (its origin and direction as `R` holds them) in f64, at
    // the same distance, but within a few units of fixed point's last place of the silhouette.
    let (mut st, mut st64) = (vec![Object::<R>::default(); 2], vec![Object::<f64>::default(); 2]);
    let (mut parts, mut parts64) = (lattice_rt::Parts::default(), lattice_rt::Parts::default());
    let scene = parse::<R>(text, &mut st, &mut parts).unwrap();
    let s64 = parse::<f64>(text, &mut st64, &mut parts64).unwrap();
    let (sphere, sphere64) = (&scene.objects()[1], &s64.objects()[1]);
    let mut hits = 0;
    for from in [Vec3::new(1.0, 0.0, 150.0), Vec3::new(-3000.0, 2000.0, 150.0), Vec3::new(3900.0, -3900.0, -0.5)] {
        for k in 0..400 {
            let off = Vec3::new((k % 20) as f64 - 9.5, (k / 20) as f64 - 9.5, 0.0) * 0.0012;
            let r = Ray::new(from.cast::<R>(), (centre + off - from).normalize().cast::<R>());
            let r64 = Ray::new(r.origin.cast::<f64>(), r.dir.cast::<f64>());
            let (hit, hit64) = (sphere.intersect(&r, R::ZERO, R::MAX), sphere64.intersect(&r64, 0.0, f64::MAX));
            let (o, d) = (r64.origin - centre, r64.dir.normalize());
            let closest = (o - d * o.dot(d)).length();
            match (hit, hit64) {
                (Some(h), Some(h64)) => {
                    hits += 1;
                    let err = (h.t.to_f64() - h64.t).abs();
                    assert!(
                        err < 0.02,
                        "{}: from {from:?} offset {off:?}: t {} against {}",
                        R::NAME,
                        h.t.to_f64(),
                        h64.t
                    );
                }
                (None, None) => {}
                (h, h64) => assert!(
                    (closest - 0.01).abs() < 2e-4,
                    "{}: from {from:?} offset {off:?}: {closest} {h:?} {h64:?}",
                    R::NAME
                ),
            }
        }
    }
    assert!(hits > 3 * 150, "{}: {hits} hits", R::NAME);
}

/// Casts 64 x 64 eye rays into the scene `text` of `objects` objects in `R` and in `f64`: where
/// they disagree on hitting anything, the ray passes within half a `pixel` of the silhouette of
/// the sphere `(centre, radius)`. A refusal is allowed where `may_refuse`, in fixed point only,
/// as too small.
fn silhouette_as_f64<R: Real>(
    text: &str,
    objects: usize,
    (centre, radius): (Vec3<f64>, f64),
    pixel: f64,
    may_refuse: bool,
) {
    let mut st = vec![Object::<R>::default(); objects];
    let mut parts = lattice_rt::Parts::default();
    let scene = match parse::<R>(text, &mut st, &mut parts) {
        Ok(s) => s,
        Err(e) => {
            assert!(may_refuse && R::NAME == "fixed", "{e}");
            return assert!(e.to_string().contains("too small for this scene"), "{e}");
        }
    };
    let mut st64 = vec![Object::<f64>::default(); objects];
    let mut parts = lattice_rt::Parts::default();
    let s64 = parse::<f64>(text, &mut st64, &mut parts).unwrap();
    let n = 64;
    let mut mb = vec![0; 4];
    let mut q = Query::new(&mut mb);
    let mut disagree = 0;
    for y in 0..n {
        for x in 0..n {
            let r = scene.camera().ray(2 * x + 1, 2 * y + 1, 2 * n, 2 * n);
            let r64 = s64.camera().ray(2 * x + 1, 2 * y + 1, 2 * n, 2 * n);
            let hit = BruteForce.nearest(&scene, &r, R::ZERO, R::MAX, &mut q).map(|h| h.object);
            let hit64 = BruteForce.nearest(&s64, &r64, 0.0, f64::MAX, &mut q).map(|h| h.object);
            if hit != hit64 {
                // Only rays passing within half a pixel of the f64 silhouette may disagree.
                let d = r64.dir.normalize();
                let o = r64.origin - centre;
                let closest = (o - d * o.dot(d)).length();
                assert!((closest - radius).abs() < 0.5 * pixel, "{}: pixel {x},{y} {hit:?} vs {hit64:?}", R::NAME);
                disagree += 1;
            }
        }
    }
    assert!(disagree < n, "{}: {disagree} rays disagree", R::NAME);
}

// 4. Rays tangent to a sphere, cylinder and cone, swept a few units in the last place (LSB)
// either side: never NaN, and hit or miss is monotone (once the sweep misses it stays missed).
fn tangent_rays<R: Real>() {
    let step = match R::NAME {
        "f64" => 2.3e-16,
        "f32" => 1.2e-7,
        _ => 1.0 / 65536.0,
    };
    for (shape, top) in [(Shape::Sphere, 1.0), (Shape::Cylinder, 1.0), (Shape::Cone { top: R::ZERO }, 0.5)] {
        let mut missed = false;
        for k in -8i32..=8 {
            // A ray along x at height `top` in z: grazes the side of each shape at z = radius.
            let z = (if let Shape::Cone { .. } = shape { 0.5 } else { 1.0 }) + k as f64 * step;
            let r = Ray::new(
                v::<R>(-5.0, if let Shape::Sphere = shape { 0.0 } else { 1.0 - top }, z),
                v::<R>(1.0, 0.0, 0.0),
            );
            let hit = shape.intersect(&r, R::ZERO, R::MAX);
            if let Some(ShapeHit { t, normal: n, .. }) = hit {
                assert!(t.is_finite() && n.x.is_finite() && n.y.is_finite() && n.z.is_finite(), "{}: NaN", R::NAME);
                assert!(!missed, "{} {shape:?}: hit again at +{k} LSB after a miss", R::NAME);
            } else {
                missed = true;
            }
        }
        assert!(missed, "{} {shape:?}: the sweep never misses", R::NAME);
        assert!(shape
            .intersect(
                &Ray::new(
                    v::<R>(-5.0, if let Shape::Sphere = shape { 0.0 } else { 1.0 - top }, 0.0),
                    v::<R>(1.0, 0.0, 0.0)
                ),
                R::ZERO,
                R::MAX
            )
            .is_some());
    }
}

// 5. Glass: the critical angle plus and minus a little, and a ray starting inside glass.
fn glass_and_total_internal_reflection<R: Real>() {
    let ior = 1.5f64;
    let crit = (1.0 / ior).asin();
    let n_out = v::<R>(0.0, 1.0, 0.0);
    for (delta, tir) in [(-0.01, false), (0.01, true)] {
        let a = crit + delta;
        // From inside the glass towards the surface (along the outward normal).
        let d = v::<R>(a.sin(), a.cos(), 0.0);
        let side = facing(d, n_out);
        let (n, eta, entering) = (side.normal, side.eta(R::from_f64(ior)), side.entering);
        assert!(!entering, "{}", R::NAME);
        assert_eq!(n, v::<R>(0.0, -1.0, 0.0), "{}: normal flipped towards the ray", R::NAME);
        assert_eq!(eta, R::from_f64(ior), "{}: ratio swapped to ior/1 inside", R::NAME);
        let t = refract(d, n, eta);
        assert_eq!(t.is_none(), tir, "{} at critical {:+}", R::NAME, delta);
        if let Some(t) = t {
            // Snell: sin_t = ior * sin_i, leaving on the outside.
            let sin_t = t.x.to_f64() / t.length().to_f64();
            assert!((sin_t - ior * a.sin()).abs() < 2e-3, "{}: sin_t {sin_t}", R::NAME);
            assert!(t.y > R::ZERO);
        }
    }
    // Entering from air: never total internal reflection, bends towards the normal.
    let d = v::<R>(0.8, -0.6, 0.0);
    let side = facing(d, n_out);
    let (n, eta, entering) = (side.normal, side.eta(R::from_f64(ior)), side.entering);
    assert!(entering && n == n_out && eta == R::ONE / R::from_f64(ior));
    let t = refract(d, n, eta).unwrap();
    assert!((t.x.to_f64() - 0.8 / ior).abs() < 2e-3, "{}", R::NAME);
}

// 6. Rays parallel to lattice planes, +0.0 and -0.0, from a point on a cell plane.
fn signed_zero_parallel_rays<R: Real>() {
    let text = "camera eye 0 0 -10\nlight directional dir 0 -1 0\nbox min -2 -2 -2 max -1 -1 -1\nsphere center 1 1 1 radius 0.7\nbox min -1 0 1 max 2 1 2\n";
    let mut st = Default::default();
    let scene = scene_in::<R>(text, &mut st);
    let cfg = LatticeConfig { top: Resolution::Uniform([6, 6, 6]), ..LatticeConfig::default() };
    with_accels(&scene, &cfg, |name, a| {
        let mut mb = vec![0; 16];
        let mut q = Query::new(&mut mb);
        for (x, y) in [(-1.0, -1.0), (1.0, 1.0), (0.0, 0.5), (-1.5, -1.5)] {
            let mut answers = Vec::new();
            for (sx, sy) in [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)] {
                let r = Ray::new(v::<R>(x, y, -10.0), v::<R>(sx, sy, 1.0));
                answers.push(a.nearest(&scene, &r, R::ZERO, R::MAX, &mut q));
            }
            assert!(answers.windows(2).all(|w| w[0] == w[1]), "{} {name}: +0 and -0 differ at {x},{y}", R::NAME);
            let want = BruteForce.nearest(
                &scene,
                &Ray::new(v::<R>(x, y, -10.0), v::<R>(0.0, 0.0, 1.0)),
                R::ZERO,
                R::MAX,
                &mut q,
            );
            assert_eq!(answers[0], want, "{} {name}", R::NAME);
        }
    });
}

// 7-8. Diagonal rays through cell corners and along edges, rays in a face plane of the world
// box, from its far face, from inside a sub-lattice and into a sub-lattice's corner: the
// lattice answers exactly as brute force.
fn corners_faces_and_sub_lattices<R: Real>() {
    let text = "camera eye -4 -4 -4 look 0 0 0\nbox min 0 0 0 max 1 1 1\nsphere center 2 2 2 radius 0.5\ngroup g\n  box min 3 0 0 max 4 1 1\n  sphere center 3.5 2 0.5 radius 0.5\nend\n";
    let mut st = Default::default();
    let scene = scene_in::<R>(text, &mut st);
    let cfg = LatticeConfig {
        top: Resolution::Uniform([4, 4, 4]),
        sub: Resolution::Uniform([2, 2, 2]),
        ..LatticeConfig::default()
    };
    let w = scene.world();
    let g = scene.composites()[0].bounds;
    let rays = [
        Ray::new(w.min, w.max - w.min),                                        // corner to corner
        Ray::new(Vec3::new(w.min.x, w.min.y, w.min.z), v::<R>(1.0, 1.0, 0.0)), // along a face edge
        Ray::new(Vec3::new(w.min.x - R::ONE, w.min.y, R::ZERO), v::<R>(1.0, 0.0, 0.0)), // in a face plane, from outside
        Ray::new(Vec3::new(w.max.x, R::HALF, R::HALF), v::<R>(-1.0, 0.0, 0.0)), // starting on the far face
        Ray::new((g.min + g.max) * R::HALF, v::<R>(0.3, 1.0, 0.2)),            // inside the sub-lattice
        Ray::new(g.min - v::<R>(1.0, 1.0, 1.0), v::<R>(1.0, 1.0, 1.0)),        // into the sub-lattice's corner
    ];
    let mut mb = vec![0; 16];
    let mut q = Query::new(&mut mb);
    with_accels(&scene, &cfg, |name, a| {
        for r in &rays {
            for dir in [r.dir, -r.dir] {
                let r = Ray::new(r.origin, dir);
                let want = BruteForce.nearest(&scene, &r, R::ZERO, R::MAX, &mut q);
                assert_eq!(a.nearest(&scene, &r, R::ZERO, R::MAX, &mut q), want, "{} {name} {r:?}", R::NAME);
            }
        }
    });
}

// 19. An object reaching far out (a sphere far off, as large as it is far) beside a crowd of small
// ones: the world cell they crowd into gets a lattice of its own over the part of the cell they
// occupy, found in steps of the cell, and a coordinate far nearer the middle than the cell is
// wide is lost beside its side when the step is reckoned. The crowd's lattice still holds every
// one of them, so the lattice answers as brute force.
fn far_reaching_object_beside_a_crowd<R: Real>() {
    let far = (R::LIMIT / 10.0).min(1e30);
    let mut text = format!(
        "camera eye -1 -2.6 0.5 look -1 -1.6 0.5 up 0 0 1 fov 60 60\nsphere center {far} 0 0 radius {}\n",
        far / 4.0
    );
    // More than the split (16) in one world cell.
    for k in 0..24 {
        let a = k as f64 * std::f64::consts::TAU / 24.0;
        text += &format!("sphere center {} {} {} radius 0.3\n", -1.0 + 2.0 * a.cos(), 2.0, 1.2 * a.sin());
    }
    let mut st = Default::default();
    let scene = scene_in::<R>(&text, &mut st);
    let mut mb = vec![0; 32];
    let mut q = Query::new(&mut mb);
    let mut hits = 0;
    with_accels(&scene, &LatticeConfig::default(), |name, a| {
        for k in 0..32 * 32 {
            let r = scene.camera().ray(k % 32, k / 32, 32, 32);
            let want = BruteForce.nearest(&scene, &r, R::ZERO, R::MAX, &mut q);
            hits += usize::from(want.is_some());
            assert_eq!(a.nearest(&scene, &r, R::ZERO, R::MAX, &mut q), want, "{} {name} {r:?}", R::NAME);
        }
    });
    assert!(hits > 3 * 100, "{}: {hits} hits", R::NAME);
}

// 9. A long ray across thousands of cells: the same cell sequence as an exact walk.
fn long_walk_does_not_drift<R: Real>() {
    let text = "camera eye 0 0 -5 look 1 1 0\nbox min 0 0 0 max 1000 1000 1\n";
    let mut st = Default::default();
    let scene = scene_in::<R>(text, &mut st);
    let cfg = LatticeConfig { top: Resolution::Uniform([1000, 1000, 1]), ..LatticeConfig::default() };
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    let ray = Ray::new(v::<R>(0.37, 0.11, 0.5), v::<R>(0.8, 0.6, 0.0));
    let mut walked = Vec::new();
    lat.walk_cells(&ray, R::ZERO, R::MAX, |c, _, _| walked.push((c[0], c[1])));
    // The exact walk over the same planes, in f64 on the scalar's own coordinates.
    let (xs, ys) = (
        lat.coordinate_list(0, 0).iter().map(|v| v.to_f64()).collect::<Vec<_>>(),
        lat.coordinate_list(0, 1).iter().map(|v| v.to_f64()).collect::<Vec<_>>(),
    );
    let (o, d) = ([ray.origin.x.to_f64(), ray.origin.y.to_f64()], [ray.dir.x.to_f64(), ray.dir.y.to_f64()]);
    let start = |c: &[f64], x: f64| c.iter().rposition(|&p| p <= x).unwrap_or(0).min(c.len() - 2);
    let (mut i, mut j) = (start(&xs, o[0]), start(&ys, o[1]));
    let mut exact = vec![(i, j)];
    loop {
        let tx = (xs[i + 1] - o[0]) / d[0];
        let ty = (ys[j + 1] - o[1]) / d[1];
        if tx <= ty {
            i += 1
        } else {
            j += 1
        }
        if i + 1 >= xs.len() || j + 1 >= ys.len() {
            break;
        }
        exact.push((i, j));
    }
    assert!(walked.len() > 1500, "{}: {} cells", R::NAME, walked.len());
    if let Some(k) = walked.iter().zip(&exact).position(|(a, b)| a != b).filter(|&k| k > 0) {
        let (i, j) = exact[k - 1];
        let tx = (xs[i + 1] - o[0]) / d[0];
        let ty = (ys[j + 1] - o[1]) / d[1];
        eprintln!(
            "{}: first difference at step {k}: walked {:?}, exact {:?}, |tx - ty| = {:e}",
            R::NAME,
            walked[k],
            exact[k],
            (tx - ty).abs()
        );
    }
    assert_eq!(walked, exact, "{}: the walk drifted", R::NAME);
}

// 10. A large object spanning many cells, hit several cells ahead, while a nearer object lives
// only in that later cell: the nearer one wins, and each object is tested once per ray.
fn large_object_and_mailbox<R: Real>() {
    let text = "camera eye 0 0.5 -1\nbox min -50 -1 10 max 50 2 60\nsphere center 0 0.5 9.5 radius 0.3\n";
    let mut st = Default::default();
    let scene = scene_in::<R>(text, &mut st);
    let cfg = LatticeConfig { top: Resolution::Uniform([100, 3, 60]), ..LatticeConfig::default() };
    with_accels(&scene, &cfg, |name, a| {
        let mut mb = vec![0; 4];
        let mut q = Query::new(&mut mb);
        let hit = a
            .nearest(&scene, &Ray::new(v::<R>(0.0, 0.5, -1.0), v::<R>(0.0, 0.0, 1.0)), R::ZERO, R::MAX, &mut q)
            .unwrap();
        assert_eq!(hit.object, 1, "{} {name}: the sphere is nearer", R::NAME);
        if name != "bbox" {
            assert!(
                q.stats.object_tests <= 2,
                "{} {name}: {} object tests for 2 objects",
                R::NAME,
                q.stats.object_tests
            );
        }
    });
}

/// Objects at one place (a file that writes one sphere thousands of times, a box with copies of
/// itself): no lattice separates them, so the lattice stays coarse and its references bounded
/// (the automatic resolution once listed each of 3,000 such spheres in every one of 24^3
/// cells: 41 million references), and every accelerator gives the same nearest object.
fn objects_at_one_place<R: Real>() {
    let mut text = String::from("camera eye 0 0.5 -6\n");
    for _ in 0..1500 {
        text.push_str("sphere center 0 0 0 radius 1\nbox min -0.8 -0.8 -0.8 max 0.8 0.8 0.8\n");
    }
    let mut st = Default::default();
    let scene = scene_in::<R>(&text, &mut st);
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    assert!(
        lat.ref_count() <= 2 * scene.objects().len(),
        "{}: {} references for {} objects",
        R::NAME,
        lat.ref_count(),
        scene.objects().len()
    );
    let mut nearest = Vec::new();
    with_accels(&scene, &cfg, |name, a| {
        let mut mb = vec![0; scene.objects().len().div_ceil(32)];
        let mut q = Query::new(&mut mb);
        let ray = Ray::new(v::<R>(0.1, 0.2, -6.0), v::<R>(0.0, 0.0, 1.0));
        let hit =
            a.nearest(&scene, &ray, R::ZERO, R::MAX, &mut q).unwrap_or_else(|| panic!("{} {name}: no hit", R::NAME));
        nearest.push((name.to_string(), hit.object, hit.t));
    });
    assert!(nearest.windows(2).all(|w| (w[0].1, w[0].2) == (w[1].1, w[1].2)), "{}: {nearest:?}", R::NAME);
}

// 11. Cylinder and cone special rays.
fn cylinder_and_cone_special_rays<R: Real>() {
    let cyl = Shape::<R>::Cylinder;
    // Parallel to the axis, inside the radius: hits the bottom cap.
    let ShapeHit { t, normal: n, .. } =
        cyl.intersect(&Ray::new(v(0.3, -2.0, 0.2), v(0.0, 1.0, 0.0)), R::ZERO, R::MAX).unwrap();
    assert_eq!((t, n), (R::from_f64(2.0), v(0.0, -1.0, 0.0)), "{}", R::NAME);
    // Down onto the cap rim and just inside/outside it: no crack between cap and side.
    for x in [0.999, 1.0] {
        assert!(
            cyl.intersect(&Ray::new(v(x, 3.0, 0.0), v(0.0, -1.0, 0.0)), R::ZERO, R::MAX).is_some(),
            "{} rim {x}",
            R::NAME
        );
    }
    // Diagonally through the rim edge from outside: hits, never falls between cap and side.
    for k in -3..=3 {
        let y = 1.0 + k as f64 * 1e-3;
        let r = Ray::new(v(-3.0, y + 3.0, 0.0), v(1.0, -1.0, 0.0));
        assert!(cyl.intersect(&r, R::ZERO, R::MAX).is_some(), "{} crack at {y}", R::NAME);
    }
    let cone = Shape::Cone { top: R::ZERO };
    // Through the apex along the axis from above: hits at the apex.
    let ShapeHit { t, .. } = cone.intersect(&Ray::new(v(0.0, 3.0, 0.0), v(0.0, -1.0, 0.0)), R::ZERO, R::MAX).unwrap();
    assert!((t.to_f64() - 2.0).abs() < 1e-3, "{} apex t {t:?}", R::NAME);
    // Parallel to a generating line (slope -1 in x against y), outside: the linear case.
    let r = Ray::new(v(-2.0, -1.0, 0.0), v(1.0, 1.0, 0.0));
    if let Some(ShapeHit { t, normal: n, .. }) = cone.intersect(&r, R::ZERO, R::MAX) {
        assert!(t.is_finite() && n.x.is_finite(), "{}", R::NAME);
    }
    // The mirror cone above the apex is never hit.
    for y in [1.2, 1.5, 2.0] {
        assert!(
            cone.intersect(&Ray::new(v(-5.0, y, 0.0), v(1.0, 0.0, 0.0)), R::ZERO, R::MAX).is_none(),
            "{} mirror cone at {y}",
            R::NAME
        );
    }
}

// 12. Boxes under extreme transforms: hits and normals as in f64, or refused.
fn boxes_under_extreme_transforms<R: Real>() {
    for (name, tr) in [
        ("scale 1000", "scale 1000"),
        ("scale 0.001", "scale 0.001"),
        ("shear", "shear x y 3 rotate z 20"),
        ("mixed", "scale 1000 1 0.01"),
    ] {
        let text = format!("camera eye 0.3 0.2 -20\nbox min -0.5 -0.5 -0.5 max 0.5 0.5 0.5 {tr}\n");
        let mut st = vec![Object::<R>::default(); 2];
        let mut parts = lattice_rt::Parts::default();
        let scene = match parse::<R>(&text, &mut st, &mut parts) {
            Ok(s) => s,
            Err(e) => {
                assert!(R::NAME == "fixed" && e.to_string().contains("fixed"), "{} {name}: {e}", R::NAME);
                continue;
            }
        };
        let mut st64 = vec![Object::<f64>::default(); 2];
        let mut parts = lattice_rt::Parts::default();
        let s64 = parse::<f64>(&text, &mut st64, &mut parts).unwrap();
        let mut mb = vec![0; 2];
        let mut q = Query::new(&mut mb);
        for k in 0..50 {
            let (x, y) = ((k % 7) as f64 * 0.13 - 0.4, (k / 7) as f64 * 0.11 - 0.35);
            let d = [x * 0.04, y * 0.04, 1.0];
            let r = Ray::new(scene.camera().eye, v::<R>(d[0], d[1], d[2]));
            let r64 = Ray::new(s64.camera().eye, Vec3::new(d[0], d[1], d[2]));
            let h = BruteForce.nearest(&scene, &r, R::ZERO, R::MAX, &mut q);
            let h64 = BruteForce.nearest(&s64, &r64, 0.0, f64::MAX, &mut q);
            match (h, h64) {
                (Some(a), Some(b)) => {
                    let rel = (a.t.to_f64() - b.t).abs() / b.t;
                    assert!(rel < 1e-3, "{} {name}: t {} vs {}", R::NAME, a.t.to_f64(), b.t);
                    let (na, nb) = (scene.objects()[0].world_normal(a.normal), s64.objects()[0].world_normal(b.normal));
                    assert!(
                        na.x.to_f64() * nb.x + na.y.to_f64() * nb.y + na.z.to_f64() * nb.z > 0.99,
                        "{} {name}: normal",
                        R::NAME
                    );
                }
                (None, None) => {}
                (a, b) => {
                    // Disagreement only for rays grazing an edge: the f64 hit is near the box's silhouette.
                    let grazing =
                        b.is_none_or(|b| s64.objects()[0].world_normal(b.normal).dot(r64.dir.normalize()).abs() < 0.05);
                    assert!(grazing, "{} {name}: hit {:?} vs {:?}", R::NAME, a.map(|h| h.t), b.map(|h| h.t));
                }
            }
        }
    }
}

// 13. Fixed point: spheres far enough that squaring their distance would overflow Q16.16, and
// tiny radii near the LSB: correct, or refused by validation.
#[test]
fn fixed_point_far_spheres_are_right_and_tiny_ones_refused() {
    // Distance 4000: 4000^2 overflows i32 Q16.16 many times over; the hit must still be right.
    let text = "camera eye 0 0 -4000 look 0 0 0 fov 2 2\nsphere radius 40\n";
    let (mut a, mut b) = (vec![Object::<Fx>::default(); 2], vec![Object::<f64>::default(); 2]);
    let (mut pa, mut pb) = (lattice_rt::Parts::default(), lattice_rt::Parts::default());
    let (fx, f) = (parse::<Fx>(text, &mut a, &mut pa).unwrap(), parse::<f64>(text, &mut b, &mut pb).unwrap());
    let mut mb = vec![0; 2];
    let mut q = Query::new(&mut mb);
    let h =
        BruteForce.nearest(&fx, &Ray::new(fx.camera().eye, fx.camera().forward), Fx::ZERO, Fx::MAX, &mut q).unwrap();
    let h64 = BruteForce.nearest(&f, &Ray::new(f.camera().eye, f.camera().forward), 0.0, f64::MAX, &mut q).unwrap();
    // Right to 1e-4 of the distance (the saturating, unshifted quadratic would be off by far more).
    assert!((h.t.to_f64() - h64.t).abs() < 1e-4 * h64.t, "{} vs {}", h.t.to_f64(), h64.t);
    // A radius near the LSB in a scene of size 10 is refused, with the object's line.
    let tiny = "camera eye 0 0 -10\nsphere radius 1\nsphere center 2 0 0 radius 0.0001\n";
    let mut c = vec![Object::<Fx>::default(); 3];
    let mut parts = lattice_rt::Parts::default();
    let e = parse::<Fx>(tiny, &mut c, &mut parts).unwrap_err();
    assert_eq!((e.line, e.token), (3, "sphere"), "{e}");
}

// 14. Metamorphic: mirroring scene and camera mirrors the image; scaling everything by a power
// of two leaves the floating-point image bit-identical.
fn mirror_and_scale<R: Real>() {
    let base = scene_text("chair");
    let mirrored = format!(
        "{}\n",
        base.replace("group chair rotate y 20", "group chair rotate y 20 scale -1 1 1")
            .replace("box min -4 -0.1 -4 max 4 0 4", "box min -4 -0.1 -4 max 4 0 4 scale -1 1 1")
            .replace("camera eye 3 2.6", "camera eye -3 2.6")
            .replace("dir -0.5 -1 0.6", "dir 0.5 -1 0.6")
    );
    let frame = Frame::new(96, 48);
    let (mut s1, mut s2) = Default::default();
    let (a, b) = (scene_in::<R>(&base, &mut s1), scene_in::<R>(&mirrored, &mut s2));
    let (ga, gb) = (gray_all(&a, &frame, true), gray_all(&b, &frame, true));
    let w = frame.width as usize;
    let off = (0..ga.len()).filter(|&i| ga[i].abs_diff(gb[(i / w) * w + (w - 1 - i % w)]) > 1).count();
    assert!(off <= ga.len() / 200, "{}: {off} pixels not mirrored", R::NAME);
    if R::NAME == "fixed" {
        return; // rounding in fixed point does not scale exactly
    }
    let scaled = scale_scene(&base, 2.0);
    let mut s3 = Default::default();
    let c = scene_in::<R>(&scaled, &mut s3);
    assert!(gray_all(&a, &frame, true) == gray_all(&c, &frame, true), "{}: scaling by 2 changed the image", R::NAME);
}

/// The scene text with every length multiplied by `k`.
fn scale_scene(text: &str, k: f64) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap();
        let words: Vec<&str> = line.split_whitespace().collect();
        let mut res = Vec::new();
        let mut i = 0;
        while i < words.len() {
            res.push(words[i].to_string());
            let n = match words[i] {
                "eye" | "look" | "center" | "min" | "max" | "base" | "translate" => 3,
                "radius" | "height" | "top" => 1,
                _ => 0,
            };
            for j in 1..=n {
                res.push(format!("{}", words[i + j].parse::<f64>().unwrap() * k));
            }
            i += n + 1;
        }
        out.push_str(&res.join(" "));
        out.push('\n');
    }
    out
}

every_scalar! {
    shadow_rays_leave_surfaces_without_acne => no_self_shadow_acne;
    rays_leaving_a_surface_from_outside_miss_its_object => leaving_rays_miss_their_object;
    a_scene_far_from_the_origin_renders_the_same => far_from_the_origin;
    a_small_far_sphere_keeps_its_silhouette => small_far_sphere;
    a_small_sphere_in_a_large_scene_keeps_its_silhouette => small_sphere_in_a_large_scene;
    tangent_rays_never_give_nan_and_decide_consistently => tangent_rays;
    glass_handles_the_critical_angle_and_rays_from_inside => glass_and_total_internal_reflection;
    plus_and_minus_zero_directions_give_the_same_answer => signed_zero_parallel_rays;
    corners_faces_and_sub_lattices_answer_as_brute_force => corners_faces_and_sub_lattices;
    an_object_reaching_far_out_hides_no_other_from_the_lattice => far_reaching_object_beside_a_crowd;
    a_long_walk_follows_the_exact_cell_sequence => long_walk_does_not_drift;
    a_large_object_does_not_hide_a_nearer_one_and_each_is_tested_once => large_object_and_mailbox;
    cylinder_and_cone_special_rays_behave => cylinder_and_cone_special_rays;
    boxes_under_extreme_transforms_match_f64 => boxes_under_extreme_transforms;
    mirroring_mirrors_and_doubling_changes_nothing => mirror_and_scale;
    objects_at_one_place_keep_the_lattice_small_and_agree => objects_at_one_place;
}
