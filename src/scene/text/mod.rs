//! The plain-text scene format, parsed without allocation (firmware can `include_str!` the same
//! files the desktop reads). The format is documented in `docs/scene-format.md`.
//!
//! One statement per line, `#` starts a comment. Every error names the line and column (1-based,
//! columns count bytes), the offending token and the reason. Parsing feeds a
//! [`SceneBuilder`](crate::scene::SceneBuilder), which validates each object as it arrives, so
//! range errors also point at their line.

mod error;
mod locate;
mod parser;
mod suggest;
mod words;

pub use error::{ParseError, ParseErrorKind, SHOWN_TOKEN};
pub use locate::{camera_statement, object_count, object_statement, OBJECT_KEYWORDS};
pub use parser::{parse, parse_with};
pub use words::{parse_number, text_from_bytes};

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
