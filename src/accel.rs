//! The `Accelerator` trait and the two baselines: brute force and the paper's bounding-box
//! method with its inside test. The lattice (in `lattice`) implements the same trait, so tests
//! and benchmarks compare all three on the same rays.
//!
//! All accelerators share one rule for the nearest hit, [`offer`]: the smaller `t` wins and, for
//! hits within [`tie`] of each other (one point, up to rounding: the bottom of a glass box and
//! the floor it stands on), the smaller object index. Since every object test is exact for its
//! interval, any accelerator that tests every object the ray can hit up to the best hit's tie
//! window returns the brute-force answer bit for bit.

use crate::bounds::at;
use crate::math::{Ray, Vec3};
use crate::scalar::Real;
use crate::scene::{Culled, Scene};

/// The nearest intersection found for a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit<R> {
    /// Ray parameter of the hit.
    pub t: R,
    /// Index of the object hit.
    pub object: u32,
    /// Outward normal in object space (not normalised).
    pub normal: Vec3<R>,
    /// The point in object space, as the ray reached it ([`crate::scene::Object::surface_point`] puts
    /// it on the surface and in the world).
    pub point: Vec3<R>,
    /// How far beyond `t` another object's hit still counts as the same point ([`tie`]).
    pub tie: R,
}

/// Kinds of rays counted by [`Stats`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// Eye ray.
    Primary = 0,
    /// Shadow ray towards a light.
    Shadow = 1,
    /// Mirror-reflection ray.
    Reflection = 2,
    /// Refraction (transmission) ray.
    Refraction = 3,
}

/// Work counted while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Rays traced, by [`RayKind`].
    pub rays: [u64; 4],
    /// Of those, the rays that hit an object, by [`RayKind`] (a shadow ray that hits is
    /// blocked: its light is hidden); with the `hit-counts` feature (a default one).
    #[cfg(feature = "hit-counts")]
    pub hits: [u64; 4],
    /// Ray-object intersection tests.
    pub object_tests: u64,
    /// Bounding-box inside tests (the paper's baseline).
    pub inside_tests: u64,
    /// Lattice cells entered (top level and sub-lattices).
    pub cells_visited: u64,
    /// Eye-ray object tests skipped because the ray passes outside the object's window
    /// ([`crate::scene::EyeWindow`]); not counted in `object_tests`.
    pub culled: u64,
}

impl Stats {
    /// Adds another set of counts.
    pub fn add(&mut self, o: &Stats) {
        for (a, b) in self.rays.iter_mut().zip(o.rays.iter()) {
            *a += b;
        }
        #[cfg(feature = "hit-counts")]
        for (a, b) in self.hits.iter_mut().zip(o.hits.iter()) {
            *a += b;
        }
        self.object_tests += o.object_tests;
        self.inside_tests += o.inside_tests;
        self.cells_visited += o.cells_visited;
        self.culled += o.culled;
    }
    /// Counts a ray of `kind` that hit (`hit`), with the `hit-counts` feature.
    #[inline(always)]
    pub fn hit(&mut self, kind: RayKind, hit: bool) {
        #[cfg(feature = "hit-counts")]
        {
            self.hits[kind as usize] += u64::from(hit);
        }
        #[cfg(not(feature = "hit-counts"))]
        let _ = (kind, hit);
    }
    /// All rays of every kind.
    pub fn total_rays(&self) -> u64 {
        self.rays.iter().sum()
    }
}

/// What an accelerator is asked with a ray: what that ray may skip ([`Filter`], set by the
/// caller for each call), and the accelerator's own scratch, statistics and the mailbox (one
/// stamp per object and per composite, so a ray tests each once). Nothing else: what the tracer
/// remembers from ray to ray is its own ([`crate::trace::Work`]).
///
/// The filter rides in the query rather than beside it, so an accelerator's inner calls (the
/// object test above all) take one pointer for both. Its layout is fixed, the counters and the
/// filter first: a Cortex-M0+ loads and stores a word at most 124 bytes past a pointer in one
/// instruction, and these are read on every test.
#[derive(Debug)]
#[repr(C)]
pub struct Query<'m> {
    /// Counts so far.
    pub stats: Stats,
    /// What the ray being asked about may skip ([`Filter::NONE`] until the caller says more).
    pub filter: Filter,
    mailbox: &'m mut [u32],
    ray_id: u32,
}

impl<'m> Query<'m> {
    /// Scratch with a caller-provided mailbox of [`Query::mailbox_len`] entries. A shorter
    /// mailbox is allowed: objects beyond it are simply re-tested (same answer, more work).
    pub fn new(mailbox: &'m mut [u32]) -> Self {
        mailbox.iter_mut().for_each(|m| *m = 0);
        Query { stats: Stats::default(), filter: Filter::NONE, mailbox, ray_id: 0 }
    }
    /// Mailbox entries a scene needs: one per object and one per composite.
    pub fn mailbox_len<R: Real>(scene: &Scene<'_, R>) -> usize {
        scene.objects.len() + scene.composites.len()
    }
    /// Starts a new ray: every mailbox entry becomes unvisited.
    pub fn next_ray(&mut self) {
        self.ray_id = self.ray_id.wrapping_add(1);
        if self.ray_id == 0 {
            self.mailbox.iter_mut().for_each(|m| *m = 0);
            self.ray_id = 1;
        }
    }
    /// Marks entry `i` visited by the current ray; true if it was not yet.
    #[inline]
    pub fn first_visit(&mut self, i: usize) -> bool {
        match self.mailbox.get_mut(i) {
            Some(m) if *m == self.ray_id => false,
            Some(m) => {
                *m = self.ray_id;
                true
            }
            None => true,
        }
    }
}

/// What one ray may skip, given with the ray to [`Accelerator::nearest`] and
/// [`Accelerator::occluded`] in its query ([`Query::filter`]): the objects it is known to miss, the
/// objects whose regions it
/// passes outside ([`crate::scene::region`]: an eye ray's window position, a shadow ray's position across
/// a directional first light), and whether a lattice walk tests an object's box before it. The
/// answer is the same whatever the filter says; only the work differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Filter {
    /// Objects the ray is known to miss, each stored plus one (0: none): the one it leaves and
    /// one already tried. With `no_box_tests`, a filter that skips nothing is all zeros, so
    /// making one takes no table of its bytes (the tiny image's 16 KiB counts them).
    skip: [u32; 2],
    /// Its window position, both coordinates packed in one word ([`pack_uv`]): written and read
    /// whole, so a read finds the write in the store buffer (two narrow stores read as one
    /// wide load stall until they retire, on x86).
    eye_uv: u64,
    /// Whether the ray is an eye ray with a window position.
    eye_on: bool,
    /// Whether a lattice walk leaves out its test of an object's box before the object.
    no_box_tests: bool,
    /// A shadow ray towards the scene's first light, when that light is directional: its
    /// position across the light ([`Real::to_raw`] bits of the coordinates objects' shadow
    /// windows are in).
    first_light: Option<[u64; 2]>,
}

impl Filter {
    /// A ray that skips nothing, with box tests on.
    pub const NONE: Filter = Filter { eye_on: false, eye_uv: 0, first_light: None, skip: [0; 2], no_box_tests: false };

    /// An eye ray through window position `uv` (from [`crate::camera::Camera::window_uv`]), or
    /// not one (`None`): objects whose eye region does not hold it are not tested.
    #[inline]
    pub fn eye(mut self, uv: Option<[i32; 2]>) -> Self {
        self.set_eye(uv);
        self
    }
    /// A shadow ray towards the scene's first light, when that light is directional (its
    /// direction the light's `to_light`), at position `at` across the light (the origin's
    /// products with the two axes of the scene's shadow basis), or not one (`None`): objects
    /// then take the direction's object-space image from the scene, and objects whose shadow
    /// window does not hold `at` are not tested.
    #[inline]
    pub fn first_light<R: Real>(mut self, at: Option<[R; 2]>) -> Self {
        self.set_first_light(at);
        self
    }
    /// The object the ray leaves (`None`: none): it starts outside it, on the side of the
    /// tangent plane its outward normal points to, and travels away from that plane. Every
    /// primitive is convex, so lies wholly behind that plane: the ray cannot hit it.
    #[inline]
    pub fn leaving(mut self, object: Option<u32>) -> Self {
        self.set_leaving(object.unwrap_or(u32::MAX));
        self
    }
    /// An object the ray was already tested against and missed (`None`: none).
    #[inline]
    pub fn tried(mut self, object: Option<u32>) -> Self {
        self.set_tried(object);
        self
    }
    /// Switches a lattice walk's box test before each object's own (on by default): the same
    /// hits, fewer exact tests where objects are smaller than the cells that list them, at six
    /// crossings per object met.
    #[inline]
    pub fn box_tests(mut self, on: bool) -> Self {
        self.set_box_tests(on);
        self
    }
    /// [`Filter::eye`] in place: the tracer keeps one filter per core and changes only what
    /// changes from ray to ray (a few stores, where a new filter would be a copy of all of it).
    #[inline]
    pub(crate) fn set_eye(&mut self, uv: Option<[i32; 2]>) {
        self.eye_on = uv.is_some();
        if let Some(uv) = uv {
            self.eye_uv = pack_uv(uv);
        }
    }
    /// [`Filter::first_light`] in place.
    #[inline]
    pub(crate) fn set_first_light<R: Real>(&mut self, at: Option<[R; 2]>) {
        self.first_light = at.map(|w| [w[0].to_raw(), w[1].to_raw()]);
    }
    /// [`Filter::leaving`] in place (`u32::MAX`: none).
    #[inline]
    pub(crate) fn set_leaving(&mut self, object: u32) {
        self.skip[0] = object.wrapping_add(1);
    }
    /// [`Filter::tried`] in place.
    #[inline]
    pub(crate) fn set_tried(&mut self, object: Option<u32>) {
        self.skip[1] = object.unwrap_or(u32::MAX).wrapping_add(1);
    }
    /// [`Filter::box_tests`] in place.
    #[inline]
    pub(crate) fn set_box_tests(&mut self, on: bool) {
        self.no_box_tests = !on;
    }
    /// Whether object `i` is known to be missed by the ray ([`Filter::leaving`],
    /// [`Filter::tried`]).
    #[inline]
    pub fn skips(&self, i: u32) -> bool {
        let stored = i.wrapping_add(1);
        self.skip[0] == stored || self.skip[1] == stored
    }
    /// The eye ray's window position, if the ray is an eye ray with one.
    #[inline]
    pub fn eye_ray(&self) -> Option<[i32; 2]> {
        self.eye_on.then(|| unpack_uv(self.eye_uv))
    }
    /// Whether a lattice walk tests boxes before objects ([`Filter::box_tests`]).
    #[inline]
    pub fn tests_boxes(&self) -> bool {
        !self.no_box_tests
    }
    /// Whether the ray is tested through regions: an eye ray, or a shadow ray towards the first
    /// light.
    #[inline]
    pub(crate) fn by_windows(&self) -> bool {
        self.eye_on || self.first_light.is_some()
    }
}

/// How far apart two hits at about `p` may lie along a ray and still be one point: the offset a
/// secondary ray takes there off a unit object ([`Real::offset`]). Faces of two objects that
/// coincide (a glass box on a floor) meet within it, and which is hit then is decided by object
/// index, not by how each scalar rounds, so f32, fixed point and f64 draw them alike.
#[inline]
pub fn tie<R: Real>(p: Vec3<R>) -> R {
    R::offset(p.max_abs(), R::ONE)
}

/// The farthest `t` at which a hit can still win against `best` (its tie window), or `tmax`.
#[inline]
pub fn reach<R: Real>(best: &Option<Hit<R>>, tmax: R) -> R {
    best.map_or(tmax, |b| (b.t + b.tie).min(tmax))
}

/// A window position packed in one word (see `Filter::eye_uv`).
#[inline]
fn pack_uv(uv: [i32; 2]) -> u64 {
    u64::from(uv[0] as u32) | (u64::from(uv[1] as u32) << 32)
}

/// The window position [`pack_uv`] packed.
#[inline]
fn unpack_uv(w: u64) -> [i32; 2] {
    [w as u32 as i32, (w >> 32) as u32 as i32]
}

/// Tests object `i` against `ray` on `(tmin, reach]` ([`reach`]) and keeps the better hit: the
/// nearer, or within [`tie`] of each other the lower object index. Returns whether the object
/// was hit at all in that range.
#[inline]
pub fn offer<R: Real>(
    scene: &Scene<'_, R>,
    i: usize,
    ray: &Ray<R>,
    tmin: R,
    tmax: R,
    best: &mut Option<Hit<R>>,
    q: &mut Query<'_>,
) -> bool {
    if q.filter.skips(i as u32) {
        q.stats.culled += 1;
        return false;
    }
    let limit = reach(best, tmax);
    let o = at(scene.objects, i);
    let hit = match q.filter.eye_ray() {
        Some(uv) => match o.intersect_eye_ray(ray, uv, tmin, limit) {
            Ok(hit) => hit,
            Err(Culled) => {
                q.stats.culled += 1;
                return false;
            }
        },
        None => match q.filter.first_light {
            Some(w) => {
                if !o.shadow_window_holds([R::from_raw(w[0]), R::from_raw(w[1])]) {
                    q.stats.culled += 1;
                    return false;
                }
                o.intersect_first_light_ray(ray, tmin, limit)
            }
            None => o.intersect(ray, tmin, limit),
        },
    };
    q.stats.object_tests += 1;
    match hit {
        Some(h) => {
            let t = h.t;
            let tie = tie(ray.at(t));
            let better = match best {
                Some(b) if (t - b.t).abs() <= tie.max(b.tie) => (i as u32) < b.object,
                Some(b) => t < b.t,
                None => true,
            };
            if better {
                *best = Some(Hit { t, object: i as u32, normal: h.normal, point: h.point, tie });
            }
            true
        }
        None => false,
    }
}

/// Answers ray queries against a scene.
pub trait Accelerator<R: Real> {
    /// Short name for reports.
    fn name(&self) -> &'static str;
    /// The nearest hit with `t0 < t <= t1`, skipping what the query's filter allows.
    fn nearest(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<Hit<R>>;
    /// An object hit with `t0 < t <= t1`, if any (shadow rays: the occluder), skipping what the
    /// query's filter allows.
    fn occluded(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<u32>;
}

/// Tests every object for every ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct BruteForce;

impl<R: Real> Accelerator<R> for BruteForce {
    fn name(&self) -> &'static str {
        "brute"
    }
    fn nearest(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<Hit<R>> {
        let mut best = None;
        for i in 0..s.objects.len() {
            offer(s, i, ray, t0, t1, &mut best, q);
        }
        best
    }
    fn occluded(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<u32> {
        let mut best = None;
        (0..s.objects.len()).find(|&i| offer(s, i, ray, t0, t1, &mut best, q)).map(|i| i as u32)
    }
}

/// How much wider than a box an accelerator takes it for `ray` (a lattice's and an object's
/// alike). An object test rounds its hit's `t`, in fixed point to 2^-16 of the object's own
/// scale, so a ray that grazes a box can hit an object inside it at a point a few units of `t`
/// (each `|dir|` long) outside the box, which brute force would find and an accelerator that
/// took the box as it is would miss. And a box's crossings are found through the reciprocal
/// of the direction, whose rounding moves them by about the scalar's precision times the
/// distance from the origin: in fixed point (absolute precision) a ray from 2,000 units away
/// entered a lattice a few hundredths late and passed objects near its side untested. So the
/// box is also widened by the scalar's padding of the origin's size. Taking it a little wider
/// is safe: an accelerator only chooses which objects are tested.
#[inline]
pub(crate) fn slack<R: Real>(ray: &Ray<R>) -> R {
    ray.dir.max_abs() * R::pad_eps() + (ray.origin.max_abs() + R::ONE).padding()
}

/// The paper's baseline: every object's box gets an inside test for every ray, and only the
/// objects whose box the ray passes are intersected.
///
/// The inside test is done the paper's way: a rotation maps the ray onto the +z axis through
/// the origin, the box corners are mapped by the same matrix, and the ray passes the box only
/// if the mapped x values straddle 0 and the mapped y values straddle 0 (and the box is not
/// wholly behind the origin). The paper maps two corners; we map all eight, which makes the
/// test conservative for any orientation, so it never rejects a box the ray really enters; each
/// box is taken `slack` wider, as a lattice takes its boxes.
#[derive(Clone, Copy, Debug, Default)]
pub struct BoundingBox;

/// The rotation of the paper's inside test: an orthonormal frame with `w` along the ray.
struct RayFrame<R> {
    o: Vec3<R>,
    u: Vec3<R>,
    v: Vec3<R>,
    w: Vec3<R>,
}

impl<R: Real> RayFrame<R> {
    fn new(ray: &Ray<R>) -> Self {
        let w = ray.dir.normalize();
        // Any vector not parallel to w gives the other two axes.
        let a = if w.x.abs() < R::from_f64(0.57) {
            Vec3::new(R::ONE, R::ZERO, R::ZERO)
        } else {
            Vec3::new(R::ZERO, R::ONE, R::ZERO)
        };
        let u = w.cross(a).normalize();
        let v = w.cross(u);
        RayFrame { o: ray.origin, u, v, w }
    }

    /// The inside test for one box: the mapped corners' x values have opposite signs (or one is
    /// zero), so do their y values, and some corner lies ahead of the origin.
    fn passes(&self, b: &crate::math::Aabb<R>) -> bool {
        let (mut lo, mut hi) = ([R::MAX; 3], [-R::MAX; 3]);
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            ) - self.o;
            for (k, axis) in [self.u, self.v, self.w].into_iter().enumerate() {
                let c = p.dot(axis);
                lo[k] = lo[k].min(c);
                hi[k] = hi[k].max(c);
            }
        }
        lo[0] <= R::ZERO && hi[0] >= R::ZERO && lo[1] <= R::ZERO && hi[1] >= R::ZERO && hi[2] >= R::ZERO
    }
}

impl BoundingBox {
    fn run<R: Real>(
        scene: &Scene<'_, R>,
        ray: &Ray<R>,
        tmin: R,
        tmax: R,
        any: bool,
        q: &mut Query<'_>,
    ) -> Option<Hit<R>> {
        let frame = RayFrame::new(ray);
        let slack = slack(ray);
        let mut best = None;
        for (i, o) in scene.objects.iter().enumerate() {
            q.stats.inside_tests += 1;
            if frame.passes(&o.bounds.padded(slack)) && offer(scene, i, ray, tmin, tmax, &mut best, q) && any {
                return best;
            }
        }
        best
    }
}

impl<R: Real> Accelerator<R> for BoundingBox {
    fn name(&self) -> &'static str {
        "bbox"
    }
    fn nearest(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<Hit<R>> {
        Self::run(s, ray, t0, t1, false, q)
    }
    fn occluded(&self, s: &Scene<'_, R>, ray: &Ray<R>, t0: R, t1: R, q: &mut Query<'_>) -> Option<u32> {
        Self::run(s, ray, t0, t1, true, q).map(|h| h.object)
    }
}
