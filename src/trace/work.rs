//! What a tracer works in, per core: the accelerator's scratch and what the tracer remembers
//! between rays. The tracer itself is shared by both cores and holds nothing that changes.

use crate::accel::{Query, Stats};
use crate::bounds::at;
use crate::math::Vec3;
use crate::scalar::Real;
use crate::scene::{axis_normal, Scene, MAX_LIGHTS};

/// A tracer's working memory on one core (or thread): the accelerator's [`Query`] (mailbox and
/// statistics), and what the tracer carries from ray to ray: which objects the eye rays of the
/// tile being rendered can hit (set by the render, per tile), each light's last occluder (shadow
/// coherence; forgotten per band of tiles, so a band renders the same whichever band came
/// before it) and the last unit normal mapped to the world.
///
/// Its layout is fixed, the query first (see [`Query`]'s).
#[derive(Debug)]
#[repr(C)]
pub struct Work<'m> {
    /// The accelerator's scratch: mailbox and statistics.
    pub query: Query<'m>,
    /// Per light, the object that last hid it ([`u32::MAX`]: none yet).
    occluders: [u32; MAX_LIGHTS],
    /// The last world normal [`Work::world_normal`] mapped from a unit axis: the object, the axis
    /// ([`crate::scene::axis_normal`]) and the normal's components as [`Real::to_raw`] bits.
    axis_normal: Option<(u32, u8, [u64; 3])>,
    /// The objects (bit `i`: object `i`) whose eye region meets the current tile; the others
    /// cannot be hit by its eye rays (see [`Work::set_eye_candidates`]).
    pub(crate) eye_candidates: u64,
    /// The objects whose eye window meets the current tile, when a render listed them (see
    /// [`Work::set_eye_list`]); `None`: not listed. Only with the `tile-lists` feature.
    #[cfg(feature = "tile-lists")]
    pub(crate) eye_list: Option<&'m [u32]>,
    /// Without the `tile-lists` feature nothing is listed.
    #[cfg(not(feature = "tile-lists"))]
    pub(crate) eye_list: core::marker::PhantomData<&'m [u32]>,
}

impl<'m> Work<'m> {
    /// Working memory with a caller-provided mailbox of [`Query::mailbox_len`] entries (a
    /// shorter one only costs repeated tests).
    pub fn new(mailbox: &'m mut [u32]) -> Self {
        Work {
            query: Query::new(mailbox),
            occluders: [u32::MAX; MAX_LIGHTS],
            axis_normal: None,
            eye_candidates: u64::MAX,
            eye_list: Default::default(),
        }
    }
    /// The work counted so far.
    pub fn stats(&self) -> &Stats {
        &self.query.stats
    }
    /// Declares which objects the eye rays to come can hit at all (bit `i`: object `i`; from
    /// [`crate::scene::Scene::eye_candidates`] for the tile being rendered): tracing by windows
    /// then tests only these, and counts the others as culled, as their windows would have
    /// culled them ray by ray. `u64::MAX` (the default) holds every object.
    pub fn set_eye_candidates(&mut self, objects: u64) {
        self.eye_candidates = objects;
    }
    /// The objects eye rays can hit (see [`Work::set_eye_candidates`]).
    pub fn eye_candidates(&self) -> u64 {
        self.eye_candidates
    }
    /// Declares which objects the eye rays to come can hit at all, in index order (those whose
    /// window meets the tile being rendered), or that they are not listed (`None`): eye rays
    /// through an accelerator then test the listed objects instead of asking it.
    pub fn set_eye_list(&mut self, objects: Option<&'m [u32]>) {
        #[cfg(feature = "tile-lists")]
        {
            self.eye_list = objects;
        }
        #[cfg(not(feature = "tile-lists"))]
        let _ = objects;
    }
    /// The objects eye rays can hit, if listed (see [`Work::set_eye_list`]).
    pub fn eye_list(&self) -> Option<&'m [u32]> {
        #[cfg(feature = "tile-lists")]
        return self.eye_list;
        #[cfg(not(feature = "tile-lists"))]
        None
    }
    /// The object that last hid light `l` from a shaded point, if any.
    pub fn occluder(&self, l: usize) -> Option<u32> {
        self.occluders.get(l).copied().filter(|&i| i != u32::MAX)
    }
    /// Remembers `occluder` as what hides light `l` (`None`: the light is not hidden, forget).
    pub fn set_occluder(&mut self, l: usize, occluder: Option<u32>) {
        if let Some(o) = self.occluders.get_mut(l) {
            *o = occluder.unwrap_or(u32::MAX);
        }
    }
    /// Forgets the remembered occluders (the render does so at every band of tiles, so a band's
    /// work does not depend on the bands rendered before it, on whichever core or thread).
    pub fn forget_occluders(&mut self) {
        self.occluders.fill(u32::MAX);
    }
    /// [`crate::scene::Object::world_normal`] of object `i` of `scene`: a unit-axis normal (a
    /// box's face, a cap) that is the last one asked for is given again without mapping it anew
    /// (neighbouring eye rays mostly hit one face, the floor's above all).
    #[inline]
    pub fn world_normal<R: Real>(&mut self, scene: &Scene<'_, R>, i: u32, n_obj: Vec3<R>) -> Vec3<R> {
        let o = at(scene.objects, i as usize);
        let Some(axis) = axis_normal(n_obj) else { return o.world_normal(n_obj) };
        if let Some((j, k, raw)) = self.axis_normal {
            if (j, k) == (i, axis) {
                return Vec3::new(R::from_raw(raw[0]), R::from_raw(raw[1]), R::from_raw(raw[2]));
            }
        }
        let n = o.axis_world_normal(axis);
        self.axis_normal = Some((i, axis, [n.x.to_raw(), n.y.to_raw(), n.z.to_raw()]));
        n
    }
}
