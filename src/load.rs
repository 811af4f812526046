//! Loading: a scene's text parsed into a [`StorageView`]'s object storage and its lattice built
//! in the rest, what is left becoming the render's [`Scratch`]. The one place that goes from
//! text to a scene ready to trace.

use crate::lattice::{Lattice, LatticeConfig, LatticeError};
use crate::render::Scratch;
use crate::scalar::Real;
use crate::scene::parse_with;
use crate::scene::text::ParseError;
use crate::scene::{CameraDesc, Scene};
use crate::storage::StorageView;
use core::fmt;

/// A scene loaded from text with its lattice built, and the scratch left for the render.
#[derive(Debug)]
pub struct Loaded<'a, R> {
    /// The validated scene.
    pub scene: Scene<'a, R>,
    /// Its lattice.
    pub lattice: Lattice<'a, R>,
    /// What the render works in.
    pub scratch: Scratch<'a>,
}

/// Why a scene could not be loaded into a [`StorageView`].
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadError<'t> {
    /// The text is not a valid scene, or declares more objects than the storage holds.
    Parse(ParseError<'t>),
    /// The lattice does not fit the storage.
    Lattice(LatticeError),
}

impl fmt::Display for LoadError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Parse(e) => write!(f, "scene: {e}"),
            LoadError::Lattice(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for LoadError<'_> {}

impl<'a, R: Real> StorageView<'a, R> {
    /// Parses `text` into the object storage and builds its lattice with `cfg` in the rest;
    /// what is left becomes the render's scratch.
    pub fn load<'t>(self, text: &'t str, cfg: &LatticeConfig) -> Result<Loaded<'a, R>, LoadError<'t>> {
        self.load_with(text, cfg, |_| {})
    }

    /// [`StorageView::load`] with the scene's camera changed by `camera` before validation
    /// (an orbit's frames: [`crate::scene::CameraDesc::orbit`]).
    pub fn load_with<'t>(
        self,
        text: &'t str,
        cfg: &LatticeConfig,
        camera: impl FnOnce(&mut CameraDesc),
    ) -> Result<Loaded<'a, R>, LoadError<'t>> {
        let ((objects, parts), rest) = self.split();
        let scene = parse_with::<R>(text, objects, parts, camera).map_err(LoadError::Parse)?;
        let (lattice, scratch) = rest.lattice(&scene, cfg).map_err(LoadError::Lattice)?;
        Ok(Loaded { scene, lattice, scratch })
    }
}
