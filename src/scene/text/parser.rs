//! The parser: one statement at a time into a [`SceneBuilder`], each value blamed on its
//! line and column when it is refused, and scene-wide errors on the statement behind them.

use super::error::{ParseError, ParseErrorKind};
use super::locate::{object_count, object_statement};
use super::suggest::{attributes, edit_distance};
use super::words::{lines, Words};
use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::scene::effects::MAX_DEPTH;
use crate::scene::{CameraDesc, Light, Material, Object, Parts, Scene, SceneBuilder, SceneError, IOR, MAX_MATERIALS};
use crate::shape::Shape;
use heapless::Vec;

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
