//! A message on the panel: what the board shows when it has no picture to show (its scene slot
//! is empty or corrupt, a scene is refused), instead of a frozen frame. Drawn by the firmware and
//! by the host with the same code, so `cargo xtask board` checks the panel bit for bit.

use embedded_graphics::mono_font::{ascii::FONT_6X10, MonoTextStyle};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};

/// Characters per line (6-pixel glyphs).
const COLUMNS: usize = 21;
/// Pixels per line.
const LINE: i32 = 10;

/// Draws `text` word-wrapped in 6x10 glyphs, lit on black, over a `width x height` target
/// (every pixel of it is drawn: the message replaces the picture). Lines that do not fit are
/// left out.
pub fn draw<D: DrawTarget<Color = BinaryColor>>(
    target: &mut D,
    width: u32,
    height: u32,
    text: &str,
) -> Result<(), D::Error> {
    target.fill_solid(
        &embedded_graphics::primitives::Rectangle::new(Point::zero(), Size::new(width, height)),
        BinaryColor::Off,
    )?;
    let style = MonoTextStyle::new(&FONT_6X10, BinaryColor::On);
    let columns = (width as usize / 6).clamp(1, COLUMNS);
    let mut y = 0;
    for line in lines(text, columns) {
        if y + LINE > height as i32 {
            break;
        }
        Text::with_baseline(line, Point::new(0, y), style, Baseline::Top).draw(target)?;
        y += LINE;
    }
    Ok(())
}

/// The lines `text` wraps into at `columns` characters: broken at spaces (and at a newline),
/// a word longer than a line broken where the line ends.
pub fn lines(text: &str, columns: usize) -> impl Iterator<Item = &str> {
    let mut rest = text.trim_start_matches(' ');
    core::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        // The longest prefix of at most `columns` characters, up to a newline.
        let hard = rest.find('\n').unwrap_or(rest.len());
        let limit = rest.char_indices().nth(columns).map_or(rest.len(), |(i, _)| i).min(hard);
        let end = if limit == hard || limit == rest.len() {
            limit
        } else {
            // Break at the last space within the limit, if any (the space itself dropped).
            match rest[..=limit].rfind(' ') {
                Some(space) if space > 0 => space,
                _ => limit,
            }
        };
        let line = &rest[..end];
        rest = rest[end..].trim_start_matches([' ', '\n']);
        Some(line)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    #[test]
    fn messages_wrap_at_spaces_and_break_long_words() {
        let l: Vec<&str> = lines("no scene in the slot: write one with host-sim uf2 --scene FILE", 21).collect();
        assert_eq!(l, ["no scene in the slot:", "write one with", "host-sim uf2 --scene", "FILE"]);
        let l: Vec<&str> = lines("abcdefghijklmnopqrstuvwxyz", 10).collect();
        assert_eq!(l, ["abcdefghij", "klmnopqrst", "uvwxyz"]);
        let l: Vec<&str> = lines("a\nb c", 10).collect();
        assert_eq!(l, ["a", "b c"]);
    }
}
