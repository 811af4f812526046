//! host-sim: the desktop driver of the lattice-rt core, what a user runs on scenes. Renders
//! scenes to PNG/PBM/PGM, prints statistics, exports to POV-Ray, orbits the camera, writes the
//! board's UF2 file, and (with no arguments) renders the paper's four scenes into `out/`. The
//! project's own checks and studies are `cargo xtask` (xtask/).

use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use host_sim::cli::{RenderArgs, Scalar, StatsArgs};
use host_sim::{load, orbit, output, pov, run, uf2};
use std::path::PathBuf;

/// Desktop driver for the lattice-rt ray tracer.
///
/// With no command it renders every scene in `scenes/` (the paper's four and the Whitted scene)
/// as `render` does by default, at 128x64 and 160x100, into `out/`, and prints the command
/// that draws each picture and its statistics.
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
    /// Render every scene file in a folder as `render` does by default, at 128x64 and 160x100
    /// (PNG, PBM and a gray PNG of each), printing the command that draws each.
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
        /// Write POV-Ray scene language (the default, and so far the only format).
        #[arg(long)]
        pov: bool,
        /// Each object a flat distinct gray, no lights (for comparing object masks).
        #[arg(long)]
        ids: bool,
        /// File to write.
        #[arg(short, long, default_value = "out/scene.pov")]
        output: PathBuf,
        /// The frame the view is fitted to (its shape: square pixels), as `render --size`.
        #[arg(long, default_value = "128x64", value_parser = host_sim::cli::parse_size)]
        size: (u16, u16),
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
        #[arg(long, default_value_t = board_records::frame::ORBIT_FRAMES)]
        frames: u32,
    },
    /// Generate a scene of Eric Haines' Standard Procedural Databases as NFF, as the SPD's own
    /// program does (`balls -s 4` ...): the field's benchmark scenes, for `render`, `stats` and
    /// `export` (which read NFF as they read scene files).
    Spd {
        /// The SPD generator.
        #[arg(value_enum)]
        generator: host_sim::spd::Generator,
        /// Size factor [default: the SPD's own for that scene, the published figures' size].
        #[arg(short, long)]
        size: Option<u32>,
        /// NFF file to write (`-`: standard output) [default: out/spd/<generator>-<size>.nff].
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Build the Pico (or Pico 2) image and write it as a UF2 file, for flashing without a
    /// probe: hold BOOTSEL while plugging the board in and copy the file onto the drive it
    /// shows (RPI-RP2 for the Pico, RP2350 for the Pico 2). With --scene, no build: the scene
    /// is written into the scene slot of a prebuilt slot image (`--features slot`, built once,
    /// or downloaded from the playground), which parses and shows it on the Pico.
    Uf2 {
        /// The board: pico (RP2040, fixed point) or pico2 (RP2350, f32).
        #[arg(long, value_enum, default_value = "pico")]
        board: uf2::Board,
        /// The firmware's build options, comma-separated (docs/flashing.md): `spi` for a 7-pin SPI
        /// module, `i2c-1mhz`, `orbit`, `progressive`, `no-outline`, ...
        #[arg(long, value_name = "LIST")]
        features: Option<String>,
        /// The panel the image drives (its firmware feature added to --features): ssd1306 (the
        /// default), sh1106 (1.3" modules), ssd1309 (2.42"), ssd1306-128x32, ssd1306-72x40,
        /// sharp-400x240 (Sharp memory LCD LS027B7DH01), sharp-128x128 (LS013B7DH03), uc8151
        /// (the Badger 2040's 296x128 e-paper), thumby (the Thumby: its 72x40 SSD1306 and its A
        /// button, on its own pins).
        #[arg(long, value_parser = host_sim::cli::parse_panel, conflicts_with = "scene")]
        panel: Option<board_records::frame::Panel>,
        /// UF2 file to write [default: out/lattice-rt-<board>.uf2; with --features,
        /// out/lattice-rt-<board>-<features>.uf2; with --scene, out/lattice-rt-pico-<scene>.uf2].
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// A scene file (or `-`) to write into the slot image's scene slot: checked as the Pico
        /// will read it (fixed point, 128x64, the slot's storage), no compiler involved.
        #[arg(long, conflicts_with = "features")]
        scene: Option<PathBuf>,
        /// The slot image's UF2 file the scene is written beside.
        #[arg(long, default_value = "out/lattice-rt-pico-slot.uf2", requires = "scene")]
        image: PathBuf,
        /// Scene or NFF files (comma-separated) to bake into the image in place of the default
        /// scenes: objects, lattice and windows as tables in flash, thousands of objects
        /// (`host-sim spd balls --size 3`). The firmware's `triangles` is added for a scene with
        /// triangles (NFF's polygons), and on the Pico `lean-objects` when the tables do not
        /// fit its flash whole.
        #[arg(long, value_name = "FILES", value_delimiter = ',', conflicts_with = "scene")]
        bake: Vec<PathBuf>,
    },
}

fn main() {
    // What is left of the last lines is flushed here, so a failure to write it is reported too.
    if let Err(e) = real_main().and_then(|()| host_sim::stdout::flush()) {
        if host_sim::stdout::is_closed_pipe(&e) {
            // The reader went away (`| head`): the output was not wanted further.
            std::process::exit(0);
        }
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
            match a.scalar() {
                Scalar::F64 => run::render_cmd::<f64>(&a),
                Scalar::F32 => run::render_cmd::<f32>(&a),
                Scalar::Fixed => run::render_cmd::<lattice_rt::Fx>(&a),
            }
        }
        Some(Command::Export { scene, pov, ids, output, size }) => {
            let _ = pov; // POV-Ray is the one format, with or without the flag.
            let text = load::read(&scene)?;
            let mut storage = load::object_storage::<f64>(&text)?;
            let s = load::parse_scene::<f64>(&scene, &text, &mut storage, &lattice_rt::Frame::new(size.0, size.1))?;
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
            host_sim::say!("wrote {}", output.display())?;
            Ok(())
        }
        Some(Command::Spd { generator, size, output }) => {
            let size = size.unwrap_or(generator.default_size());
            let text = generator.nff(size)?;
            match output {
                Some(p) if p.as_os_str() == "-" => host_sim::stdout::bytes(text.as_bytes())?,
                _ => {
                    let path = output.unwrap_or_else(|| format!("out/spd/{}-{size}.nff", generator.name()).into());
                    output::write_atomic(&path, text.as_bytes())?;
                    let (primitives, objects) =
                        (host_sim::spd::primitives(&text), lattice_rt::scene::object_count(&text));
                    host_sim::say!(
                        "wrote {} ({primitives} primitives as the SPD counts them; {objects} objects as the tracer \
                         stores them, each polygon cut into triangles)",
                        path.display()
                    )?;
                }
            }
            Ok(())
        }
        Some(Command::Orbit { scene, output, frames }) => orbit::orbit_cmd(&scene, &output, frames),
        Some(Command::Uf2 { board, features, panel, output, scene, image, bake }) => match scene {
            Some(scene) => uf2::scene_cmd(board, &scene, &image, output.as_deref()),
            None => {
                let features = uf2::with_panel(features.as_deref(), panel);
                uf2::uf2_cmd(&std::env::current_dir()?, board, features.as_deref(), &bake, output.as_deref())
            }
        },
        Some(Command::Stats(a)) => match a.scalar {
            Scalar::F64 => run::stats_cmd::<f64>(&a),
            Scalar::F32 => run::stats_cmd::<f32>(&a),
            Scalar::Fixed => run::stats_cmd::<lattice_rt::Fx>(&a),
        },
    }
}
