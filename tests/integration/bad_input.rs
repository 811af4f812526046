//! Bad input never gives a wrong picture: every class of docs/robustness.md's "Bad input" table
//! that concerns the core, in every scalar it concerns. A scene is either refused with the
//! line and column of what is at fault, or it renders right.

use crate::common;
use common::*;
use lattice_rt::scene::text::text_from_bytes;
use lattice_rt::scene::Object;
use lattice_rt::{parse, Frame, Fx, LatticeConfig, Real, Tracer};

/// The error message for `text` in `R` (panics if the scene is accepted).
fn err<R: Real>(text: &str) -> String {
    let mut storage = vec![Object::<R>::default(); 16];
    let mut parts = lattice_rt::Parts::default();
    match parse::<R>(text, &mut storage, &mut parts) {
        Ok(_) => panic!("{} accepted:\n{text}", R::NAME),
        Err(e) => e.to_string(),
    }
}

/// Whether `text` is accepted in `R`.
fn accepted<R: Real>(text: &str) -> bool {
    let mut storage = vec![Object::<R>::default(); 16];
    let mut parts = lattice_rt::Parts::default();
    parse::<R>(text, &mut storage, &mut parts).is_ok()
}

/// Gray levels of `text` in `R` (lattice, the scene's own effects and depth).
fn gray<R: Real>(text: &str, frame: &Frame) -> Vec<u8> {
    let mut storage = vec![Object::<R>::default(); 16];
    let mut parts = lattice_rt::Parts::default();
    let scene =
        parse_for::<R>(text, &mut storage, &mut parts, frame.size()).unwrap_or_else(|e| panic!("{}: {e}", R::NAME));
    let cfg = LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    gray_of(&Tracer::new(&scene, &lat), frame)
}

/// A glass pane `thick` thick in front of a sphere on a floor.
fn pane(thick: f64) -> String {
    format!(
        "camera eye 0.3 0.5 -6\nlight directional dir -1 -2 1\nmaterial glass ka 0.1 kd 0.1 kt 0.8 ior 1.5\n\
         box min -2 -2 0 max 2 2 {thick} material glass rotate y 10\nsphere center 0 0 3 radius 1\n\
         box min -10 -3 -5 max 10 -2 10\n"
    )
}

// Class 2: thin geometry.
#[test]
fn a_pane_thinner_than_the_ray_offset_is_refused_naming_it_and_the_smallest_size() {
    let text = pane(1e-5);
    let msg = err::<f32>(&text);
    assert!(msg.starts_with("line 4, column 1 at `box`: object 0 is too thin for this scene in f32: it is 1e-5 across, the smallest this scalar traces here is 3e-5"), "{msg}");
    // Fixed point finds it too small for its object-space range first.
    let msg = err::<Fx>(&text);
    assert!(msg.starts_with("line 4, column 1 at `box`: object 0 is too small for this scene in fixed"), "{msg}");
    assert!(accepted::<f64>(&text));
}

#[test]
fn a_thin_pane_that_is_accepted_renders_as_in_f64() {
    let frame = Frame::new(96, 64);
    // Thin, yet thick enough for f32 (its limit here is about 3e-5: the pane's own offset).
    for thick in [1e-3, 1e-4] {
        let text = pane(thick);
        assert!(accepted::<f32>(&text));
        let off = share_off(&gray::<f32>(&text, &frame), &gray::<f64>(&text, &frame));
        assert!(off < 0.01, "pane {thick}: f32 against f64: {:.1} % of pixels more than one level off", off * 100.0);
    }
    // The 1e-5 pane in f64 renders like a slightly thicker one (no pixel of the sphere is lost).
    let thin = gray::<f64>(&pane(1e-5), &frame);
    let thicker = gray::<f64>(&pane(1e-4), &frame);
    assert!(share_off(&thin, &thicker) < 0.01);
}

// Class 3: numbers other than coordinates, against the scalar's range, at their column.
#[test]
fn shading_numbers_beyond_the_scalar_are_refused_at_their_column() {
    let lights = "light directional dir 0 -1 0 intensity 6000\nlight directional dir 0 -1 0 intensity -6000\nsphere\n";
    assert_eq!(
        err::<Fx>(lights),
        "line 1, column 40 at `6000`: brightness out of range for fixed: lights, ambient, background and coefficients add up to 9600 along one ray, the limit is 8192 (lower the intensities, or keep ks + kt near 1 or below)"
    );
    assert_eq!(
        err::<Fx>("ambient 9000\nsphere"),
        "line 1, column 9 at `9000`: ambient out of range for fixed: magnitude must stay below 8192"
    );
    assert_eq!(
        err::<f32>("material glass kt 0.5 ior 1e39\nsphere material glass"),
        "line 1, column 27 at `1e39`: index of refraction out of range for f32: magnitude must stay below 8192"
    );
    assert_eq!(
        err::<f64>("light point pos 0 5 0 intensity 1e200\nsphere"),
        "line 1, column 33 at `1e200`: light intensity out of range for f64: magnitude must stay below 1e150"
    );
    assert_eq!(
        err::<Fx>("background -1e5\nsphere"),
        "line 1, column 12 at `-1e5`: background out of range for fixed: magnitude must stay below 8192"
    );
    assert_eq!(
        err::<Fx>("material m ks 3 kt 3\nsphere material m"),
        "line 1, column 15 at `3`: brightness out of range for fixed: lights, ambient, background and coefficients add up to 80620 along one ray, the limit is 8192 (lower the intensities, or keep ks + kt near 1 or below)"
    );
    // Ordinary mirrors and glass stay well inside every scalar.
    let ok = "light directional dir 0 -1 0 intensity 2\nmaterial m ks 0.7 kt 0.6 ior 2.4\nsphere material m\n";
    assert!(accepted::<Fx>(ok) && accepted::<f32>(ok) && accepted::<f64>(ok));
}

// Class 6: the error names the statement at fault.
#[test]
fn an_object_whose_padded_box_leaves_the_range_is_blamed_on_its_own_line() {
    let text = "camera eye 0 0 -10\nsphere center 8191 0 0 radius 0.9\nsphere\n";
    let msg = err::<Fx>(text);
    assert!(msg.starts_with("line 2, column 1 at `sphere`: coordinate out of range for fixed"), "{msg}");
}

#[test]
fn a_singular_group_transform_is_blamed_on_the_group() {
    assert_eq!(
        err::<f64>("sphere\ngroup g scale 1 0 1\nsphere\nend\n"),
        "line 2, column 1 at `group`: transform is singular (zero or near-zero scale)"
    );
    assert_eq!(
        err::<f64>("group g\nsphere\nend\ngroup h rotate y 30 scale 0 1 1 translate 1 2 3\nbox\nend\n"),
        "line 4, column 1 at `group`: transform is singular (zero or near-zero scale)"
    );
}

#[test]
fn an_object_scaled_to_nothing_is_refused_in_every_scalar() {
    for text in [
        "sphere\nsphere scale 1e-300\n",
        "sphere\nbox scale 1 1e-250 1\n",
        "sphere\ngroup g scale 1e-80\ncone scale 1e-80\nend\n",
    ] {
        for msg in [err::<f64>(text), err::<f32>(text), err::<Fx>(text)] {
            let line = if text.contains("group") { "line 3, column 1 at `cone`" } else { "line 2, column 1 at" };
            // Refused on its own line: singular where the determinant underflows to zero.
            assert!(
                msg.starts_with(line) && (msg.contains("object 1 is too") || msg.contains("singular")),
                "{text:?}: {msg}"
            );
        }
    }
}

#[test]
fn directions_too_short_to_normalise_are_refused() {
    assert_eq!(
        err::<f64>("light directional dir 1e-320 0 0\nsphere"),
        "line 1, column 1 at `light`: light direction is zero"
    );
    assert_eq!(
        err::<f64>("camera eye 0 0 0 look 1e-320 0 1e-320\nsphere"),
        "line 1, column 1 at `camera`: camera looks nowhere or straight along its up vector"
    );
    assert_eq!(
        err::<f64>("camera up 1e-320 1e-320 0\nsphere"),
        "line 1, column 1 at `camera`: camera looks nowhere or straight along its up vector"
    );
    assert!(accepted::<f64>("camera up 1e300 1e300 0\nlight directional dir 1e300 -1e300 0\nsphere"));
}

// Class 7: encodings, line endings, numbers out of range, tokens that cannot be echoed.
#[test]
fn invalid_utf8_is_reported_at_its_line_and_column() {
    let e = text_from_bytes(b"sphere\n# caf\xe9 au lait\nsphere\n").unwrap_err();
    assert_eq!(e.to_string(), "line 2, column 6: not UTF-8 text (byte 0xe9)");
    let e = text_from_bytes(b"sphere\r\rbox \xff").unwrap_err();
    assert_eq!(e.to_string(), "line 3, column 5: not UTF-8 text (byte 0xff)");
    assert_eq!(text_from_bytes(b"sphere\n").unwrap(), "sphere\n");
}

#[test]
fn a_byte_order_mark_and_every_line_ending_parse_alike() {
    let plain = "camera eye 0 0 -10\nsphere\nbox min 1 1 1 max 2 2 2\n";
    for text in [format!("\u{feff}{plain}"), plain.replace('\n', "\r\n"), plain.replace('\n', "\r")] {
        let mut storage = vec![Object::<f64>::default(); 4];
        let mut parts = lattice_rt::Parts::default();
        let scene = parse::<f64>(&text, &mut storage, &mut parts).unwrap_or_else(|e| panic!("{text:?}: {e}"));
        assert_eq!(scene.objects().len(), 2);
    }
    // Line numbers count CR-only lines too.
    assert_eq!(
        err::<f64>("sphere\rsphere\rcone material gold"),
        "line 3, column 15 at `gold`: material not defined before this line"
    );
}

#[test]
fn zero_is_zero_whatever_its_exponent() {
    for zero in ["0e999", "-0e999", "0.000e-999", "0e0"] {
        let text = format!("sphere center {zero} 0 0");
        let mut storage = vec![Object::<f64>::default(); 1];
        let mut parts = lattice_rt::Parts::default();
        let scene = parse::<f64>(&text, &mut storage, &mut parts).unwrap_or_else(|e| panic!("{zero}: {e}"));
        let mut parts = lattice_rt::Parts::default();
        let expected = parse::<f64>("sphere center 0 0 0", &mut vec![Object::<f64>::default(); 1], &mut parts)
            .unwrap()
            .objects()[0]
            .origin();
        assert_eq!(scene.objects()[0].origin(), expected, "{zero}");
    }
    // Tiny non-zero numbers underflow to zero as f64 itself rounds them.
    assert!(accepted::<f64>("sphere center 1e-999 0 0"));
}

#[test]
fn numbers_and_transforms_beyond_f64_say_out_of_range() {
    assert_eq!(
        err::<f64>("sphere center 1e999 0 0"),
        "line 1, column 15 at `1e999`: number out of range: beyond the largest f64 (about 1.8e308)"
    );
    assert_eq!(
        err::<f64>("ambient -1e400\nsphere"),
        "line 1, column 9 at `-1e400`: number out of range: beyond the largest f64 (about 1.8e308)"
    );
    assert_eq!(
        err::<f64>("sphere scale 1e200 scale 1e200"),
        "line 1, column 20 at `scale`: transform out of range: its entries, composed or multiplied, overflow (more than 1e308)"
    );
    assert_eq!(err::<f64>("sphere center nan 0 0"), "line 1, column 15 at `nan`: number is not finite");
}

#[test]
fn a_large_exact_shear_is_not_singular() {
    // Determinant 1: invertible. Sheared by 1e12 the cube is a slab 1e-12 thick and 1e12 long:
    // too thin for f64 (too small in f32), out of range for fixed point; never "singular".
    let text = "camera eye 0 0 -10\nbox shear x y 1e12\n";
    let msg = err::<f64>(text);
    assert!(
        msg.starts_with("line 2, column 1 at `box`: object 0 is too thin") && msg.contains("1e-12 across"),
        "{msg}"
    );
    let msg = err::<f32>(text);
    assert!(msg.starts_with("line 2, column 1 at `box`: object 0 is too small for this scene in f32"), "{msg}");
    let msg = err::<Fx>(text);
    assert!(msg.starts_with("line 2, column 1 at `box`: coordinate out of range for fixed"), "{msg}");
    // A shear by 1000 is traced in floats.
    assert!(accepted::<f64>("camera eye 0 0 -10\nbox shear x y 1e3\n"));
}

#[test]
fn long_tokens_are_cut_and_control_characters_escaped() {
    let long = "x".repeat(1 << 20);
    let msg = err::<f64>(&format!("sphere {long}"));
    assert!(msg.len() < 200, "{} bytes", msg.len());
    assert!(msg.contains(&format!("`{}... (1048576 bytes)`", "x".repeat(40))), "{msg}");
    let msg = err::<f64>("sphere \u{1b}[2J\u{1b}]0;owned\u{7}");
    assert!(!msg.contains('\u{1b}') && !msg.contains('\u{7}'), "{msg:?}");
    assert!(msg.contains("\\u{1b}[2J\\u{1b}]0;owned\\u{7}"), "{msg}");
    let msg = err::<f64>("\u{202e}sphere");
    assert!(msg.contains("\\u{202e}sphere") && !msg.contains('\u{202e}'), "{msg}");
}

// Class 8: a shear names two different axes.
#[test]
fn a_same_axis_shear_is_refused() {
    assert_eq!(
        err::<f64>("sphere shear x x 1"),
        "line 1, column 16 at `x`: a shear needs two different axes (`shear x y K`: x gains K times y)"
    );
    assert_eq!(
        err::<f64>("group g shear z z 2\nsphere\nend"),
        "line 1, column 17 at `z`: a shear needs two different axes (`shear x y K`: x gains K times y)"
    );
}
