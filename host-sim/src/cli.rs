//! The command line's shared vocabulary: scalars, accelerators, dithers and sampling as
//! options, the options of `render` and `stats`, and their parsers (also used by `cargo xtask`).

use crate::output;
use crate::shared;
use clap::ValueEnum;
use lattice_rt::Dither;
use std::path::PathBuf;

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

impl Accel {
    /// The name reports use.
    pub fn name(self) -> &'static str {
        match self {
            Accel::Lattice => "lattice",
            Accel::Bbox => "bbox",
            Accel::Brute => "brute",
        }
    }
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
    /// Adaptive sub-sampling (the QEMU boards' default): every second pixel traced, the rest
    /// filled in where the traced pixels around hit one object and differ by at most 4 levels.
    Adaptive,
    /// Adaptive sub-sampling in two levels (the panels' default): every fourth pixel traced
    /// first, then every second filled in the same way where no other object can show between
    /// (by its eye window and hull, or as hidden behind the traced one) and no mirror or glass
    /// lies there, then the rest.
    Coarse,
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
            SamplingArg::Adaptive => Sampling::Adaptive { contrast: 4, coarse: false },
            SamplingArg::Coarse => Sampling::Adaptive { contrast: 4, coarse: true },
        }
    }
}

/// Parses `WxH`.
pub fn parse_size(s: &str) -> Result<(u16, u16), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size `{s}` is not WIDTHxHEIGHT"))?;
    let num = |v: &str| v.trim().parse::<u16>().ok().filter(|&n| n > 0 && n <= 4096);
    match (num(w), num(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("size `{s}`: width and height must be whole numbers from 1 to 4096")),
    }
}

/// Parses `NXxNYxNZ` into a manual lattice resolution.
pub fn parse_cells(s: &str) -> Result<[u16; 3], String> {
    let v: Vec<Option<u16>> =
        s.split(['x', 'X']).map(|p| p.trim().parse::<u16>().ok().filter(|&n| (1..=1024).contains(&n))).collect();
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
    /// Scene file (`-`: read it from standard input).
    pub scene: PathBuf,
    /// File to write; its extension names the format: .png (the 1-bit frame in --theme), .pbm
    /// (the 1-bit frame), .pgm (gray levels 0..=64). `-` writes the PNG to standard output (the
    /// messages then go to standard error).
    #[arg(short, long, default_value = "out/render.png")]
    pub output: PathBuf,
    /// Image size (the scene's view is fitted to its shape: pixels are square).
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
    /// PNG pixel scale (1 to 64; at 1 the PNG has the frame's own size; the PNG may have at
    /// most 2^26 pixels).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub scale: u32,
    /// Draw a one-pixel grid between the PNG's pixels, as a panel looks close up.
    #[arg(long)]
    pub grid: bool,
    /// Also write the gray levels (0..=64): FILE.pgm, or FILE.png as a gray PNG.
    #[arg(long)]
    pub gray: Option<PathBuf>,
    /// Also write the 1-bit frame as PBM (FILE.pbm).
    #[arg(long)]
    pub pbm: Option<PathBuf>,
    /// Shades the panel shows: 2 (a 1-bit frame) or 4 (the gray mode: error diffusion over
    /// black, two grays and white, each pixel lit in 0 to 3 of the panel's three subframes;
    /// the PNG shows the shades as the eye sees them). A 4-shade frame is not written as PBM.
    #[arg(long, default_value_t = 2, value_parser = parse_levels)]
    pub levels: u8,
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
    /// Contribution cutoff: mirror and glass rays, and shadow rays of light terms, weighing
    /// less than 2^-K of a pixel are not traced (7: half a gray step, what the boards do; 1 to
    /// 14). Without it every branch is traced.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u8).range(1..=14))]
    pub cutoff: Option<u8>,
    /// Print the statistics as JSON on standard output instead of text (fields: docs/json.md).
    #[arg(long)]
    pub json: bool,
    /// Exactly the frame this board's default image shows: 128x64, its scalar (the Pico fixed
    /// point, the Pico 2 f32), coarse sampling, 16x16 tiles, Floyd-Steinberg with lines and
    /// cutoff 7 (the frame options above cannot be given with it); with `--levels 4`, the gray
    /// image's (`--features gray`: the same without lines).
    #[arg(long, value_enum, conflicts_with_all = ["size", "dither", "sampling", "scalar", "tile", "no_outline", "gamma", "cutoff"])]
    pub board: Option<crate::uf2::Board>,
    /// With --board: the panel the image drives, whose glass sets the frame's size (ssd1306,
    /// sh1106, ssd1309: 128x64; ssd1306-128x32; ssd1306-72x40; sharp-400x240; sharp-128x128;
    /// uc8151: 296x128).
    #[arg(long, value_parser = parse_panel, requires = "board")]
    pub panel: Option<board_records::frame::Panel>,
}

/// `--levels`: 2 or 4.
fn parse_levels(s: &str) -> Result<u8, String> {
    match s {
        "2" => Ok(2),
        "4" => Ok(4),
        _ => Err(format!("{s}: 2 (a 1-bit frame) or 4 (the gray mode's shades)")),
    }
}

/// A panel's name as `--panel` takes it.
pub fn parse_panel(name: &str) -> Result<board_records::frame::Panel, String> {
    use board_records::frame::Panel;
    Panel::of(name).ok_or_else(|| {
        let names: Vec<&str> = Panel::ALL.iter().map(|p| p.name()).collect();
        format!("one of {}", names.join(", "))
    })
}

impl RenderArgs {
    /// The scalar the render runs in: the board's, or `--scalar`.
    pub fn scalar(&self) -> Scalar {
        match self.board {
            Some(crate::uf2::Board::Pico) => Scalar::Fixed,
            Some(crate::uf2::Board::Pico2) => Scalar::F32,
            None => self.scalar,
        }
    }

    /// The frame the options describe (the board's own with `--board`, at its panel's size).
    pub fn frame(&self) -> lattice_rt::Frame {
        if self.board.is_some() {
            let glass = self.panel.unwrap_or_default().glass();
            // Four shades are the gray image's frame (the `gray` feature: no silhouette lines).
            let gray = self.levels == 4;
            return board_records::frame::rendered(board_records::frame::Build {
                glass,
                gray,
                ..board_records::frame::PICO
            });
        }
        lattice_rt::Frame {
            tile: self.tile,
            dither: self.dither.mode(),
            sampling: self.sampling.mode(),
            outline: !self.no_outline,
            tone: lattice_rt::Tone { gamma_tenths: self.gamma },
            cutoff: self.cutoff,
            ..lattice_rt::Frame::new(self.size.0, self.size.1)
        }
    }
}

/// Options of `stats`.
#[derive(clap::Args, Debug)]
pub struct StatsArgs {
    /// Scene file (`-`: read it from standard input).
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
    /// Print the statistics as JSON instead of text (fields: docs/json.md).
    #[arg(long)]
    pub json: bool,
    /// Count rays under the Standard Procedural Databases' testing protocol instead (512x512,
    /// eye rays through the 513x513 pixel corners, depth 5 counting the eye ray, no cutoff): the
    /// ray invariants Havran and Sixta published, and object tests and cell steps per ray with
    /// the lattice alone (as Havran measured) and with the tracer's defaults. `--size` is not used.
    #[arg(long)]
    pub spd: bool,
}

/// The scenes given, or the paper's four and the Whitted showcase.
pub fn default_scenes(scenes: Vec<PathBuf>) -> Vec<PathBuf> {
    if scenes.is_empty() {
        shared::default_scene_paths()
    } else {
        scenes
    }
}
