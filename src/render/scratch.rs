//! The memory a render works in ([`Scratch`]): the mailbox, the rows of error diffusion and
//! edge detection, and the tiles' object lists; in caller slices or, with the `alloc`
//! feature, on the heap ([`HeapScratch`]).

#[cfg(feature = "alloc")]
use super::frame::Frame;
#[cfg(feature = "alloc")]
use crate::accel::Query;
#[cfg(feature = "alloc")]
use crate::scalar::Real;
#[cfg(feature = "alloc")]
use crate::scene::Scene;

/// Scratch on the heap for `scene` and `frame`: an exact mailbox and rows (for renders on
/// several threads, each with its own).
#[cfg(feature = "alloc")]
#[derive(Debug)]
pub struct HeapScratch {
    mailbox: alloc::vec::Vec<u32>,
    rows: alloc::vec::Vec<i16>,
    cover: alloc::vec::Vec<u32>,
}

#[cfg(feature = "alloc")]
impl HeapScratch {
    /// Scratch sized for `scene` and `frame`.
    pub fn new<R: Real>(scene: &Scene<'_, R>, frame: &Frame) -> Self {
        HeapScratch {
            mailbox: alloc::vec![0; Query::mailbox_len(scene)],
            rows: alloc::vec![0; frame.scratch_len()],
            // Only scenes of more than 64 objects list windows per tile.
            cover: alloc::vec![0; if super::cull::tiles::lists(scene.objects().len()) { frame.cover_len() } else { 0 }],
        }
    }

    /// The scratch to render in.
    pub fn scratch(&mut self) -> Scratch<'_> {
        Scratch::new(&mut self.mailbox, &mut self.rows).with_cover(&mut self.cover)
    }
}

/// The memory a render works in: the mailbox (one stamp per primitive and per composite,
/// so a ray tests each once; a shorter one only costs repeated tests) and the rows
/// ([`Frame::scratch_len`](super::Frame::scratch_len) entries; error diffusion and edge detection fail without them).
#[derive(Debug)]
pub struct Scratch<'a> {
    pub(crate) mailbox: &'a mut [u32],
    pub(crate) rows: &'a mut [i16],
    pub(crate) cover: &'a mut [u32],
}

impl<'a> Scratch<'a> {
    /// Scratch in caller-owned slices.
    pub fn new(mailbox: &'a mut [u32], rows: &'a mut [i16]) -> Self {
        Scratch { mailbox, rows, cover: &mut [] }
    }

    /// With room to list which objects' eye windows meet each tile ([`Frame::cover_len`](super::Frame::cover_len)
    /// entries): in a scene of more than 64 objects, the eye rays of a tile that few windows
    /// meet then test those objects without walking the lattice (the same frame, sooner).
    /// Without it (or with too few entries, or without the `tile-lists` feature) every eye ray
    /// walks.
    pub fn with_cover(self, cover: &'a mut [u32]) -> Self {
        Scratch { cover, ..self }
    }
}
