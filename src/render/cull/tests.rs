//! The regions' tests: hulls that hold every hit, blocks whose hidden objects never show.

use super::block::{behind, block_directions};
use crate::camera::Camera;
use crate::math::Vec3;
use crate::scalar::Real;
#[cfg(feature = "eye-hulls")]
use crate::scene::hull::convex_hull;
use crate::scene::region::{hull_meets, HullEdge, NO_HULL};
use crate::scene::Scene;
use crate::scene::{Object, Parts, SceneBuilder};

/// `each` over the paper's five scenes in scalar `R`, with the scene's name: the sum of what
/// it counted.
fn over_paper<R: Real>(mut each: impl FnMut(&Scene<'_, R>, &str) -> usize) -> usize {
    let mut sum = 0;
    for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
        let text = std::fs::read_to_string(std::format!("{}/scenes/{name}.scene", env!("CARGO_MANIFEST_DIR"))).unwrap();
        let (mut storage, mut parts) = (std::vec![Object::<R>::default(); 64], Parts::default());
        let scene = crate::parse::<R>(&text, &mut storage, &mut parts).unwrap();
        sum += each(&scene, name);
    }
    sum
}

/// `each` over generated scenes of turned, sheared and scaled objects (eight seeds) in fixed
/// point, seen from far off and from among them, with what names each: how many scenes were
/// built, and the sum of what `each` counted.
fn over_generated(mut each: impl FnMut(&Scene<'_, crate::Fx>, &str) -> usize) -> (usize, usize) {
    let (mut built, mut sum) = (0, 0);
    for seed in 0..8u64 {
        for (eye, look) in [((0.0, 2.0, -30.0), (0.0, 0.0, 0.0)), ((3.0, 4.0, 3.0), (6.0, 5.0, 9.0))] {
            let (mut storage, mut parts) = (std::vec![Object::<crate::Fx>::default(); 24], Parts::default());
            let mut b = SceneBuilder::new(&mut storage, &mut parts);
            crate::generate::random_scene(
                &mut b,
                &crate::generate::RandomScene { objects: 24, composite_size: 3, spread: 12.0, seed },
            )
            .unwrap();
            b.camera.eye = Vec3::new(eye.0, eye.1, eye.2);
            b.camera.look = Vec3::new(look.0, look.1, look.2);
            b.camera.fov = crate::scene::FieldOfView::Within(70.0, 50.0);
            let Ok(scene) = b.finish() else { continue };
            built += 1;
            sum += each(&scene, &std::format!("seed {seed}, eye {eye:?}"));
        }
    }
    (built, sum)
}

/// A square's hull test: rectangles inside, across an edge, and wholly outside one edge.
#[test]
fn a_rectangle_outside_an_edge_is_culled() {
    // The diamond |u| + |v| <= 1 (units of 2^-10: 1024), as four edges with a, b = 2^14.
    let n: i16 = 1 << 14;
    let mut hull = NO_HULL;
    for (k, (a, b)) in [(n, n), (-n, n), (-n, -n), (n, -n)].into_iter().enumerate() {
        hull[k] = HullEdge::new(a, b, i32::from(n) * 1024);
    }
    let unit = 1 << 16;
    assert!(hull_meets(&hull, [0, 0], [0, 0]));
    assert!(hull_meets(&hull, [unit / 4, unit], [unit / 4, unit]));
    // The corner square beyond the edge u + v = 1.
    assert!(!hull_meets(&hull, [unit * 3 / 5, unit], [unit * 3 / 5, unit]));
    assert!(!hull_meets(&hull, [-unit, -unit * 3 / 5], [-unit, -unit * 3 / 5]));
    assert!(hull_meets(&NO_HULL, [i32::MIN, i32::MIN], [i32::MAX, i32::MAX]));
}

/// Just outside each edge of every object's hull (one unit of 2^-10 beyond it, all along
/// the edge within the object's eye window) no eye ray hits the object, in every scalar:
/// on the paper's scenes, and on generated scenes of turned, sheared and scaled objects
/// seen from far off and from among them.
#[cfg(feature = "eye-hulls")]
#[test]
fn no_eye_ray_just_outside_a_hull_edge_hits_the_object() {
    fn along_edges<R: Real>(objects: &[Object<R>], cam: &Camera<R>, what: &str, every_object: bool) -> usize {
        let mut rays = 0;
        for (i, o) in objects.iter().enumerate() {
            let w = o.region.eye_window;
            // A hull's edges touch the padded object's image, which lies in its window: the
            // walks along them find points there (an edge may pass outside the window
            // where the window is the tighter bound; for an object seen well in front of
            // the eye, as in the paper's scenes, not every edge).
            let before = rays;
            let edges = o.region.eye_hull.iter().filter(|e| !e.is_everywhere()).count();
            for &HullEdge { a, b, c } in o.region.eye_hull.iter().filter(|e| !e.is_everywhere()) {
                let (a, b) = (f64::from(a), f64::from(b));
                let n2 = a * a + b * b;
                // The foot of the line a U + b V = c + 1 (units of 2^-10), and its direction.
                let foot = [a * (f64::from(c) + 1.0) / n2, b * (f64::from(c) + 1.0) / n2];
                let along = [-b / n2.sqrt(), a / n2.sqrt()];
                for k in -4000..=4000 {
                    let s = f64::from(k) * 2.0;
                    let (u, v) = ((foot[0] + s * along[0]) / 1024.0, (foot[1] + s * along[1]) / 1024.0);
                    let inside =
                        |x: f64, lo: i32, hi: i32| x * 65536.0 >= f64::from(lo) && x * 65536.0 <= f64::from(hi);
                    if !(inside(u, w[0], w[1]) && inside(v, w[2], w[3])) {
                        continue;
                    }
                    rays += 1;
                    let ray = cam.ray_through(R::from_f64(u), R::from_f64(v));
                    assert!(
                        o.intersect(&ray, R::ZERO, R::MAX).is_none(),
                        "{what}, {}: object {i} hit at ({u}, {v}), outside its hull edge {a} u + {b} v <= {c}",
                        R::NAME
                    );
                }
            }
            assert!(
                !every_object || edges == 0 || rays > before,
                "{what}, {}: object {i}'s hull edges all miss its window {w:?}: {:?}",
                R::NAME,
                o.region.eye_hull
            );
        }
        rays
    }
    // On the paper's scenes, objects seen well in front of the eye: every object's hull is checked
    // to meet its window.
    fn paper<R: Real>(scene: &Scene<'_, R>, name: &str) -> usize {
        along_edges(scene.objects(), scene.camera(), name, true)
    }
    for rays in [over_paper::<f64>(paper), over_paper::<f32>(paper), over_paper::<crate::Fx>(paper)] {
        assert!(rays > 10_000, "{rays} rays along the hulls' edges");
    }
    let (built, _) = over_generated(|s, what| along_edges(s.objects(), s.camera(), what, false));
    assert!(built >= 10, "{built} generated scenes");
}

/// Over every block of pixels whose corner rays hit one object, no pixel's eye ray sees an
/// object [`behind`] counts hidden there, in every scalar, on the paper's scenes and on
/// generated ones; and some objects are counted hidden, so the check is not empty.
#[test]
fn objects_behind_a_block_s_object_show_in_none_of_its_pixels() {
    use crate::{BruteForce, Query, Tracer};
    fn blocks<R: Real>(scene: &Scene<'_, R>, what: &str) -> usize {
        let (w, h) = (64usize, 32usize);
        let (w4, h4) = (4 * w as i32, 4 * h as i32);
        let tracer = Tracer::new(scene, &BruteForce);
        let mut mailbox = std::vec![0; Query::mailbox_len(scene)];
        let mut work = crate::trace::Work::new(&mut mailbox);
        let centre = |p: usize| 4 * p as i32 + 2;
        let mut hit = |x: usize, y: usize| {
            let ray = scene.camera().ray(centre(x), centre(y), w4, h4);
            let (id, t) = tracer.eye_hit(ray, None, &mut work);
            (id, if id == crate::trace::NO_OBJECT { u16::MAX } else { t.depth_key() })
        };
        let pixels: std::vec::Vec<(u32, u16)> =
            (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| hit(x, y)).collect();
        let all = if scene.objects().len() >= 64 { u64::MAX } else { (1u64 << scene.objects().len()) - 1 };
        let mut counted = 0;
        for size in [2usize, 4] {
            for y0 in 0..h - size {
                for x0 in 0..w - size {
                    let (xs, ys) = ([x0, x0 + size], [y0, y0 + size]);
                    let corners = [(xs[0], ys[0]), (xs[1], ys[0]), (xs[0], ys[1]), (xs[1], ys[1])]
                        .map(|(x, y)| pixels[y * w + x]);
                    let id = corners[0].0;
                    if id == crate::trace::NO_OBJECT || corners.iter().any(|c| c.0 != id) {
                        continue;
                    }
                    let far = corners.iter().map(|c| c.1).max().unwrap();
                    let us = [Camera::<R>::ray_u(centre(xs[0]), w4), Camera::<R>::ray_u(centre(xs[1]), w4)];
                    let vs = [Camera::<R>::ray_v(centre(ys[0]), h4), Camera::<R>::ray_v(centre(ys[1]), h4)];
                    let hidden =
                        behind(scene, all & !(1 << id), id as usize, far, &block_directions(scene.camera(), us, vs));
                    counted += hidden.count_ones() as usize;
                    for y in ys[0]..=ys[1] {
                        for x in xs[0]..=xs[1] {
                            let seen = pixels[y * w + x].0;
                            let shown = seen == crate::trace::NO_OBJECT || hidden & (1 << seen) == 0;
                            let name = R::NAME;
                            assert!(
                                shown,
                                "{what}, {name}: object {seen} counted hidden behind {id} over ({x0}, {y0}) + {size} \
                                 shows at ({x}, {y})"
                            );
                        }
                    }
                }
            }
        }
        counted
    }
    for counted in [over_paper::<f64>(blocks), over_paper::<f32>(blocks), over_paper::<crate::Fx>(blocks)] {
        assert!(counted > 1000, "{counted} objects counted hidden");
    }
    let (_, counted) = over_generated(blocks);
    assert!(counted > 0, "no object counted hidden in the generated scenes");
}

/// The hull of a square's corners and four points inside is the square, counter-clockwise.
#[cfg(feature = "eye-hulls")]
#[test]
fn the_hull_of_eight_points_is_their_outer_ring() {
    let pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [0.2, 0.7], [0.9, 0.1], [0.5, 0.0]];
    let (ring, n) = convex_hull(pts);
    assert_eq!(&ring[..n], &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
}
