//! host-sim: the desktop driver of the lattice-rt core. Renders scenes to PNG/PBM/PGM, prints
//! statistics, and (with no arguments) renders the paper's four scenes into `out/`.

mod bench;
mod board;
mod display;
mod effects;
mod firmware;
mod load;
mod memory;
mod pov;
mod shared;
mod progress;
mod orbit;
mod output;
mod plot;
mod run;
mod tradeoff;
mod versus;

use anyhow::{bail, Result};
use clap::{Parser, Subcommand, ValueEnum};
use lattice_rt::Dither;
use std::path::PathBuf;

/// Desktop driver for the lattice-rt ray tracer.
///
/// With no command it renders the paper's four scenes (chair, desk, polyhedron, spheres) at
/// 160x100 and 128x64 into `out/` and prints their statistics.
#[derive(Parser, Debug)]
#[command(version)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Output folder of the default job.
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render one scene to a 1-bit PNG (and optionally PBM and gray PGM).
    Render(RenderArgs),
    /// Lattice shape, memory and per-accelerator work for a scene.
    Stats(StatsArgs),
    /// Render the paper's four scenes at 160x100 and 128x64 into a folder.
    Gallery {
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Folder holding the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
    },
    /// Write the POV-Ray equivalent of a scene (docs/povray.md has the mapping).
    Export {
        /// Scene file.
        scene: PathBuf,
        /// Write POV-Ray scene language.
        #[arg(long)]
        pov: bool,
        /// Each object a flat distinct gray, no lights (for comparing object masks).
        #[arg(long)]
        ids: bool,
        /// File to write.
        #[arg(short, long, default_value = "out/scene.pov")]
        output: PathBuf,
    },
    /// The paper's Table 1 reproduced, scaling to 100 000 primitives, the lattice's resolution
    /// choice against a sweep, and host-sim against POV-Ray (when `povray` is installed):
    /// docs/performance.md and a log-log plot.
    Bench {
        /// A short run for CI (N up to 1 000, one timed run).
        #[arg(long)]
        quick: bool,
        /// Timed runs per measurement (the median is used).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Report to write.
        #[arg(long, default_value = "docs/performance.md")]
        out: PathBuf,
        /// Plot to write (SVG).
        #[arg(long, default_value = "docs/performance.svg")]
        plot: PathBuf,
    },
    /// The memory-time frontier: lattices built within byte budgets from 64 B to 1 MiB on the
    /// paper's scenes and generated ones; writes docs/memory.md and its plots.
    Memory {
        /// Generated scenes up to 1 000 primitives, one timed run.
        #[arg(long)]
        quick: bool,
        /// Timed runs per measurement (the median is used).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Report to write.
        #[arg(long, default_value = "docs/memory.md")]
        out: PathBuf,
        /// Plot of time per ray against the budget (SVG).
        #[arg(long, default_value = "docs/memory.svg")]
        plot: PathBuf,
        /// Plot of object tests per ray against the budget (SVG).
        #[arg(long, default_value = "docs/memory-tests.svg")]
        tests_plot: PathBuf,
    },
    /// What accuracy costs in time: error against a 16-ray f64 reference and cost, one knob
    /// at a time (scalar, tree depth, cutoff, sampling, dithering).
    Tradeoff {
        /// Scene files (default: the paper's four and the Whitted showcase).
        scenes: Vec<PathBuf>,
        /// Image size.
        #[arg(long, default_value = "128x64", value_parser = parse_size)]
        size: (u16, u16),
        /// Timed runs per configuration (the median is used).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Report to write.
        #[arg(long, default_value = "docs/accuracy.md")]
        out: PathBuf,
        /// Plot to write (SVG).
        #[arg(long, default_value = "docs/accuracy.svg")]
        plot: PathBuf,
        /// Instruction counts written by `host-sim firmware`.
        #[arg(long, default_value = "docs/firmware.csv")]
        firmware_csv: PathBuf,
    },
    /// What the 1-bit display shows: every dither with and without silhouette lines and
    /// through several tone curves, measured against the reference gray image after a low-pass
    /// (mean error, SSIM); contact sheets per scene and the progressive passes: docs/display.md.
    Display {
        /// Scene files (default: the paper's four and the Whitted showcase).
        scenes: Vec<PathBuf>,
        /// Report to write.
        #[arg(long, default_value = "docs/display.md")]
        out: PathBuf,
        /// Folder for the contact sheets.
        #[arg(long, default_value = "docs/images")]
        images: PathBuf,
    },
    /// What simulating only the effects a scene calls for saves (rays, time, instructions,
    /// flash), and what the contribution cutoff saves and changes.
    Effects {
        /// Scene files (default: the paper's four and the Whitted showcase).
        scenes: Vec<PathBuf>,
        /// Timed runs per configuration (the median is used).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Report to write.
        #[arg(long, default_value = "docs/effects.md")]
        out: PathBuf,
        /// Instruction counts and flash sizes written by `host-sim firmware`.
        #[arg(long, default_value = "docs/firmware.csv")]
        firmware_csv: PathBuf,
    },
    /// Build the firmware, run it in QEMU, check its frames against the host bit for bit,
    /// and write the flash/RAM/instruction budgets to a report.
    Firmware {
        /// Report to write.
        #[arg(long, default_value = "docs/firmware.md")]
        out: PathBuf,
        /// Use the firmware already built instead of building it.
        #[arg(long)]
        no_build: bool,
    },
    /// Run the Pico image (the one `cargo pico` flashes) on an emulated RP2040 with an SSD1306:
    /// every frame must match host-sim bit for bit; writes the board's budgets to a report.
    ///
    /// Needs Node.js (rp2040js is installed from firmware/board/package-lock.json), python3 and
    /// PyPI (for the RP2040 bootrom), and flip-link (`cargo install flip-link`).
    Board {
        /// Report to write.
        #[arg(long, default_value = "docs/board.md")]
        out: PathBuf,
        /// Folder for the UF2 file that was run, the frames the panel showed (PNG), and, when a
        /// frame differs, host-sim's frame and a picture of the difference.
        #[arg(long, default_value = "target/board")]
        frames: PathBuf,
        /// Use the image already built instead of running `cargo pico-build`.
        #[arg(long)]
        no_build: bool,
    },
    /// The camera circles a scene (around the vertical line through the point it looks at):
    /// the frames as the Pico renders and shows them (128x64, fixed point, its sampling and
    /// dither), as an animated GIF.
    Orbit {
        /// Scene file.
        scene: PathBuf,
        /// GIF to write.
        #[arg(short, long, default_value = "out/orbit.gif")]
        output: PathBuf,
        /// Frames per turn.
        #[arg(long, default_value_t = firmware::board_frame::ORBIT_FRAMES)]
        frames: u32,
    },
    /// Flicker of each dither while the camera orbits the scenes: docs/motion.md.
    Motion {
        /// Scene files (default: the paper's four and the Whitted showcase).
        scenes: Vec<PathBuf>,
        /// Frames per turn.
        #[arg(long, default_value_t = 36)]
        frames: u32,
        /// Report to write.
        #[arg(long, default_value = "docs/motion.md")]
        out: PathBuf,
    },
    /// Build the Pico (or Pico 2) image and write it as a UF2 file, for flashing without a
    /// probe: hold BOOTSEL while plugging the board in and copy the file onto the drive it
    /// shows (RPI-RP2 for the Pico, RP2350 for the Pico 2).
    Uf2 {
        /// The board: pico (RP2040, fixed point) or pico2 (RP2350, f32).
        #[arg(long, value_enum, default_value = "pico")]
        board: board::Board,
        /// UF2 file to write [default: out/lattice-rt-<board>.uf2].
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

/// Numeric type the tracer runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Scalar {
    /// 64-bit float (the reference).
    F64,
    /// 32-bit float with libm.
    F32,
    /// Q16.16 fixed point.
    Fixed,
}

/// Ray-query method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Accel {
    /// The lattice (space subdivision with sub-lattices).
    Lattice,
    /// The paper's baseline: a bounding-box inside test per object per ray.
    Bbox,
    /// Every object for every ray.
    Brute,
}

/// Dithering mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DitherArg {
    /// 8x8 Bayer ordered dither, one ray per pixel.
    Bayer,
    /// The paper's 8x8 patterning: one ray per 8x8 block (65 levels).
    Pattern8,
    /// 4x4 patterning: one ray per 4x4 block (17 levels).
    Pattern4,
    /// 2x2 patterning: one ray per 2x2 block (5 levels).
    Pattern2,
    /// Floyd-Steinberg error diffusion.
    Fs,
    /// Atkinson error diffusion.
    Atkinson,
    /// Ordered dither with a 16x16 blue-noise (void-and-cluster) mask, one ray per pixel.
    BlueNoise,
}

impl DitherArg {
    /// The core's dithering mode.
    pub fn mode(self) -> Dither {
        match self {
            DitherArg::Bayer => Dither::Bayer,
            DitherArg::Pattern8 => Dither::Pattern(8),
            DitherArg::Pattern4 => Dither::Pattern(4),
            DitherArg::Pattern2 => Dither::Pattern(2),
            DitherArg::Fs => Dither::FloydSteinberg,
            DitherArg::Atkinson => Dither::Atkinson,
            DitherArg::BlueNoise => Dither::BlueNoise,
        }
    }
}

/// Eye rays per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SamplingArg {
    /// One ray through each pixel centre.
    One,
    /// Four rays per pixel (2x2 grid).
    Four,
    /// One ray per pixel, four at object edges only.
    Edges,
    /// One ray per pixel, four at object edges and where neighbours differ by 16 of 64 levels.
    EdgesContrast,
    /// Adaptive sub-sampling (the boards' default): every second pixel traced, the rest
    /// filled in where the traced pixels around hit one object and differ by at most 4 levels.
    Adaptive,
}

impl SamplingArg {
    /// The core's sampling mode.
    pub fn mode(self) -> lattice_rt::render::Sampling {
        use lattice_rt::render::Sampling;
        match self {
            SamplingArg::One => Sampling::Center,
            SamplingArg::Four => Sampling::Grid2x2,
            SamplingArg::Edges => Sampling::Edges { contrast: u8::MAX },
            SamplingArg::EdgesContrast => Sampling::Edges { contrast: 16 },
            SamplingArg::Adaptive => Sampling::Adaptive { contrast: 4 },
        }
    }
}

/// Parses `WxH`.
fn parse_size(s: &str) -> Result<(u16, u16), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size `{s}` is not WIDTHxHEIGHT"))?;
    let num = |v: &str| v.trim().parse::<u16>().ok().filter(|&n| n > 0 && n <= 4096);
    match (num(w), num(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("size `{s}`: width and height must be whole numbers from 1 to 4096")),
    }
}

/// Parses `NXxNYxNZ` into a manual lattice resolution.
fn parse_cells(s: &str) -> Result<[u16; 3], String> {
    let v: Vec<Option<u16>> = s.split(['x', 'X']).map(|p| p.trim().parse::<u16>().ok().filter(|&n| (1..=1024).contains(&n))).collect();
    match v.as_slice() {
        [Some(x), Some(y), Some(z)] => Ok([*x, *y, *z]),
        _ => Err(format!("cells `{s}`: expected NXxNYxNZ with each from 1 to 1024")),
    }
}

/// The lattice configuration chosen on the command line.
pub fn lattice_config(cells: Option<[u16; 3]>, budget: Option<usize>) -> lattice_rt::LatticeConfig {
    let mut cfg = lattice_rt::LatticeConfig { budget, ..Default::default() };
    if let Some(n) = cells {
        cfg.top = lattice_rt::lattice::Resolution::Uniform(n);
    }
    cfg
}

/// Options of `render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// PNG to write.
    #[arg(short, long, default_value = "out/render.png")]
    pub output: PathBuf,
    /// Image size.
    #[arg(long, default_value = "128x64", value_parser = parse_size)]
    pub size: (u16, u16),
    /// Dithering mode (the default scores best in `host-sim display`, docs/display.md).
    #[arg(long, value_enum, default_value_t = DitherArg::Fs)]
    pub dither: DitherArg,
    /// Eye rays per pixel.
    #[arg(long, value_enum, default_value_t = SamplingArg::One)]
    pub sampling: SamplingArg,
    /// Ray-query method.
    #[arg(long, value_enum, default_value_t = Accel::Lattice)]
    pub accel: Accel,
    /// Numeric type.
    #[arg(long, value_enum, default_value_t = Scalar::F64)]
    pub scalar: Scalar,
    /// Display theme of the PNG.
    #[arg(long, value_enum, default_value_t = output::Theme::OledWhite)]
    pub theme: output::Theme,
    /// PNG pixel scale (1 to 64; the PNG may have at most 2^26 pixels).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub scale: u32,
    /// Also write the gray levels (0..=64) as PGM.
    #[arg(long)]
    pub gray: Option<PathBuf>,
    /// Also write the 1-bit frame as PBM.
    #[arg(long)]
    pub pbm: Option<PathBuf>,
    /// Tile side in pixels.
    #[arg(long, default_value_t = 8)]
    pub tile: u8,
    /// World lattice resolution, overriding the automatic choice.
    #[arg(long, value_parser = parse_cells, value_name = "NXxNYxNZ")]
    pub cells: Option<[u16; 3]>,
    /// Most bytes the lattice may take: the lattice of least estimated cost within it is built
    /// (docs/memory.md); too small for one cell, the lattice method is refused.
    #[arg(long, value_name = "BYTES")]
    pub budget: Option<usize>,
    /// Leave out the silhouette lines. By default the farther pixel where neighbours hit
    /// different objects is drawn black: without them thin parts of the same gray as what lies
    /// behind (the chair's legs on its floor) vanish in a 1-bit frame (docs/display.md).
    #[arg(long)]
    pub no_outline: bool,
    /// Tone curve before dithering: gray levels raised to the power GAMMA/10 (5 to 20; 10 leaves
    /// them unchanged).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u8).range(5..=20))]
    pub gamma: u8,
}

/// Options of `stats`.
#[derive(clap::Args, Debug)]
pub struct StatsArgs {
    /// Scene file.
    pub scene: PathBuf,
    /// Image size used to count work per ray.
    #[arg(long, default_value = "160x100", value_parser = parse_size)]
    pub size: (u16, u16),
    /// Numeric type.
    #[arg(long, value_enum, default_value_t = Scalar::F64)]
    pub scalar: Scalar,
    /// Timed repetitions per accelerator (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// World lattice resolution, overriding the automatic choice.
    #[arg(long, value_parser = parse_cells, value_name = "NXxNYxNZ")]
    pub cells: Option<[u16; 3]>,
    /// Most bytes the lattice may take: the lattice of least estimated cost within it is built
    /// (docs/memory.md); too small for one cell, the lattice method is refused.
    #[arg(long, value_name = "BYTES")]
    pub budget: Option<usize>,
}

/// The scenes given, or the paper's four and the Whitted showcase.
fn default_scenes(scenes: Vec<PathBuf>) -> Vec<PathBuf> {
    if scenes.is_empty() {
        shared::default_scene_paths()
    } else {
        scenes
    }
}

fn main() {
    if let Err(e) = real_main() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        None => run::gallery(&cli.out, &PathBuf::from("scenes")),
        Some(Command::Gallery { out, scenes }) => run::gallery(&out, &scenes),
        Some(Command::Render(a)) => {
            if a.tile == 0 || a.tile > 16 {
                bail!("--tile must be from 1 to 16");
            }
            match a.scalar {
                Scalar::F64 => run::render_cmd::<f64>(&a),
                Scalar::F32 => run::render_cmd::<f32>(&a),
                Scalar::Fixed => run::render_cmd::<lattice_rt::Fx>(&a),
            }
        }
        Some(Command::Display { scenes, out, images }) => display::display_cmd(&default_scenes(scenes), &out, &images),
        Some(Command::Tradeoff { scenes, size, runs, out, plot, firmware_csv }) => {
            tradeoff::tradeoff_cmd(&default_scenes(scenes), size, runs, &out, &plot, &firmware_csv)
        }
        Some(Command::Export { scene, pov, ids, output }) => {
            if !pov {
                bail!("say which format: --pov is the one there is");
            }
            let text = load::read(&scene)?;
            let mut storage = load::object_storage::<f64>(&text)?;
            let s = load::parse_scene::<f64>(&scene, &text, &mut storage)?;
            let out = pov::export(&s, if ids { pov::PovMode::Ids } else { pov::PovMode::Full }).map_err(|e| {
                match e.downcast_ref::<pov::Unrepresentable>() {
                    Some(u) => {
                        let (line, col, _) = lattice_rt::scene::text::object_statement(&text, u.object);
                        anyhow::anyhow!("{}: line {line}, column {col}: cannot export {u}", scene.display())
                    }
                    None => e,
                }
            })?;
            output::write_atomic(&output, out.as_bytes())?;
            println!("wrote {}", output.display());
            Ok(())
        }
        Some(Command::Bench { quick, runs, out, plot }) => bench::bench_cmd(quick, runs, &out, &plot),
        Some(Command::Memory { quick, runs, out, plot, tests_plot }) => memory::memory_cmd(&memory::MemoryArgs { runs, quick, out, plot, tests_plot }),
        Some(Command::Effects { scenes, runs, out, firmware_csv }) => effects::effects_cmd(&default_scenes(scenes), runs, &out, &firmware_csv),
        Some(Command::Firmware { out, no_build }) => firmware::firmware_cmd(&std::env::current_dir()?, &out, no_build),
        Some(Command::Board { out, frames, no_build }) => board::board_cmd(&std::env::current_dir()?, &out, &frames, no_build),
        Some(Command::Orbit { scene, output, frames }) => orbit::orbit_cmd(&scene, &output, frames),
        Some(Command::Motion { scenes, frames, out }) => orbit::motion_cmd(&default_scenes(scenes), frames, &out),
        Some(Command::Uf2 { board, output }) => board::uf2_cmd(&std::env::current_dir()?, board, output.as_deref()),
        Some(Command::Stats(a)) => match a.scalar {
            Scalar::F64 => run::stats_cmd::<f64>(&a),
            Scalar::F32 => run::stats_cmd::<f32>(&a),
            Scalar::Fixed => run::stats_cmd::<lattice_rt::Fx>(&a),
        },
    }
}
