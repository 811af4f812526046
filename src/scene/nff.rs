//! NFF, the Neutral File Format of Eric Haines' Standard Procedural Databases (SPD), read into
//! a [`Scene`] as [`super::text`] reads our own format: every entity of `NFF.TXT`.
//!
//! * `v` (`from`, `at`, `up`, `angle`, `hither`, `resolution`): the camera. `angle` is measured
//!   between the centres of the edge pixels of a `resolution` frame (aspect 1), so the view
//!   from edge to edge is a little wider: `tan(a'/2) = tan(a/2) n / (n - 1)` for `n` pixels
//!   (the smaller of the two). `hither` is read and not used (rays start at the eye).
//! * `b R G B`: the background, as a gray ([`luminance`]).
//! * `l X Y Z [R G B]`: a point light. NFF gives no intensity; each of `n` lights gets the SPD
//!   Readme's `sqrt(n) / (2 n)` (times the gray of its colour, when one is given), and so does
//!   the ambient light.
//! * `f R G B Kd Ks Shine T ior`: the material of the objects that follow: diffuse and ambient
//!   `Kd` times the colour's gray, mirror and highlight `Ks`, the Phong power `Shine`
//!   ([`Material::power`]), transmission `T`, and the index of refraction (used only when
//!   `T > 0`). Equal materials are stored once.
//! * `s X Y Z r`: a sphere. `c` with base point and radius, apex point and radius: the side of
//!   a cylinder or cone without end caps ([`Shape::Open`]).
//! * `p n` and `n` vertices: a planar polygon, convex or not, cut into `n - 2` triangles
//!   ([`triangulate`]). `pp n` and `n` vertices with normals: the same polygon, its triangles shaded by
//!   the normals interpolated across them ([`crate::scene::Smooth`]; a build without `alloc`
//!   refuses them).
//! * `#` starts a comment that runs to the end of the line.
//!
//! What the tracer cannot draw is refused by name, never ignored: a negative radius (NFF's
//! inside-only surface), a polygon of fewer than three vertices or of no area, a cone whose
//! base and apex coincide. Every error says where (line and column), which word, and why.

use super::builder::SceneBuilder;
use super::error::SceneError;
use super::model::{Light, Material, Object, Parts, Scene, MAX_LIGHTS, MAX_MATERIALS};
use super::polygon::{crosses_itself, triangulate, MAX_VERTICES};
use super::text::{parse_number, ParseError, ParseErrorKind};
use crate::camera::{CameraDesc, FieldOfView};
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::shape::Shape;
use heapless::Vec;

/// The number of objects NFF text makes ([`parse_with`]'s storage): one per sphere and cone or
/// cylinder, `n - 2` triangles per polygon of `n` vertices. A count that does not read as a
/// number counts nothing (the parser reports it).
pub fn object_count(text: &str) -> usize {
    let mut t = Tokens::new(text);
    let mut n = 0usize;
    while let Some((_, _, w)) = t.next() {
        match w {
            "s" | "c" => n += 1,
            "p" | "pp" => {
                // A polygon larger than the reader takes is refused at its line; it counts no more
                // than the largest it takes (so no storage is sized for a count it refuses).
                if let Some(k) = t.next().and_then(|(_, _, c)| c.parse::<usize>().ok()) {
                    n = n.saturating_add(k.min(MAX_VERTICES).saturating_sub(2));
                }
            }
            _ => {}
        }
    }
    n
}

/// The line, column and word of the last view (`v`) of NFF text, if any: what a view refused
/// outside the reader (a render's frame) is blamed on.
pub fn view_entity(text: &str) -> Option<(u32, u32, &str)> {
    let mut t = Tokens::new(text);
    let mut found = None;
    while let Some(at) = t.next() {
        if at.2 == "v" {
            found = Some(at);
        }
    }
    found
}

/// The gray of an RGB colour: its luminance by the Rec. 709 weights.
pub fn luminance(r: f64, g: f64, b: f64) -> f64 {
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// Parses NFF text into a [`Scene`], storing objects in `storage` (at least [`object_count`]
/// long) and the materials and lights in `parts`; the camera the text describes is changed by
/// `camera` before the scene is validated (a frame's shape, the frames of an orbit).
// Out of line: its reader's tables (and a polygon's vertices, in `polygon`) are on the stack
// only while NFF is read, not in the frame of a caller that reads the other format (the Pico's
// run-time parsing has a few KiB of stack).
#[inline(never)]
pub fn parse_with<'a, 't, R: Real>(
    text: &'t str,
    storage: &'a mut [Object<R>],
    parts: &'a mut Parts<R>,
    camera: impl FnOnce(&mut CameraDesc),
) -> Result<Scene<'a, R>, ParseError<'t>> {
    let mut p = Reader {
        t: Tokens::new(text),
        b: SceneBuilder::<R>::new(storage, parts),
        materials: Vec::new(),
        material: None,
        lights: Vec::new(),
        last: (1, 1, ""),
        view: None,
        background: None,
    };
    p.b.background = 0.0;
    while let Some(at) = p.t.next() {
        p.last = at;
        p.entity(at)?;
    }
    p.finish(camera)
}

/// A word of the text with its line and column (1-based).
type At<'t> = (u32, u32, &'t str);

/// The words of NFF text, with their lines and columns; `#` comments skipped. A line ends at
/// LF, CR LF or a lone CR, as in the scene format. Columns are counted in characters as the
/// words go by, so a file of one long line reads in time linear in its length.
#[derive(Clone, Copy)]
struct Tokens<'t> {
    text: &'t str,
    pos: usize,
    line: u32,
    /// The byte up to which the line's characters are counted, and the column there.
    counted: (usize, u32),
    /// Just past the last word read: its line and the column after it (where a value missing
    /// after it is reported).
    end: (u32, u32),
}

impl<'t> Tokens<'t> {
    fn new(text: &'t str) -> Self {
        Tokens { text, pos: 0, line: 1, counted: (0, 1), end: (1, 1) }
    }

    /// The column of byte `at` of the current line (at or after the bytes counted so far).
    fn column(&mut self, at: usize) -> u32 {
        let col = self.counted.1 + self.text[self.counted.0..at].chars().count() as u32;
        self.counted = (at, col);
        col
    }

    fn next(&mut self) -> Option<At<'t>> {
        let b = self.text.as_bytes();
        let ends_line = |i: usize| b[i] == b'\n' || (b[i] == b'\r' && b.get(i + 1) != Some(&b'\n'));
        loop {
            let c = *b.get(self.pos)?;
            if ends_line(self.pos) {
                self.pos += 1;
                self.line += 1;
                self.counted = (self.pos, 1);
            } else if c.is_ascii_whitespace() {
                self.pos += 1;
            } else if c == b'#' {
                while self.pos < b.len() && !ends_line(self.pos) {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
        let start = self.pos;
        while b.get(self.pos).is_some_and(|&c| !c.is_ascii_whitespace() && c != b'#') {
            self.pos += 1;
        }
        let col = self.column(start);
        self.end = (self.line, self.column(self.pos));
        Some((self.line, col, &self.text[start..self.pos]))
    }

    /// The next word without taking it.
    fn peek(&self) -> Option<At<'t>> {
        { *self }.next()
    }

    /// A value missing after the last word read: reported just past that word.
    fn missing(&self) -> ParseError<'t> {
        ParseError { line: self.end.0, col: self.end.1, token: "", kind: ParseErrorKind::MissingValue }
    }
}

/// The reader's state: the builder, the materials so far (to store each once), the current
/// one, the lights (added at the end, when their number, which sets their intensity, is known).
struct Reader<'a, 't, R> {
    t: Tokens<'t>,
    b: SceneBuilder<'a, R>,
    materials: Vec<(Material<f64>, u8), MAX_MATERIALS>,
    material: Option<u8>,
    lights: Vec<(Vec3<f64>, f64, At<'t>), MAX_LIGHTS>,
    /// The entity being read (what a scene-wide error is blamed on).
    last: At<'t>,
    /// The last view (`v`) and background (`b`): what a camera's or the background's error,
    /// found when the scene is validated, is blamed on.
    view: Option<At<'t>>,
    background: Option<At<'t>>,
}

fn error(at: At<'_>, kind: ParseErrorKind) -> ParseError<'_> {
    ParseError { line: at.0, col: at.1, token: at.2, kind }
}

impl<'a, 't, R: Real> Reader<'a, 't, R> {
    fn entity(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        match at.2 {
            "v" => self.view(at),
            "b" => {
                self.b.background = self.colour()?;
                self.background = Some(at);
                Ok(())
            }
            "l" => self.light(at),
            "f" => self.fill(at),
            "s" => self.sphere(at),
            "c" => self.cone(at),
            "p" => self.polygon(at, false),
            "pp" => self.polygon(at, true),
            _ => Err(error(at, ParseErrorKind::UnknownEntity)),
        }
    }

    /// The next word, or an error just past the last word at the end of the text.
    fn word(&mut self) -> Result<At<'t>, ParseError<'t>> {
        self.t.next().ok_or_else(|| self.t.missing())
    }

    /// A finite number. An entity's word on a later line than the word before it (the next
    /// entity, where this one's last value is missing) is reported as a value missing just past
    /// the word before it.
    fn number(&mut self) -> Result<f64, ParseError<'t>> {
        let before = self.t;
        let at = self.word()?;
        if at.0 > before.end.0 && super::NFF_ENTITIES.contains(&at.2) {
            return Err(before.missing());
        }
        match parse_number(at.2) {
            Some(v) if v.is_finite() => Ok(v),
            // Digits beyond f64 (`1e999`) are out of range; `nan` and `inf` are not finite.
            Some(_) if at.2.trim_start_matches(['+', '-']).starts_with(|c: char| c.is_ascii_digit() || c == '.') => {
                Err(error(at, ParseErrorKind::NumberOutOfRange))
            }
            Some(_) => Err(error(at, ParseErrorKind::Scene(SceneError::NotFinite))),
            None => Err(error(at, ParseErrorKind::ExpectedNumber)),
        }
    }

    fn numbers<const N: usize>(&mut self) -> Result<[f64; N], ParseError<'t>> {
        let mut v = [0.0; N];
        for x in v.iter_mut() {
            *x = self.number()?;
        }
        Ok(v)
    }

    /// A number that `ok` accepts, or `kind` at its word.
    fn checked(&mut self, ok: impl Fn(f64) -> bool, kind: ParseErrorKind) -> Result<f64, ParseError<'t>> {
        let at = self.t.peek();
        let v = self.number()?;
        match at {
            Some(at) if !ok(v) => Err(error(at, kind)),
            _ => Ok(v),
        }
    }

    /// `R G B`, each at least 0, as a gray ([`luminance`]); a gray beyond f64 is out of range at
    /// the colour's first word.
    fn colour(&mut self) -> Result<f64, ParseError<'t>> {
        let at = self.t.peek();
        let mut rgb = [0.0; 3];
        for c in rgb.iter_mut() {
            *c = self.checked(|v| v >= 0.0, ParseErrorKind::NegativeColour)?;
        }
        let gray = luminance(rgb[0], rgb[1], rgb[2]);
        match at {
            Some(at) if !gray.is_finite() => Err(error(at, ParseErrorKind::NumberOutOfRange)),
            _ => Ok(gray),
        }
    }

    fn point(&mut self) -> Result<Vec3<f64>, ParseError<'t>> {
        let [x, y, z] = self.numbers()?;
        Ok(Vec3::new(x, y, z))
    }

    /// A radius: a number at least 0 (a negative one is NFF's inside-only surface).
    fn radius(&mut self) -> Result<f64, ParseError<'t>> {
        let at = self.t.peek();
        let r = self.number()?;
        match at {
            Some(at) if r < 0.0 => Err(error(at, ParseErrorKind::InsideOnly)),
            _ => Ok(r),
        }
    }

    /// `v` and its lines: `from`, `at`, `up` and `angle` needed, `hither` and `resolution`
    /// optional, in any order.
    fn view(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        let (mut from, mut look, mut up, mut angle, mut res) = (None, None, None, None, None);
        while let Some(next) = self.t.peek() {
            match next.2 {
                "from" | "at" | "up" | "angle" | "hither" | "resolution" => {
                    self.t.next();
                }
                _ => break,
            }
            match next.2 {
                "from" => from = Some(self.point()?),
                "at" => look = Some(self.point()?),
                "up" => up = Some(self.point()?),
                "angle" => {
                    let a = self.number()?;
                    if !(a > 0.0 && a < 180.0) {
                        return Err(error(next, ParseErrorKind::Scene(SceneError::BadFieldOfView)));
                    }
                    angle = Some(a);
                }
                "hither" => {
                    self.number()?;
                }
                _ => {
                    let [w, h] = self.numbers()?;
                    if !(w >= 1.0 && h >= 1.0) {
                        return Err(error(next, ParseErrorKind::BadResolution));
                    }
                    res = Some(w.min(h));
                }
            }
        }
        let missing = |what| error(at, ParseErrorKind::ExpectedWord(what));
        let angle = angle.ok_or(missing("angle"))?;
        let c = &mut self.b.camera;
        (c.eye, c.look, c.up) = (from.ok_or(missing("from"))?, look.ok_or(missing("at"))?, up.ok_or(missing("up"))?);
        // From the centres of the edge pixels to the frame's edges: n pixels' centres span
        // n - 1 pixels.
        let widen = match res {
            Some(n) if n > 1.0 => n / (n - 1.0),
            _ => 1.0,
        };
        let half = libm::tan(angle.to_radians() / 2.0) * widen;
        let edges = 2.0 * libm::atan(half).to_degrees();
        if !(edges < 180.0) {
            return Err(error(at, ParseErrorKind::Scene(SceneError::BadFieldOfView)));
        }
        c.fov = FieldOfView::Within(edges, edges);
        self.view = Some(at);
        Ok(())
    }

    /// `l X Y Z [R G B]`: kept until the end, when the number of lights is known.
    fn light(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        let pos = self.point()?;
        // A colour follows when the next word is a number.
        let gray = if self.t.peek().is_some_and(|(_, _, w)| parse_number(w).is_some()) { self.colour()? } else { 1.0 };
        self.lights.push((pos, gray, at)).map_err(|_| error(at, ParseErrorKind::Scene(SceneError::TooManyLights)))
    }

    /// `f R G B Kd Ks Shine T ior`: the material of the objects that follow.
    fn fill(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        let gray = self.colour()?;
        let coefficient = || ParseErrorKind::Scene(SceneError::BadCoefficient);
        let kd_at = self.t.peek();
        let kd = self.checked(|v| v >= 0.0, coefficient())?;
        let ks = self.checked(|v| v >= 0.0, coefficient())?;
        let shine = self.checked(|v| v >= 0.0, coefficient())?;
        let t = self.checked(|v| v >= 0.0, coefficient())?;
        let ior = self.checked(|v| t == 0.0 || v >= 1.0, coefficient())?;
        if let Some(kd_at) = kd_at.filter(|_| !(kd * gray).is_finite()) {
            return Err(error(kd_at, ParseErrorKind::NumberOutOfRange));
        }
        let m = Material {
            ka: kd * gray,
            kd: kd * gray,
            ks,
            kt: t,
            ior: if t > 0.0 { ior } else { 1.0 },
            shine: if shine >= 0.0 { Material::power(shine) } else { 0 },
        };
        if let Some(&(_, id)) = self.materials.iter().find(|(known, _)| *known == m) {
            self.material = Some(id);
            return Ok(());
        }
        let id = self.b.add_material(m).map_err(|e| error(at, ParseErrorKind::Scene(e)))?;
        let _ = self.materials.push((m, id));
        self.material = Some(id);
        Ok(())
    }

    /// The material for the next object: the last `f`'s, or the default before any.
    fn material(&mut self, at: At<'t>) -> Result<u8, ParseError<'t>> {
        match self.material {
            Some(id) => Ok(id),
            None => {
                let id = self.b.add_material(Material::DEFAULT).map_err(|e| error(at, ParseErrorKind::Scene(e)))?;
                self.material = Some(id);
                Ok(id)
            }
        }
    }

    /// `s X Y Z r`.
    fn sphere(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        let c = self.point()?;
        let r = self.radius()?;
        if r == 0.0 {
            return Err(error(at, ParseErrorKind::Scene(SceneError::NonPositiveSize)));
        }
        let m = self.material(at)?;
        let place = Affine::translate(c).after(&Affine::scale(Vec3::new(r, r, r)));
        self.b.add_object(Shape::Sphere, place, m).map_err(|e| error(at, ParseErrorKind::Scene(e)))
    }

    /// `c`, base point and radius, apex point and radius: an open side.
    fn cone(&mut self, at: At<'t>) -> Result<(), ParseError<'t>> {
        let (mut base, mut r0) = (self.point()?, self.radius()?);
        let (mut apex, mut r1) = (self.point()?, self.radius()?);
        if r1 > r0 {
            // The wider end is the canonical cone's base.
            (base, r0, apex, r1) = (apex, r1, base, r0);
        }
        if r0 == 0.0 {
            return Err(error(at, ParseErrorKind::Scene(SceneError::NonPositiveSize)));
        }
        let axis = apex - base;
        if axis.max_abs() == 0.0 {
            return Err(error(at, ParseErrorKind::CoincidentEnds));
        }
        // Two unit vectors across the axis, from the axis of the world least along it.
        let a = axis.normalize();
        let helper = if a.x.abs() < 0.6 { Vec3::new(1.0, 0.0, 0.0) } else { Vec3::new(0.0, 1.0, 0.0) };
        let u = a.cross(helper).normalize();
        let w = a.cross(u).normalize();
        let place = Affine::from_columns(u * r0, axis, w * r0, base);
        let m = self.material(at)?;
        self.b.add_object(Shape::Open { top: r1 / r0 }, place, m).map_err(|e| error(at, ParseErrorKind::Scene(e)))
    }

    /// `p n` or `pp n` and the vertices (with normals for `pp`, which shade the triangles
    /// smoothly: [`crate::scene::Smooth`]): cut into triangles ([`triangulate`]). A triangle of no area (three vertices in a line, a vertex
    /// repeated) adds nothing and is left out; a polygon left with none is refused.
    #[inline(never)]
    fn polygon(&mut self, at: At<'t>, patch: bool) -> Result<(), ParseError<'t>> {
        let n_at = self.word()?;
        let n = match n_at.2.parse::<usize>() {
            Ok(n) if n >= 3 => n,
            _ => return Err(error(n_at, ParseErrorKind::BadVertexCount)),
        };
        if n > MAX_VERTICES {
            return Err(error(n_at, ParseErrorKind::PolygonTooLarge { most: MAX_VERTICES }));
        }
        let m = self.material(at)?;
        let mut v: Vec<Vec3<f64>, MAX_VERTICES> = Vec::new();
        let mut normals: Vec<Vec3<f64>, MAX_VERTICES> = Vec::new();
        for _ in 0..n {
            let _ = v.push(self.point()?);
            if patch {
                // A vertex's normal follows it on its line: one missing is reported there, not
                // where the numbers of the lines after it run out.
                let line = self.t.end.0;
                if self.t.peek().is_none_or(|w| w.0 > line) {
                    return Err(self.t.missing());
                }
                let _ = normals.push(self.point()?);
            }
        }
        if crosses_itself(&v) {
            return Err(error(at, ParseErrorKind::SelfIntersecting));
        }
        let (mut added, mut failed) = (0usize, None);
        triangulate(&v, |[a, b, c]| {
            let added_one = match normals.get(a).zip(normals.get(b)).zip(normals.get(c)) {
                Some(((&na, &nb), &nc)) => self.b.add_smooth_triangle([v[a], v[b], v[c]], [na, nb, nc], m),
                None => self.b.add_triangle([v[a], v[b], v[c]], m),
            };
            match (failed, added_one) {
                (None, Ok(())) => added += 1,
                (None, Err(SceneError::DegenerateTriangle)) => {}
                (None, Err(e)) => failed = Some(e),
                (Some(_), _) => {}
            }
        });
        match failed {
            Some(e) => Err(error(at, ParseErrorKind::Scene(e))),
            None if added == 0 => Err(error(at, ParseErrorKind::Scene(SceneError::DegenerateTriangle))),
            None => Ok(()),
        }
    }

    /// Adds the lights and ambient light (`sqrt(n) / (2 n)` each) and validates the scene.
    fn finish(mut self, camera: impl FnOnce(&mut CameraDesc)) -> Result<Scene<'a, R>, ParseError<'t>> {
        let n = self.lights.len() as f64;
        let each = if n > 0.0 { libm::sqrt(n) / (2.0 * n) } else { 0.0 };
        self.b.ambient = if n > 0.0 { each } else { 0.5 };
        for &(pos, gray, at) in &self.lights {
            self.b
                .add_light(Light::Point { pos, intensity: each * gray })
                .map_err(|e| error(at, ParseErrorKind::Scene(e)))?;
        }
        camera(&mut self.b.camera);
        // The camera's and the background's errors are the view's and the background's; the
        // rest are the scene's, blamed on its last entity.
        let blame = |e: &SceneError| match e {
            SceneError::DegenerateCamera | SceneError::BadFieldOfView | SceneError::OutOfRange { .. } => self.view,
            SceneError::ValueOutOfRange { what: "background", .. } => self.background,
            _ => None,
        };
        let last = self.last;
        self.b.finish().map_err(|e| error(blame(&e).unwrap_or(last), ParseErrorKind::Scene(e)))
    }
}
