//! `cargo xtask`: the project's own checks and studies, which users of the ray tracer never
//! compile (the xtask convention). Each command builds what it needs (firmware images, host
//! renders), runs it, checks it and writes its report under docs/: the Pico image on the
//! emulated board (`board`), the firmware in QEMU (`firmware`), and the studies (`bench`,
//! `memory`, `tradeoff`, `effects`, `display`, `motion`), and a QEMU build's exact
//! instruction profile (`profile`).

mod bench;
mod board;
mod display;
mod effects;
mod elf;
mod firmware;
mod layers;
mod memory;
mod motion;
mod playground;
mod plot;
mod profile;
mod spd;
mod tradeoff;
mod versus;

use anyhow::Result;
use clap::{Parser, Subcommand};
use host_sim::cli::{default_scenes, parse_size};
use std::path::PathBuf;

/// The lattice-rt project's checks and studies (`cargo xtask COMMAND`).
#[derive(Parser, Debug)]
#[command(version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
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
        /// Run only the Standard Procedural Databases' images, print their section and draw
        /// their plot beside the report (the report itself is not written).
        #[arg(long)]
        spd_only: bool,
        /// Of the Standard Procedural Databases, run only the scenes of at most a thousand
        /// objects (the sphereflake at sizes 1 to 3, jacks): what CI runs, as each scene of
        /// thousands takes minutes to bake and run (docs/board.md has them all).
        #[arg(long)]
        spd_small: bool,
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
        /// Also bake the SPD's curve scenes at their default sizes (7,383 to 8,402 objects)
        /// into the image of the Pico 2's core, one image each, run them in QEMU and check their
        /// frames (about 10 minutes more; not run by CI).
        #[arg(long)]
        spd: bool,
    },
    /// Build the browser playground (the core in WebAssembly, the panel, the exact Pico image
    /// on an emulated RP2040) into a folder to serve; `--serve` serves it, `--check` tests it in
    /// headless Chromium against host-sim.
    ///
    /// Needs wasm-bindgen-cli 0.2.105 (`cargo install --locked wasm-bindgen-cli --version
    /// 0.2.105`), the wasm32-unknown-unknown target, Node.js and npm; `--check` needs Chromium.
    Playground {
        /// Folder to build the page into.
        #[arg(long, default_value = "target/playground")]
        out: PathBuf,
        /// Serve the page at this address (for example 127.0.0.1:8080) once built.
        #[arg(long, value_name = "ADDR")]
        serve: Option<String>,
        /// Open the page in headless Chromium and check it against host-sim.
        #[arg(long)]
        check: bool,
        /// With --check: write a screenshot of the page here.
        #[arg(long)]
        screenshot: Option<PathBuf>,
        /// Use the Pico image already built instead of running `cargo pico-build`.
        #[arg(long)]
        no_build: bool,
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
    /// host-sim against POV-Ray on chosen scenes of `bench`'s comparison, printed as a table
    /// (nothing written): for measuring one scene while working on it.
    /// The Standard Procedural Databases at their default sizes: the ray invariants against
    /// Havran's and the SPD Readme's, object tests and cell steps per ray against the published
    /// structures, and the time against POV-Ray 3.7. Writes docs/spd.md.
    Spd {
        /// Report to write.
        #[arg(long, default_value = "docs/spd.md")]
        out: PathBuf,
        /// Timed runs per scene against POV-Ray (the median is used).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Leave POV-Ray's column out.
        #[arg(long)]
        no_povray: bool,
    },
    Versus {
        /// Scenes by name or name prefix (`chair`, `loose clustered 1000`, `random`); all when none.
        scenes: Vec<String>,
        /// Timed runs per scene (the median is used).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// host-sim only (POV-Ray's column left empty): for profiling.
        #[arg(long)]
        no_povray: bool,
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
        /// Instruction counts written by `cargo xtask firmware`.
        #[arg(long, default_value = "docs/firmware.csv")]
        firmware_csv: PathBuf,
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
        /// Instruction counts and flash sizes written by `cargo xtask firmware`.
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
        /// Where `cargo xtask board` left the frames the emulated Pico's panel showed
        /// (`<scene>.pbm`), scored beside the host's.
        #[arg(long, default_value = "target/board")]
        board: PathBuf,
    },
    /// Where a QEMU firmware build's instructions go, per function, counted exactly: QEMU logs
    /// every block it runs (`-d in_asm,exec,nochain`), each instruction is credited to its
    /// function and to every function it was inlined into (DWARF). Prints Markdown tables.
    ///
    /// Needs qemu-system-arm; the image is built with the one scene embedded.
    Profile {
        /// A variant of `cargo xtask firmware` that runs in QEMU (`qemu-m33-f32`, `qemu-m0-fixed-baked`, ...).
        #[arg(default_value = "qemu-m33-f32")]
        variant: String,
        /// The scene the image embeds alone.
        #[arg(long, default_value = "chair")]
        scene: String,
        /// Rows per table.
        #[arg(long, default_value_t = 25)]
        top: usize,
        /// Also break down this function's instructions (by name, as the tables print it: `Tracer::eye_sample`,
        /// `offer`) by what it inlined and its own source lines.
        #[arg(long)]
        under: Option<String>,
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
    /// Check the house's layers: the modules of every folder of every crate depend on each
    /// other without a circle (printed lowest layer first), and ARCHITECTURE.md names every
    /// module. `cargo test -p xtask` runs the same check.
    Layers,
}

fn main() {
    if let Err(e) = real_main() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn real_main() -> Result<()> {
    let root = std::env::current_dir()?;
    match Cli::parse().command {
        Command::Board { out, frames, no_build, spd_only, spd_small } => {
            board::board_cmd(&root, &out, &frames, no_build, (spd_only, spd_small))
        }
        Command::Playground { out, serve, check, screenshot, no_build } => {
            playground::playground_cmd(&root, &playground::PlaygroundArgs { out, serve, check, screenshot, no_build })
        }
        Command::Firmware { out, no_build, spd } => firmware::firmware_cmd(&root, &out, no_build, spd),
        Command::Bench { quick, runs, out, plot } => bench::bench_cmd(quick, runs, &out, &plot),
        Command::Spd { out, runs, no_povray } => spd::spd_cmd(&out, runs, !no_povray),
        Command::Versus { scenes, runs, no_povray } => bench::versus_cmd(&scenes, runs, !no_povray),
        Command::Memory { quick, runs, out, plot, tests_plot } => {
            memory::memory_cmd(&memory::MemoryArgs { runs, quick, out, plot, tests_plot })
        }
        Command::Tradeoff { scenes, size, runs, out, plot, firmware_csv } => {
            tradeoff::tradeoff_cmd(&default_scenes(scenes), size, runs, &out, &plot, &firmware_csv)
        }
        Command::Effects { scenes, runs, out, firmware_csv } => {
            effects::effects_cmd(&default_scenes(scenes), runs, &out, &firmware_csv)
        }
        Command::Display { scenes, out, images, board } => {
            display::display_cmd(&default_scenes(scenes), &out, &images, &board)
        }
        Command::Profile { variant, scene, top, under } => {
            profile::profile_cmd(&root, &profile::ProfileArgs { variant, scene, top, under })
        }
        Command::Motion { scenes, frames, out } => motion::motion_cmd(&default_scenes(scenes), frames, &out),
        Command::Layers => layers::layers_cmd(&root),
    }
}
