//! The plain-text scene format, parsed without allocation (firmware can `include_str!` the same
//! files the desktop reads). The format is documented in `docs/scene-format.md`.
//!
//! One statement per line, `#` starts a comment. Every error names the line and column (1-based,
//! columns count bytes), the offending token and the reason. Parsing feeds a [`SceneBuilder`],
//! which validates each object as it arrives, so range errors also point at their line.

use super::effects::MAX_DEPTH;
use super::{
    check_value, CameraDesc, FieldOfView, Light, Material, Object, Parts, Scene, SceneBuilder, SceneError, IOR,
    MAX_MATERIALS,
};
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::shape::Shape;
use core::fmt;
use heapless::Vec;

/// What is wrong at a position of the scene text.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParseErrorKind {
    /// The first word of a line is not a statement.
    UnknownStatement,
    /// A word that is not an attribute of this statement.
    UnknownAttribute {
        /// The attributes the statement takes.
        valid: &'static [&'static str],
        /// The valid attribute nearest the word, when one is near (one or two letters off).
        near: Option<&'static str>,
    },
    /// An attribute given twice in one statement (`sphere radius 1 radius 2`); transforms
    /// compose and may repeat.
    RepeatedAttribute,
    /// A number was expected.
    ExpectedNumber,
    /// The line ended where a value was expected.
    MissingValue,
    /// A material name that was not defined earlier.
    UnknownMaterial,
    /// A material name defined twice.
    DuplicateMaterial,
    /// An axis other than x, y or z.
    UnknownAxis,
    /// A light kind other than `directional` or `point`.
    UnknownLightKind,
    /// `depth` must be a whole number from 0 to the tracer's maximum.
    BadDepth,
    /// A number beyond `f64` (`1e999`, `0e999`).
    NumberOutOfRange,
    /// A shear of an axis by itself (`shear x x K`).
    SameAxisShear,
    /// The text is not UTF-8: the byte at this position starts no character.
    InvalidUtf8 {
        /// The offending byte.
        byte: u8,
    },
    /// NFF: the word starts no NFF entity.
    UnknownEntity,
    /// NFF: a view (`v`) without one of its lines (`from`, `at`, `up`, `angle`).
    ExpectedWord(&'static str),
    /// NFF: a negative radius, NFF's surface visible from inside only, which the tracer does not
    /// draw.
    InsideOnly,
    /// NFF: a polygon's vertex count is not a whole number of at least 3.
    BadVertexCount,
    /// NFF: a cone or cylinder whose base and apex are the same point.
    CoincidentEnds,
    /// NFF text given to a build without the `nff` feature (the firmware's).
    NffLeftOut,
    /// NFF: a `resolution` that is not at least one pixel each way.
    BadResolution,
    /// NFF: a colour with a negative component (of a surface, a light or the background).
    NegativeColour,
    /// NFF: a polygon whose edges cross (a bow tie): it has no inside to draw.
    SelfIntersecting,
    /// NFF: a polygon of more vertices than this build reads.
    PolygonTooLarge {
        /// The most it reads (`scene::polygon::MAX_VERTICES`).
        most: usize,
    },
    /// The scene itself is invalid.
    Scene(SceneError),
}

/// A scene-text error: where, what token, why.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParseError<'t> {
    /// 1-based line.
    pub line: u32,
    /// 1-based column (in bytes).
    pub col: u32,
    /// The token at fault (empty at the end of a line or file).
    pub token: &'t str,
    /// The reason.
    pub kind: ParseErrorKind,
}

impl fmt::Display for ParseErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParseErrorKind::UnknownStatement => write!(
                f,
                "unknown statement (expected camera, ambient, background, depth, light, material, \
                 sphere, cylinder, cone, box, triangle, group or end)"
            ),
            ParseErrorKind::UnknownAttribute { valid, near } => {
                write!(f, "not an attribute of this statement")?;
                if let Some(n) = near {
                    write!(f, " (did you mean `{n}`?)")?;
                }
                match valid {
                    [] => write!(f, "; it takes nothing after its value"),
                    _ => {
                        write!(f, "; it takes ")?;
                        for (i, v) in valid.iter().enumerate() {
                            let sep = if i == 0 {
                                ""
                            } else if i + 1 == valid.len() {
                                " or "
                            } else {
                                ", "
                            };
                            write!(f, "{sep}{v}")?;
                        }
                        Ok(())
                    }
                }
            }
            ParseErrorKind::RepeatedAttribute => write!(f, "attribute given twice in this statement"),
            ParseErrorKind::ExpectedNumber => write!(f, "expected a number"),
            ParseErrorKind::MissingValue => write!(f, "a value is missing at the end of the line"),
            ParseErrorKind::UnknownMaterial => write!(f, "material not defined before this line"),
            ParseErrorKind::DuplicateMaterial => write!(f, "material already defined"),
            ParseErrorKind::UnknownAxis => write!(f, "axis must be x, y or z"),
            ParseErrorKind::UnknownLightKind => write!(f, "light must be `directional` or `point`"),
            ParseErrorKind::BadDepth => write!(f, "depth must be a whole number from 0 to {MAX_DEPTH}"),
            ParseErrorKind::NumberOutOfRange => {
                write!(f, "number out of range: beyond the largest f64 (about 1.8e308)")
            }
            ParseErrorKind::SameAxisShear => {
                write!(f, "a shear needs two different axes (`shear x y K`: x gains K times y)")
            }
            ParseErrorKind::InvalidUtf8 { byte } => write!(f, "not UTF-8 text (byte 0x{byte:02x})"),
            ParseErrorKind::UnknownEntity => {
                write!(f, "unknown NFF entity (expected v, b, l, f, c, s, p, pp or a # comment)")
            }
            ParseErrorKind::ExpectedWord(w) => write!(f, "the view needs its `{w}` line"),
            ParseErrorKind::InsideOnly => write!(
                f,
                "a negative radius (NFF's inside-only surface): not drawn by this tracer; give the radius as positive"
            ),
            ParseErrorKind::BadVertexCount => write!(f, "a polygon's vertex count must be a whole number, at least 3"),
            ParseErrorKind::CoincidentEnds => write!(f, "the cone's base and apex are the same point"),
            ParseErrorKind::NffLeftOut => {
                write!(f, "NFF, which this build does not read (its lattice-rt lacks the feature `nff`)")
            }
            ParseErrorKind::BadResolution => write!(f, "a resolution must be at least 1 pixel each way"),
            ParseErrorKind::NegativeColour => write!(f, "a colour's components must be >= 0"),
            ParseErrorKind::SelfIntersecting => {
                write!(f, "the polygon's edges cross each other (NFF's polygons are simple: no inside to draw)")
            }
            ParseErrorKind::PolygonTooLarge { most } => {
                write!(f, "a polygon of more vertices than this build reads (at most {most})")
            }
            ParseErrorKind::Scene(e) => write!(f, "{e}"),
        }
    }
}

impl fmt::Display for ParseError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}, column {}", self.line, self.col)?;
        if !self.token.is_empty() {
            write!(f, " at `{}`", Shown(self.token))?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// Longest part of a token an error message repeats (in characters).
pub const SHOWN_TOKEN: usize = 40;

/// A token as an error message shows it: control and bidirectional-formatting characters
/// escaped (so a scene cannot send escape sequences to the terminal), and cut after
/// [`SHOWN_TOKEN`] characters with the length it had.
struct Shown<'t>(&'t str);

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for c in self.0.chars().take(SHOWN_TOKEN) {
            let bidi = matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
            if c.is_control() || bidi {
                write!(f, "{}", c.escape_unicode())?;
            } else {
                write!(f, "{c}")?;
            }
        }
        if self.0.chars().nth(SHOWN_TOKEN).is_some() {
            write!(f, "... ({} bytes)", self.0.len())?;
        }
        Ok(())
    }
}

/// The scene text in `bytes`, or an error at the line and column of the first byte that is
/// not UTF-8 (for scenes read from files or received at run time).
pub fn text_from_bytes(bytes: &[u8]) -> Result<&str, ParseError<'static>> {
    match core::str::from_utf8(bytes) {
        Ok(t) => Ok(t),
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            // Lines end as in `Lines`: `\n`, `\r\n` or a lone `\r`.
            let (mut line, mut start, mut i) = (1u32, 0usize, 0usize);
            while i < good.len() {
                if good[i] == b'\r' && good.get(i + 1) == Some(&b'\n') {
                    i += 1;
                }
                if good[i] == b'\n' || good[i] == b'\r' {
                    line += 1;
                    start = i + 1;
                }
                i += 1;
            }
            let col = (good.len() - start) as u32 + 1;
            Err(ParseError { line, col, token: "", kind: ParseErrorKind::InvalidUtf8 { byte: bytes[e.valid_up_to()] } })
        }
    }
}

/// The lines of a scene text: ended by `\n`, `\r\n` or a lone `\r` (old Mac files), so that
/// every convention gives the same lines and line numbers. A leading byte-order mark is skipped
/// by [`parse`] before this.
struct Lines<'t> {
    rest: &'t str,
}

impl<'t> Iterator for Lines<'t> {
    type Item = &'t str;
    fn next(&mut self) -> Option<&'t str> {
        if self.rest.is_empty() {
            return None;
        }
        let (line, used) = match self.rest.find(['\n', '\r']) {
            Some(i) if self.rest[i..].starts_with("\r\n") => (&self.rest[..i], i + 2),
            Some(i) => (&self.rest[..i], i + 1),
            None => (self.rest, self.rest.len()),
        };
        self.rest = &self.rest[used..];
        Some(line)
    }
}

/// The lines of `text` (see [`Lines`]), without a leading byte-order mark.
fn lines(text: &str) -> Lines<'_> {
    Lines { rest: text.strip_prefix('\u{feff}').unwrap_or(text) }
}

/// Parses a decimal number (`[+-]digits[.digits][(e|E)[+-]digits]`) without core's `f64`
/// parser, whose 1.7 KB stack frame is more than the whole render needs on a Cortex-M0+.
/// Up to 19 significant digits are kept; for the numbers scenes use (at most 15 digits,
/// exponents within +-22) the result is the correctly rounded `f64`. Returns `None` for
/// anything else; `Some(inf)` or `Some(NaN)` for the words `inf`, `infinity` and `nan`.
pub fn parse_number(tok: &str) -> Option<f64> {
    let b = tok.as_bytes();
    let (neg, mut i) = match b.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let word = &tok[i..];
    if word.eq_ignore_ascii_case("inf") || word.eq_ignore_ascii_case("infinity") {
        return Some(if neg { f64::NEG_INFINITY } else { f64::INFINITY });
    }
    if word.eq_ignore_ascii_case("nan") {
        return Some(f64::NAN);
    }
    let (mut mant, mut exp10, mut digits, mut kept) = (0u64, 0i32, 0u32, 0u32);
    let mut seen_point = false;
    while i < b.len() {
        match b[i] {
            c @ b'0'..=b'9' => {
                digits += 1;
                if kept < 19 {
                    if mant != 0 || c != b'0' {
                        kept += 1;
                    }
                    mant = mant * 10 + (c - b'0') as u64;
                    if seen_point {
                        exp10 -= 1;
                    }
                } else if !seen_point {
                    exp10 += 1;
                }
            }
            b'.' if !seen_point => seen_point = true,
            _ => break,
        }
        i += 1;
    }
    if digits == 0 {
        return None;
    }
    if i < b.len() {
        exp10 += exponent(&b[i..])?;
    }
    // Zero is zero whatever the exponent (`0e999` would otherwise be 0 * inf).
    if mant == 0 {
        return Some(if neg { -0.0 } else { 0.0 });
    }
    // 10^|exp10| by squaring (exact up to 10^22), then one multiplication or division.
    let (mut p, mut base, mut k) = (1.0f64, 10.0f64, exp10.unsigned_abs());
    while k > 0 {
        if k & 1 == 1 {
            p *= base;
        }
        base *= base;
        k >>= 1;
    }
    let v = if exp10 < 0 { mant as f64 / p } else { mant as f64 * p };
    Some(if neg { -v } else { v })
}

/// The exponent part of a number, `e` or `E`, an optional sign and at least one digit (held to
/// 10,000 in size, far past any `f64`), or `None` if `b` is anything else.
fn exponent(b: &[u8]) -> Option<i32> {
    let (neg, digits) = match b {
        [b'e' | b'E', b'-', rest @ ..] => (true, rest),
        [b'e' | b'E', b'+', rest @ ..] => (false, rest),
        [b'e' | b'E', rest @ ..] => (false, rest),
        _ => return None,
    };
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let e = digits.iter().fold(0i32, |e, d| (e * 10 + (d - b'0') as i32).min(10_000));
    Some(if neg { -e } else { e })
}

/// The words of one line with their columns.
struct Words<'t> {
    line: &'t str,
    pos: usize,
    lineno: u32,
    /// The largest coordinate magnitude of the scalar the scene is parsed for, and its name.
    limit: f64,
    scalar: &'static str,
}

impl<'t> Words<'t> {
    fn new(line: &'t str, lineno: u32) -> Self {
        let line = match line.find('#') {
            Some(i) => &line[..i],
            None => line,
        };
        Words { line, pos: 0, lineno, limit: f64::MAX, scalar: "f64" }
    }

    /// Words whose coordinates are checked against the range of `R`.
    fn for_scalar<R: Real>(line: &'t str, lineno: u32) -> Self {
        Words { limit: R::LIMIT, scalar: R::NAME, ..Self::new(line, lineno) }
    }

    fn next(&mut self) -> Option<(u32, &'t str)> {
        let rest = &self.line[self.pos..];
        let start = self.pos + (rest.len() - rest.trim_start().len());
        if start >= self.line.len() {
            self.pos = self.line.len();
            return None;
        }
        let len = self.line[start..].find(|c: char| c.is_whitespace()).unwrap_or(self.line.len() - start);
        self.pos = start + len;
        Some((start as u32 + 1, &self.line[start..start + len]))
    }

    fn err(&self, col: u32, token: &'t str, kind: ParseErrorKind) -> ParseError<'t> {
        ParseError { line: self.lineno, col, token, kind }
    }

    fn end_err(&self) -> ParseError<'t> {
        self.err(self.line.trim_end().len() as u32 + 1, "", ParseErrorKind::MissingValue)
    }

    fn word(&mut self) -> Result<(u32, &'t str), ParseError<'t>> {
        self.next().ok_or_else(|| self.end_err())
    }

    /// A finite number, with its column and token.
    fn number_at(&mut self) -> Result<(f64, u32, &'t str), ParseError<'t>> {
        let (col, tok) = self.word()?;
        let v = parse_number(tok).ok_or_else(|| self.err(col, tok, ParseErrorKind::ExpectedNumber))?;
        if !v.is_finite() {
            let digits = tok.trim_start_matches(['+', '-']).starts_with(|c: char| c.is_ascii_digit() || c == '.');
            let kind =
                if digits { ParseErrorKind::NumberOutOfRange } else { ParseErrorKind::Scene(SceneError::NotFinite) };
            return Err(self.err(col, tok, kind));
        }
        Ok((v, col, tok))
    }

    /// A finite number (a factor composed in `f64`: scale, shear, angle, field of view).
    fn number(&mut self) -> Result<f64, ParseError<'t>> {
        Ok(self.number_at()?.0)
    }

    /// An angle of a field of view: above 0 and below 180 degrees (an error points at it).
    fn view_angle(&mut self) -> Result<f64, ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        if !(v > 0.0 && v < 180.0) {
            return Err(self.err(col, tok, ParseErrorKind::Scene(SceneError::BadFieldOfView)));
        }
        Ok(v)
    }

    /// `A [D]`: the angle across, and the angle down if a number follows.
    fn field_of_view(&mut self) -> Result<FieldOfView, ParseError<'t>> {
        let across = self.view_angle()?;
        let save = self.pos;
        match self.next() {
            Some((_, tok)) if parse_number(tok).is_some() => {
                self.pos = save;
                Ok(FieldOfView::Within(across, self.view_angle()?))
            }
            _ => {
                self.pos = save;
                Ok(FieldOfView::Across(across))
            }
        }
    }

    /// A coordinate or length: below the scalar's coordinate limit.
    fn coord(&mut self) -> Result<f64, ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        if v.abs() >= self.limit {
            return Err(self.err(
                col,
                tok,
                ParseErrorKind::Scene(SceneError::OutOfRange { limit: self.limit, scalar: self.scalar }),
            ));
        }
        Ok(v)
    }

    /// A shading number (intensity, ambient, background, coefficient, index of refraction),
    /// checked against the range of `R`.
    fn value<R: Real>(&mut self, what: &'static str) -> Result<(f64, u32, &'t str), ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        check_value::<R>(what, v).map_err(|e| self.err(col, tok, ParseErrorKind::Scene(e)))?;
        Ok((v, col, tok))
    }

    /// A Phong power: a number at least 0, rounded to a whole one ([`Material::power`]).
    fn shine(&mut self) -> Result<u16, ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        if v < 0.0 {
            return Err(self.err(col, tok, ParseErrorKind::Scene(SceneError::BadCoefficient)));
        }
        Ok(Material::power(v))
    }

    fn positive(&mut self) -> Result<f64, ParseError<'t>> {
        let save = self.pos;
        let v = self.coord()?;
        if v <= 0.0 {
            self.pos = save;
            let (col, tok) = self.word()?;
            return Err(self.err(col, tok, ParseErrorKind::Scene(SceneError::NonPositiveSize)));
        }
        Ok(v)
    }

    /// A point: three coordinates.
    fn point(&mut self) -> Result<Vec3<f64>, ParseError<'t>> {
        Ok(Vec3::new(self.coord()?, self.coord()?, self.coord()?))
    }

    /// A direction: three finite numbers (only their ratios matter).
    fn vec3(&mut self) -> Result<Vec3<f64>, ParseError<'t>> {
        Ok(Vec3::new(self.number()?, self.number()?, self.number()?))
    }

    fn axis(&mut self) -> Result<usize, ParseError<'t>> {
        let (col, tok) = self.word()?;
        match tok {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            _ => Err(self.err(col, tok, ParseErrorKind::UnknownAxis)),
        }
    }

    /// Parses a transform attribute if `key` (at `col`) is one, composing it after `t`.
    fn transform(&mut self, col: u32, key: &'t str, t: &mut Affine<f64>) -> Result<bool, ParseError<'t>> {
        let op = match key {
            "translate" => Affine::translate(self.point()?),
            "rotate" => {
                let a = self.axis()?;
                let turn = Affine::rotate(a, self.number()?);
                // `about X Y Z`: about the line through that point (not the origin).
                let save = self.pos;
                match self.next() {
                    Some((_, "about")) => {
                        let p = self.point()?;
                        Affine::translate(p).after(&turn.after(&Affine::translate(-p)))
                    }
                    _ => {
                        self.pos = save;
                        turn
                    }
                }
            }
            "scale" => {
                let x = self.number()?;
                let save = self.pos;
                match self.next() {
                    Some((_, tok)) if parse_number(tok).is_some() => {
                        self.pos = save;
                        let (y, z) = (self.number()?, self.number()?);
                        Affine::scale(Vec3::new(x, y, z))
                    }
                    _ => {
                        self.pos = save;
                        Affine::scale(Vec3::new(x, x, x))
                    }
                }
            }
            "shear" => {
                let i = self.axis()?;
                let save = self.pos;
                let j = self.axis()?;
                if i == j {
                    self.pos = save;
                    let (jcol, jtok) = self.word()?;
                    return Err(self.err(jcol, jtok, ParseErrorKind::SameAxisShear));
                }
                Affine::shear(i, j, self.number()?)
            }
            _ => return Ok(false),
        };
        *t = op.after(t);
        if t.m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(self.err(col, key, ParseErrorKind::Scene(SceneError::TransformOverflow)));
        }
        Ok(true)
    }
}

/// The keywords of the statements that add one object.
pub const OBJECT_KEYWORDS: [&str; 5] = ["sphere", "cylinder", "cone", "box", "triangle"];

/// The number of object statements ([`OBJECT_KEYWORDS`]) in scene text: the
/// object storage [`parse`] needs for it (line endings and comments as [`parse`] reads them).
pub fn object_count(text: &str) -> usize {
    lines(text).filter(|line| Words::new(line, 0).next().is_some_and(|(_, k)| OBJECT_KEYWORDS.contains(&k))).count()
}

/// The line, column and word of the `camera` statement of `text` (the scene format), if any:
/// what a view refused outside the parser (a render's frame) is blamed on.
pub fn camera_statement(text: &str) -> Option<(u32, u32, &str)> {
    lines(text).enumerate().find_map(|(i, line)| {
        let mut w = Words::new(line, i as u32 + 1);
        w.next().filter(|(_, key)| *key == "camera").map(|(col, key)| (i as u32 + 1, col, key))
    })
}

/// Line, column and keyword of the `index`-th object statement (for errors found after
/// parsing, by the parser or by tools that use the scene).
pub fn object_statement(text: &str, index: usize) -> (u32, u32, &str) {
    let mut seen = 0;
    for (i, line) in lines(text).enumerate() {
        let mut w = Words::new(line, i as u32 + 1);
        if let Some((col, key)) = w.next() {
            if OBJECT_KEYWORDS.contains(&key) {
                if seen == index {
                    return (i as u32 + 1, col, key);
                }
                seen += 1;
            }
        }
    }
    (1, 1, "")
}

/// Where a statement's value was read: line, column and token (what an error is blamed on).
type At<'t> = (u32, u32, &'t str);

/// One statement being parsed: its line, its keyword and the words after it.
struct Statement<'t> {
    lineno: u32,
    kcol: u32,
    key: &'t str,
    w: Words<'t>,
    /// The attributes (not transforms) read so far, to refuse one given twice.
    seen: Vec<&'t str, 8>,
    /// The attributes the statement takes (for an error naming them).
    valid: &'static [&'static str],
}

impl<'t> Statement<'t> {
    /// A scene error blamed on the statement's keyword.
    fn err(&self, e: SceneError) -> ParseError<'t> {
        ParseError { line: self.lineno, col: self.kcol, token: self.key, kind: ParseErrorKind::Scene(e) }
    }

    /// An attribute the statement does not take: the error lists those it takes, and the
    /// nearest of them if the word is one or two letters off it.
    fn unknown(&self, col: u32, attr: &'t str) -> ParseError<'t> {
        let near = self
            .valid
            .iter()
            .map(|v| (edit_distance(attr, v), *v))
            .filter(|(d, _)| *d <= 2 && *d < attr.len())
            .min_by_key(|(d, _)| *d)
            .map(|(_, v)| v);
        self.w.err(col, attr, ParseErrorKind::UnknownAttribute { valid: self.valid, near })
    }

    /// Refuses an attribute the statement has already read.
    fn once(&mut self, col: u32, attr: &'t str) -> Result<(), ParseError<'t>> {
        if self.seen.contains(&attr) {
            return Err(self.w.err(col, attr, ParseErrorKind::RepeatedAttribute));
        }
        // More distinct attributes than any statement takes cannot be pushed: nothing to check.
        let _ = self.seen.push(attr);
        Ok(())
    }
}

/// The attributes each statement takes (by its keyword, and a light by its kind).
fn attributes(key: &str, light: Option<&str>) -> &'static [&'static str] {
    const TRANSFORMS: [&str; 4] = ["translate", "rotate", "scale", "shear"];
    match (key, light) {
        ("camera", _) => &["eye", "look", "up", "fov"],
        ("light", Some("directional")) => &["dir", "intensity"],
        ("light", Some("point")) => &["pos", "intensity"],
        ("material", _) => &["ka", "kd", "ks", "kt", "ior", "shine"],
        ("sphere", _) => &["center", "radius", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("cylinder", _) => &[
            "base",
            "radius",
            "height",
            "open",
            "material",
            TRANSFORMS[0],
            TRANSFORMS[1],
            TRANSFORMS[2],
            TRANSFORMS[3],
        ],
        ("cone", _) => &[
            "base",
            "radius",
            "height",
            "top",
            "open",
            "material",
            TRANSFORMS[0],
            TRANSFORMS[1],
            TRANSFORMS[2],
            TRANSFORMS[3],
        ],
        ("triangle", _) => &["a", "b", "c", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("box", _) => &["min", "max", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("group", _) => &TRANSFORMS,
        _ => &[],
    }
}

/// Levenshtein distance of two short words (at most 16 bytes of `b` counted; longer words are
/// never near).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if b.len() > 16 || a.len() > 32 {
        return usize::MAX;
    }
    let mut row = [0usize; 17];
    for (j, r) in row.iter_mut().enumerate().take(b.len() + 1) {
        *r = j;
    }
    for (i, &ca) in a.iter().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(ca != cb)).min(row[j] + 1).min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The parser's state between statements: the builder, material names, and where the
/// statements that scene-wide errors are blamed on were read.
struct Parser<'a, 't, R> {
    text: &'t str,
    b: SceneBuilder<'a, R>,
    names: Vec<(&'t str, u8), MAX_MATERIALS>,
    camera_at: At<'t>,
    group_at: At<'t>,
    /// The largest shading number so far: what a too-bright scene is blamed on.
    bright_at: (u32, u32, &'t str, f64),
}

impl<'a, 't, R: Real> Parser<'a, 't, R> {
    /// A scene error blamed on statement `st`; an object count is completed from the text.
    fn scene_err(&self, st: &Statement<'t>, e: SceneError) -> ParseError<'t> {
        st.err(match e {
            SceneError::TooManyObjects { capacity, .. } => {
                SceneError::TooManyObjects { capacity, needed: object_count(self.text) }
            }
            e => e,
        })
    }

    /// A shading number (ambient, background, coefficient, intensity), remembered if it is the
    /// largest so far.
    fn shading(&mut self, st: &mut Statement<'t>, what: &'static str) -> Result<f64, ParseError<'t>> {
        let (v, col, tok) = st.w.value::<R>(what)?;
        if v.abs() > self.bright_at.3 {
            self.bright_at = (st.lineno, col, tok, v.abs());
        }
        Ok(v)
    }

    /// `camera eye X Y Z look X Y Z up X Y Z fov A [D]`
    fn camera(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        self.camera_at = (st.lineno, st.kcol, st.key);
        let c = &mut self.b.camera;
        while let Some((col, attr)) = st.w.next() {
            st.once(col, attr)?;
            match attr {
                "eye" => c.eye = st.w.point()?,
                "look" => c.look = st.w.point()?,
                "up" => c.up = st.w.vec3()?,
                "fov" => c.fov = st.w.field_of_view()?,
                _ => return Err(st.unknown(col, attr)),
            }
        }
        Ok(())
    }

    /// `depth N`
    fn depth(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        let (col, tok) = st.w.word()?;
        self.b.max_depth = match tok.parse::<u8>() {
            Ok(d) if d <= MAX_DEPTH => d,
            _ => return Err(st.w.err(col, tok, ParseErrorKind::BadDepth)),
        };
        Ok(())
    }

    /// `light directional dir X Y Z [intensity I]` or `light point pos X Y Z [intensity I]`
    fn light(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        let (col, kind) = st.w.word()?;
        let mut v = Vec3::zero();
        let mut intensity = 1.0;
        let want = match kind {
            "directional" => "dir",
            "point" => "pos",
            _ => return Err(st.w.err(col, kind, ParseErrorKind::UnknownLightKind)),
        };
        st.valid = attributes("light", Some(kind));
        while let Some((col, attr)) = st.w.next() {
            st.once(col, attr)?;
            match attr {
                "dir" if want == "dir" => v = st.w.vec3()?,
                "pos" if want == "pos" => v = st.w.point()?,
                "intensity" => intensity = self.shading(st, "light intensity")?,
                _ => return Err(st.unknown(col, attr)),
            }
        }
        let light = if want == "dir" {
            Light::Directional { to_light: -v, intensity }
        } else {
            Light::Point { pos: v, intensity }
        };
        self.b.add_light(light).map_err(|e| self.scene_err(st, e))
    }

    /// `material NAME [ka K] [kd K] [ks K] [kt K] [ior N] [shine P]`
    fn material(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        let (ncol, name) = st.w.word()?;
        if self.names.iter().any(|(n, _)| *n == name) {
            return Err(st.w.err(ncol, name, ParseErrorKind::DuplicateMaterial));
        }
        let mut m = Material::DEFAULT;
        while let Some((col, attr)) = st.w.next() {
            st.once(col, attr)?;
            if attr == "shine" {
                m.shine = st.w.shine()?;
                continue;
            }
            let (slot, what) = match attr {
                "ka" => (&mut m.ka, "coefficient"),
                "kd" => (&mut m.kd, "coefficient"),
                "ks" => (&mut m.ks, "coefficient"),
                "kt" => (&mut m.kt, "coefficient"),
                "ior" => (&mut m.ior, IOR),
                _ => return Err(st.unknown(col, attr)),
            };
            let save = st.w.pos;
            *slot = if what == IOR { st.w.value::<R>(what)?.0 } else { self.shading(st, what)? };
            if *slot < if what == IOR { 1.0 } else { 0.0 } {
                st.w.pos = save;
                let (vcol, tok) = st.w.word()?;
                return Err(st.w.err(vcol, tok, ParseErrorKind::Scene(SceneError::BadCoefficient)));
            }
        }
        let id = self.b.add_material(m).map_err(|e| st.w.err(ncol, name, ParseErrorKind::Scene(e)))?;
        let _ = self.names.push((name, id));
        Ok(())
    }

    /// `sphere`, `cylinder`, `cone`, `box` or `triangle` with its size, material and transforms.
    fn object(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        let key = st.key;
        let (mut pos, mut radius, mut height, mut top) = (Vec3::zero(), 1.0, 1.0, 0.0);
        let (mut open, mut corners) = (false, [None; 3]);
        let (mut lo, mut hi) = (Vec3::zero(), Vec3::new(1.0, 1.0, 1.0));
        let mut material = 0u8;
        let mut t = Affine::identity();
        while let Some((col, attr)) = st.w.next() {
            if !matches!(attr, "translate" | "rotate" | "scale" | "shear") {
                st.once(col, attr)?;
            }
            let w = &mut st.w;
            match (key, attr) {
                ("sphere", "center") | ("cylinder" | "cone", "base") => pos = w.point()?,
                ("sphere" | "cylinder" | "cone", "radius") => radius = w.positive()?,
                ("cylinder" | "cone", "height") => height = w.positive()?,
                ("cone", "top") => {
                    top = w.coord()?;
                    if top < 0.0 {
                        return Err(w.err(col, attr, ParseErrorKind::Scene(SceneError::NonPositiveSize)));
                    }
                }
                ("cylinder" | "cone", "open") => open = true,
                ("triangle", "a") => corners[0] = Some(w.point()?),
                ("triangle", "b") => corners[1] = Some(w.point()?),
                ("triangle", "c") => corners[2] = Some(w.point()?),
                ("box", "min") => lo = w.point()?,
                ("box", "max") => hi = w.point()?,
                (_, "material") => {
                    let (mcol, name) = w.word()?;
                    material = self
                        .names
                        .iter()
                        .find(|(n, _)| *n == name)
                        .map(|(_, id)| *id)
                        .ok_or_else(|| w.err(mcol, name, ParseErrorKind::UnknownMaterial))?;
                }
                _ => {
                    if !w.transform(col, attr, &mut t)? {
                        return Err(st.unknown(col, attr));
                    }
                }
            }
        }
        if key == "triangle" {
            let [Some(a), Some(b), Some(c)] = corners else {
                return Err(self.scene_err(st, SceneError::MissingCorner));
            };
            let corners = [a, b, c].map(|p| t.point(p));
            return self.b.add_triangle(corners, material).map_err(|e| self.scene_err(st, e));
        }
        let (shape, placement) = match key {
            "sphere" => {
                (Shape::Sphere, Affine::translate(pos).after(&Affine::scale(Vec3::new(radius, radius, radius))))
            }
            "box" => {
                let size = hi - lo;
                if !(size.x > 0.0 && size.y > 0.0 && size.z > 0.0) {
                    return Err(self.scene_err(st, SceneError::NonPositiveSize));
                }
                (Shape::Box, Affine::translate(lo).after(&Affine::scale(size)))
            }
            _ => {
                let shape = match (key, open) {
                    ("cone", false) => Shape::Cone { top: top / radius },
                    ("cone", true) => Shape::Open { top: top / radius },
                    (_, false) => Shape::Cylinder,
                    (_, true) => Shape::Open { top: 1.0 },
                };
                (shape, Affine::translate(pos).after(&Affine::scale(Vec3::new(radius, height, radius))))
            }
        };
        self.b.add_object(shape, t.after(&placement), material).map_err(|e| self.scene_err(st, e))
    }

    /// `group [NAME] [transforms]`: opens a composite.
    fn group(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        self.group_at = (st.lineno, st.kcol, st.key);
        let mut t = Affine::identity();
        // An optional name comes first; it documents the scene and is not stored.
        let save = st.w.pos;
        if let Some((_, word)) = st.w.next() {
            if matches!(word, "translate" | "rotate" | "scale" | "shear") {
                st.w.pos = save;
            }
        }
        while let Some((col, attr)) = st.w.next() {
            if !st.w.transform(col, attr, &mut t)? {
                return Err(st.unknown(col, attr));
            }
        }
        self.b.begin_composite(t).map_err(|e| self.scene_err(st, e))
    }

    /// One line: dispatches on the keyword, then refuses anything left over.
    fn statement(&mut self, st: &mut Statement<'t>) -> Result<(), ParseError<'t>> {
        match st.key {
            "camera" => self.camera(st)?,
            "ambient" => self.b.ambient = self.shading(st, "ambient")?,
            "background" => self.b.background = self.shading(st, "background")?,
            "depth" => self.depth(st)?,
            "light" => self.light(st)?,
            "material" => self.material(st)?,
            "sphere" | "cylinder" | "cone" | "box" | "triangle" => self.object(st)?,
            "group" => self.group(st)?,
            "end" => self.b.end_composite().map_err(|e| self.scene_err(st, e))?,
            _ => return Err(st.w.err(st.kcol, st.key, ParseErrorKind::UnknownStatement)),
        }
        match st.w.next() {
            Some((col, tok)) => Err(st.unknown(col, tok)),
            None => Ok(()),
        }
    }

    /// Validates the whole scene, blaming a scene-wide error on the statement behind it.
    fn finish(self, last_line: u32) -> Result<Scene<'a, R>, ParseError<'t>> {
        let Parser { text, b, camera_at, group_at, bright_at, .. } = self;
        b.finish().map_err(|e| {
            let (line, col, token) = match e {
                SceneError::ObjectOutOfRange { object, .. } | SceneError::ObjectTooThin { object, .. } => {
                    object_statement(text, object)
                }
                SceneError::UnclosedComposite => group_at,
                SceneError::TooBright { .. } if bright_at.0 > 0 => (bright_at.0, bright_at.1, bright_at.2),
                SceneError::DegenerateCamera | SceneError::BadFieldOfView | SceneError::OutOfRange { .. }
                    if camera_at.0 > 0 =>
                {
                    camera_at
                }
                _ => (last_line, 1, ""),
            };
            ParseError { line, col, token, kind: ParseErrorKind::Scene(e) }
        })
    }
}

/// Parses scene text into a validated scene whose objects live in `storage` and whose
/// composites, materials and lights live in `parts`. A mistake is an error that says where:
///
/// ```
/// use lattice_rt::{parse, scene::Object, Parts};
///
/// let (mut storage, mut parts) = ([Object::<f32>::default(); 4], Parts::default());
/// let scene = parse::<f32>("light directional dir -1 -1 1\nsphere radius 1\n", &mut storage, &mut parts);
/// assert_eq!(scene.map(|s| s.objects().len()), Ok(1));
///
/// let (mut storage, mut parts) = ([Object::<f32>::default(); 4], Parts::default());
/// let err = parse::<f32>("sphere raduis 1\n", &mut storage, &mut parts).unwrap_err();
/// assert_eq!((err.line, err.col, err.token), (1, 8, "raduis"));
/// ```
///
/// Kept out of line so that on a microcontroller the parser's frame is released before the
/// render that follows it needs the stack.
#[inline(never)]
pub fn parse<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
) -> Result<Scene<'a, R>, ParseError<'t>> {
    parse_with(text, storage, parts, |_| {})
}

/// [`parse`], with the camera the text describes changed by `camera` before the scene is
/// validated (the frames of an orbit: [`CameraDesc::orbit`]).
pub fn parse_with<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
    camera: impl FnOnce(&mut CameraDesc),
) -> Result<Scene<'a, R>, ParseError<'t>> {
    let mut p = Parser {
        text,
        b: SceneBuilder::<R>::new(storage, parts),
        names: Vec::new(),
        camera_at: (0, 0, ""),
        group_at: (0, 0, ""),
        bright_at: (0, 0, "", -1.0),
    };
    let mut last_line = 1u32;
    for (i, line) in lines(text).enumerate() {
        let lineno = i as u32 + 1;
        last_line = lineno;
        let mut w = Words::for_scalar::<R>(line, lineno);
        let Some((kcol, key)) = w.next() else { continue };
        p.statement(&mut Statement { lineno, kcol, key, w, seen: Vec::new(), valid: attributes(key, None) })?;
    }
    camera(&mut p.b.camera);
    p.finish(last_line)
}

#[cfg(test)]
mod tests {
    use super::parse_number;

    /// A cone whose top is wider than its base is the frustum it describes, in every scalar:
    /// level rays across it hit it where its radius at their height reaches them, and miss it
    /// where it does not (the canonical cone's box would cut it to its base's radius).
    #[test]
    fn a_cone_wider_at_its_top_is_the_frustum_it_describes() {
        fn check<R: crate::Real>() {
            let text = "camera eye 0 1 -6 look 0 1 0\ncone base 0 0 0 radius 0.5 height 2 top 1.5\n";
            let (mut storage, mut parts) =
                (std::vec![crate::scene::Object::<R>::default(); 4], crate::Parts::default());
            let scene = crate::parse::<R>(text, &mut storage, &mut parts).unwrap();
            let o = &scene.objects()[0];
            // The radius at height y is 0.5 + y / 2: a level ray at distance d from the axis hits
            // below the radius, misses beyond it.
            for (y, d, hits) in [
                (1.9, 1.4, true),
                (1.9, 1.5, false),
                (0.1, 0.5, true),
                (0.1, 0.6, false),
                (1.0, 0.95, true),
                (1.0, 1.05, false),
            ] {
                let ray =
                    crate::Ray::new(crate::Vec3::new(-5.0, y, d).cast::<R>(), crate::Vec3::new(1.0, 0.0, 0.0).cast());
                assert_eq!(o.intersect(&ray, R::ZERO, R::MAX).is_some(), hits, "{}: height {y}, distance {d}", R::NAME);
            }
        }
        check::<f64>();
        check::<f32>();
        check::<crate::Fx>();
    }

    #[test]
    fn numbers_parse_like_core_for_scene_values() {
        for t in [
            "0",
            "1",
            "-2.5",
            "0.42",
            "+3",
            ".5",
            "5.",
            "1e3",
            "-1.25E-2",
            "123456.789",
            "0.1",
            "2.2",
            "1e-7",
            "3.14159",
        ] {
            assert_eq!(parse_number(t), Some(t.parse::<f64>().unwrap()), "{t}");
        }
    }

    #[test]
    fn non_numbers_are_refused() {
        for t in ["", "-", ".", "e5", "1e", "1e+", "1.2.3", "one", "1x", "--1"] {
            assert_eq!(parse_number(t), None, "{t}");
        }
        assert!(parse_number("NaN").unwrap().is_nan());
        assert_eq!(parse_number("-inf"), Some(f64::NEG_INFINITY));
        assert_eq!(parse_number("1e999"), Some(f64::INFINITY));
    }
}
