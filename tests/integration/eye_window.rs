//! Eye-ray windows skip work, never change a pixel: every eye ray traced with its window
//! position (objects outside their window are not tested; with `EyeRays::Windows` no walk at
//! all, for shadow rays towards a directional light too) gives the brightness and the object
//! it gives without, in every scalar and accelerator, on the paper's scenes, the Whitted scene,
//! generated scenes and cameras that sit inside or right beside an object.

use crate::common;

use common::{build_lattice, lattice_storage, scene_text, ACCELS};
use lattice_rt::generate::{random_scene, RandomScene};
use lattice_rt::scene::{Camera, Object};
use lattice_rt::trace::Work;
use lattice_rt::{
    parse, Accelerator, BoundingBox, BruteForce, EyeRays, Fx, LatticeConfig, Query, Real, Scene, SceneBuilder, Tracer,
};

/// Traces every eye ray of a `w x h` frame (pixel centres and a quarter-pixel offset) with and
/// without its window position; returns how many object tests the windows skipped.
fn same_with_and_without<R: Real>(scene: &Scene<'_, R>, w: i32, h: i32, what: &str) -> u64 {
    let mut st = lattice_storage(scene, &LatticeConfig::default());
    let lat = build_lattice(scene, &LatticeConfig::default(), &mut st);
    let mut culled = 0;
    for accel in ACCELS {
        let a: &dyn Accelerator<R> = match accel {
            common::Accel::Lattice => &lat,
            common::Accel::Bbox => &BoundingBox,
            common::Accel::Brute => &BruteForce,
        };
        // The reference: the accelerator alone, no window of any kind.
        let mut reference = Tracer::new(scene, a);
        reference.set_eye_rays(EyeRays::Plain);
        let mut mb0 = vec![0; Query::mailbox_len(scene)];
        let mut q0 = Work::new(&mut mb0);
        for how in [EyeRays::Accelerator, EyeRays::Windows] {
            let mut tracer = Tracer::new(scene, a);
            tracer.set_eye_rays(how);
            let mut mb = vec![0; Query::mailbox_len(scene)];
            let mut q = Work::new(&mut mb);
            let (w4, h4) = (4 * w, 4 * h);
            for sy in (1..h4).step_by(2) {
                for sx in (1..w4).step_by(2) {
                    let ray = scene.camera().ray(sx, sy, w4, h4);
                    let plain = reference.radiance_and_object(ray, None, &mut q0);
                    // Without the eye ray's window position only shadow windows act.
                    let shadows_only = tracer.radiance_and_object(ray, None, &mut q);
                    let uv = Camera::<R>::window_uv(sx, sy, w4, h4);
                    let windowed = tracer.radiance_and_object(ray, Some(uv), &mut q);
                    let at = format!("{what}, {}, {accel:?}, {how:?}: eye ray ({sx}, {sy}) of ({w4}, {h4})", R::NAME);
                    assert_eq!(plain, shadows_only, "{at}, shadow windows");
                    assert_eq!(plain, windowed, "{at}");
                }
            }
            culled += q.stats().culled;
        }
    }
    culled
}

fn scenes_in<R: Real>() {
    for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
        let text = scene_text(name);
        let mut storage = vec![Object::<R>::default(); 64];
        let mut parts = lattice_rt::Parts::default();
        let scene = parse::<R>(&text, &mut storage, &mut parts).unwrap();
        let culled = same_with_and_without(&scene, 48, 24, name);
        assert!(culled > 0, "{name}, {}: the windows skipped no test", R::NAME);
    }
}

#[test]
fn the_paper_scenes_render_the_same_with_windows_in_every_scalar() {
    scenes_in::<f64>();
    scenes_in::<f32>();
    scenes_in::<Fx>();
}

/// A random scene of 40 objects (4 per composite) seen from `eye` towards `look` (the view
/// fitted to frames of 48x32), or `None` if the camera is refused.
fn generated<'a>(
    storage: &'a mut [Object<f64>],
    parts: &'a mut lattice_rt::Parts<f64>,
    seed: u64,
    eye: (f64, f64, f64),
    look: (f64, f64, f64),
) -> Option<Scene<'a, f64>> {
    generated_for(storage, parts, seed, eye, look, [48, 32])
}

/// [`generated`] with the view fitted to frames of `shape`.
fn generated_for<'a>(
    storage: &'a mut [Object<f64>],
    parts: &'a mut lattice_rt::Parts<f64>,
    seed: u64,
    eye: (f64, f64, f64),
    look: (f64, f64, f64),
    shape: [u32; 2],
) -> Option<Scene<'a, f64>> {
    let mut b = SceneBuilder::new(storage, parts);
    random_scene(&mut b, &RandomScene { objects: 40, composite_size: 4, spread: 0.0, seed }).unwrap();
    b.camera.eye = lattice_rt::Vec3::new(eye.0, eye.1, eye.2);
    b.camera.look = lattice_rt::Vec3::new(look.0, look.1, look.2);
    b.camera.fov = lattice_rt::scene::FieldOfView::Within(70.0, 50.0);
    b.camera.frame = shape;
    b.finish().ok()
}

/// `each` over generated scenes (six seeds) seen from far off, from inside and from beside
/// their objects, each with what names it: how many scenes were built, and the sum of what
/// `each` counted.
fn over_generated(mut each: impl FnMut(&Scene<'_, f64>, &str) -> u64) -> (u32, u64) {
    let (mut built, mut counted) = (0, 0);
    for seed in 0..6u64 {
        for (eye, look) in [
            ((0.0, 2.0, -30.0), (0.0, 0.0, 0.0)),
            ((0.1, 0.2, 0.3), (5.0, 1.0, 2.0)),
            ((3.0, 0.0, 0.0), (-3.0, 0.5, 0.0)),
        ] {
            let (mut storage, mut parts) = (vec![Object::<f64>::default(); 40], lattice_rt::Parts::default());
            let Some(scene) = generated(&mut storage, &mut parts, seed, eye, look) else { continue };
            built += 1;
            counted += each(&scene, &format!("seed {seed}, eye {eye:?}"));
        }
    }
    (built, counted)
}

#[test]
fn generated_scenes_and_cameras_inside_or_beside_objects_render_the_same() {
    let (built, culled) = over_generated(|scene, what| same_with_and_without(scene, 32, 20, what));
    assert!(built >= 12 && culled > 0, "{built} scenes built, {culled} tests skipped");
}

/// A render checks each tile's eye rays only against the objects that can appear in the tile
/// (`Scene::eye_candidates`: their windows meet it, and their eye hulls). Every object left out
/// must be one that no eye ray through the tile hits (its window culls the ray, or the ray
/// misses it), and frames rendered so must equal those whose eye rays check every object's
/// window one by one (`EyeRays::Accelerator` over brute force).
#[test]
fn tile_candidates_leave_out_only_objects_no_eye_ray_of_the_tile_can_hit() {
    let (mut checked, mut left_out) = (0, 0);
    for seed in 0..4u64 {
        for (eye, look) in [((0.0, 2.0, -30.0), (0.0, 0.0, 0.0)), ((0.1, 0.2, 0.3), (5.0, 1.0, 2.0))] {
            let (mut storage, mut parts) = (vec![Object::<f64>::default(); 40], lattice_rt::Parts::default());
            let Some(scene) = generated(&mut storage, &mut parts, seed, eye, look) else { continue };
            // 8x8 tiles of a 48x32 frame, every quarter-pixel ray position in each.
            let (w4, h4) = (4 * 48, 4 * 32);
            for (tx, ty) in (0..6).flat_map(|tx| (0..4).map(move |ty| (tx, ty))) {
                let (sx, sy) = ([32 * tx, 32 * tx + 32], [32 * ty, 32 * ty + 32]);
                let (lo, hi) =
                    (Camera::<f64>::window_uv(sx[0], sy[1], w4, h4), Camera::<f64>::window_uv(sx[1], sy[0], w4, h4));
                let mask = scene.eye_candidates([lo[0], hi[0]], [lo[1], hi[1]]);
                for (i, o) in scene.objects().iter().enumerate().filter(|&(i, _)| mask & (1 << i) == 0) {
                    left_out += 1;
                    for y in sy[0]..=sy[1] {
                        for x in sx[0]..=sx[1] {
                            let ray = scene.camera().ray(x, y, w4, h4);
                            let uv = Camera::<f64>::window_uv(x, y, w4, h4);
                            assert!(!matches!(o.intersect_eye_ray(&ray, uv, 0.0, f64::MAX), Ok(Some(_))), "seed {seed}, eye {eye:?}: object {i} left out of tile ({tx}, {ty}) but hit at ({x}, {y})");
                        }
                    }
                }
            }
            for frame in [
                lattice_rt::Frame::new(48, 32),
                lattice_rt::Frame {
                    sampling: lattice_rt::Sampling::Adaptive { contrast: 4, coarse: false },
                    ..lattice_rt::Frame::new(37, 21)
                },
                lattice_rt::Frame {
                    sampling: lattice_rt::Sampling::Adaptive { contrast: 4, coarse: true },
                    ..lattice_rt::Frame::new(37, 21)
                },
            ] {
                let (mut storage, mut parts) = (vec![Object::<f64>::default(); 40], lattice_rt::Parts::default());
                let Some(scene) = generated_for(&mut storage, &mut parts, seed, eye, look, frame.size()) else {
                    continue;
                };
                let mut by_tiles = Tracer::new(&scene, &BruteForce);
                by_tiles.set_eye_rays(EyeRays::Windows);
                let mut by_rays = Tracer::new(&scene, &BruteForce);
                by_rays.set_eye_rays(EyeRays::Accelerator);
                assert_eq!(
                    common::render_tracer(&by_tiles, &frame).0,
                    common::render_tracer(&by_rays, &frame).0,
                    "seed {seed}, eye {eye:?}, {}x{}",
                    frame.width,
                    frame.height
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 8 && left_out > 0, "{checked} frames checked, {left_out} objects left out of tiles");
}

/// Every eye ray that hits an object passes inside the object's eye hull (`Object::
/// eye_region_meets` at the ray's window position), in every scalar, for the paper's scenes and
/// generated scenes seen from inside, beside and far from their objects; and the hulls cull
/// eye rays the windows alone let through, so the check is not empty.
#[test]
fn eye_rays_that_hit_an_object_pass_inside_its_eye_hull() {
    fn check<R: Real>(scene: &Scene<'_, R>, what: &str) -> (u64, u64) {
        let (w4, h4) = (4 * 64, 4 * 32);
        let (mut hits, mut culled) = (0, 0);
        for sy in 0..=h4 {
            for sx in 0..=w4 {
                let ray = scene.camera().ray(sx, sy, w4, h4);
                let uv = Camera::<R>::window_uv(sx, sy, w4, h4);
                for (i, o) in scene.objects().iter().enumerate() {
                    let inside = o.eye_region_meets([uv[0]; 2], [uv[1]; 2]);
                    culled += u64::from(o.eye_window_meets([uv[0]; 2], [uv[1]; 2]) && !inside);
                    if o.intersect(&ray, R::ZERO, R::MAX).is_some() {
                        hits += 1;
                        assert!(
                            inside,
                            "{what}, {}: the eye ray ({sx}, {sy}) of ({w4}, {h4}) hits object {i} outside its eye hull",
                            R::NAME
                        );
                    }
                }
            }
        }
        (hits, culled)
    }
    fn paper<R: Real>() -> (u64, u64) {
        let mut sum = (0, 0);
        for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
            let mut storage = vec![Object::<R>::default(); 64];
            let mut parts = lattice_rt::Parts::default();
            let scene = parse::<R>(&scene_text(name), &mut storage, &mut parts).unwrap();
            let (h, c) = check(&scene, name);
            sum = (sum.0 + h, sum.1 + c);
        }
        sum
    }
    for (hits, culled) in [paper::<f64>(), paper::<f32>(), paper::<Fx>()] {
        assert!(hits > 10_000 && culled > 10_000, "{hits} hits, {culled} rays culled by hulls alone");
    }
    let (built, culled) = over_generated(|scene, what| check(scene, what).1);
    assert!(built >= 12 && culled > 0, "{built} scenes built, {culled} rays culled by hulls alone");
}

/// A shadow ray towards the first light (directional) takes its direction's object-space image
/// from the scene: every object answers it as it answers the same ray mapped afresh, in every
/// scalar, from points all over the world box.
#[test]
fn first_light_rays_meet_objects_as_any_ray_does() {
    fn check<R: Real>() -> usize {
        let mut hits = 0;
        for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
            let mut storage = vec![Object::<R>::default(); 64];
            let mut parts = lattice_rt::Parts::default();
            let scene = parse::<R>(&scene_text(name), &mut storage, &mut parts).unwrap();
            let Some(lattice_rt::scene::Light::Directional { to_light, .. }) = scene.lights().first().copied() else {
                panic!("{name}: no directional light")
            };
            let w = scene.world();
            for i in 0..=20 {
                for j in 0..=20 {
                    let f = |lo: R, hi: R, k: i32| lo + (hi - lo) * R::from_i32(k) / R::from_i32(20);
                    let p = lattice_rt::Vec3::new(
                        f(w.min.x, w.max.x, i),
                        f(w.min.y, w.max.y, j),
                        f(w.min.z, w.max.z, (i * 7 + j * 3) % 21),
                    );
                    let ray = lattice_rt::Ray::new(p, to_light);
                    for o in scene.objects() {
                        let want = o.intersect(&ray, R::ZERO, R::MAX);
                        hits += usize::from(want.is_some());
                        assert_eq!(
                            o.intersect_first_light_ray(&ray, R::ZERO, R::MAX),
                            want,
                            "{name}, {}, from {p:?}",
                            R::NAME
                        );
                    }
                }
            }
        }
        hits
    }
    for hits in [check::<f64>(), check::<f32>(), check::<Fx>()] {
        assert!(hits > 100, "only {hits} of the rays hit anything");
    }
}

/// The query's world normals (the last unit-axis normal kept) are the objects' own, whatever
/// order objects and faces are asked in, in every scalar.
#[test]
fn kept_axis_normals_are_the_objects_own() {
    fn check<R: Real>() {
        let mut storage = vec![Object::<R>::default(); 64];
        let mut parts = lattice_rt::Parts::default();
        let scene = parse::<R>(&scene_text("whitted"), &mut storage, &mut parts).unwrap();
        let mut mb = vec![0; Query::mailbox_len(&scene)];
        let mut q = Work::new(&mut mb);
        let (o, z, h) = (R::ONE, R::ZERO, R::HALF);
        let v = lattice_rt::Vec3::new;
        let normals =
            [v(o, z, z), v(-o, z, z), v(z, o, z), v(z, -o, z), v(z, z, o), v(z, z, -o), v(h, o, z), v(z, z, h)];
        let n = scene.objects().len() as u32;
        let mut x = 7u32;
        for _ in 0..4000 {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            let (i, k) = ((x >> 8) % n, ((x >> 20) % 8) as usize);
            // Runs of the same pair, as neighbouring rays ask.
            for _ in 0..(x >> 28) % 3 + 1 {
                let want = scene.objects()[i as usize].world_normal(normals[k]);
                assert_eq!(q.world_normal(&scene, i, normals[k]), want, "{}: object {i}, normal {k}", R::NAME);
            }
        }
    }
    check::<f64>();
    check::<f32>();
    check::<Fx>();
}

/// Renders `frame` of `scene` with the tracer's defaults over its lattice, with the scratch's
/// tile lists (`Scratch::with_cover`) or without; returns the PBM bytes and the gray levels.
fn render_cover<R: Real>(
    scene: &Scene<'_, R>,
    frame: &lattice_rt::Frame,
    cover: bool,
) -> (Vec<u8>, Vec<u8>, lattice_rt::Stats) {
    struct Gray(Vec<u8>, usize);
    impl lattice_rt::Hooks for Gray {
        fn gray_tile(&mut self, x0: u16, y0: u16, w: u16, h: u16, levels: &[u8]) {
            for y in 0..h as usize {
                let at = (y0 as usize + y) * self.1 + x0 as usize;
                self.0[at..at + w as usize].copy_from_slice(&levels[y * w as usize..(y + 1) * w as usize]);
            }
        }
    }
    let mut st = lattice_storage(scene, &LatticeConfig::default());
    let lat = build_lattice(scene, &LatticeConfig::default(), &mut st);
    let tracer = Tracer::new(scene, &lat);
    let (w, h) = (frame.width as usize, frame.height as usize);
    let mut bits = vec![0u8; lattice_rt::BitFrame::bytes(w as u32, h as u32)];
    let mut target = lattice_rt::BitFrame::new(w as u32, h as u32, &mut bits).unwrap();
    let (mut mailbox, mut rows) = (vec![0; Query::mailbox_len(scene)], vec![0; frame.scratch_len()]);
    let mut room = vec![0; if cover { frame.cover_len() } else { 0 }];
    let mut scratch = lattice_rt::Scratch::new(&mut mailbox, &mut rows).with_cover(&mut room);
    let mut gray = Gray(vec![0; w * h], w);
    let stats = lattice_rt::render(&tracer, frame, &mut target, &mut scratch, &mut gray).expect("render");
    (bits, gray.0, stats)
}

/// Past 64 objects a render lists per tile the objects whose eye windows meet it, and the eye
/// rays of a tile with few test those instead of walking the lattice: every frame equals the
/// one rendered without the lists, in every scalar, for clustered and spread generated scenes
/// seen from outside and from within, with adaptive sampling, silhouette lines and error
/// diffusion (whose samples and apron rays reach past the tile).
#[test]
fn tile_lists_change_no_pixel() {
    fn check<R: Real>() -> (usize, usize) {
        let (mut checked, mut fewer_walks) = (0, 0);
        for (seed, composite_size, spread) in [(1u64, 0, 0.0), (2, 0, 40.0), (3, 25, 0.0), (4, 0, 6.0)] {
            for (eye, look) in [
                ((0.0, 8.0, -60.0), (0.0, 0.0, 0.0)),
                ((0.3, 0.2, 0.1), (5.0, 1.0, 2.0)),
                ((40.0, 3.0, 5.0), (0.0, 0.0, 0.0)),
            ] {
                let frames = [
                    lattice_rt::Frame::new(64, 40),
                    lattice_rt::Frame {
                        sampling: lattice_rt::Sampling::Adaptive { contrast: 4, coarse: false },
                        outline: true,
                        dither: lattice_rt::Dither::FloydSteinberg,
                        ..lattice_rt::Frame::new(53, 35)
                    },
                    lattice_rt::Frame {
                        sampling: lattice_rt::Sampling::Adaptive { contrast: 4, coarse: true },
                        outline: true,
                        tile: 16,
                        ..lattice_rt::Frame::new(53, 35)
                    },
                    lattice_rt::Frame {
                        sampling: lattice_rt::Sampling::Edges { contrast: 8 },
                        rows: (1, 3),
                        ..lattice_rt::Frame::new(48, 40)
                    },
                ];
                for frame in &frames {
                    let mut storage = vec![Object::<R>::default(); 150];
                    let mut parts = lattice_rt::Parts::default();
                    let mut b = SceneBuilder::new(&mut storage, &mut parts);
                    random_scene(&mut b, &RandomScene { objects: 150, composite_size, spread, seed }).unwrap();
                    b.camera.eye = lattice_rt::Vec3::new(eye.0, eye.1, eye.2);
                    b.camera.look = lattice_rt::Vec3::new(look.0, look.1, look.2);
                    b.camera.fov = lattice_rt::scene::FieldOfView::Within(60.0, 40.0);
                    b.camera.frame = frame.size();
                    let Ok(scene) = b.finish() else { continue };
                    let (with, without) = (render_cover(&scene, frame, true), render_cover(&scene, frame, false));
                    let at = format!("{}, seed {seed}, eye {eye:?}, {}x{}", R::NAME, frame.width, frame.height);
                    assert_eq!((&with.0, &with.1), (&without.0, &without.1), "{at}");
                    fewer_walks += usize::from(with.2.cells_visited < without.2.cells_visited);
                    checked += 1;
                }
            }
        }
        (checked, fewer_walks)
    }
    for (checked, fewer_walks) in [check::<f64>(), check::<f32>(), check::<Fx>()] {
        assert!(checked >= 24 && fewer_walks >= 12, "{checked} frames checked, {fewer_walks} walked less");
    }
}
