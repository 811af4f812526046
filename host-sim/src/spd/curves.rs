//! The SPD generators whose scenes are spheres, cylinders and cones (and at most one background
//! polygon): `balls`, `rings`, `tree`, `lattice`, `jacks`, `shells`, as their C sources
//! (`src/*.c` of the SPD) compute them, in the same order of operations so that every number
//! prints as theirs does.

use super::nff::{axis_rotate, multiply, normalize, rotate, transform_coord, transform_point, Axis, Coord4, Writer};
use super::nff::{Matrix, IDENTITY};
use std::f64::consts::PI;

/// The SPD's sky blue background.
const SKY: [f64; 3] = [0.078, 0.361, 0.753];

/// `balls` (the sphereflake): 1 + 9 + ... + 9^size spheres on a floor polygon.
pub fn balls(size: u32) -> String {
    let mut w = Writer::new();
    w.background(SKY);
    w.viewpoint([2.1, 1.3, 1.7], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 45.0, 0.01, [512, 512]);
    for l in [[4.0, 3.0, 2.0], [1.0, -4.0, 4.0], [-3.0, 1.0, 5.0]] {
        w.light(l);
    }
    w.color([1.0, 0.75, 0.33], 0.2, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0);
    let radius = 1.0;
    let b = [12.0 * radius, 12.0 * radius, -radius / 2.0];
    w.polygon(&[[b[0], b[1], b[2]], [-b[0], b[1], b[2]], [-b[0], -b[1], b[2]], [b[0], -b[1], b[2]]]);
    w.color([1.0, 0.9, 0.7], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 1.0);
    let objset = ball_directions();
    // Depth first, as the C recursion outputs them: a parent, then each child's subtree.
    let mut stack = vec![(size, [0.0, 0.0, 0.0, radius / 2.0], [0.0, 0.0, 1.0, 1.0 / 3.0])];
    while let Some((depth, center, dir)) = stack.pop() {
        w.sphere(center);
        if depth == 0 {
            continue;
        }
        let mx = if dir[2] >= 0.9999 {
            IDENTITY
        } else if dir[2] <= -0.9999 {
            rotate(Axis::Y, PI)
        } else {
            let z = [0.0, 0.0, 1.0];
            let axis = normalize(cross(z, [dir[0], dir[1], dir[2]]));
            axis_rotate(axis, (z[0] * dir[0] + z[1] * dir[1] + z[2] * dir[2]).acos())
        };
        let scale = center[3] * (1.0 + dir[3]);
        let mut children = Vec::with_capacity(9);
        for o in &objset {
            let mut p = transform_coord(*o, &mx);
            for k in 0..3 {
                p[k] = p[k] * scale + center[k];
            }
            p[3] = center[3] * dir[3];
            let mut d = [p[0] - center[0], p[1] - center[1], p[2] - center[2], dir[3]];
            for v in d.iter_mut().take(3) {
                *v /= scale;
            }
            children.push((depth - 1, p, d));
        }
        stack.extend(children.into_iter().rev());
    }
    w.out
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `create_objset`: the nine directions of a sphere's children.
fn ball_directions() -> [Coord4; 9] {
    let dist = 1.0 / 2.0f64.sqrt();
    let mut trio = [[dist, dist, 0.0, 0.0], [dist, 0.0, -dist, 0.0], [0.0, dist, -dist, 0.0]];
    let axis = normalize([1.0, -1.0, 0.0]);
    let mx = axis_rotate(axis, (2.0 / 6.0f64.sqrt()).asin());
    for t in trio.iter_mut() {
        *t = transform_coord(*t, &mx);
    }
    let mut set = [[0.0; 4]; 9];
    for s in 0..3 {
        let mx = rotate(Axis::Z, s as f64 * 2.0 * PI / 3.0);
        for v in 0..3 {
            set[s * 3 + v] = transform_coord(trio[v], &mx);
        }
    }
    set
}

/// `rings`: pyramids of rings of six pentagons (cylinders and spheres) before a wall.
pub fn rings(size: u32) -> String {
    let mut w = Writer::new();
    let radius = 0.07412;
    let spread = 1.0 / (PI / 8.0).sin();
    // SPREAD_OUT is 1, no more than the spread.
    let (y_diff, xz_diff) = (spread / 1.0, 1.0);
    w.background(SKY);
    let from = [-1.0, -spread, 0.5];
    w.viewpoint(from, [from[0], from[1] + 1.0, from[2]], [0.0, 0.0, 1.0], 45.0, 1.0, [512, 512]);
    for l in [[3.0, -spread, 3.0], [-4.0, -spread, 1.0], [2.0, -spread, -4.0]] {
        w.light(l);
    }
    w.color([1.0, 1.0, 1.0], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let wy = y_diff * (size as f64 + 1.0);
    let wxz = 1.01 * (wy - from[1]) * (PI / 8.0).tan();
    w.polygon(&[
        [wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, -wxz + from[2]],
        [wxz + from[0], wy, -wxz + from[2]],
    ]);
    let colors = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 0.0]];
    let dodec = dodecahedron(radius);
    for depth in 0..size as i32 {
        let oy = y_diff * (depth + 1) as f64;
        for z in 0..=depth {
            let oz = xz_diff * (2 * z - depth) as f64;
            for x in 0..=depth {
                let ox = xz_diff * (2 * x - depth) as f64;
                for e in 0..30 {
                    let at = |k: usize| [dodec[k][0] + ox, dodec[k][1] + oy, dodec[k][2] + oz, radius];
                    let prev = if e % 5 == 0 {
                        w.color(colors[e / 5], 0.0, 0.5, 0.2, 0.3, 37.0, 0.0, 0.0);
                        e + 4
                    } else {
                        e - 1
                    };
                    w.cylcone(at(e), at(prev));
                    w.sphere(at(e));
                }
            }
        }
    }
    w.out
}

/// `create_dodec`: the 30 vertices of six pentagons on a dodecahedron.
fn dodecahedron(minor_radius: f64) -> [[f64; 4]; 30] {
    let mut v = [[0.0; 4]; 30];
    let scale = 1.0 / (1.0 + minor_radius);
    for (k, p) in v.iter_mut().take(5).enumerate() {
        let a = k as f64 * 2.0 * PI / 5.0;
        *p = [scale * a.cos(), scale * a.sin(), 0.0, 1.0];
    }
    let x_rotation = 2.0 * ((PI / 3.0).cos() / (PI / 5.0).sin()).acos();
    let xm = rotate(Axis::X, x_rotation);
    for pentagon in 1..6 {
        let zm = rotate(Axis::Z, PI * (2.0 * (pentagon - 1) as f64 + 1.0) / 5.0);
        for k in 0..5 {
            let t = transform_point(v[k], &xm);
            let p = transform_point(t, &zm);
            v[5 * pentagon + k] = [p[0], p[1], p[2], v[5 * pentagon + k][3]];
        }
    }
    v
}

/// `tree`: a tree of cones and spheres after Aono and Kunii, on a field, with seven lights.
pub fn tree(size: u32) -> String {
    let mut w = Writer::new();
    w.background(SKY);
    w.viewpoint([4.5, 0.4, 2.0], [0.0, 0.0, 1.5], [0.0, 0.0, 1.0], 45.0, 1.0, [512, 512]);
    for l in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        w.light(l);
    }
    w.color([0.2, 0.7, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    w.polygon(&[[50.0, 50.0, 0.0], [-50.0, 50.0, 0.0], [-50.0, -50.0, 0.0], [50.0, -50.0, 0.0]]);
    w.color([0.55, 0.4, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let branches = [(40.0, 90.0, 0.65), (25.0, 140.0 + 90.0, 0.70)].map(|(angle, divergence, contraction)| {
        let r = multiply(&rotate(Axis::X, angle * PI / 180.0), &rotate(Axis::Z, divergence * PI / 180.0));
        let mut st = IDENTITY;
        (st[0][0], st[1][1], st[2][2], st[3][2]) = (contraction, contraction, contraction, 1.0);
        multiply(&r, &st)
    });
    let mut stack: Vec<(Matrix, f64, u32)> = vec![(IDENTITY, 1.0, size)];
    while let Some((m, scale, depth)) = stack.pop() {
        let mut base = transform_point([0.0, 0.0, 0.0, 0.0], &m);
        base[3] = scale * 0.15;
        let mut apex = transform_point([0.0, 0.0, 1.0, 0.0], &m);
        apex[3] = base[3] * 0.67;
        w.cylcone(base, apex);
        w.sphere(apex);
        if depth > 0 {
            stack.push((multiply(&branches[1], &m), scale * 0.67, depth - 1));
            stack.push((multiply(&branches[0], &m), scale * 0.67, depth - 1));
        }
    }
    w.out
}

/// `lattice`: a cubic lattice of spheres joined by cylinders, six lights.
pub fn lattice(size: u32) -> String {
    let mut w = Writer::new();
    let n = size as f64;
    let inv = 1.0 / n;
    let (radius1, radius2) = (0.25 / n, (1.0 / 16.0) / n);
    let delta = (radius1 * (1.0 - (0.0625f64 / 0.25).sqrt())) * 0.99;
    w.background(SKY);
    let mid = ((size >> 1) as f64 + 0.5) * inv;
    let half = 1.0 / (size << 1) as f64;
    w.viewpoint([mid, 1.0, 1.0 - half], [mid, -1.0, -1.0 - half], [0.2, 1.0, 0.0], 60.0, 0.0, [512, 512]);
    for l in [[2.0, 0.5, 0.5], [-1.0, 0.5, 0.5], [0.5, 2.0, 0.5], [0.5, -1.0, 0.5], [0.5, 0.5, 2.0], [0.5, 0.5, -1.0]] {
        w.light(l);
    }
    for x in 0..=size {
        let x0 = x as f64 / n;
        for y in 0..=size {
            let y0 = y as f64 / n;
            for z in 0..=size {
                let z0 = z as f64 / n;
                w.color([0.9, 0.9, 0.9], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 0.0);
                w.sphere([x0, y0, z0, radius1]);
                let arms = [
                    (x, [0.9, 0.1, 0.1], [1.0, 0.0, 0.0]),
                    (y, [0.1, 0.9, 0.1], [0.0, 1.0, 0.0]),
                    (z, [0.1, 0.1, 0.9], [0.0, 0.0, 1.0]),
                ];
                for (along, color, axis) in arms {
                    if along == size {
                        continue;
                    }
                    w.color(color, 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    // Only the coordinate along the arm moves: x0 + delta and x0 + inv - delta.
                    let at = |d: f64| {
                        let c = [x0, y0, z0];
                        let m = |k: usize| if axis[k] == 1.0 { c[k] + d } else { c[k] };
                        [m(0), m(1), m(2), radius2]
                    };
                    let far = |k: usize| [x0, y0, z0][k] + inv - delta;
                    let mut apex = at(0.0);
                    for k in 0..3 {
                        if axis[k] == 1.0 {
                            apex[k] = far(k);
                        }
                    }
                    w.cylcone(at(delta), apex);
                }
            }
        }
    }
    w.out
}

/// `jacks`: a jack (three cylinders, six spheres) and smaller jacks in its octants.
pub fn jacks(size: u32) -> String {
    let mut w = Writer::new();
    w.background([0.2, 0.05, 0.2]);
    w.viewpoint([0.0, 0.0, -8.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 25.0, 0.001, [256, 256]);
    w.light([-10.0, 3.0, -20.0]);
    w.push();
    w.apply(&rotate(Axis::X, -30.0 * PI / 180.0));
    w.apply(&rotate(Axis::Y, -20.0 * PI / 180.0));
    w.color([0.737, 0.561, 0.561], 0.1, 0.7, 0.7, 0.4, 20.0, 0.0, 1.0);
    jack(&mut w, 1, size);
    w.pop();
    w.out
}

/// `make_rec_jack` (recursive, as the C is; its depth is the size factor, a few levels).
fn jack(w: &mut Writer, depth: u32, max_depth: u32) {
    w.push();
    w.apply(&scaling(0.75));
    for axis in 0..3 {
        let mut base = [0.0, 0.0, 0.0, 0.1];
        let mut apex = base;
        (base[axis], apex[axis]) = (-1.0, 1.0);
        w.cylcone(base, apex);
    }
    for sign in [1.0, -1.0] {
        for axis in 0..3 {
            let mut c = [0.0, 0.0, 0.0, 0.2];
            c[axis] = sign;
            w.sphere(c);
        }
    }
    w.pop();
    if depth < max_depth {
        for i in [-0.5, 0.5] {
            for j in [-0.5, 0.5] {
                for k in [-0.5, 0.5] {
                    w.push();
                    let mut t = IDENTITY;
                    t[3][..3].copy_from_slice(&[i, j, k]);
                    w.apply(&t);
                    w.apply(&scaling(0.5));
                    jack(w, depth + 1, max_depth);
                    w.pop();
                }
            }
        }
    }
}

fn scaling(s: f64) -> Matrix {
    let mut m = IDENTITY;
    (m[0][0], m[1][1], m[2][2]) = (s, s, s);
    m
}

/// `shells`: spheres along a logarithmic spiral (a sea shell), one light.
pub fn shells(size: u32) -> String {
    let mut w = Writer::new();
    let (gamma, beta, a, k) = (1.0, -2.0, 0.15, 1.0);
    w.background(SKY);
    w.viewpoint([-6.0, -60.0, 35.0], [0.0, 8.0, -15.0], [0.0, 0.0, 1.0], 45.0, 0.5, [512, 512]);
    w.light([-100.0, -100.0, 100.0]);
    w.color([1.0, 0.8, 0.4], 0.0, 0.8, 0.2, 0.5, 10.0, 0.0, 1.0);
    let steps = (180.0 * 2.0f64.powf(size as f64)) as i64;
    for i in -steps * 2 / 3..=steps / 3 {
        let angle = 3.0 * 6.0 * PI * i as f64 / steps as f64;
        let r = k * (a * angle).exp();
        // alpha is 0: z = beta r.
        w.sphere([r * angle.sin(), r * angle.cos(), beta * r, r / gamma]);
    }
    w.out
}
