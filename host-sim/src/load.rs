//! Loading scene files and building accelerators with heap-backed storage (the host's side of
//! the core's caller-provided buffers).

use anyhow::{anyhow, bail, Context, Result};
use lattice_rt::lattice::LatticeSizes;
use lattice_rt::scene::object_count;
use lattice_rt::scene::parse_with;
use lattice_rt::scene::text::text_from_bytes;
use lattice_rt::scene::Object;
use lattice_rt::{Frame, HeapStorage, Lattice, LatticeConfig, Parts, Real, Scene, SceneBuilder, Sizes};
use std::io::Read;
use std::path::Path;

/// The largest scene file host-sim reads (a 100,000-object scene is about 5 MB).
pub const MAX_SCENE_BYTES: u64 = 32 << 20;

/// The most memory object storage may take (about a million objects in f64).
pub const MAX_OBJECT_BYTES: usize = 128 << 20;

/// Reads a scene file: at most [`MAX_SCENE_BYTES`], UTF-8 (an error says the line and column
/// of the first byte that is not). `-` reads standard input.
pub fn read(path: &Path) -> Result<String> {
    let mut bytes = Vec::new();
    if path == Path::new("-") {
        std::io::stdin()
            .take(MAX_SCENE_BYTES + 1)
            .read_to_end(&mut bytes)
            .context("cannot read the scene from standard input")?;
    } else {
        let file = std::fs::File::open(path).with_context(|| format!("cannot read scene file {}", path.display()))?;
        file.take(MAX_SCENE_BYTES + 1)
            .read_to_end(&mut bytes)
            .with_context(|| format!("cannot read scene file {}", path.display()))?;
    }
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        bail!(
            "{}: the scene file is larger than {} MiB, the most host-sim reads",
            path.display(),
            MAX_SCENE_BYTES >> 20
        );
    }
    // Validated once; only a failure is located (line and column) by the core.
    String::from_utf8(bytes).map_err(|e| match text_from_bytes(e.as_bytes()) {
        Err(at) => anyhow!("{}: {at}", path.display()),
        Ok(_) => anyhow!("{}: not UTF-8 text", path.display()),
    })
}

/// A scene's storage on the host: its objects and its composites, materials and lights.
#[derive(Debug, Default)]
pub struct SceneStore<R> {
    /// The objects.
    pub objects: Vec<Object<R>>,
    /// The composites, materials and lights.
    pub parts: Parts<R>,
}

impl<R: Real> SceneStore<R> {
    /// A builder of a scene into this storage.
    pub fn builder(&mut self) -> SceneBuilder<'_, R> {
        SceneBuilder::new(&mut self.objects, &mut self.parts)
    }
}

/// Object storage for the objects `text` declares (counted before anything is allocated), or
/// an error when it would take more than [`MAX_OBJECT_BYTES`].
pub fn object_storage<R: Real>(text: &str) -> Result<SceneStore<R>> {
    let n = object_count(text);
    let each = core::mem::size_of::<Object<R>>();
    if n.saturating_mul(each) > MAX_OBJECT_BYTES {
        bail!(
            "the scene declares {n} objects: {} bytes of object storage, more than the limit of {MAX_OBJECT_BYTES} (at most {} objects in {})",
            n.saturating_mul(each),
            MAX_OBJECT_BYTES / each,
            R::NAME
        );
    }
    Ok(SceneStore { objects: vec![Object::default(); n.max(1)], parts: Parts::new() })
}

/// Parses `text` into `storage` with its camera fitted to `frame`'s shape (square pixels),
/// turning errors into messages that name the file.
pub fn parse_scene<'a, R: Real>(
    path: &Path,
    text: &str,
    storage: &'a mut SceneStore<R>,
    frame: &Frame,
) -> Result<Scene<'a, R>> {
    let objects = storage.objects.len();
    let _shown = crate::progress::step(objects, format!("reading {} ({objects} objects)", path.display()));
    let scene = parse_with::<R>(text, &mut storage.objects, &mut storage.parts, |c| c.frame = frame.size())
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    // A view the render would refuse for this frame (too narrow for the scalar), refused here
    // at the scene's camera.
    frame.check_scene_view(text, scene.camera()).map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(scene)
}

/// The most memory a lattice may take on the host (so that no flag makes host-sim allocate
/// gigabytes: `--cells 1024x1024x1024` alone would be 4.3 GB).
pub const MAX_LATTICE_BYTES: usize = 512 << 20;

/// Heap storage for the lattice of `scene` with `cfg` and a render's mailbox (objects are
/// parsed apart, into [`object_storage`]), or an error when it would take more than
/// [`MAX_LATTICE_BYTES`] (checked before anything is allocated).
pub fn lattice_storage<R: Real>(scene: &Scene<'_, R>, cfg: &LatticeConfig) -> Result<HeapStorage<R>> {
    let _shown = crate::progress::step(scene.objects().len(), "planning the lattice");
    let sizes = Sizes { objects: 0, rows: 0, ..Sizes::of(scene, Some(cfg), &Frame::new(1, 1)) };
    let bytes = sizes.bytes::<R>();
    if bytes > MAX_LATTICE_BYTES {
        let LatticeSizes { cells, refs, .. } = Lattice::plan(scene, cfg);
        bail!(
            "the lattice would need {bytes} bytes ({cells} cells, {refs} references), more than the limit of {MAX_LATTICE_BYTES}: ask for fewer cells with --cells"
        );
    }
    Ok(HeapStorage::new(sizes))
}

/// No lattice fits the byte budget asked for (`--budget`): an error its callers can tell apart
/// (render adds what it can do instead).
#[derive(Debug)]
pub struct BudgetTooSmall {
    /// Bytes the budget gives.
    pub available: usize,
    /// Bytes the smallest lattice takes.
    pub needed: usize,
}

impl std::fmt::Display for BudgetTooSmall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "no lattice fits --budget {}: the smallest takes {} bytes; give at least that",
            self.available, self.needed
        )
    }
}

impl std::error::Error for BudgetTooSmall {}

/// Builds the lattice of `scene` with `cfg` in `storage` (from [`lattice_storage`]).
pub fn build_lattice<'a, R: Real>(
    storage: &'a mut HeapStorage<R>,
    scene: &Scene<'_, R>,
    cfg: &LatticeConfig,
) -> Result<Lattice<'a, R>> {
    let _shown = crate::progress::step(scene.objects().len(), "building the lattice");
    let (lattice, _) = storage.view().split().1.lattice(scene, cfg).map_err(|e| {
        if e.capacity == "budget" {
            anyhow::Error::new(BudgetTooSmall { available: e.available, needed: e.needed })
        } else {
            anyhow!("{e}")
        }
    })?;
    Ok(lattice)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lattice_too_large_for_the_host_is_refused_before_allocation() {
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/chair.scene"));
        let text = read(path).unwrap();
        let mut storage = object_storage::<f64>(&text).unwrap();
        let scene = parse_scene::<f64>(path, &text, &mut storage, &Frame::new(128, 64)).unwrap();
        let err =
            lattice_storage(&scene, &crate::cli::lattice_config(Some([1024, 1024, 1024]), None)).expect_err("refused");
        let msg = format!("{err:#}");
        assert!(msg.contains("--cells") && msg.contains(&MAX_LATTICE_BYTES.to_string()), "{msg}");
        assert!(lattice_storage(&scene, &crate::cli::lattice_config(Some([64, 64, 64]), None)).is_ok());
    }

    #[test]
    fn a_png_too_large_is_refused_with_the_flags_to_change() {
        let msg = format!("{:#}", crate::output::check_png_size(4096, 4096, 64).unwrap_err());
        assert!(msg.contains("--scale") && msg.contains("--size"), "{msg}");
        assert!(crate::output::check_png_size(4096, 4096, 2).is_ok());
    }
}
