//! The frame every board renders: the firmware renders it, its `build.rs` sizes the storage
//! for it, and the host renders it to check the board's frames bit for bit.

use lattice_rt::render::Sampling;
use lattice_rt::{Dither, EyeRays, Frame, Tone};

/// The frame's width on the boards without a panel, and on the default panel (SSD1306 128x64;
/// a build's own is [`rendered`]'s).
pub const WIDTH: u16 = 128;
/// Its height.
pub const HEIGHT: u16 = 64;

/// How the boards without a panel spend eye rays: adaptive sub-sampling (every second pixel
/// traced, the rest filled where the traced pixels around agree to 4 levels of 64; its error
/// is in docs/accuracy.md). The firmware's `exact-sampling` feature traces one ray per pixel
/// instead (`app::RENDERED`).
pub const SAMPLING: Sampling = Sampling::Adaptive { contrast: 4, coarse: false };

/// How the boards with a panel spend eye rays: adaptive sub-sampling in two levels (every
/// fourth pixel traced, then every second, filled in the same way where no other object's eye
/// window and no mirror or glass lies between, then the rest; its error is in
/// docs/accuracy.md). In 16x16 tiles it traces a third fewer of the chair's eye rays with the
/// same gray levels; the boards without a panel, whose tiny image has no room for its code
/// (the core's `coarse-sampling` feature), keep [`SAMPLING`].
pub const PANEL_SAMPLING: Sampling = Sampling::Adaptive { contrast: 4, coarse: true };

/// The contribution cutoff of every board's frame ([`Frame::cutoff`]): branches of the
/// intersection tree weighing less than 2^-7, half of one of the 64 gray steps of a pixel's
/// level, are not traced. Whitted's frame traces 28 % fewer rays with it (QEMU's Cortex-M0+
/// build, `cargo xtask firmware`); what it changes is in docs/accuracy.md (`cargo xtask
/// tradeoff`, cutoff 1/128). Besides mirror and glass rays it leaves out the shadow rays of a
/// light whose term at a point is that faint (the light then counts as seen): a matte scene's
/// frame changes only where light grazes a surface (the chair's default frame not at all).
pub const CUTOFF: Option<u8> = Some(7);

/// The frame of the boards without a panel (the QEMU machines and the micro:bit, whose frames
/// only CI looks at): 128x64, 8x8 tiles (one SSD1306 page high), blue-noise ordered dither, no
/// silhouette lines. It carries nothing from tile to tile and needs no dither carries (1 KiB of
/// RAM the baked micro:bit builds keep). The `outline` feature adds the lines.
pub const FRAME: Frame = Frame {
    width: WIDTH,
    height: HEIGHT,
    tile: 8,
    dither: Dither::BlueNoise,
    sampling: SAMPLING,
    rows: (0, u16::MAX),
    tone: Tone::LINEAR,
    outline: false,
    cutoff: CUTOFF,
};

/// The tile side of the frames on a panel (the Raspberry Pi boards): 16 pixels, two SSD1306
/// pages high. Adaptive sampling traces every second row and column of a tile and its last, so
/// a 16x16 tile traces 9x9 of its pixels first where four 8x8 tiles trace 4x5x5: the chair
/// frame's eye rays fall by a quarter (4,988 to 3,733 in `host-sim render --sampling adaptive
/// --scalar fixed --tile 16`), at the cost of a band twice as high on the bus at the frame's end.
/// In two levels ([`PANEL_SAMPLING`]) a 16x16 tile traces 5x5 first, and the chair's eye rays
/// fall to 2,549 (`--sampling coarse`).
pub const PANEL_TILE: u8 = 16;

/// The dither of a still frame on a panel: Floyd-Steinberg error diffusion, which with lines
/// scores best of every dither in `cargo xtask display` (docs/display.md). Two cores trace each
/// band of tiles and one dithers the finished bands in order (`lattice_rt::trace_share`,
/// `dither_band`), so error diffusion costs the boards no second core.
pub const STILL_DITHER: Dither = Dither::FloydSteinberg;

/// The dither of frames in motion (orbit mode, and the progressive frames' passes): blue noise,
/// which flickers least from frame to frame in `cargo xtask motion` (docs/motion.md).
pub const MOTION_DITHER: Dither = Dither::BlueNoise;

/// The glass a panel board draws on: its size in pixels (the controller's RAM may be larger).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Glass {
    /// 128x64, the common 0.96" (SSD1306), 1.3" (SH1106) and 2.42" (SSD1309) modules.
    #[default]
    Oled128x64,
    /// 128x32, the 0.91" SSD1306 modules (the firmware's `ssd1306-128x32` feature).
    Oled128x32,
    /// 72x40, the 0.42" SSD1306 modules and the Thumby's panel (`ssd1306-72x40`).
    Oled72x40,
    /// 400x240, the Sharp memory LCD LS027B7DH01 (2.7", the Playdate's kind; `sharp-400x240`).
    Sharp400x240,
    /// 128x128, the Sharp memory LCD LS013B7DH03 (1.28"; `sharp-128x128`).
    Sharp128x128,
    /// 296x128, the Badger 2040's 2.9" e-paper (UC8151; `uc8151`).
    Epaper296x128,
}

impl Glass {
    /// Width and height in pixels.
    pub const fn size(self) -> (u16, u16) {
        match self {
            Glass::Oled128x64 => (128, 64),
            Glass::Oled128x32 => (128, 32),
            Glass::Oled72x40 => (72, 40),
            Glass::Sharp400x240 => (400, 240),
            Glass::Sharp128x128 => (128, 128),
            Glass::Epaper296x128 => (296, 128),
        }
    }

    /// The glass a build's features (answered by name) choose.
    pub fn of(has: impl Fn(&str) -> bool) -> Glass {
        if has("ssd1306-128x32") {
            Glass::Oled128x32
        } else if has("ssd1306-72x40") {
            Glass::Oled72x40
        } else if has("sharp-400x240") {
            Glass::Sharp400x240
        } else if has("sharp-128x128") {
            Glass::Sharp128x128
        } else if has("uc8151") {
            Glass::Epaper296x128
        } else {
            Glass::Oled128x64
        }
    }
}

/// The panels the Raspberry Pi boards' image drives, each chosen by a firmware feature (none:
/// the SSD1306 128x64).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Panel {
    /// SSD1306 128x64 (the default).
    #[default]
    Ssd1306,
    /// SH1106 128x64, the 1.3" modules.
    Sh1106,
    /// SSD1309 128x64, the 2.42" modules.
    Ssd1309,
    /// SSD1306 on 128x32 glass.
    Ssd1306x32,
    /// SSD1306 on 72x40 glass.
    Ssd1306x40,
    /// Sharp memory LCD LS027B7DH01, 400x240.
    Sharp400x240,
    /// Sharp memory LCD LS013B7DH03, 128x128.
    Sharp128x128,
    /// UC8151 e-paper, 296x128 (the Badger 2040's).
    Uc8151,
    /// The Thumby's own panel: an SSD1306 on 72x40 glass on SPI, wired to the Thumby's pins
    /// (chip select GP16, data/command GP17, reset GP20; its A button on GP27).
    Thumby,
}

impl Panel {
    /// Every panel.
    pub const ALL: [Panel; 9] = [
        Panel::Ssd1306,
        Panel::Sh1106,
        Panel::Ssd1309,
        Panel::Ssd1306x32,
        Panel::Ssd1306x40,
        Panel::Sharp400x240,
        Panel::Sharp128x128,
        Panel::Uc8151,
        Panel::Thumby,
    ];

    /// Its name: `host-sim --panel`'s and the emulated board's (`run.mjs --panel`).
    pub const fn name(self) -> &'static str {
        match self {
            Panel::Ssd1306 => "ssd1306",
            Panel::Sh1106 => "sh1106",
            Panel::Ssd1309 => "ssd1309",
            Panel::Ssd1306x32 => "ssd1306-128x32",
            Panel::Ssd1306x40 => "ssd1306-72x40",
            Panel::Sharp400x240 => "sharp-400x240",
            Panel::Sharp128x128 => "sharp-128x128",
            Panel::Uc8151 => "uc8151",
            Panel::Thumby => "thumby",
        }
    }

    /// The firmware feature that drives it: its name (none for the default), so that
    /// `--panel` and `--features` speak of a panel in one word.
    pub const fn feature(self) -> Option<&'static str> {
        match self {
            Panel::Ssd1306 => None,
            _ => Some(self.name()),
        }
    }

    /// Its glass.
    pub const fn glass(self) -> Glass {
        match self {
            Panel::Ssd1306 | Panel::Sh1106 | Panel::Ssd1309 => Glass::Oled128x64,
            Panel::Ssd1306x32 => Glass::Oled128x32,
            Panel::Ssd1306x40 | Panel::Thumby => Glass::Oled72x40,
            Panel::Sharp400x240 => Glass::Sharp400x240,
            Panel::Sharp128x128 => Glass::Sharp128x128,
            Panel::Uc8151 => Glass::Epaper296x128,
        }
    }

    /// The panel named `name`.
    pub fn of(name: &str) -> Option<Panel> {
        Panel::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// What a firmware build asks of its frame: its features.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Build {
    /// The board renders the frame of a panel (the Raspberry Pi boards' SSD1306, or the
    /// firmware's `panel-frame` feature on a board without one).
    pub panel: bool,
    /// Orbit mode (`orbit`): frames in motion.
    pub orbit: bool,
    /// Progressive frames (`progressive`): passes in motion.
    pub progressive: bool,
    /// Silhouette lines forced on (`outline`) or off (`no-outline`); `None`: on a panel, off
    /// elsewhere.
    pub lines: Option<bool>,
    /// One eye ray per pixel (`exact-sampling`).
    pub exact_sampling: bool,
    /// The panel's glass, whose size the frame takes (boards without a panel: [`FRAME`]'s).
    pub glass: Glass,
    /// The gray mode (`gray`): four shades, shown as subframes. Its frames have no silhouette
    /// lines unless asked for (`outline`): with grays the thin parts show without them, and
    /// the lines cost legibility (docs/display.md, *Four shades*).
    pub gray: bool,
}

impl Build {
    /// The build of a firmware whose Cargo features `has` answers for by name (`rp` is a
    /// panel, and `panel-frame` renders its frame).
    pub fn of(has: impl Fn(&str) -> bool) -> Build {
        let lines = if has("outline") {
            Some(true)
        } else if has("no-outline") {
            Some(false)
        } else {
            None
        };
        Build {
            panel: has("rp") || has("panel-frame"),
            orbit: has("orbit"),
            progressive: has("progressive"),
            lines,
            exact_sampling: has("exact-sampling"),
            glass: Glass::of(&has),
            gray: has("gray"),
        }
    }
}

/// The frame a build renders. On a panel: stills in [`STILL_DITHER`], frames in motion in
/// [`MOTION_DITHER`], both with silhouette lines, without which the chair's legs and seat vanish
/// into a floor of the same gray, and [`PANEL_TILE`], at the glass's size. Without a panel:
/// [`FRAME`].
pub const fn rendered(b: Build) -> Frame {
    let dither = if b.panel && !b.orbit && !b.progressive { STILL_DITHER } else { MOTION_DITHER };
    let outline = match b.lines {
        Some(on) => on,
        None => b.panel && !b.gray,
    };
    let sampling = match (b.exact_sampling, b.panel) {
        (true, _) => Sampling::Center,
        (false, true) => PANEL_SAMPLING,
        (false, false) => SAMPLING,
    };
    let (tile, (width, height)) = if b.panel { (PANEL_TILE, b.glass.size()) } else { (FRAME.tile, (WIDTH, HEIGHT)) };
    Frame { dither, outline, sampling, tile, width, height, ..FRAME }
}

/// The Raspberry Pi Pico's default image: a still frame on a panel.
pub const PICO: Build = Build {
    panel: true,
    orbit: false,
    progressive: false,
    lines: None,
    exact_sampling: false,
    glass: Glass::Oled128x64,
    gray: false,
};

/// Frames per turn of the camera in orbit mode (the firmware's `orbit` feature, `host-sim orbit`).
pub const ORBIT_FRAMES: u32 = 36;

/// Steps per circle of the camera-turn button (the firmware's `Wiring::TURN`): each press draws
/// the scene from an eighth of a circle further around it.
pub const TURN_STEPS: u32 = 8;

/// How a frame is traced: the real-time levers that can be switched at run time, so one image
/// measures them one by one (the `ladder` feature) with every frame still checked against
/// host-sim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tuning {
    /// How eye rays find their hit (`None`: the scene's default, `EyeRays::for_scene`).
    pub eye_rays: Option<EyeRays>,
    /// Shadow rays try the object that last hid their light first.
    pub shadow_coherence: bool,
    /// A lattice walk tests an object's box before the object (`Tracer::set_box_tests`).
    pub box_tests: bool,
    /// Eye rays per pixel.
    pub sampling: Sampling,
}

/// What the boards run: every lever on.
pub const TUNING: Tuning = Tuning { eye_rays: None, shadow_coherence: true, box_tests: true, sampling: SAMPLING };

/// The ladder of the real-time work, from the paper's method to what the boards run, one lever
/// added per rung (docs/board.md, written by `cargo xtask board` from the `ladder` image).
pub const LADDER: [(&str, Tuning); 7] = [
    (
        "the paper's nested lattice, one ray per pixel",
        Tuning {
            eye_rays: Some(EyeRays::Plain),
            shadow_coherence: false,
            box_tests: false,
            sampling: Sampling::Center,
        },
    ),
    (
        "+ shadow rays try the last occluder first",
        Tuning { eye_rays: Some(EyeRays::Plain), shadow_coherence: true, box_tests: false, sampling: Sampling::Center },
    ),
    (
        "+ the walk tests an object's box before the object",
        Tuning { eye_rays: Some(EyeRays::Plain), shadow_coherence: true, box_tests: true, sampling: Sampling::Center },
    ),
    (
        "+ eye windows: the walk skips objects whose window misses the eye ray",
        Tuning {
            eye_rays: Some(EyeRays::Accelerator),
            shadow_coherence: true,
            box_tests: true,
            sampling: Sampling::Center,
        },
    ),
    (
        "+ eye rays and first-light shadow rays by windows alone, no walk",
        Tuning {
            eye_rays: Some(EyeRays::Windows),
            shadow_coherence: true,
            box_tests: true,
            sampling: Sampling::Center,
        },
    ),
    ("+ adaptive sub-sampling: every second pixel traced first", TUNING),
    ("+ in two levels: every fourth pixel first (the panels' default)", Tuning { sampling: PANEL_SAMPLING, ..TUNING }),
];

/// Tile shares a frame is rendered in (`Share`): one per RP2040 core. Where only one core runs
/// (the emulator), core 0 renders both, one after the other, and logs each share's time.
pub const SHARES: u8 = 2;

#[cfg(test)]
mod tests {
    use super::*;

    /// A panel's `--panel` name is the firmware feature that drives it, and the firmware has
    /// that feature: one word per panel everywhere.
    #[test]
    fn every_panel_is_named_as_its_firmware_feature() {
        let manifest = include_str!("../../firmware/Cargo.toml");
        for p in Panel::ALL {
            match p.feature() {
                None => assert_eq!(p, Panel::Ssd1306, "only the default panel has no feature"),
                Some(f) => {
                    assert_eq!(f, p.name(), "{p:?}");
                    let declared = manifest.lines().any(|l| l.strip_prefix(f).is_some_and(|r| r.starts_with(" = ")));
                    assert!(declared, "no firmware feature `{f}`");
                }
            }
        }
    }
}
