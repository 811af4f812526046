//! The effects a scene calls for ([`Effects`]) and the deepest intersection tree it may ask for
//! ([`MAX_DEPTH`]): worked out when the scene is validated, read by the tracer.

/// Deepest intersection tree the tracer supports (eye ray = depth 0).
pub const MAX_DEPTH: u8 = 8;

/// The effects a render simulates, as a typed flag set: the scene's own set ([`Effects::of`]),
/// a forced one, and at compile time the set a [`Tracer`](crate::Tracer) is built with (its const parameter
/// holds [`Effects::bits`], since a const parameter must be an integer).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Effects(u8);

impl Effects {
    /// No effect: ambient and diffuse shading only.
    pub const NONE: Self = Effects(0);
    /// Shadow rays towards lights.
    pub const SHADOWS: Self = Effects(1);
    /// Mirror-reflection rays (`Ks > 0`).
    pub const REFLECTION: Self = Effects(2);
    /// Refraction rays (`Kt > 0`).
    pub const REFRACTION: Self = Effects(4);
    /// Point lights (directional lights are always compiled in).
    pub const POINT_LIGHTS: Self = Effects(8);
    /// Composite objects, walked as sub-lattices.
    pub const COMPOSITES: Self = Effects(16);
    /// Phong highlights (a material with `Ks > 0` and a `shine` power).
    pub const HIGHLIGHTS: Self = Effects(32);
    /// Every effect.
    pub const ALL: Self = Effects(63);
    /// Names of the effects, lowest bit first.
    pub const NAMES: [&'static str; 6] =
        ["shadows", "reflection", "refraction", "point lights", "composites", "highlights"];

    /// The set as bits (for a [`Tracer`](crate::Tracer)'s const parameter).
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// The set with these bits; bits that name no effect are dropped.
    pub const fn from_bits(bits: u8) -> Self {
        Effects(bits & Self::ALL.0)
    }

    /// Whether every effect of `other` is in the set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether the set is empty.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The effects in either set.
    pub const fn union(self, other: Self) -> Self {
        Effects(self.0 | other.0)
    }

    /// The effects in this set and not in `other`.
    pub const fn difference(self, other: Self) -> Self {
        Effects(self.0 & !other.0)
    }
}

impl core::ops::BitOr for Effects {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        self.union(o)
    }
}

impl core::ops::Sub for Effects {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.difference(o)
    }
}

impl Effects {
    /// The names of the effects in the set (`shadows`, `reflection`, ...).
    pub fn names(self) -> impl Iterator<Item = &'static str> + Clone {
        Self::NAMES.iter().enumerate().filter(move |(i, _)| self.0 & (1 << i) != 0).map(|(_, n)| *n)
    }

    /// The pieces [`Display`](core::fmt::Display) and `defmt` write: the effects' names
    /// separated by ", ", or "diffuse only".
    fn words(self) -> impl Iterator<Item = &'static str> {
        let names = self.names();
        let none = names.clone().next().is_none().then_some("diffuse only");
        names.enumerate().flat_map(|(k, n)| [if k == 0 { "" } else { ", " }, n]).chain(none)
    }
}

impl core::fmt::Display for Effects {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.words().try_for_each(|w| f.write_str(w))
    }
}

/// Logged as the same words [`Display`](core::fmt::Display) writes.
#[cfg(feature = "defmt")]
impl defmt::Format for Effects {
    fn format(&self, f: defmt::Formatter<'_>) {
        self.words().for_each(|w| defmt::write!(f, "{=str}", w));
    }
}
