//! The playground's engine: scene text in, the Pico's 128x64 1-bit panel and what the lattice did
//! out. Compiled to WebAssembly for the page in `playground/web/` (`cargo xtask playground`
//! builds it); the same functions run natively in the tests, against host-sim's renders.
//!
//! The page calls [`panel`] as the user types; [`Panel`] carries the packed 1-bit frame and a
//! JSON report (the lattice's shape and bytes, the effects the scene calls for, rays and object
//! tests), [`ScriptError`] the line and column of a scene's mistake.

use board_records::frame::{self as board_frame, Build, Glass, PICO};
use embedded_graphics_core::pixelcolor::{BinaryColor, Gray2};
use lattice_rt::dither::Shade;
use lattice_rt::render::{RenderError, Sampling};
use lattice_rt::scene::Object;
use lattice_rt::scene::{object_count, parse_with};
use lattice_rt::Effects;
use lattice_rt::{
    render, BitFrame, Dither, Frame, Fx, HeapScratch, HeapStorage, LatticeConfig, NoHooks, Real, ShadeFrame, Sizes,
    Tone, Tracer,
};
use std::fmt::Write;
use wasm_bindgen::prelude::*;

/// The most objects a scene in the page may declare (a page should answer as the user types).
pub const MAX_OBJECTS: usize = 20_000;

/// The most bytes a lattice in the page may take.
pub const MAX_LATTICE_BYTES: usize = 64 << 20;

/// The dithers the page offers, by the names its switch uses: the display study's four
/// (docs/display.md) and the paper's patterning.
pub const DITHERS: [(&str, Dither); 7] = [
    ("fs", Dither::FloydSteinberg),
    ("blue-noise", Dither::BlueNoise),
    ("bayer", Dither::Bayer),
    ("atkinson", Dither::Atkinson),
    ("pattern2", Dither::Pattern(2)),
    ("pattern4", Dither::Pattern(4)),
    ("pattern8", Dither::Pattern(8)),
];

/// How the page renders: by default the Pico's still frame (`board_records::frame::rendered`
/// of the Pico's build, fixed point), each setting switchable.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// `fixed` (Q16.16, the Pico's), `f32` or `f64`.
    pub scalar: String,
    /// One of [`DITHERS`]' names.
    pub dither: String,
    /// Silhouette lines.
    pub lines: bool,
    /// Tone curve exponent in tenths (5..=20; 10 leaves levels unchanged).
    pub gamma: u8,
    /// Eye rays by host-sim's names (`render --sampling`): `coarse` (adaptive in two levels,
    /// the Pico's), `adaptive` (in one level) or `one` (one ray per pixel).
    pub sampling: String,
    /// The camera's turn around the scene (0..1), as `host-sim orbit` turns it.
    pub turn: f64,
    /// Shades the panel shows: 2 (1-bit) or 4 (the gray mode, `host-sim render --levels 4`).
    pub shades: u8,
    /// The panel, by the firmware's names (`board_records::frame::Panel::name`): its glass
    /// sets the frame's size.
    pub panel: String,
}

impl Default for Settings {
    fn default() -> Self {
        let f = board_frame::rendered(PICO);
        Settings {
            scalar: "fixed".into(),
            dither: dither_name(f.dither).into(),
            lines: f.outline,
            gamma: f.tone.gamma_tenths,
            sampling: sampling_name(f.sampling).into(),
            turn: 0.0,
            shades: 2,
            panel: board_frame::Panel::default().name().into(),
        }
    }
}

fn dither_name(d: Dither) -> &'static str {
    DITHERS.iter().find(|(_, x)| *x == d).map_or("fs", |(n, _)| n)
}

/// The sampling modes the page offers, by host-sim's names.
const SAMPLINGS: [(&str, Sampling); 3] =
    [("coarse", board_frame::PANEL_SAMPLING), ("adaptive", board_frame::SAMPLING), ("one", Sampling::Center)];

fn sampling_name(s: Sampling) -> &'static str {
    SAMPLINGS.iter().find(|(_, x)| *x == s).map_or("one", |(n, _)| n)
}

impl Settings {
    /// The frame these settings render (the panel's glass, 16x16 tiles, as the Pico's image
    /// for that panel renders it).
    pub fn frame(&self) -> Result<Frame, String> {
        let panel = board_frame::Panel::of(&self.panel).ok_or_else(|| {
            let names: Vec<&str> = board_frame::Panel::ALL.iter().map(|p| p.name()).collect();
            format!("unknown panel `{}` (one of {})", self.panel, names.join(", "))
        })?;
        let glass = panel.glass();
        if self.shades == 4 && !matches!(glass, Glass::Oled128x64 | Glass::Oled72x40) {
            return Err(format!("the gray mode is for the SSD1306 128x64 and 72x40 panels, not {}", self.panel));
        }
        let dither =
            DITHERS.iter().find(|(n, _)| *n == self.dither).map(|(_, d)| *d).ok_or_else(|| {
                format!("unknown dither `{}` (one of {})", self.dither, DITHERS.map(|d| d.0).join(", "))
            })?;
        let sampling = SAMPLINGS.iter().find(|(n, _)| *n == self.sampling).map(|(_, s)| *s).ok_or_else(|| {
            format!("unknown sampling `{}` (one of {})", self.sampling, SAMPLINGS.map(|s| s.0).join(", "))
        })?;
        if !Tone::RANGE.contains(&self.gamma) {
            return Err(format!("gamma {} is outside 5..=20 tenths", self.gamma));
        }
        if !(0.0..=1.0).contains(&self.turn) {
            return Err(format!("turn {} is outside 0..1", self.turn));
        }
        let build = Build { lines: Some(self.lines), glass, ..PICO };
        Ok(Frame { dither, sampling, tone: Tone { gamma_tenths: self.gamma }, ..board_frame::rendered(build) })
    }
}

/// A scene's mistake, where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Mistake {
    /// 1-based line (0: not tied to a line, as a lattice too large).
    pub line: u32,
    /// 1-based column in bytes (0 with line 0).
    pub col: u32,
    /// What is wrong, with the place as host-sim writes it (`line 3, column 15 at `-1`: ...`).
    pub message: String,
}

/// What [`render_panel`] gives: the panel and what the lattice did.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// The frame's width and height in pixels (the panel's glass).
    pub size: (u32, u32),
    /// The 1-bit frame, packed as `BitFrame` packs it (rows of width / 8 bytes rounded up,
    /// most significant bit first, 1 lit): the pixels lit in any subframe.
    pub bits: Vec<u8>,
    /// Each pixel's shade, row-major: its step, 0..=1 (two shades) or 0..=3 (four).
    pub shades: Vec<u8>,
    /// The report as JSON (see [`render_panel`]).
    pub report: String,
}

/// Renders scene `text` onto the 128x64 panel with `settings`. The report's fields: `objects`,
/// `composites`, `lights`, `effects` (the effect set the scene calls for), `lattices` (cells per
/// axis of the world lattice and each sub-lattice), `cells`, `references`, `bytes`, `rays`
/// (eye, shadow, reflection, refraction), `objectTests`, `cellsVisited`, `culled`.
pub fn render_panel(text: &str, settings: &Settings) -> Result<Output, Mistake> {
    let unplaced = |message: String| Mistake { line: 0, col: 0, message };
    let frame = settings.frame().map_err(unplaced)?;
    match (settings.scalar.as_str(), settings.shades) {
        ("fixed", 2) => render_in::<Fx, BinaryColor>(text, settings.turn, &frame),
        ("f32", 2) => render_in::<f32, BinaryColor>(text, settings.turn, &frame),
        ("f64", 2) => render_in::<f64, BinaryColor>(text, settings.turn, &frame),
        ("fixed", 4) => render_in::<Fx, Gray2>(text, settings.turn, &frame),
        ("f32", 4) => render_in::<f32, Gray2>(text, settings.turn, &frame),
        ("f64", 4) => render_in::<f64, Gray2>(text, settings.turn, &frame),
        (_, 2 | 4) => Err(unplaced(format!("unknown scalar `{}` (fixed, f32 or f64)", settings.scalar))),
        (_, n) => Err(unplaced(format!("{n} shades: the panel shows 2 or 4"))),
    }
}

fn render_in<R: Real, C: Shade>(text: &str, turn: f64, frame: &Frame) -> Result<Output, Mistake> {
    let unplaced = |message: String| Mistake { line: 0, col: 0, message };
    let n = object_count(text);
    if n > MAX_OBJECTS {
        return Err(unplaced(format!("the scene declares {n} objects; the playground takes at most {MAX_OBJECTS}")));
    }
    let (mut objects, mut parts) = (vec![Object::<R>::default(); n.max(1)], lattice_rt::Parts::new());
    let scene = parse_with::<R>(text, &mut objects, &mut parts, |c| {
        c.frame = frame.size();
        *c = c.orbit(turn);
    })
    .map_err(|e| Mistake { line: e.line, col: e.col, message: e.to_string() })?;
    let cfg = LatticeConfig::default();
    let sizes = Sizes { objects: 0, rows: 0, ..Sizes::of(&scene, Some(&cfg), &Frame::new(1, 1)) };
    if sizes.bytes::<R>() > MAX_LATTICE_BYTES {
        return Err(unplaced(format!(
            "the lattice would take {} bytes; the playground allows {MAX_LATTICE_BYTES}",
            sizes.bytes::<R>()
        )));
    }
    let mut storage = HeapStorage::<R>::new(sizes);
    let (lattice, _) = storage.view().split().1.lattice(&scene, &cfg).map_err(|e| unplaced(e.to_string()))?;
    let tracer = Tracer::new(&scene, &lattice);
    let (w, h) = (frame.width as u32, frame.height as u32);
    let mut shades = vec![0u8; w as usize * h as usize];
    let mut target = ShadeFrame::<C>::new(w, h, &mut shades).expect("sized above");
    let mut scratch = HeapScratch::new(&scene, frame);
    let stats = render(&tracer, frame, &mut target, &mut scratch.scratch(), &mut NoHooks).map_err(|e| match e {
        RenderError::Draw(never) => match never {},
        other => unplaced(other.to_string()),
    })?;
    let mut report = String::new();
    let lattices: Vec<String> =
        lattice.lattices().iter().map(|g| format!("[{},{},{}]", g.n[0], g.n[1], g.n[2])).collect();
    write!(
        report,
        r#"{{"scalar":"{}","objects":{},"composites":{},"lights":{},"effects":"{}","lattices":[{}],"cells":{},"references":{},"bytes":{},"rays":[{},{},{},{}],"objectTests":{},"cellsVisited":{},"culled":{}}}"#,
        R::NAME,
        scene.objects().len(),
        scene.composites().len(),
        scene.lights().len(),
        Effects::of(&scene),
        lattices.join(","),
        lattice.cell_count(),
        lattice.ref_count(),
        lattice.bytes(),
        stats.rays[0],
        stats.rays[1],
        stats.rays[2],
        stats.rays[3],
        stats.object_tests,
        stats.cells_visited,
        stats.culled,
    )
    .expect("writing to a String");
    let mut bits = vec![0u8; BitFrame::bytes(w, h)];
    target.lit(&mut BitFrame::new(w, h, &mut bits).expect("sized by BitFrame::bytes"));
    Ok(Output { size: (w, h), bits, shades, report })
}

/// The scenes the page starts from: the paper's four and the Whitted showcase, by name.
pub const SCENES: [(&str, &str); 5] = [
    ("chair", include_str!("../../scenes/chair.scene")),
    ("desk", include_str!("../../scenes/desk.scene")),
    ("polyhedron", include_str!("../../scenes/polyhedron.scene")),
    ("spheres", include_str!("../../scenes/spheres.scene")),
    ("whitted", include_str!("../../scenes/whitted.scene")),
];

/// The panel the page draws ([`panel`]'s answer).
#[wasm_bindgen]
pub struct Panel(Output);

#[wasm_bindgen]
impl Panel {
    /// The frame's width in pixels.
    pub fn width(&self) -> u32 {
        self.0.size.0
    }
    /// The frame's height in pixels.
    pub fn height(&self) -> u32 {
        self.0.size.1
    }
    /// The packed 1-bit frame (rows of width / 8 bytes rounded up, most significant bit first,
    /// 1 lit).
    pub fn bits(&self) -> Vec<u8> {
        self.0.bits.clone()
    }
    /// Each pixel's step, row-major (0..=1 with two shades, 0..=3 with four).
    pub fn shades(&self) -> Vec<u8> {
        self.0.shades.clone()
    }
    /// What the lattice did, as JSON.
    pub fn report(&self) -> String {
        self.0.report.clone()
    }
}

/// A scene's mistake as the page shows it.
#[wasm_bindgen]
pub struct ScriptError(Mistake);

#[wasm_bindgen]
impl ScriptError {
    /// 1-based line, 0 when the mistake is not on a line.
    pub fn line(&self) -> u32 {
        self.0.line
    }
    /// 1-based column in bytes.
    pub fn col(&self) -> u32 {
        self.0.col
    }
    /// The message, with its place.
    pub fn message(&self) -> String {
        self.0.message.clone()
    }
}

/// Renders `text` for the page: [`render_panel`] with the settings given one by one (plain
/// values cross the WebAssembly boundary without glue of their own, a struct would not).
#[wasm_bindgen]
#[allow(clippy::too_many_arguments)]
pub fn panel(
    text: &str,
    scalar: &str,
    dither: &str,
    lines: bool,
    gamma: u8,
    sampling: &str,
    turn: f64,
    shades: u8,
    panel_name: &str,
) -> Result<Panel, ScriptError> {
    let settings = Settings {
        scalar: scalar.into(),
        dither: dither.into(),
        lines,
        gamma,
        sampling: sampling.into(),
        turn,
        shades,
        panel: panel_name.into(),
    };
    render_panel(text, &settings).map(Panel).map_err(ScriptError)
}

/// The slot image's UF2 file `image` with scene `text` in its scene slot: what `host-sim uf2
/// --scene` writes (the scene checked as the Pico reads it; an error says where and why).
#[wasm_bindgen]
pub fn slot_uf2(image: &[u8], text: &str) -> Result<Vec<u8>, String> {
    board_records::slot::with::scene(image, text)
}

/// The names of the scenes the page starts from, comma-separated.
#[wasm_bindgen]
pub fn scene_names() -> String {
    SCENES.map(|s| s.0).join(",")
}

/// The text of scene `name` (empty when there is none).
#[wasm_bindgen]
pub fn scene_text(name: &str) -> String {
    SCENES.iter().find(|s| s.0 == name).map_or(String::new(), |s| s.1.to_string())
}

/// The page's default settings as JSON (the Pico's still frame).
#[wasm_bindgen]
pub fn default_settings() -> String {
    let s = Settings::default();
    format!(
        r#"{{"scalar":"{}","dither":"{}","lines":{},"gamma":{},"sampling":"{}","turn":0,"shades":{},"panel":"{}","dithers":"{}"}}"#,
        s.scalar,
        s.dither,
        s.lines,
        s.gamma,
        s.sampling,
        s.shades,
        s.panel,
        DITHERS.map(|d| d.0).join(",")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn the_default_panel_is_the_pico_frame_host_sim_renders() {
        for (name, text) in SCENES {
            let out = render_panel(text, &Settings::default()).expect("a paper scene renders");
            let want =
                host_sim::run::render_text::<Fx>(Path::new(name), text, &board_frame::rendered(PICO), |_| {}).unwrap();
            assert_eq!(out.bits, want.bits, "{name}");
            assert!(
                out.report.contains(r#""objectTests":"#) && out.report.starts_with('{') && out.report.ends_with('}')
            );
        }
    }

    #[test]
    fn four_shades_are_host_sims_gray_frame() {
        let s = Settings { shades: 4, ..Settings::default() };
        for (name, text) in SCENES {
            let out = render_panel(text, &s).unwrap();
            let frame = s.frame().unwrap();
            let want = host_sim::run::render_text_in::<Fx, Gray2>(Path::new(name), text, &frame, |_| {}).unwrap();
            assert_eq!(out.shades, want.shades, "{name}");
            assert!(out.shades.iter().any(|&k| k == 1 || k == 2), "{name}: no gray in four shades");
        }
        let e = render_panel(SCENES[0].1, &Settings { shades: 3, ..Settings::default() }).unwrap_err();
        assert!(e.message.contains("2 or 4"), "{}", e.message);
    }

    #[test]
    fn every_switch_changes_what_it_should() {
        let chair = SCENES[0].1;
        let base = render_panel(chair, &Settings::default()).unwrap();
        for s in [
            Settings { dither: "blue-noise".into(), ..Settings::default() },
            Settings { lines: false, ..Settings::default() },
            Settings { gamma: 15, ..Settings::default() },
            Settings { turn: 0.25, ..Settings::default() },
            Settings { scalar: "f64".into(), sampling: "one".into(), ..Settings::default() },
        ] {
            let out = render_panel(chair, &s).unwrap();
            assert_ne!(out.bits, base.bits, "{s:?}");
        }
        let orbit = Settings { turn: 0.25, dither: "blue-noise".into(), ..Settings::default() };
        let want = host_sim::orbit::orbit_frames::<Fx>(
            Path::new("chair"),
            chair,
            4,
            &board_frame::rendered(Build { orbit: true, ..PICO }),
        )
        .unwrap();
        assert_eq!(
            render_panel(chair, &orbit).unwrap().bits,
            want[1],
            "a quarter turn is host-sim orbit's frame 1 of 4"
        );
    }

    #[test]
    fn each_panel_is_its_images_frame_host_sim_renders() {
        for p in board_frame::Panel::ALL {
            let s = Settings { panel: p.name().into(), ..Settings::default() };
            let (name, text) = SCENES[0];
            let out = render_panel(text, &s).unwrap();
            let want = host_sim::run::render_text::<Fx>(
                Path::new(name),
                text,
                &board_frame::rendered(Build { glass: p.glass(), ..PICO }),
                |_| {},
            )
            .unwrap();
            let (w, h) = p.glass().size();
            assert_eq!(out.size, (u32::from(w), u32::from(h)), "{}", p.name());
            assert_eq!(out.bits, want.bits, "{}", p.name());
        }
        let e = render_panel(SCENES[0].1, &Settings { panel: "crt".into(), ..Settings::default() }).unwrap_err();
        assert!(e.message.contains("unknown panel `crt`") && e.message.contains("uc8151"), "{}", e.message);
        let gray = Settings { panel: "sharp-400x240".into(), shades: 4, ..Settings::default() };
        assert!(render_panel(SCENES[0].1, &gray).unwrap_err().message.contains("gray mode"));
    }

    #[test]
    fn mistakes_say_where() {
        let bad = "camera eye 0 0 -4\nlight directional dir -1 -1 1\nsphere radius -1\n";
        let e = render_panel(bad, &Settings::default()).unwrap_err();
        assert_eq!((e.line, e.col), (3, 15));
        assert!(e.message.contains("line 3, column 15"), "{}", e.message);
        let e = render_panel(SCENES[0].1, &Settings { dither: "sepia".into(), ..Settings::default() }).unwrap_err();
        assert!(e.line == 0 && e.message.contains("unknown dither `sepia`"), "{}", e.message);
    }
}
