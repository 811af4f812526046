//! Reading the scene text: its bytes as UTF-8, its lines (any line ending), the words of a
//! line with their columns, and numbers read without core's `f64` parser.

use super::error::{ParseError, ParseErrorKind};
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::scene::{check_value, FieldOfView, Material, SceneError};

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
pub(super) struct Lines<'t> {
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
pub(super) fn lines(text: &str) -> Lines<'_> {
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
pub(super) struct Words<'t> {
    line: &'t str,
    pub(super) pos: usize,
    lineno: u32,
    /// The largest coordinate magnitude of the scalar the scene is parsed for, and its name.
    limit: f64,
    scalar: &'static str,
}

impl<'t> Words<'t> {
    pub(super) fn new(line: &'t str, lineno: u32) -> Self {
        let line = match line.find('#') {
            Some(i) => &line[..i],
            None => line,
        };
        Words { line, pos: 0, lineno, limit: f64::MAX, scalar: "f64" }
    }

    /// Words whose coordinates are checked against the range of `R`.
    pub(super) fn for_scalar<R: Real>(line: &'t str, lineno: u32) -> Self {
        Words { limit: R::LIMIT, scalar: R::NAME, ..Self::new(line, lineno) }
    }

    pub(super) fn next(&mut self) -> Option<(u32, &'t str)> {
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

    pub(super) fn err(&self, col: u32, token: &'t str, kind: ParseErrorKind) -> ParseError<'t> {
        ParseError { line: self.lineno, col, token, kind }
    }

    pub(super) fn end_err(&self) -> ParseError<'t> {
        self.err(self.line.trim_end().len() as u32 + 1, "", ParseErrorKind::MissingValue)
    }

    pub(super) fn word(&mut self) -> Result<(u32, &'t str), ParseError<'t>> {
        self.next().ok_or_else(|| self.end_err())
    }

    /// A finite number, with its column and token.
    pub(super) fn number_at(&mut self) -> Result<(f64, u32, &'t str), ParseError<'t>> {
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
    pub(super) fn number(&mut self) -> Result<f64, ParseError<'t>> {
        Ok(self.number_at()?.0)
    }

    /// An angle of a field of view: above 0 and below 180 degrees (an error points at it).
    pub(super) fn view_angle(&mut self) -> Result<f64, ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        if !(v > 0.0 && v < 180.0) {
            return Err(self.err(col, tok, ParseErrorKind::Scene(SceneError::BadFieldOfView)));
        }
        Ok(v)
    }

    /// `A [D]`: the angle across, and the angle down if a number follows.
    pub(super) fn field_of_view(&mut self) -> Result<FieldOfView, ParseError<'t>> {
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
    pub(super) fn coord(&mut self) -> Result<f64, ParseError<'t>> {
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
    pub(super) fn value<R: Real>(&mut self, what: &'static str) -> Result<(f64, u32, &'t str), ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        check_value::<R>(what, v).map_err(|e| self.err(col, tok, ParseErrorKind::Scene(e)))?;
        Ok((v, col, tok))
    }

    /// A Phong power: a number at least 0, rounded to a whole one ([`Material::power`]).
    pub(super) fn shine(&mut self) -> Result<u16, ParseError<'t>> {
        let (v, col, tok) = self.number_at()?;
        if v < 0.0 {
            return Err(self.err(col, tok, ParseErrorKind::Scene(SceneError::BadCoefficient)));
        }
        Ok(Material::power(v))
    }

    pub(super) fn positive(&mut self) -> Result<f64, ParseError<'t>> {
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
    pub(super) fn point(&mut self) -> Result<Vec3<f64>, ParseError<'t>> {
        Ok(Vec3::new(self.coord()?, self.coord()?, self.coord()?))
    }

    /// A direction: three finite numbers (only their ratios matter).
    pub(super) fn vec3(&mut self) -> Result<Vec3<f64>, ParseError<'t>> {
        Ok(Vec3::new(self.number()?, self.number()?, self.number()?))
    }

    pub(super) fn axis(&mut self) -> Result<usize, ParseError<'t>> {
        let (col, tok) = self.word()?;
        match tok {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            _ => Err(self.err(col, tok, ParseErrorKind::UnknownAxis)),
        }
    }

    /// Parses a transform attribute if `key` (at `col`) is one, composing it after `t`.
    pub(super) fn transform(&mut self, col: u32, key: &'t str, t: &mut Affine<f64>) -> Result<bool, ParseError<'t>> {
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
