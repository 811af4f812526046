//! Loading scene files and building accelerators with heap-backed storage (the host's side of
//! the core's caller-provided buffers).

use anyhow::{anyhow, Context, Result};
use lattice_rt::lattice::{Grid, LatticeSizes};
use lattice_rt::scene::Object;
use lattice_rt::{parse, Lattice, LatticeConfig, LatticeStorage, Real, Scene};
use std::path::Path;

/// Reads a scene file.
pub fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read scene file {}", path.display()))
}

/// Object storage big enough for any scene in `text` (one object per line at most).
pub fn object_storage<R: Real>(text: &str) -> Vec<Object<R>> {
    vec![Object::default(); text.lines().count().max(1)]
}

/// Parses `text` into `storage`, turning errors into messages that name the file.
pub fn parse_scene<'a, R: Real>(path: &Path, text: &str, storage: &'a mut [Object<R>]) -> Result<Scene<'a, R>> {
    parse::<R>(text, storage).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// Heap storage for a lattice, sized by [`Lattice::plan`].
pub struct LatticeBufs<R> {
    grids: Vec<Grid<R>>,
    coords: Vec<R>,
    cells: Vec<u32>,
    refs: Vec<u32>,
}

impl<R: Real> LatticeBufs<R> {
    /// Storage for the lattice of `scene` with `cfg`.
    pub fn for_scene(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Self {
        let LatticeSizes { grids, coords, cells, refs } = Lattice::plan(scene, cfg);
        LatticeBufs {
            grids: vec![Grid::EMPTY; grids],
            coords: vec![R::ZERO; coords],
            cells: vec![0; cells],
            refs: vec![0; refs],
        }
    }
    /// Builds the lattice in this storage.
    pub fn build<'a>(&'a mut self, scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Result<Lattice<'a, R>> {
        let storage = LatticeStorage {
            grids: &mut self.grids,
            coords: &mut self.coords,
            cells: &mut self.cells,
            refs: &mut self.refs,
        };
        Lattice::build(scene, cfg, storage).map_err(|e| anyhow!("{e}"))
    }
}

/// Parses scene text, builds its default lattice and renders `frame` on one core, after
/// `tune` has adjusted the tracer (depth, cutoff, effects).
pub fn render_text<R: Real>(
    path: &Path,
    text: &str,
    frame: &lattice_rt::Frame,
    tune: impl FnOnce(&mut lattice_rt::Tracer<'_, '_, R, Lattice<'_, R>>),
) -> Result<crate::run::Rendered> {
    let mut storage = object_storage::<R>(text);
    let scene = parse_scene::<R>(path, text, &mut storage)?;
    let cfg = LatticeConfig::default();
    let mut bufs = LatticeBufs::for_scene(&scene, &cfg);
    let lattice = bufs.build(&scene, &cfg)?;
    let mut tracer = lattice_rt::Tracer::new(&scene, &lattice);
    tune(&mut tracer);
    crate::run::render_band(&tracer, frame, false)
}
