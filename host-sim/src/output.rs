//! Writing images: PNG through `embedded-graphics-simulator` (with OLED/LCD themes), binary
//! PBM for 1-bit frames and PGM for gray levels.

use anyhow::{Context, Result};
use embedded_graphics::geometry::Size;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::*;
use embedded_graphics_simulator::{BinaryColorTheme, OutputSettingsBuilder, SimulatorDisplay};
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

/// Display themes offered on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Theme {
    /// Black on white, like the paper's print-out.
    Paper,
    /// White OLED pixels on black.
    OledWhite,
    /// Blue OLED pixels on black.
    OledBlue,
    /// White LCD.
    LcdWhite,
}

impl Theme {
    fn sim(self) -> BinaryColorTheme {
        match self {
            Theme::Paper => BinaryColorTheme::Default,
            Theme::OledWhite => BinaryColorTheme::OledWhite,
            Theme::OledBlue => BinaryColorTheme::OledBlue,
            Theme::LcdWhite => BinaryColorTheme::LcdWhite,
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

/// Writes a 1-bit frame as PNG with a display theme and pixel scale.
pub fn write_png(frame: &BitFrame<'_>, path: &Path, theme: Theme, scale: u32) -> Result<()> {
    let size = frame.size();
    check_png_size(size.width, size.height, scale)?;
    let mut display = SimulatorDisplay::<BinaryColor>::new(Size::new(size.width, size.height));
    for y in 0..size.height {
        for x in 0..size.width {
            // Pixels on are lit (white on an OLED); the paper theme inverts to black ink.
            let c = BinaryColor::from(frame.get(x, y));
            Pixel(Point::new(x as i32, y as i32), c).draw(&mut display)?;
        }
    }
    let settings = OutputSettingsBuilder::new().theme(theme.sim()).scale(scale.max(1)).build();
    create_parent(path)?;
    let mut staged = Staged::default();
    let tmp = staged.stage(path)?;
    display.to_rgb_output_image(&settings).save_png(&tmp).with_context(|| format!("cannot write {}", path.display()))?;
    staged.commit()
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
