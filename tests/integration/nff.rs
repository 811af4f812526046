//! NFF in: every entity of `NFF.TXT` read, what the tracer cannot draw refused by name, and
//! every error placed at its line and column.

use crate::common;
use common::{build_lattice, gray_of, lattice_storage};
use lattice_rt::scene::nff;
use lattice_rt::scene::{Format, Light, Object, Parts};
use lattice_rt::Shape;

const SCENE: &str = "\
# a comment, then every entity
v
from 0 -10 2
at 0 0 0
up 0 0 1
angle 45
hither 0.01
resolution 512 512
b 0.2 0.4 0.6
l 5 -5 5
l -5 -5 5 1 0.5 0.5
f 1 0 0 0.8 0.2 30 0 1
s 0 0 1 1
c 2 0 0 0.5 2 0 2 0.5
c -2 0 0 0.8 -2 0 1.5 0.2   # a cone
p 4
-5 -5 0
5 -5 0
5 5 0
-5 5 0
f 0.5 0.5 0.5 0.5 0.5 0 0.5 1.5
pp 3
0 3 0 0 0 1
1 3 0 0 0 1
0 4 0 0 0 1
";

fn read(text: &str) -> Result<(Vec<Object<f64>>, usize), String> {
    let mut storage = vec![Object::<f64>::default(); nff::object_count(text).max(1)];
    let mut parts = Parts::default();
    let scene = nff::parse_with::<f64>(text, &mut storage, &mut parts, |_| {}).map_err(|e| e.to_string())?;
    Ok((scene.objects().to_vec(), scene.lights().len()))
}

fn err(text: &str) -> String {
    read(text).err().unwrap_or_else(|| panic!("accepted:\n{text}"))
}

#[test]
fn every_entity_is_read() {
    assert_eq!(Format::of(SCENE), Format::Nff);
    assert_eq!(Format::of("sphere radius 1"), Format::Text);
    assert_eq!(nff::object_count(SCENE), 1 + 2 + 2 + 1);
    let mut storage = vec![Object::<f64>::default(); 6];
    let mut parts = Parts::default();
    let scene = nff::parse_with::<f64>(SCENE, &mut storage, &mut parts, |_| {}).unwrap();
    let kinds: Vec<usize> = scene.objects().iter().map(|o| o.shape().kind()).collect();
    let (sphere, open, triangle) =
        (Shape::<f64>::Sphere.kind(), Shape::Open { top: 1.0 }.kind(), Shape::<f64>::Triangle.kind());
    assert_eq!(kinds, [sphere, open, open, triangle, triangle, triangle]);
    assert_eq!(scene.objects()[1].shape(), Shape::Open { top: 1.0 });
    assert_eq!(scene.objects()[2].shape(), Shape::Open { top: 0.25 });
    // Two lights of sqrt(2) / 4 each, the second times its colour's gray; the ambient too.
    let each = 2f64.sqrt() / 4.0;
    let gray = nff::luminance(1.0, 0.5, 0.5);
    let intensities: Vec<f64> = scene
        .lights()
        .iter()
        .map(|l| match *l {
            Light::Point { intensity, .. } | Light::Directional { intensity, .. } => intensity,
        })
        .collect();
    assert_eq!(intensities, [each, each * gray]);
    assert_eq!(scene.ambient(), each);
    assert_eq!(scene.background(), nff::luminance(0.2, 0.4, 0.6));
    // Two materials: the red one's Kd times its gray, Ks, the power; the glass's T and index.
    let m = scene.materials();
    assert_eq!(m.len(), 2);
    assert_eq!((m[0].kd, m[0].ks, m[0].shine, m[0].kt), (0.8 * nff::luminance(1.0, 0.0, 0.0), 0.2, 30, 0.0));
    assert_eq!((m[1].kt, m[1].ior), (0.5, 1.5));
}

#[test]
fn equal_materials_are_stored_once() {
    let text = "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 40\nl 0 -5 5\nf 1 1 1 1 0 0 0 1\ns 0 0 0 1\nf 1 1 1 1 0 0 0 1\ns 2 0 0 1\n";
    let mut storage = vec![Object::<f64>::default(); 2];
    let mut parts = Parts::default();
    let scene = nff::parse_with::<f64>(text, &mut storage, &mut parts, |_| {}).unwrap();
    assert_eq!(scene.materials().len(), 1);
}

#[test]
fn what_cannot_be_drawn_is_refused_by_name_at_its_place() {
    let view = "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 40\n";
    assert_eq!(
        err(&format!("{view}s 0 0 0 -1\n")),
        "line 2, column 9 at `-1`: a negative radius (NFF's inside-only surface): not drawn by this tracer; give the radius as positive"
    );
    assert_eq!(
        err(&format!("{view}c 0 0 0 -1\n0 0 1 -1\n")),
        "line 2, column 9 at `-1`: a negative radius (NFF's inside-only surface): not drawn by this tracer; give the radius as positive"
    );
    assert_eq!(
        err(&format!("{view}p 2\n0 0 0\n1 0 0\n")),
        "line 2, column 3 at `2`: a polygon's vertex count must be a whole number, at least 3"
    );
    assert_eq!(
        err(&format!("{view}p 3\n0 0 0\n1 0 0\n2 0 0\n")),
        "line 2, column 1 at `p`: the polygon's corners lie on one line: it has no area"
    );
    assert_eq!(
        err(&format!("{view}c 1 1 1 1\n1 1 1 1\n")),
        "line 2, column 1 at `c`: the cone's base and apex are the same point"
    );
    assert_eq!(
        err(&format!("{view}t 0 0 0\n")),
        "line 2, column 1 at `t`: unknown NFF entity (expected v, b, l, f, c, s, p, pp or a # comment)"
    );
    assert_eq!(err(&format!("{view}s 0 0 zero 1\n")), "line 2, column 7 at `zero`: expected a number");
    assert!(err(&format!("{view}s 0 0 nan 1\n")).starts_with("line 2, column 7 at `nan`: "));
    assert!(err(&format!("{view}s 0 0 1e999 1\n")).starts_with("line 2, column 7 at `1e999`: number out of range"));
    // A value missing is reported just past the entity's last word, on its own line.
    assert_eq!(err(&format!("{view}s 0 0 0\n")), "line 2, column 8: a value is missing at the end of the line");
    assert_eq!(
        err("v from 0 -5 0 at 0 0 0 angle 40\ns 0 0 0 1\n"),
        "line 1, column 1 at `v`: the view needs its `up` line"
    );
    assert_eq!(
        err(&format!("{view}f 1 1 1 1 0 0 0.5 0.5\ns 0 0 0 1\n")),
        "line 2, column 19 at `0.5`: coefficients must be >= 0 and the index of refraction >= 1"
    );
}

#[test]
fn the_view_angle_spans_the_edge_pixels_centres() {
    // 45 degrees between the centres of the edge pixels of 512: the frame's edges are half a
    // pixel further out on each side.
    let text = "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45 resolution 512 512\ns 0 0 0 1\n";
    let mut storage = vec![Object::<f64>::default(); 1];
    let mut parts = Parts::default();
    let scene = nff::parse_with::<f64>(text, &mut storage, &mut parts, |_| {}).unwrap();
    let c = scene.camera();
    // The default frame is 2:1, so the view's limit is its height.
    let half = c.up.length();
    let want = (22.5f64).to_radians().tan() * 512.0 / 511.0;
    assert!((half - want).abs() < 1e-12, "{half} {want}");
}

/// A triangle facing the eye (normal -z), lit head-on, as `p` or as `pp` with the normals
/// given for its corners (0 0), (4 0), (0 4).
fn facing_triangle(normals: Option<[[f64; 3]; 3]>) -> String {
    let corners = [[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [-2.0, 2.0, 0.0]];
    let mut t = String::from("v\nfrom 0 0 -10\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 32 32\n");
    t.push_str("l 0 0 -20\nf 1 1 1 1 0 0 0 1\n");
    t.push_str(if normals.is_some() { "pp 3\n" } else { "p 3\n" });
    for (k, c) in corners.iter().enumerate() {
        let n = normals.map(|n| format!(" {} {} {}", n[k][0], n[k][1], n[k][2])).unwrap_or_default();
        t.push_str(&format!("{} {} {}{n}\n", c[0], c[1], c[2]));
    }
    t
}

fn gray(text: &str) -> Vec<u8> {
    let frame = lattice_rt::Frame::new(32, 32);
    let mut storage = vec![Object::<f64>::default(); 4];
    let mut parts = Parts::default();
    let scene = lattice_rt::scene::parse_with::<f64>(text, &mut storage, &mut parts, |c| c.frame = [32, 32]).unwrap();
    let cfg = lattice_rt::LatticeConfig::default();
    let mut bufs = lattice_storage(&scene, &cfg);
    let lat = build_lattice(&scene, &cfg, &mut bufs);
    gray_of(&lattice_rt::Tracer::new(&scene, &lat), &frame)
}

#[test]
fn patch_normals_shade_smoothly() {
    let flat = gray(&facing_triangle(None));
    // Normals equal to the face's (either way round) shade as the flat triangle does.
    assert_eq!(gray(&facing_triangle(Some([[0.0, 0.0, -1.0]; 3]))), flat);
    assert_eq!(gray(&facing_triangle(Some([[0.0, 0.0, 2.0]; 3]))), flat);
    // Tilted at two corners: darker towards them, as bright as flat where the normal is the
    // face's, and the same pixels covered (the outline stays the flat triangle's).
    let tilted = gray(&facing_triangle(Some([[0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]])));
    let background = flat[0];
    let covered = |g: &[u8]| g.iter().map(|&v| v != background).collect::<Vec<_>>();
    assert_eq!(covered(&tilted), covered(&flat));
    let lit: Vec<(usize, u8, u8)> =
        (0..flat.len()).filter(|&i| flat[i] != background).map(|i| (i, flat[i], tilted[i])).collect();
    assert!(lit.len() > 50, "{} pixels", lit.len());
    assert!(lit.iter().all(|&(_, f, t)| t <= f), "no pixel brighter than flat");
    // Row 31 - y, column x: the corner (-2, -2) is at the bottom left, (2, -2) bottom right.
    let at = |x: usize, y: usize| lit.iter().find(|p| p.0 == y * 32 + x).map(|p| (p.1, p.2));
    let near_a = at(9, 22).expect("the pixel near the corner a is covered");
    let near_b = at(22, 24).expect("the pixel near the corner b is covered");
    assert!(near_a.1 + 2 >= near_a.0, "near a {near_a:?}");
    assert!(near_b.1 + 8 < near_b.0, "near b {near_b:?}");
}

#[test]
fn smooth_normals_interpolate_and_face_the_ray() {
    use lattice_rt::scene::Smooth;
    use lattice_rt::Vec3;
    let n = [Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)];
    let s = Smooth { object: 0, normals: n };
    let up = Vec3::new(0.0, 1.0, 0.0);
    let close = |a: Vec3<f64>, b: Vec3<f64>| (a - b).length() < 1e-12;
    assert!(close(s.normal(Vec3::new(0.0, 0.0, 0.0), up), n[0]));
    assert!(close(s.normal(Vec3::new(1.0, 0.0, 0.0), up), n[1]));
    assert!(close(s.normal(Vec3::new(0.0, 0.0, 1.0), up), n[2]));
    let third = 1.0 / 3.0;
    let mid = s.normal(Vec3::new(third, 0.0, third), up);
    assert!(close(mid, Vec3::new(1.0, 1.0, 1.0).normalize()), "{mid:?}");
    // Met from the other side: turned round.
    assert!(close(s.normal(Vec3::new(third, 0.0, third), -up), -mid));
}

/// Hostile NFF, each case with the line, column and reason its error must give (issue 88): the
/// camera's and the background's errors at `v` and `b`, not at the last entity; each word of
/// `f` at its own column; a value missing just past the entity's last word, on its line; a
/// byte-order mark and lone CRs read as an editor shows them.
#[test]
fn hostile_nff_is_refused_at_its_place_for_its_reason() {
    let view = "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 40\n";
    let sphere = "s 0 0 0 1\n";
    let cases: Vec<(String, &str, &str)> = vec![
        (
            format!("v from 0 -5 0 at 0 -5 0 up 0 0 1 angle 40\n{sphere}s 1 1 1 1\n"),
            "line 1, column 1 at `v`",
            "camera",
        ),
        (format!("v from 0 -5 0 at 0 0 0 up 0 0 0 angle 40\n{sphere}"), "line 1, column 1 at `v`", "camera"),
        (format!("v from 0 -5 0 at 0 0 0 up 0 1 0 angle 40\n{sphere}"), "line 1, column 1 at `v`", "camera"),
        (format!("v from 0 1e200 -10 at 0 0 0 up 0 0 1 angle 40\n{sphere}"), "line 1, column 1 at `v`", ""),
        (format!("{view}b 1e300 1e300 1e300\n{sphere}s 2 0 0 1\n"), "line 2, column 1 at `b`", "background"),
        (format!("{view}b 1e308 1e308 1e308\n{sphere}"), "line 2, column 1 at `b`", "background"),
        (
            format!("{view}v from 0 -5 0 at 0 0 0 up 0 0 1 angle 40 resolution 0 0\n{sphere}"),
            "line 2, column 42 at `resolution`",
            "resolution",
        ),
        (format!("{view}f 1 -1 1 1 0 0 0 1\n{sphere}"), "line 2, column 5 at `-1`", "colour"),
        (format!("{view}f 1 1 1 -1 0 0 0 1\n{sphere}"), "line 2, column 9 at `-1`", "coefficients"),
        (format!("{view}f 1 1 1 1 0 0 0.5 0.5\n{sphere}"), "line 2, column 19 at `0.5`", "index of refraction"),
        (format!("{view}f 1e200 1e200 1e200 1e200 0 0 0 1\n{sphere}"), "line 2, column 21 at `1e200`", "out of range"),
        (format!("{view}l 0 0 5 1 -0.5 1\n{sphere}"), "line 2, column 11 at `-0.5`", "colour"),
        (format!("{view}s 0 0 0 6e102\n"), "line 2, column 1 at `s`", "out of range"),
        (format!("{view}s 0 0 0\ns 1 1 1 1\n"), "line 2, column 8", "missing"),
        (format!("{view}pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0\n"), "line 5, column 6", "missing"),
        (format!("{view}pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0\ns 0 0 0 1\n"), "line 5, column 6", "missing"),
        // A normal missing mid-polygon, at its vertex's line, not where the numbers run out.
        (format!("{view}pp 3\n0 0 0 0 0 1\n1 0 0\n0 1 0 0 0 1\ns 0 0 3 1\n"), "line 4, column 6", "missing"),
        (format!("{view}pp 3\n0 0 0\n1 0 0 0 0 1\n0 1 0 0 0 1\n"), "line 3, column 6", "missing"),
        (format!("{view}p 3\n0 0 0\n1 0 0\n"), "line 4, column 6", "missing"),
        (format!("{view}p 3000000\n"), "line 2, column 3 at `3000000`", "more vertices"),
        (format!("{view}p 18446744073709551615\n"), "line 2, column 3 at `18446744073709551615`", "more vertices"),
        (format!("{view}p 4\n-2 -1 0\n2 1 0\n2 -1 0\n-2 1 0\n"), "line 2, column 1 at `p`", "cross"),
        (format!("{view}p 4\n0 -2 -1\n0 2 1\n0 2 -1\n0 -2 1\n"), "line 2, column 1 at `p`", "cross"),
        (format!("\u{feff}{view}s 0 0 0 -1\n"), "line 2, column 9 at `-1`", "negative radius"),
        (format!("{}\rs 0 0 0 -1\r", view.trim_end()), "line 2, column 9 at `-1`", "negative radius"),
        (format!("{}\rs 0 0 0\rs 1 1 1 1\r", view.trim_end()), "line 2, column 8", "missing"),
    ];
    for (text, place, reason) in &cases {
        let mut storage = vec![Object::<f64>::default(); lattice_rt::scene::object_count(text).clamp(1, 1 << 16)];
        let mut parts = Parts::default();
        let e = match lattice_rt::scene::parse::<f64>(text, &mut storage, &mut parts) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e.to_string(),
        };
        assert!(e.starts_with(&format!("{place}:")), "{text:?}\n  gave {e}\n  want {place}");
        assert!(e.contains(reason), "{text:?}\n  gave {e}\n  want the reason `{reason}`");
    }
}

/// `pp` normals of any finite length shade as the same normals of length 1 (a normal of
/// 1e200 squared overflows, one of 1e-200 vanishes: neither may fall back to the flat shading).
#[test]
fn patch_normals_of_any_length_keep_their_direction() {
    let tilt = [[0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]];
    let unit = gray(&facing_triangle(Some(tilt)));
    assert_ne!(unit, gray(&facing_triangle(None)), "the tilted normals shade unlike the flat face");
    for scale in [1e300, 1e200, 1e-200, 1e-300] {
        let scaled = tilt.map(|n| n.map(|c| c * scale));
        assert_eq!(gray(&facing_triangle(Some(scaled))), unit, "normals scaled by {scale}");
    }
}

/// One line of 20,000 spheres reads in time linear in its length: as fast, to a small factor,
/// as the same spheres one per line (it was quadratic: columns counted from the line's start).
#[test]
fn one_long_line_reads_as_fast_as_many() {
    let spheres = |sep: &str| {
        let mut t = String::from("v from 0 -50 0 at 0 0 0 up 0 0 1 angle 40\nl 0 -50 50\n");
        for i in 0..20_000 {
            t.push_str(&format!("s {} {} 0 0.4{sep}", i % 200, i / 200));
        }
        t
    };
    let time = |text: &str| {
        let start = std::time::Instant::now();
        let (objects, _) = read(text).expect("read");
        assert_eq!(objects.len(), 20_000);
        start.elapsed()
    };
    let (lines, line) = (spheres("\n"), spheres(" "));
    let (a, b) = (time(&lines), time(&line));
    // Quadratic, one line took 40 times as long as 20,000 lines; linear, about the same.
    assert!(b < a * 5 + std::time::Duration::from_millis(50), "one line {b:?}, one per line {a:?}");
}
