//! What is wrong at a place of the scene text: [`ParseError`], its [`ParseErrorKind`], and
//! how an error message shows the token it blames.

use crate::scene::effects::MAX_DEPTH;
use crate::scene::SceneError;
use core::fmt;

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
