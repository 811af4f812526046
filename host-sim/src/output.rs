//! Writing images: PNG through `embedded-graphics-simulator` (with OLED/LCD themes), binary
//! PBM for 1-bit frames and PGM for gray levels.

use anyhow::{Context, Result};
use embedded_graphics::geometry::Size;
use embedded_graphics::prelude::*;
use embedded_graphics_simulator::{OutputSettingsBuilder, SimulatorDisplay};
use lattice_rt::BitFrame;
use std::path::Path;

/// The largest PNG host-sim writes (2^26 pixels, 192 MiB of RGB before compression).
pub const MAX_PNG_PIXELS: u64 = 1 << 26;

/// Refuses a PNG of more than [`MAX_PNG_PIXELS`] (check it before rendering the frame).
pub fn check_png_size(width: u32, height: u32, scale: u32) -> Result<()> {
    let pixels = width as u64 * height as u64 * scale as u64 * scale as u64;
    if pixels > MAX_PNG_PIXELS {
        anyhow::bail!(
            "a {width}x{height} frame at --scale {scale} would be a PNG of {pixels} pixels, more than the limit of {MAX_PNG_PIXELS}: lower --scale or --size"
        );
    }
    Ok(())
}

/// Display themes offered on the command line. Every theme shows the picture as it is: what
/// the tracer lit is the bright colour, so no theme draws a negative.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Theme {
    /// Black ink on white paper, like the paper's print-outs: lit pixels are the white paper,
    /// the rest black ink (and the grid, if asked for, is paper too).
    Paper,
    /// A white OLED: lit pixels white, the rest the dark of a panel that is off.
    OledWhite,
    /// A blue OLED: lit pixels light blue, the rest dark blue.
    OledBlue,
    /// A reflective white LCD (a Sharp memory display): lit pixels the light of the glass, the
    /// rest dark gray segments.
    LcdWhite,
}

impl Theme {
    /// The colours of a lit pixel, an unlit pixel and the grid between pixels.
    pub fn colours(self) -> [[u8; 3]; 3] {
        match self {
            Theme::Paper => [[255; 3], [0; 3], [255; 3]],
            Theme::OledWhite => [[255; 3], [20; 3], [0; 3]],
            Theme::OledBlue => [[0, 210, 255], [0, 20, 40], [0, 10, 20]],
            Theme::LcdWhite => [[245; 3], [32; 3], [245; 3]],
        }
    }
}

fn create_parent(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot write {}: cannot create its folder {}", path.display(), dir.display()))?;
    }
    Ok(())
}

/// How a 1-bit frame becomes a PNG: its theme, pixel scale and whether a one-pixel grid
/// separates the pixels (as on a panel seen close up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PngLook {
    /// Colours.
    pub theme: Theme,
    /// Each frame pixel as `scale x scale` PNG pixels.
    pub scale: u32,
    /// A one-pixel line of the theme's grid colour between neighbouring pixels.
    pub grid: bool,
}

impl PngLook {
    /// The PNG's width and height for a `w x h` frame: the frame's own size at scale 1
    /// without a grid.
    pub fn size(&self, w: u32, h: u32) -> (u32, u32) {
        let gap = u32::from(self.grid);
        let side = |n: u32| n * self.scale.max(1) + n.saturating_sub(1) * gap;
        (side(w), side(h))
    }
}

/// The RGB bytes (row-major) of a 1-bit frame drawn with `look`, and their width and height.
pub fn rgb_pixels(frame: &BitFrame<'_>, look: PngLook) -> (u32, u32, Vec<u8>) {
    let size = frame.size();
    rgb_shaded(size.width, size.height, look, |x, y| if frame.get(x, y) { 1.0 } else { 0.0 })
}

/// The RGB bytes of a `w x h` frame whose pixel `(x, y)` is lit for the share `lit(x, y)`
/// (0: unlit, 1: lit; between them, a gray shade of the theme), drawn with `look`.
fn rgb_shaded(w: u32, h: u32, look: PngLook, lit: impl Fn(u32, u32) -> f64) -> (u32, u32, Vec<u8>) {
    let (pw, ph) = look.size(w, h);
    let [on, off, grid] = look.theme.colours();
    let mix = |s: f64| -> [u8; 3] {
        core::array::from_fn(|c| (f64::from(off[c]) + (f64::from(on[c]) - f64::from(off[c])) * s).round() as u8)
    };
    let (scale, pitch) = (look.scale.max(1), look.scale.max(1) + u32::from(look.grid));
    let mut out = Vec::with_capacity(pw as usize * ph as usize * 3);
    for y in 0..ph {
        for x in 0..pw {
            let colour = if x % pitch >= scale || y % pitch >= scale { grid } else { mix(lit(x / pitch, y / pitch)) };
            out.extend_from_slice(&colour);
        }
    }
    (pw, ph, out)
}

/// The bytes of a PNG of a frame of shades: `steps` (row-major, `w x h`) each `0..=top`, a
/// pixel of step `k` lit for `k / top` of the time (the gray mode's subframes), drawn with
/// `look` in the theme's colours and the shades between them.
pub fn shades_png_bytes(w: u32, h: u32, steps: &[u8], top: u8, look: PngLook) -> Result<Vec<u8>> {
    check_png_size(w, h, look.scale)?;
    let share = |x: u32, y: u32| f64::from(steps[(y * w + x) as usize]) / f64::from(top.max(1));
    let (pw, ph, rgb) = rgb_shaded(w, h, look, share);
    encode_rgb(pw, ph, &rgb)
}

/// Writes a 1-bit frame as PNG with a display theme and pixel scale (no grid).
pub fn write_png(frame: &BitFrame<'_>, path: &Path, theme: Theme, scale: u32) -> Result<()> {
    write_png_look(frame, path, PngLook { theme, scale, grid: false })
}

/// Writes a 1-bit frame as PNG drawn with `look`.
pub fn write_png_look(frame: &BitFrame<'_>, path: &Path, look: PngLook) -> Result<()> {
    write_atomic(path, &png_bytes(frame, look)?)
}

/// The bytes of a PNG of a 1-bit frame drawn with `look`.
pub fn png_bytes(frame: &BitFrame<'_>, look: PngLook) -> Result<Vec<u8>> {
    let size = frame.size();
    check_png_size(size.width, size.height, look.scale)?;
    let (w, h, rgb) = rgb_pixels(frame, look);
    encode_rgb(w, h, &rgb)
}

/// RGB bytes as a PNG file's bytes.
fn encode_rgb(w: u32, h: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().context("PNG header")?;
    writer.write_image_data(rgb).context("PNG data")?;
    writer.finish().context("PNG end")?;
    Ok(bytes)
}

/// Writes a 1-bit frame as binary PBM (`P4`; 1 = black, so lit pixels are written as 0).
pub fn write_pbm(frame: &BitFrame<'_>, path: &Path) -> Result<()> {
    write_atomic(path, &pbm_bytes(frame))
}

/// The bytes of a binary PBM of the frame, with lit pixels white.
pub fn pbm_bytes(frame: &BitFrame<'_>) -> Vec<u8> {
    let mut out = Vec::new();
    frame.write_pbm(|b| out.extend_from_slice(b));
    out
}

/// Writes gray levels 0..=64 as a PGM with maxval 64.
pub fn write_pgm(width: u32, height: u32, levels: &[u8], path: &Path) -> Result<()> {
    let mut out = format!("P5\n{width} {height}\n64\n").into_bytes();
    out.extend_from_slice(levels);
    write_atomic(path, &out)
}

/// Writes gray levels 0..=64 as a gray PNG (through the simulator's Gray8 display).
pub fn write_gray_png(width: u32, height: u32, levels: &[u8], path: &Path, scale: u32) -> Result<()> {
    use embedded_graphics::pixelcolor::Gray8;
    let mut display = SimulatorDisplay::<Gray8>::new(Size::new(width, height));
    for (i, &l) in levels.iter().enumerate() {
        let v = (l as u32 * 255 / 64) as u8;
        Pixel(Point::new((i as u32 % width) as i32, (i as u32 / width) as i32), Gray8::new(v)).draw(&mut display)?;
    }
    create_parent(path)?;
    let settings = OutputSettingsBuilder::new().scale(scale.max(1)).build();
    display
        .to_grayscale_output_image(&settings)
        .save_png(path)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes `bytes` to `path` through a temporary file in the same folder, renamed into place
/// once complete, so a failed write never leaves a partial file behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut staged = Staged::default();
    let tmp = staged.stage(path)?;
    std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", path.display()))?;
    staged.commit()
}

/// A command's output files, written under temporary names in their own folders and renamed
/// into place only when every one of them was written: a command that fails leaves none of
/// its outputs behind (the temporary files are removed when this is dropped uncommitted).
#[derive(Default)]
pub struct Staged {
    files: Vec<(std::path::PathBuf, std::path::PathBuf)>,
}

impl Staged {
    /// The temporary path to write `path`'s contents to (its folder is created).
    pub fn stage(&mut self, path: &Path) -> Result<std::path::PathBuf> {
        create_parent(path)?;
        let name = path.file_name().with_context(|| format!("{} names no file", path.display()))?;
        let tmp = path.with_file_name(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
        self.files.push((tmp.clone(), path.to_path_buf()));
        Ok(tmp)
    }
    /// Renames every staged file into place.
    pub fn commit(mut self) -> Result<()> {
        for (tmp, path) in std::mem::take(&mut self.files) {
            std::fs::rename(&tmp, &path).with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in &self.files {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_outputs_appear_together_or_not_at_all() {
        let dir = std::env::temp_dir().join(format!("host-sim-staged-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (a, b) = (dir.join("a.png"), dir.join("b.pgm"));
        // A failed command: the first output was written, the second never was.
        {
            let mut staged = Staged::default();
            std::fs::write(staged.stage(&a).unwrap(), b"first").unwrap();
            let _second = staged.stage(&b).unwrap();
        }
        assert!(!a.exists() && !b.exists(), "nothing of a failed command is left");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "no temporary file is left either");
        // A successful one: both appear.
        let mut staged = Staged::default();
        std::fs::write(staged.stage(&a).unwrap(), b"first").unwrap();
        std::fs::write(staged.stage(&b).unwrap(), b"second").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"first");
        assert_eq!(std::fs::read(&b).unwrap(), b"second");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_write_to_an_impossible_place_names_the_path() {
        let err = write_atomic(Path::new("/proc/no-such-dir/x.pov"), b"x").unwrap_err();
        assert!(format!("{err:#}").contains("/proc/no-such-dir"), "{err:#}");
    }
}

#[cfg(test)]
mod png_tests {
    use super::*;
    use embedded_graphics::pixelcolor::BinaryColor;

    /// A 4x2 frame with its left half lit.
    fn half_lit(bits: &mut [u8]) -> BitFrame<'_> {
        let mut f = BitFrame::new(4, 2, bits).unwrap();
        for y in 0..2 {
            for x in 0..2 {
                Pixel(Point::new(x, y), BinaryColor::On).draw(&mut f).unwrap();
            }
        }
        f
    }

    #[test]
    fn at_scale_one_a_png_has_the_frames_size_and_the_grid_is_an_option() {
        let mut bits = vec![0u8; BitFrame::bytes(4, 2)];
        let f = half_lit(&mut bits);
        for theme in [Theme::Paper, Theme::OledWhite, Theme::OledBlue, Theme::LcdWhite] {
            assert_eq!(rgb_pixels(&f, PngLook { theme, scale: 1, grid: false }).0, 4);
            let (w, h, _) = rgb_pixels(&f, PngLook { theme, scale: 3, grid: false });
            assert_eq!((w, h), (12, 6));
            let (w, h, _) = rgb_pixels(&f, PngLook { theme, scale: 3, grid: true });
            assert_eq!((w, h), (4 * 3 + 3, 2 * 3 + 1));
        }
        let png = png_bytes(&f, PngLook { theme: Theme::Paper, scale: 1, grid: false }).unwrap();
        let reader = png::Decoder::new(std::io::Cursor::new(png)).read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), (4, 2));
    }

    #[test]
    fn no_theme_draws_a_negative() {
        // What the tracer lit is brighter than what it left dark, in every theme; paper is
        // black ink on white (its lit pixels and its grid are white), an LCD's glass is light.
        let mut bits = vec![0u8; BitFrame::bytes(4, 2)];
        let f = half_lit(&mut bits);
        let luma = |c: &[u8]| c.iter().map(|&v| u32::from(v)).sum::<u32>();
        for theme in [Theme::Paper, Theme::OledWhite, Theme::OledBlue, Theme::LcdWhite] {
            let (_, _, rgb) = rgb_pixels(&f, PngLook { theme, scale: 1, grid: false });
            assert!(luma(&rgb[0..3]) > luma(&rgb[9..12]), "{theme:?}: the lit pixel is darker than the unlit one");
        }
        assert_eq!(Theme::Paper.colours(), [[255; 3], [0; 3], [255; 3]]);
        assert!(luma(&Theme::LcdWhite.colours()[0]) > 600);
    }
}
