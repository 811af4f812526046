//! A planar polygon cut into triangles: ear clipping, for any simple polygon, convex or not
//! (the SPD's gears have faces of 144 vertices, their teeth concave), in either winding.

use crate::math::Vec3;
use heapless::Vec;

/// Most vertices of a polygon: 1,024 on a host (feature `alloc`), 64 on a microcontroller,
/// whose stack holds them while the polygon is cut.
pub const MAX_VERTICES: usize = if cfg!(feature = "alloc") { 1024 } else { 64 };

/// Calls `f` with `n - 2` triangles (indices into `v`, in the polygon's winding) that cover the
/// simple planar polygon `v`. An ear (a vertex whose triangle with its two neighbours turns the
/// polygon's way and holds no other vertex) is cut off until three vertices are left. Where no
/// such ear is left (vertices in a line, rounding), a vertex in a line with its neighbours is
/// cut off (a triangle of no area, which the caller leaves out), else the first turning one.
pub fn triangulate(v: &[Vec3<f64>], mut f: impl FnMut([usize; 3])) {
    let n = v.len().min(MAX_VERTICES);
    if n < 3 {
        return;
    }
    // Newell's normal; the polygon is seen along its largest axis, turning counter-clockwise.
    let mut normal = Vec3::zero();
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        normal = normal + Vec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    let axis = (0..3).max_by(|&i, &j| normal.axis(i).abs().total_cmp(&normal.axis(j).abs())).unwrap_or(2);
    let (s, t) = ((axis + 1) % 3, (axis + 2) % 3);
    let sign = if normal.axis(axis) < 0.0 { -1.0 } else { 1.0 };
    let p = |i: usize| [v[i].axis(s), v[i].axis(t)];
    let turn =
        |a: [f64; 2], b: [f64; 2], c: [f64; 2]| sign * ((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]));
    let mut left: Vec<u16, MAX_VERTICES> = (0..n as u16).collect();
    while left.len() > 3 {
        let len = left.len();
        let corner = |k: usize| (left[(k + len - 1) % len] as usize, left[k] as usize, left[(k + 1) % len] as usize);
        let ear = (0..len).find(|&k| {
            let (a, b, c) = corner(k);
            turn(p(a), p(b), p(c)) > 0.0
                && !left.iter().map(|&j| j as usize).any(|j| {
                    j != a && j != b && j != c && {
                        let q = p(j);
                        turn(p(a), p(b), q) >= 0.0 && turn(p(b), p(c), q) >= 0.0 && turn(p(c), p(a), q) >= 0.0
                    }
                })
        });
        let k = ear
            .or_else(|| {
                (0..len).find(|&k| {
                    let (a, b, c) = corner(k);
                    turn(p(a), p(b), p(c)) == 0.0
                })
            })
            .or_else(|| {
                (0..len).find(|&k| {
                    let (a, b, c) = corner(k);
                    turn(p(a), p(b), p(c)) > 0.0
                })
            })
            .unwrap_or(0);
        let (a, b, c) = corner(k);
        f([a, b, c]);
        left.remove(k);
    }
    f([left[0] as usize, left[1] as usize, left[2] as usize]);
}

/// Whether two edges of the planar polygon `v` that share no corner cross each other (a bow
/// tie): such a polygon has no inside to cut into triangles. Seen along the axis its plane
/// faces most (the largest cross product of two edges from the first corner, which a bow tie's
/// cancelling areas do not hide); edges that only touch or overlap in a line do not cross.
pub fn crosses_itself(v: &[Vec3<f64>]) -> bool {
    let n = v.len();
    if n < 4 {
        return false;
    }
    let normal = (2..n)
        .map(|k| (v[1] - v[0]).cross(v[k] - v[0]))
        .max_by(|a, b| a.max_abs().total_cmp(&b.max_abs()))
        .unwrap_or_else(Vec3::zero);
    let axis = (0..3).max_by(|&i, &j| normal.axis(i).abs().total_cmp(&normal.axis(j).abs())).unwrap_or(2);
    let (s, t) = ((axis + 1) % 3, (axis + 2) % 3);
    let p = |i: usize| [v[i % n].axis(s), v[i % n].axis(t)];
    let side = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        let x = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if x > 0.0 {
            1
        } else if x < 0.0 {
            -1
        } else {
            0
        }
    };
    (0..n).any(|i| {
        // Edge i runs from corner i to i + 1; the edges after i + 1 that do not close on i.
        (i + 2..n).filter(|&j| (j + 1) % n != i).any(|j| {
            let (a, b, c, d) = (p(i), p(i + 1), p(j), p(j + 1));
            side(a, b, c) * side(a, b, d) < 0 && side(c, d, a) * side(c, d, b) < 0
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bow_tie_crosses_itself_and_simple_polygons_do_not() {
        let poly = |pts: &[[f64; 2]], plane: usize| -> std::vec::Vec<Vec3<f64>> {
            pts.iter()
                .map(|&[a, b]| match plane {
                    0 => Vec3::new(a, b, 3.0),
                    1 => Vec3::new(a, 3.0, b),
                    _ => Vec3::new(3.0, a, b),
                })
                .collect()
        };
        for plane in 0..3 {
            assert!(crosses_itself(&poly(&[[-2.0, -1.0], [2.0, 1.0], [2.0, -1.0], [-2.0, 1.0]], plane)));
            assert!(!crosses_itself(&poly(&[[-2.0, -1.0], [2.0, -1.0], [2.0, 1.0], [-2.0, 1.0]], plane)));
            // Concave (an arrow head) and a repeated corner: simple.
            assert!(!crosses_itself(&poly(&[[0.0, 0.0], [2.0, 1.0], [0.0, 2.0], [1.0, 1.0]], plane)));
            assert!(!crosses_itself(&poly(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], plane)));
            // A pentagram crosses itself.
            let star: std::vec::Vec<[f64; 2]> = (0..5)
                .map(|k| {
                    let a = (k * 2 % 5) as f64 * core::f64::consts::TAU / 5.0;
                    [libm::cos(a), libm::sin(a)]
                })
                .collect();
            assert!(crosses_itself(&poly(&star, plane)));
        }
    }

    fn area(v: &[Vec3<f64>], t: [usize; 3]) -> f64 {
        (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).length() / 2.0
    }

    #[test]
    fn a_concave_polygon_is_covered_by_triangles_inside_it() {
        // A comb with two teeth in the plane z = 1, clockwise and counter-clockwise.
        let pts = [(0.0, 0.0), (5.0, 0.0), (5.0, 3.0), (4.0, 3.0), (4.0, 1.0), (3.0, 1.0), (3.0, 3.0), (0.0, 3.0)];
        for reverse in [false, true] {
            let mut v: std::vec::Vec<Vec3<f64>> = pts.iter().map(|&(x, y)| Vec3::new(x, y, 1.0)).collect();
            if reverse {
                v.reverse();
            }
            let mut tris = std::vec::Vec::new();
            triangulate(&v, |t| tris.push(t));
            assert_eq!(tris.len(), v.len() - 2);
            let total: f64 = tris.iter().map(|&t| area(&v, t)).sum();
            assert!((total - (15.0 - 2.0)).abs() < 1e-12, "{total}");
            // No triangle covers the notch between the teeth (its centre 3.5, 2).
            for &t in &tris {
                let c = (v[t[0]] + v[t[1]] + v[t[2]]) * (1.0 / 3.0);
                assert!(!(c.x > 3.0 && c.x < 4.0 && c.y > 1.0), "{t:?}");
            }
        }
    }

    #[test]
    fn a_convex_polygon_with_a_vertex_in_line_gives_n_minus_2_triangles() {
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let mut tris = std::vec::Vec::new();
        triangulate(&v, |t| tris.push(t));
        assert_eq!(tris.len(), 3);
        let total: f64 = tris.iter().map(|&t| area(&v, t)).sum();
        assert!((total - 4.0).abs() < 1e-12);
    }
}
