//! The block rule of two-level sampling: may a block of pixels whose corner rays all hit one
//! object be filled from them? Yes when no other object can appear there ([`alone`]), or every
//! one that can lies behind that object all over the block ([`behind`]).

use crate::accel::Accelerator;
use crate::camera::Camera;
use crate::math::{Aabb, Vec3};
use crate::scalar::Real;
use crate::scene::region::any_object;
use crate::scene::Scene;
use crate::trace::Tracer;

/// Whether the pixels of a tile at `(x0, y0)` between columns `xs` and rows `ys` (inclusive),
/// whose corners' eye rays hit object `id` (or nothing), the farthest at depth key `far`, may be
/// filled from those rays in the coarse level of adaptive sampling: no other object among the
/// tile's `candidates` can appear in them ([`Scene::eye_region_among_meets`]) but behind `id`
/// ([`behind`]), and the object neither mirrors nor refracts (in the
/// effects simulated). A tile with more than 64 objects' candidates is never filled so.
#[allow(clippy::too_many_arguments)]
pub(crate) fn alone<R: Real, A: Accelerator<R> + ?Sized, const E: u8>(
    tracer: &Tracer<'_, '_, R, A, E>,
    candidates: u64,
    (x0, y0): (usize, usize),
    (xs, ys): ([usize; 2], [usize; 2]),
    id: u16,
    far: u16,
    size: (i32, i32),
) -> bool {
    let scene = tracer.scene();
    // A scene of more than 64 objects gives every tile this mask (`Scene::eye_candidates`).
    if candidates == u64::MAX {
        return false;
    }
    if let Some(o) = scene.objects().get(id as usize) {
        if tracer.branches(crate::bounds::at(scene.materials(), o.material as usize)) != (false, false) {
            return false;
        }
    }
    let others = candidates & !(1u64.checked_shl(id as u32).unwrap_or(0));
    if others == 0 {
        return true;
    }
    // The rays that matter are those through the pixels' centres: the rectangle from the first
    // corner's centre to the last's (window `v` runs up the image).
    let (w4, h4) = size;
    let centre = |p: usize| 4 * p as i32 + 2;
    let (lo, hi) = (
        Camera::<R>::window_uv(centre(x0 + xs[0]), centre(y0 + ys[1]), w4, h4),
        Camera::<R>::window_uv(centre(x0 + xs[1]), centre(y0 + ys[0]), w4, h4),
    );
    let (u, v) = ([lo[0], hi[0]], [lo[1], hi[1]]);
    if !scene.eye_region_among_meets(others, u, v) {
        return true;
    }
    // Another object can appear there: unless it lies behind `id` all over the block.
    let us = [Camera::<R>::ray_u(centre(x0 + xs[0]), w4), Camera::<R>::ray_u(centre(x0 + xs[1]), w4)];
    let vs = [Camera::<R>::ray_v(centre(y0 + ys[0]), h4), Camera::<R>::ray_v(centre(y0 + ys[1]), h4)];
    let dirs = block_directions(scene.camera(), us, vs);
    let hidden = behind(scene, others, id as usize, far, &dirs);
    hidden != 0 && !scene.eye_region_among_meets(others & !hidden, u, v)
}

/// Depth-key steps (about 0.05 % each in fixed point, 1 % in floats) by which an object's
/// nearest possible hit must lie beyond the farthest of a block's corner hits for [`behind`] to
/// count it hidden: far more than the rounding of either.
const BEHIND_SLACK: u16 = 4;

/// The objects of `among` (bit `i`: object `i`, of the first 64) that no eye ray of a block of
/// pixels can see, because object `front` lies in front of them all over the block: the rays
/// through the block's corner pixels hit `front`, the farthest at depth key `far`
/// ([`Real::depth_key`]), and every ray of the block has a direction whose component `k` lies
/// in `dirs[k]` (the smallest and the largest). `front` is convex and the eye lies outside it,
/// so every ray between the corners hits it too, at most as far as the farthest corner (along
/// the ray through `(u, v)` the reciprocal of the entry parameter is concave in `(u, v)`); an
/// object whose box none of those rays can reach before that is hidden. None when the eye lies
/// in `front`'s box, or `front` is no object.
pub fn behind<R: Real>(scene: &Scene<'_, R>, among: u64, front: usize, far: u16, dirs: &[[R; 2]; 3]) -> u64 {
    let eye = scene.camera.eye;
    let Some(f) = scene.objects.get(front) else { return 0 };
    let inside = |lo: R, x: R, hi: R| lo <= x && x <= hi;
    if inside(f.bounds.min.x, eye.x, f.bounds.max.x)
        && inside(f.bounds.min.y, eye.y, f.bounds.max.y)
        && inside(f.bounds.min.z, eye.z, f.bounds.max.z)
    {
        return 0;
    }
    // Beyond every parameter whose key is within the slack of the farthest corner's.
    let beyond = R::key_bound(far.saturating_add(BEHIND_SLACK));
    let mut hidden = 0;
    any_object(among, scene.objects.len(), |i| {
        if scene.objects.get(i).is_some_and(|o| beyond_reach(&o.bounds, eye, dirs, beyond)) {
            hidden |= 1 << i;
        }
        false
    });
    hidden
}

/// Per component, the smallest and the largest direction `forward + right u + up v` of the eye
/// rays with `u` and `v` between the given ones (as [`Camera::ray_through`] sums them: at the
/// corners, since each product rounds monotonically), for [`behind`].
pub fn block_directions<R: Real>(cam: &Camera<R>, u: [R; 2], v: [R; 2]) -> [[R; 2]; 3] {
    let span = |f: R, r: R, up: R| {
        let (a, b, c, d) = (r * u[0], r * u[1], up * v[0], up * v[1]);
        [f + a.min(b) + c.min(d), f + a.max(b) + c.max(d)]
    };
    [
        span(cam.forward.x, cam.right.x, cam.up.x),
        span(cam.forward.y, cam.right.y, cam.up.y),
        span(cam.forward.z, cam.right.z, cam.up.z),
    ]
}

/// Whether no eye ray from `eye` whose direction's components lie in `dirs` meets box `b` at a
/// parameter below `t`: on some axis whose slab the eye lies outside, the gap to the slab is at
/// least `t` times the largest step towards it (or no ray heads towards it).
fn beyond_reach<R: Real>(b: &Aabb<R>, eye: Vec3<R>, dirs: &[[R; 2]; 3], t: R) -> bool {
    (0..3).any(|k| {
        let (e, lo, hi) = (eye.axis(k), b.min.axis(k), b.max.axis(k));
        let (gap, step) = if e > hi {
            (e - hi, -dirs[k][0])
        } else if e < lo {
            (lo - e, dirs[k][1])
        } else {
            return false;
        };
        step <= R::ZERO || gap >= t * step
    })
}
