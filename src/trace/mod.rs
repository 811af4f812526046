//! The intersection tree and the paper's eq. (1):
//! `I = Ia*Ka + sum over visible lights Ip*Kd*max(0, L.N) + Ks*S + Kt*T`.
//!
//! The tree is evaluated without recursion: since `I` is linear in `S` and `T`, a pixel's
//! brightness is the sum over the tree's nodes of (product of coefficients on the path) times
//! (the node's local term). Nodes wait on an explicit stack of at most `MAX_DEPTH + 1` entries
//! (depth-first, each node pushes at most two children).
//!
//! Secondary rays start at `p + n * eps` on the side they travel to, with `n` the normal
//! flipped to face the incoming ray, `p` the hit put on the object's surface in object space
//! and mapped to the world ([`crate::scene::Object::surface_point`]: its error does not depend on
//! where the ray came from), and `eps = Real::offset(max|p|, size of the object hit)`. That is
//! local: a far object or a far eye does not change it. In floating point it is
//! `point_eps * max|p| + offset_eps * size`: above the rounding of `p` wherever the object sits
//! (the `max|p|` term, a few units of its last place) and above the rounding of the object's own
//! arithmetic (the size term), never zero at the origin, and exactly proportional to the scene
//! when it is scaled by a power of two, so such a scaling leaves the image bit for bit the
//! same. Fixed point, whose absolute precision is the same everywhere, uses
//! `offset_eps * (1 + size)`.

mod work;
pub use work::Work;

use crate::accel::{Accelerator, BruteForce, Hit, Query, RayKind};
use crate::bounds::at;
use crate::math::{Ray, Vec3};
use crate::scalar::Real;
use crate::scene::{Effects, Light, Material, Scene, MAX_DEPTH};
use heapless::Vec;

/// The object id reported for an eye ray that hits nothing.
pub const NO_OBJECT: u32 = u32::MAX;

/// A scene needs effects the tracer was compiled without.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MissingEffects(pub Effects);

impl core::fmt::Display for MissingEffects {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "the scene needs effects this build leaves out: {}", self.0)
    }
}

impl core::error::Error for MissingEffects {}

/// A tree depth beyond [`MAX_DEPTH`] was asked for.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooDeep {
    /// The depth asked for.
    pub depth: u8,
}

impl core::fmt::Display for TooDeep {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "depth {} is deeper than the tracer supports ({MAX_DEPTH})", self.depth)
    }
}

impl core::error::Error for TooDeep {}

/// The side of a surface a ray meets ([`facing`]): the normal turned to face the ray, and
/// whether the ray enters (travels against the outward normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Side<R> {
    /// The normal on the ray's side.
    pub normal: Vec3<R>,
    /// Whether the ray travels against the outward normal (enters a solid from outside).
    pub entering: bool,
}

impl<R: Real> Side<R> {
    /// The ratio of indices `eta = n_from / n_to` at a material of index `ior` in air: `1 / ior`
    /// entering, `ior / 1` leaving.
    pub fn eta(&self, ior: R) -> R {
        if self.entering {
            R::ONE / ior
        } else {
            ior
        }
    }
}

/// The side of a surface with normal `outward` a ray of direction `d` meets: a ray from inside
/// (its direction along the outward normal) gets the flipped normal. Only the sign of `d . outward`
/// matters, so `d` need not be unit length.
pub fn facing<R: Real>(d: Vec3<R>, outward: Vec3<R>) -> Side<R> {
    if d.dot(outward) <= R::ZERO {
        Side { normal: outward, entering: true }
    } else {
        Side { normal: -outward, entering: false }
    }
}

/// Snell's law: the unit direction refracted from unit `d` at a surface with unit normal `n`
/// facing the ray, for the ratio of indices `eta`; `None` past the critical angle (total
/// internal reflection).
///
/// `sin^2` of the incidence comes from the cross product, not from `1 - cos^2`: near the normal
/// that difference cancels to the rounding of `cos`, which `eta^2` then magnifies (glass of
/// index 40,000 in f32 decided total internal reflection by rounding).
pub fn refract<R: Real>(d: Vec3<R>, n: Vec3<R>, eta: R) -> Option<Vec3<R>> {
    let cos_i = -d.dot(n);
    let c = d.cross(n);
    let k = R::ONE - eta * eta * c.dot(c);
    if k < R::ZERO {
        None
    } else {
        Some(d * eta + n * (eta * cos_i - k.sqrt()))
    }
}

/// Traces rays through a scene with one accelerator.
///
/// `E` is the set of effects compiled in (an [`Effects`] bit set): code for the others is
/// removed by the compiler, so firmware for a matte scene carries no mirror or glass code.
#[derive(Debug)]
pub struct Tracer<'s, 'a, R, A: ?Sized, const E: u8 = { Effects::ALL.bits() }> {
    scene: &'s Scene<'a, R>,
    accel: &'s A,
    effects: Effects,
    /// At most [`MAX_DEPTH`] (checked by [`Tracer::set_max_depth`]), so the node stack never
    /// overflows.
    max_depth: u8,
    cutoff: R,
    /// How eye rays given a window position find their nearest hit.
    eye_rays: EyeRays,
    /// Whether a shadow ray first tries the object that last hid its light.
    coherence: bool,
    /// Whether a lattice walk tests an object's box before the object ([`crate::accel::Filter::box_tests`]).
    box_tests: bool,
    /// Whether every ray the SPD's testing protocol asks for is spawned ([`Tracer::set_every_ray`]).
    every_ray: bool,
}

/// How eye rays find their nearest hit. Every eye ray starts at the eye, and each object knows
/// its window on the image ([`crate::scene::EyeWindow`]), so for a scene of few objects
/// testing every object's window beats walking the lattice; both give the same hit.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EyeRays {
    /// Through the tracer's accelerator like any other ray, windows unused (the paper's
    /// methods as they were, for comparing them).
    Plain,
    /// Through the tracer's accelerator, skipping objects whose window misses the ray.
    Accelerator,
    /// Every object's window tested, and the exact test made only where the window holds the
    /// ray: no walk at all. Shadow rays towards the first light, when it is directional, do
    /// the same with the objects' shadow windows ([`crate::scene::ShadowWindow`]).
    Windows,
}

impl EyeRays {
    /// Most objects for which [`EyeRays::Windows`] is the default: past some size a window
    /// test per object costs more than the walk saves. Measured on the Cortex-M0+ (QEMU): the
    /// 38-object Whitted scene takes 20 % fewer instructions with windows than with the walk.
    pub const WINDOWS_UP_TO: usize = 64;

    /// Most objects for which [`EyeRays::Windows`] also answers the rays the windows do not
    /// serve (mirror and refracted rays, shadow rays towards other lights) by testing every
    /// object, without the walk: for so few objects the walk's set-up and cell steps cost more
    /// than the tests they save, and the hit is the same (`cargo xtask versus`: the three-object
    /// spheres scene 6 % faster on the host, the others unchanged).
    pub const EVERY_OBJECT_UP_TO: usize = 4;

    /// The default for a scene: [`EyeRays::Windows`] up to [`EyeRays::WINDOWS_UP_TO`] objects.
    pub fn for_scene<R: Real>(scene: &Scene<'_, R>) -> Self {
        if scene.objects.len() <= Self::WINDOWS_UP_TO {
            EyeRays::Windows
        } else {
            EyeRays::Accelerator
        }
    }

    /// Whether the windows answer every ray a frame of `scene` casts with its default eye rays
    /// ([`EyeRays::for_scene`]), whatever effects are compiled in: eye rays by windows, and
    /// either so few objects that every other ray tests them all
    /// ([`EyeRays::EVERY_OBJECT_UP_TO`]), or no material that mirrors or refracts (no secondary
    /// rays) and no light but a first one that is directional (shadow rays by its shadow
    /// windows). A tracer of such a scene never asks its accelerator, so a build whose scenes
    /// all qualify can give it [`BruteForce`] in place of the lattice: the frames are the same,
    /// and the walk's code is not linked.
    pub fn serve_every_ray<R: Real>(scene: &Scene<'_, R>) -> bool {
        let effects = Effects::of(scene);
        let secondary = effects.contains(Effects::REFLECTION) || effects.contains(Effects::REFRACTION);
        let lights = match scene.lights {
            [] => true,
            [_] => scene.shadow_basis.is_some(),
            _ => false,
        };
        Self::for_scene(scene) == EyeRays::Windows
            && (scene.objects.len() <= Self::EVERY_OBJECT_UP_TO || !secondary && lights)
    }
}

/// The nearest hit of an eye ray among the objects whose windows hold it: the tile's
/// `candidates` ([`Work::eye_candidates`]) in index order, each window checked again for the ray
/// itself (as [`BruteForce`] would check every object's); objects that are no candidates are
/// counted as culled, as their windows would have culled them.
fn nearest_by_windows<R: Real>(
    scene: &Scene<'_, R>,
    ray: &Ray<R>,
    candidates_mask: u64,
    q: &mut Query<'_>,
) -> Option<Hit<R>> {
    let n = scene.objects.len();
    if n > 64 {
        return BruteForce.nearest(scene, ray, R::ZERO, R::MAX, q);
    }
    let mut best = None;
    // The candidates are counted as they come (cheaper than a population count on a core
    // without one): the others are culled.
    let mut candidates = 0u32;
    crate::scene::region::any_object(candidates_mask, n, |i| {
        candidates += 1;
        crate::accel::offer(scene, i, ray, R::ZERO, R::MAX, &mut best, q);
        false
    });
    q.stats.culled += u64::from(n as u32 - candidates);
    best
}

#[derive(Clone, Copy, Debug)]
struct Node<R> {
    ray: Ray<R>,
    meta: Meta<R>,
}

/// What the tracer keeps of a node of the intersection tree besides its ray.
#[derive(Clone, Copy, Debug)]
struct Meta<R> {
    weight: R,
    depth: u8,
    kind: RayKind,
    /// The object the ray leaves from outside (a mirror ray off its surface), which it cannot
    /// hit ([`crate::accel::Filter::leaving`]), or [`NO_OBJECT`].
    leaving: u32,
}

impl<'s, 'a, R: Real, A: Accelerator<R> + ?Sized> Tracer<'s, 'a, R, A> {
    /// A tracer with every effect compiled in, the scene's own effect set and depth, and no
    /// cutoff.
    pub fn new(scene: &'s Scene<'a, R>, accel: &'s A) -> Self {
        Tracer {
            scene,
            accel,
            effects: Effects::of(scene),
            max_depth: scene.max_depth.min(MAX_DEPTH),
            cutoff: R::ZERO,
            eye_rays: EyeRays::for_scene(scene),
            coherence: true,
            box_tests: true,
            every_ray: false,
        }
    }
}

impl<'s, 'a, R: Real, A: Accelerator<R> + ?Sized, const E: u8> Tracer<'s, 'a, R, A, E> {
    /// A tracer with only the effects `E` compiled in; fails if the scene needs others.
    pub fn compiled(scene: &'s Scene<'a, R>, accel: &'s A) -> Result<Self, MissingEffects> {
        let need = Effects::of(scene);
        let missing = need - Effects::from_bits(E);
        if !missing.is_empty() {
            return Err(MissingEffects(missing));
        }
        Ok(Tracer {
            scene,
            accel,
            effects: need,
            max_depth: scene.max_depth.min(MAX_DEPTH),
            cutoff: R::ZERO,
            eye_rays: EyeRays::for_scene(scene),
            coherence: true,
            box_tests: true,
            every_ray: false,
        })
    }

    /// Spawns every ray the Standard Procedural Databases' testing protocol asks for (its
    /// Readme, rules 8 and 9): a mirror ray from every transmitting surface too (its `Ks` may be
    /// 0), and every mirror and refracted ray whatever its weight. The picture is the same (the
    /// rays added weigh nothing); the ray counts become comparable with the published ones.
    pub fn set_every_ray(&mut self, on: bool) {
        self.every_ray = on;
    }

    /// How eye rays find their nearest hit.
    pub fn eye_rays(&self) -> EyeRays {
        self.eye_rays
    }

    /// Sets how eye rays find their nearest hit (the picture is the same either way).
    pub fn set_eye_rays(&mut self, how: EyeRays) {
        self.eye_rays = how;
    }

    /// Whether shadow rays try the object that last hid their light first (on by default).
    pub fn shadow_coherence(&self) -> bool {
        self.coherence
    }

    /// Switches shadow-ray coherence (the picture is the same either way; off is the paper's
    /// method as it was, for comparing).
    pub fn set_shadow_coherence(&mut self, on: bool) {
        self.coherence = on;
    }

    /// Whether a lattice walk tests an object's box before the object (on by default).
    pub fn box_tests(&self) -> bool {
        self.box_tests
    }

    /// Switches the walk's box tests ([`crate::accel::Filter::box_tests`]; the picture is the same either
    /// way; off is the paper's walk, which tests every object of every cell it enters).
    pub fn set_box_tests(&mut self, on: bool) {
        self.box_tests = on;
    }

    /// The scene traced.
    pub fn scene(&self) -> &'s Scene<'a, R> {
        self.scene
    }

    /// The accelerator answering ray queries.
    pub fn accel(&self) -> &'s A {
        self.accel
    }

    /// Effects simulated at run time (within those compiled in): the scene's own by default.
    pub fn effects(&self) -> Effects {
        self.effects
    }

    /// Simulates `effects` (those not compiled in stay off: see [`Tracer::simulates`]).
    pub fn set_effects(&mut self, effects: Effects) {
        self.effects = effects;
    }

    /// Maximum depth of the intersection tree (0: eye rays only).
    pub fn max_depth(&self) -> u8 {
        self.max_depth
    }

    /// Sets the maximum depth of the intersection tree; deeper than [`MAX_DEPTH`] is refused
    /// (the tracer's node stack holds that many levels).
    pub fn set_max_depth(&mut self, depth: u8) -> Result<(), TooDeep> {
        if depth > MAX_DEPTH {
            return Err(TooDeep { depth });
        }
        self.max_depth = depth;
        Ok(())
    }

    /// Branches whose weight falls below this are not traced (0 traces everything).
    pub fn cutoff(&self) -> R {
        self.cutoff
    }

    /// Sets the contribution cutoff (see [`Tracer::cutoff`]).
    pub fn set_cutoff(&mut self, cutoff: R) {
        self.cutoff = cutoff;
    }

    /// This tracer with its cutoff raised to 2^-k where `at_least` is `Some(k)` (a frame's
    /// [`Frame::cutoff`](crate::Frame::cutoff); `k` above 14 counts as 14), else as it is.
    pub fn with_cutoff_at_least(&self, at_least: Option<u8>) -> Self {
        let floor = at_least.map_or(R::ZERO, |k| R::ONE.div_pow2(u32::from(k)));
        Tracer { cutoff: self.cutoff.max(floor), ..*self }
    }

    /// Whether an effect is both compiled in and switched on.
    #[inline(always)]
    pub fn simulates(&self, effect: Effects) -> bool {
        Effects::from_bits(E).contains(effect) && self.effects.contains(effect)
    }

    /// Whether a hit on material `m` casts a mirror ray and whether it casts a refracted one, in
    /// the effects simulated (each ray also needs the tree's depth left).
    #[inline(always)]
    pub fn branches(&self, m: &Material<R>) -> (bool, bool) {
        let refracts = self.simulates(Effects::REFRACTION) && m.kt > R::ZERO;
        (self.simulates(Effects::REFLECTION) && (m.ks > R::ZERO || (self.every_ray && refracts)), refracts)
    }

    /// Brightness (0 black .. 1 white, clamped) seen along an eye ray.
    pub fn radiance(&self, eye: Ray<R>, w: &mut Work<'_>) -> R {
        self.eye_sample(eye, None, w).0
    }

    /// Brightness along an eye ray and the object the eye ray hits ([`NO_OBJECT`] if none);
    /// `uv` as for [`Tracer::eye_sample`].
    pub fn radiance_and_object(&self, eye: Ray<R>, uv: Option<[i32; 2]>, w: &mut Work<'_>) -> (R, u32) {
        let (v, object, _) = self.eye_sample(eye, uv, w);
        (v, object)
    }

    /// The object an eye ray hits first ([`NO_OBJECT`] if none) and how far along the ray, as
    /// [`Tracer::eye_sample`] finds them, without shading or any further ray (counted as a
    /// primary ray): what the outline's apron needs.
    pub fn eye_hit(&self, eye: Ray<R>, uv: Option<[i32; 2]>, w: &mut Work<'_>) -> (u32, R) {
        w.query.stats.rays[RayKind::Primary as usize] += 1;
        w.query.filter.set_box_tests(self.box_tests);
        let found = self.nearest(&eye, uv, w);
        w.query.stats.hit(RayKind::Primary, found.is_some());
        found.map_or((NO_OBJECT, R::MAX), |hit| (hit.object, hit.t))
    }

    /// Whether rays the windows do not serve test every object instead of asking the
    /// accelerator ([`EyeRays::EVERY_OBJECT_UP_TO`]).
    #[inline]
    fn tests_every_object(&self) -> bool {
        self.eye_rays == EyeRays::Windows && self.scene.objects.len() <= EyeRays::EVERY_OBJECT_UP_TO
    }

    /// The nearest hit of `ray`, skipping what the work's filter allows; an eye ray's window
    /// position `uv` (when given) lets [`EyeRays`] skip objects or the walk. Inlined on x86-64:
    /// the hit would come back through memory, written field by field and read in wider moves
    /// that wait for those stores to retire.
    #[cfg_attr(target_arch = "x86_64", inline(always))]
    fn nearest(&self, ray: &Ray<R>, uv: Option<[i32; 2]>, w: &mut Work<'_>) -> Option<Hit<R>> {
        let scene = self.scene;
        match uv {
            Some(uv) if self.eye_rays != EyeRays::Plain => {
                // The window position serves this ray alone.
                w.query.filter.set_eye(Some(uv));
                let list = w.eye_list();
                let q = &mut w.query;
                let found = match (self.eye_rays, list) {
                    (EyeRays::Windows, _) => nearest_by_windows(scene, ray, w.eye_candidates, q),
                    // The tile listed its objects: no walk (see `Scratch::with_cover`).
                    (_, Some(list)) => {
                        let mut best = None;
                        for &i in list {
                            crate::accel::offer(scene, i as usize, ray, R::ZERO, R::MAX, &mut best, q);
                        }
                        best
                    }
                    _ => self.accel.nearest(scene, ray, R::ZERO, R::MAX, q),
                };
                w.query.filter.set_eye(None);
                found
            }
            _ if self.tests_every_object() => BruteForce.nearest(scene, ray, R::ZERO, R::MAX, &mut w.query),
            _ => self.accel.nearest(scene, ray, R::ZERO, R::MAX, &mut w.query),
        }
    }

    /// Brightness along an eye ray, the object it hits ([`NO_OBJECT`] if none) and how far
    /// along the ray (in units of its direction's length; `R::MAX` if it hits nothing). `uv` is
    /// the eye ray's window position when the caller knows it
    /// ([`crate::camera::Camera::window_uv`]): objects whose eye region does not hold it are then
    /// not tested.
    pub fn eye_sample(&self, eye: Ray<R>, eye_uv: Option<[i32; 2]>, w: &mut Work<'_>) -> (R, u32, R) {
        let mut first = NO_OBJECT;
        let mut depth = R::MAX;
        let scene = self.scene;
        // Depth-first, each node pushes at most two children and `max_depth <= MAX_DEPTH`, so at
        // most `MAX_DEPTH + 2` nodes wait: no push below can fail.
        let mut stack: Vec<Node<R>, { MAX_DEPTH as usize + 2 }> = Vec::new();
        let mut total = R::ZERO;
        w.query.filter.set_box_tests(self.box_tests);
        // The eye ray is traced first without a trip through the stack (the stack only holds
        // children).
        let mut primary = true;
        let mut popped: Ray<R>;
        loop {
            // The eye ray is read where the caller left it (copying it would load it in wide
            // moves that straddle the narrower stores it was written with, which wait for those
            // stores to retire: no store-to-load forwarding on x86); a child is copied out of
            // the stack field by field, for the same reason, before its own children take its
            // place.
            let (ray, node) = if primary {
                primary = false;
                (&eye, Meta { weight: R::ONE, depth: 0, kind: RayKind::Primary, leaving: NO_OBJECT })
            } else if let Some(top) = stack.len().checked_sub(1) {
                let at = &stack[top];
                popped = Ray::new(at.ray.origin, at.ray.dir);
                let meta =
                    Meta { weight: at.meta.weight, depth: at.meta.depth, kind: at.meta.kind, leaving: at.meta.leaving };
                stack.truncate(top);
                (&popped, meta)
            } else {
                break;
            };
            w.query.stats.rays[node.kind as usize] += 1;
            // The eye ray's window position serves the eye ray alone.
            w.query.filter.set_leaving(node.leaving);
            let found = self.nearest(ray, if node.depth == 0 { eye_uv } else { None }, w);
            w.query.filter.set_leaving(NO_OBJECT);
            let Some(hit) = found else {
                total += node.weight.weigh(scene.background);
                continue;
            };
            w.query.stats.hit(node.kind, true);
            if node.depth == 0 {
                first = hit.object;
                depth = hit.t;
            }
            total += self.shade(ray, node, &hit, &mut stack, w);
        }
        (total.max(R::ZERO).min(R::ONE), first, depth)
    }

    /// A hit node's share of the pixel: its local term (ambient, and each light's direct term)
    /// times its weight; its children (a mirror and a refracted ray, when the material has them
    /// and the tree is not at its depth) pushed on `stack`.
    #[inline(always)]
    fn shade(
        &self,
        ray: &Ray<R>,
        node: Meta<R>,
        hit: &Hit<R>,
        stack: &mut Vec<Node<R>, { MAX_DEPTH as usize + 2 }>,
        w: &mut Work<'_>,
    ) -> R {
        let scene = self.scene;
        let obj = at(scene.objects, hit.object as usize);
        let m = at(scene.materials, obj.material as usize);
        let p = obj.surface_point(hit.point, hit.normal);
        // Children (a mirror or a refracted ray) need the unit direction; without them only
        // the side the ray meets is asked, which the direction as traced gives.
        let (reflects, refracts) = self.branches(m);
        let children = node.depth < self.max_depth && (reflects || refracts);
        let shiny = self.simulates(Effects::HIGHLIGHTS) && m.shine > 0 && m.ks > R::ZERO;
        let d = if children || shiny { ray.dir.normalize() } else { ray.dir };
        let mut side = facing(d, w.world_normal(scene, hit.object, hit.normal));
        // Rays off the outer side of the surface, towards where its normal points (shadow
        // rays to lights in front, the mirror ray), leave the object: a convex solid (and the
        // outside of an open side, part of one's boundary) cannot be met again; a triangle
        // cannot be met again from either side.
        let flat = cfg!(feature = "triangles") && matches!(obj.shape, crate::shape::Shape::Triangle);
        let leaving = if side.entering || flat { hit.object } else { NO_OBJECT };
        let eps = R::offset(p.max_abs(), obj.size());
        // Secondary rays start off the flat surface; a smooth triangle shades (lights, mirrors,
        // refracts) by its interpolated normal.
        let flat_normal = side.normal;
        let outside = p + flat_normal * eps;
        if flat && !scene.smooth.is_empty() {
            if let Some(s) = scene.smooth_of(hit.object) {
                side.normal = s.normal(hit.point, side.normal);
            }
        }
        let n = side.normal;
        let mut local = scene.ambient * m.ka;
        if m.kd > R::ZERO || shiny {
            // Lit from outside, the point's shadow rays leave its own (convex) object.
            w.query.filter.set_leaving(leaving);
            // The highlight's mirror direction, weight and power.
            let highlight = if shiny { Some((mirror(d, n), m.ks, m.shine)) } else { None };
            for (l, light) in scene.lights.iter().enumerate() {
                local += self.direct(l, light, (outside, n, m.kd), highlight, node.weight, w);
            }
            w.query.filter.set_leaving(NO_OBJECT);
        }
        let lit = node.weight.weigh(local);
        if children {
            // Only a refracted child starts inside: computed here, off the path of hits
            // without children.
            let inside = p - flat_normal * eps;
            self.push_children(node, (d, &side), (inside, outside, leaving), (reflects, refracts, m), stack);
        }
        lit
    }

    /// The children of a hit node (the `side` of the surface the ray's direction `d` meets):
    /// the refracted ray from `inside`, the mirror ray from `outside` (leaving `leaving`),
    /// each pushed when its weight passes the cutoff; total internal reflection adds the
    /// transmitted share to the mirror ray's.
    #[inline(always)]
    fn push_children(
        &self,
        node: Meta<R>,
        (d, side): (Vec3<R>, &Side<R>),
        (inside, outside, leaving): (Vec3<R>, Vec3<R>, u32),
        (reflects, refracts, m): (bool, bool, &Material<R>),
        stack: &mut Vec<Node<R>, { MAX_DEPTH as usize + 2 }>,
    ) {
        let n = side.normal;
        let child = |ray, w: R, kind, leaving| Node {
            ray,
            meta: Meta { weight: node.weight * w, depth: node.depth + 1, kind, leaving },
        };
        let mirror = mirror(d, n);
        let mut reflect_w = if reflects { m.ks } else { R::ZERO };
        if refracts {
            match refract(d, n, side.eta(m.ior)) {
                // Total internal reflection: the transmitted share is reflected.
                None => reflect_w += m.kt,
                Some(dir) if self.every_ray || node.weight * m.kt > self.cutoff => {
                    let _ = stack.push(child(Ray::new(inside, dir), m.kt, RayKind::Refraction, NO_OBJECT));
                }
                Some(_) => {}
            }
        }
        let spawn = self.every_ray && reflects;
        if spawn || (reflect_w > R::ZERO && node.weight * reflect_w > self.cutoff) {
            let _ = stack.push(child(Ray::new(outside, mirror), reflect_w, RayKind::Reflection, leaving));
        }
    }

    /// `Ip * Kd * max(0, L.N)` for one light, or zero if the light is behind the surface or
    /// (with shadows on) blocked. When the term, times the weight of the node, is below the
    /// cutoff, the shadow ray is not traced and the light counts as visible: either answer is
    /// within the cutoff of the other.
    /// The work's filter says what the shadow ray may skip (the object the point lies on, when
    /// lit from outside).
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        l: usize,
        light: &Light<R>,
        (from, n, kd): (Vec3<R>, Vec3<R>, R),
        highlight: Option<(Vec3<R>, R, u16)>,
        weight: R,
        w: &mut Work<'_>,
    ) -> R {
        let (to_light, reach, ip) = match *light {
            Light::Directional { to_light, intensity } => (to_light, R::MAX, intensity),
            // Unit direction, so every ray the tracer casts has a direction of length about 1.
            Light::Point { pos, intensity } if Effects::from_bits(E).contains(Effects::POINT_LIGHTS) => {
                let v = pos - from;
                let dir = v.normalize();
                (dir, v.dot(dir), intensity)
            }
            // Not compiled in: `compiled` refused any scene that has one.
            Light::Point { .. } => return R::ZERO,
        };
        let cos = to_light.dot(n);
        if cos <= R::ZERO {
            return R::ZERO;
        }
        let mut term = ip * kd * cos;
        if let Some((mirror, ks, shine)) = highlight {
            // Phong: the mirror direction's cosine to the light, raised to the power.
            let c = mirror.dot(to_light);
            if c > R::ZERO {
                term += ip * ks * power(c, shine);
            }
        }
        if self.simulates(Effects::SHADOWS) && weight.weigh(term) >= self.cutoff {
            w.query.stats.rays[RayKind::Shadow as usize] += 1;
            let ray = Ray::new(from, to_light);
            // Shadow-ray coherence: the object that last hid this light from a point is tried
            // before the accelerator (the last shadow ray towards the light was hidden by it);
            // neighbouring points in a shadow share their occluder.
            // Occlusion is a yes-or-no question, so the answer is the accelerator's.
            let last = if self.coherence { w.occluder(l) } else { None };
            // Towards the first light, when it is directional, every object holds the ray's
            // direction in its own space already.
            // The ray's position across it, which objects' shadow windows are in.
            let across = match self.scene.shadow_basis {
                Some((a, b)) if l == 0 => Some([from.dot(a), from.dot(b)]),
                _ => None,
            };
            let tried = last.filter(|&i| !w.query.filter.skips(i) && (i as usize) < self.scene.objects.len());
            if self.hides(tried, &ray, across, reach, &mut w.query) {
                w.query.stats.hit(RayKind::Shadow, true);
                return R::ZERO;
            }
            // Missed: the search below need not test it again.
            w.query.filter.set_tried(tried);
            let hidden = self.occluded(l, &ray, across, reach, w);
            w.query.filter.set_tried(None);
            if hidden {
                w.query.stats.hit(RayKind::Shadow, true);
                return R::ZERO;
            }
        }
        term
    }

    /// Whether object `tried` (the one that last hid the light, if any) hides it along the
    /// shadow ray `ray` (position `across` the first light when it is directional) within
    /// `reach`.
    #[inline(always)]
    fn hides(&self, tried: Option<u32>, ray: &Ray<R>, across: Option<[R; 2]>, reach: R, q: &mut Query<'_>) -> bool {
        let Some(i) = tried else { return false };
        let o = at(self.scene.objects, i as usize);
        let hit = match across {
            // Outside its window the remembered occluder cannot hide the light.
            Some(w) if !o.shadow_window_holds(w) => None,
            Some(_) => {
                q.stats.object_tests += 1;
                o.intersect_first_light_ray(ray, R::ZERO, reach)
            }
            None => {
                q.stats.object_tests += 1;
                o.intersect(ray, R::ZERO, reach)
            }
        };
        hit.is_some()
    }

    /// Whether anything hides light `l` along the shadow ray `ray` within `reach`: by the shadow
    /// windows, or by the accelerator (the occluder found remembered for the next point).
    #[inline(always)]
    fn occluded(&self, l: usize, ray: &Ray<R>, across: Option<[R; 2]>, reach: R, w: &mut Work<'_>) -> bool {
        // Towards the first light, when it is directional, a small scene's shadow rays test the
        // objects whose shadow window holds the ray, with no walk.
        let found = match across {
            Some(at) if self.eye_rays == EyeRays::Windows => self.shadow_by_windows(ray, at, reach, &mut w.query),
            _ => {
                w.query.filter.set_first_light(across);
                let found = if self.tests_every_object() {
                    BruteForce.occluded(self.scene, ray, R::ZERO, reach, &mut w.query)
                } else {
                    self.accel.occluded(self.scene, ray, R::ZERO, reach, &mut w.query)
                };
                w.query.filter.set_first_light::<R>(None);
                found
            }
        };
        // Remembered only while the light stays hidden: a lit point forgets it, so points in the
        // light pay no extra test.
        w.set_occluder(l, found);
        found.is_some()
    }

    /// The first object (in index order) whose shadow window holds the shadow ray's position
    /// `w` across the first light (directional) and which the ray hits within `reach`.
    fn shadow_by_windows(&self, ray: &Ray<R>, w: [R; 2], reach: R, q: &mut Query<'_>) -> Option<u32> {
        // Tests and culls are counted once the loop ends, not per object.
        let mut tested = 0u32;
        let mut found = None;
        let mut seen = self.scene.objects.len();
        for (i, o) in self.scene.objects.iter().enumerate() {
            if !o.shadow_window_holds(w) || q.filter.skips(i as u32) {
                continue;
            }
            tested += 1;
            if o.intersect_first_light_ray(ray, R::ZERO, reach).is_some() {
                (found, seen) = (Some(i as u32), i + 1);
                break;
            }
        }
        q.stats.object_tests += u64::from(tested);
        q.stats.culled += (seen as u64) - u64::from(tested);
        found
    }
}

/// The mirror direction of `d` at a surface of unit normal `n` (facing `d`).
#[inline(always)]
fn mirror<R: Real>(d: Vec3<R>, n: Vec3<R>) -> Vec3<R> {
    let cos_i = -d.dot(n);
    d + n * (cos_i + cos_i)
}

/// `c^n` for `0 <= c <= 1` by squaring (a whole power: every scalar, no `pow` table).
fn power<R: Real>(c: R, n: u16) -> R {
    let (mut acc, mut base, mut k) = (R::ONE, c, n);
    while k > 0 {
        if k & 1 == 1 {
            acc *= base;
        }
        k >>= 1;
        if k > 0 {
            base = base * base;
        }
    }
    acc
}
