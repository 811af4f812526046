//! Eric Haines' Standard Procedural Databases (SPD), generated here as the SPD's own programs
//! generate them (`host-sim spd NAME --size N`), written as NFF: the field's benchmark scenes
//! at any size factor, without the C sources. `tests/spd.rs` holds their output to
//! the original programs' for a few sizes (fixtures in `tests/spd/`, CC0 like the SPD).

pub mod curves;
pub mod nff;
pub mod polygons;
pub mod protocol;
pub mod teapot;

/// The primitives of NFF text as the SPD counts them (its Readme's figures, and the counts in
/// [`Generator`]'s help): each sphere, cone or cylinder and polygon once. The tracer stores a
/// polygon of `n` corners as `n - 2` triangles ([`lattice_rt::scene::object_count`]).
pub fn primitives(nff: &str) -> usize {
    nff.lines().filter(|l| matches!(l.split_whitespace().next(), Some("s" | "c" | "p" | "pp"))).count()
}

/// An SPD generator (the counts are primitives, as the SPD counts them: [`primitives`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Generator {
    /// The sphereflake: 1 + 9 + ... + 9^size spheres and a floor (default 4: 7,382 primitives).
    Balls,
    /// Pyramids of rings of pentagons (cylinders and spheres) before a wall (default 7: 8,401).
    Rings,
    /// A tree of cones and spheres on a field, seven lights (default 11: 8,191).
    Tree,
    /// A cubic lattice of spheres and cylinders, six lights (default 12: 8,281).
    Lattice,
    /// A jack with smaller jacks in its octants (default 1: 9).
    Jacks,
    /// Spheres along a logarithmic spiral (default 5: 5,761).
    Shells,
    /// Sierpinski's tetrahedron of triangles (default 6: 4,096).
    Tetra,
    /// Meshing gears, some of glass, on a floor: concave polygons (default 4: 9,345).
    Gears,
    /// A fractal mountain of triangles under four glass spheres (default 6: 8,196).
    Mount,
    /// Newell's teapot of Bezier patches as triangles with normals, on a checkerboard (default
    /// 12: 9,264 primitives; upstream's program defaults to 6, its published figures are for 12).
    Teapot,
}

impl Generator {
    /// Every generator, in the order the SPD's Readme lists them.
    pub const ALL: [Generator; 10] = [
        Generator::Balls,
        Generator::Rings,
        Generator::Tree,
        Generator::Lattice,
        Generator::Jacks,
        Generator::Shells,
        Generator::Tetra,
        Generator::Gears,
        Generator::Mount,
        Generator::Teapot,
    ];

    /// The generator's name (its program's).
    pub fn name(self) -> &'static str {
        match self {
            Generator::Balls => "balls",
            Generator::Rings => "rings",
            Generator::Tree => "tree",
            Generator::Lattice => "lattice",
            Generator::Jacks => "jacks",
            Generator::Shells => "shells",
            Generator::Tetra => "tetra",
            Generator::Gears => "gears",
            Generator::Mount => "mount",
            Generator::Teapot => "teapot",
        }
    }

    /// The size factor of the SPD's published figures (its program's default but for `teapot`, whose
    /// program writes size 6).
    pub fn default_size(self) -> u32 {
        match self {
            Generator::Balls => 4,
            Generator::Rings => 7,
            Generator::Tree => 11,
            Generator::Lattice => 12,
            Generator::Jacks => 1,
            Generator::Shells => 5,
            Generator::Tetra => 6,
            Generator::Gears => 4,
            Generator::Mount => 6,
            Generator::Teapot => 12,
        }
    }

    /// The largest size factor accepted: about ten million objects (the host's limits refuse
    /// more when the scene is read).
    pub fn max_size(self) -> u32 {
        match self {
            Generator::Balls => 7,
            Generator::Rings => 90,
            Generator::Tree => 22,
            Generator::Lattice => 140,
            Generator::Jacks => 8,
            Generator::Shells => 14,
            Generator::Tetra => 11,
            Generator::Gears => 10,
            Generator::Mount => 7,
            Generator::Teapot => 390,
        }
    }

    /// The scene as NFF text at size factor `size` (at least 1, at most [`Generator::max_size`]).
    pub fn nff(self, size: u32) -> anyhow::Result<String> {
        if size < 1 || size > self.max_size() {
            anyhow::bail!(
                "{}: the size factor must be from 1 to {} (the SPD's default is {})",
                self.name(),
                self.max_size(),
                self.default_size()
            );
        }
        Ok(match self {
            Generator::Balls => curves::balls(size),
            Generator::Rings => curves::rings(size),
            Generator::Tree => curves::tree(size),
            Generator::Lattice => curves::lattice(size),
            Generator::Jacks => curves::jacks(size),
            Generator::Shells => curves::shells(size),
            Generator::Tetra => polygons::tetra(size),
            Generator::Gears => polygons::gears(size),
            Generator::Mount => polygons::mount(size),
            Generator::Teapot => teapot::teapot(size),
        })
    }
}
