//! The SPD generators whose scenes are polygons: `tetra` and `gears`, as their C sources
//! compute them (same order of operations, so every number prints as theirs does).

use super::nff::{rotate, Axis, Writer};
use std::f64::consts::PI;

/// The SPD's sky blue background.
const SKY: [f64; 3] = [0.078, 0.361, 0.753];

/// `tetra`: Sierpinski's tetrahedron, 4^size triangles (default 6: 4,096).
pub fn tetra(size: u32) -> String {
    let mut w = Writer::new();
    w.background(SKY);
    w.viewpoint(
        [1.022846, -3.177154, -2.174512],
        [-0.004103, -0.004103, 0.216539],
        [-0.816497, -0.816497, 0.816497],
        45.0,
        1.0,
        [512, 512],
    );
    w.light([2.0, -18.0, -5.0]);
    w.color([1.0, 0.2, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    // Depth first, as the C recursion outputs them.
    let mut stack = vec![(size, [0.0, 0.0, 0.0, 1.0])];
    while let Some((depth, c)) = stack.pop() {
        let corners = |scale: f64| {
            let mut out = Vec::with_capacity(4);
            for x in [-1.0, 1.0] {
                for y in [-1.0, 1.0] {
                    for z in [-1.0f64, 1.0] {
                        if x * y * z == 1.0 {
                            out.push([c[0] + x * c[3] / scale, c[1] + y * c[3] / scale, c[2] + z * c[3] / scale]);
                        }
                    }
                }
            }
            out
        };
        if depth <= 1 {
            let p = corners(1.0);
            for face in 0..4 {
                let mut order = [face % 4, (face + 1) % 4, (face + 2) % 4];
                if face % 2 == 1 {
                    order.swap(0, 2);
                }
                w.polygon(&order.map(|k| p[k]));
            }
        } else {
            let subs: Vec<_> = corners(2.0).into_iter().map(|p| (depth - 1, [p[0], p[1], p[2], c[3] / 2.0])).collect();
            stack.extend(subs.into_iter().rev());
        }
    }
    w.out
}

/// Teeth on a gear (a multiple of 4).
const TEETH: usize = 36;
/// The outer radius a little inside the full one, so meshing gears do not touch.
const OUTER_EDGE_RATIO: f64 = 0.995;
/// 1 - the inner edge's ratio (0.9).
const EDGE_DIFF: f64 = 1.0 - 0.9;

/// `create_tooth`: the four corners of one tooth on the rim.
fn tooth(gear_angle: f64, tooth_angle: f64, center: [f64; 3], outer: [f64; 3], inner: [f64; 3]) -> [[f64; 3]; 4] {
    let at = |angle: f64, p: [f64; 3]| {
        let m = rotate(Axis::Z, angle);
        let v = [0, 1, 2].map(|j| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j]);
        [v[0] + center[0], v[1] + center[1], v[2] + center[2]]
    };
    [
        at(gear_angle - 0.19 * tooth_angle, outer),
        at(gear_angle + 0.19 * tooth_angle, outer),
        at(gear_angle + 0.3 * tooth_angle, inner),
        at(gear_angle + 0.7 * tooth_angle, inner),
    ]
}

/// `create_gear`: its top (a concave polygon of 4 x 36 corners), the sides of its teeth, its
/// bottom.
fn gear(w: &mut Writer, center: [f64; 3], offset: f64, outer_radius: f64, inner_radius: f64, thickness: f64) {
    let (mut outer, mut inner) = ([outer_radius, 0.0, 0.0], [inner_radius, 0.0, 0.0]);
    let tooth_angle = 2.0 * PI / TEETH as f64;
    let rim = |sign: f64, outer: [f64; 3], inner: [f64; 3]| {
        let mut pts = Vec::with_capacity(4 * TEETH);
        for k in 0..TEETH {
            let angle = offset + sign * 2.0 * PI * k as f64 / TEETH as f64;
            pts.extend(tooth(angle, sign * tooth_angle, center, outer, inner));
        }
        pts
    };
    let top = rim(1.0, outer, inner);
    w.polygon(&top);
    for k in 0..4 * TEETH {
        let next = (k + 1) % (4 * TEETH);
        let (mut a, mut b) = (top[k], top[next]);
        let (a0, b0) = (a, b);
        a[2] -= thickness;
        b[2] -= thickness;
        w.polygon(&[a0, a, b, b0]);
    }
    outer[2] = -thickness;
    inner[2] = -thickness;
    w.polygon(&rim(-1.0, outer, inner));
}

/// `gears`: size^3 meshing gears, some of glass, on a floor, five lights (default 4: 9,345
/// polygons).
pub fn gears(size: u32) -> String {
    let mut w = Writer::new();
    let n = size as f64;
    w.background(SKY);
    w.viewpoint([-1.1, -2.1, 2.6], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 45.0, 1.0, [512, 512]);
    for l in [[2.0, 4.0, 4.0], [-2.0, 4.0, 3.0], [2.0, -2.5, 2.5], [-1.0, -4.0, 2.0], [-1.111, -2.121, 2.626]] {
        w.light(l);
    }
    w.color([1.0, 0.85, 0.7], 0.0, 0.3, 0.6, 0.3, 37.0, 0.0, 0.0);
    w.polygon(&[[2.0, 2.0, 0.0], [-2.0, 2.0, 0.0], [-2.0, -2.0, 0.0], [2.0, -2.0, 0.0]]);
    let outer_radius = 1.0 / (n - (n - 1.0) * EDGE_DIFF / 2.0);
    let zero = [-1.0 + outer_radius, -1.0 + outer_radius, 1.0];
    let offset = [outer_radius * (2.0 - EDGE_DIFF), outer_radius * (2.0 - EDGE_DIFF), -1.0 / n];
    let fraction = |v: f64| v - (v as i64) as f64;
    for iz in 0..size as i64 {
        let cz = zero[2] + iz as f64 * offset[2];
        for iy in 0..size as i64 {
            let cy = zero[1] + iy as f64 * offset[1];
            for ix in 0..size as i64 {
                let cx = zero[0] + ix as f64 * offset[0];
                let mut c = [
                    0.01 + fraction((ix * 3 + iy * 2 + iz + 1) as f64 * 5.0 / 7.0),
                    0.01 + fraction((iy * 3 + iz * 2 + ix + 1) as f64 * 3.0 / 7.0),
                    0.01 + fraction((iz * 3 + ix * 2 + iy + 1) as f64 * 2.0 / 7.0),
                ];
                let scale = c[0].max(c[1]).max(c[2]);
                for v in c.iter_mut() {
                    *v /= scale;
                }
                if (ix * 4 + iy * 2 + iz) % 5 == 0 {
                    w.color(c, 0.0, 0.2, 0.0, 0.0, 0.0, 0.8, 1.1);
                } else {
                    w.color(c, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                }
                let angle = PI * ((ix + iy + iz) % 2) as f64 / TEETH as f64;
                let thickness = 0.1f64.min(1.0 / (2.0 * n));
                gear(
                    &mut w,
                    [cx, cy, cz],
                    angle,
                    OUTER_EDGE_RATIO * outer_radius,
                    (1.0 - EDGE_DIFF) * outer_radius,
                    thickness,
                );
            }
        }
    }
    w.out
}

/// `mount`'s old hashing function (kept by the SPD for the published image): a seed from a
/// grid point and the size factor, in 64-bit `unsigned long` as on the published platforms.
fn hash_rand(a: i64, b: i64, c: u32) -> i64 {
    let (a, b) = (a as u64, b as u64);
    ((a << (23 - c)).wrapping_add(b << (15 - c)).wrapping_add(a << (7 - c)) & 0xffff) as i64
}

/// `lib_gauss_rand`: a normally distributed number from a seed (polar Box-Muller over a linear
/// congruential generator).
fn gauss_rand(seed: i64) -> f64 {
    const M1: i64 = 134_456;
    const IA1: i64 = 8121;
    const IC1: i64 = 28_411;
    let mut ix2 = seed;
    loop {
        let ix1 = (IC1 + ix2 * IA1) % M1;
        ix2 = (IC1 + ix1 * IA1) % M1;
        // `ix * 2.0 * RM1 - 1.0` with the macro `RM1` being `1.0/M1`.
        let v1 = ix1 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        let v2 = ix2 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        let r = v1 * v1 + v2 * v2;
        if r < 1.0 {
            return v1 * (-2.0 * r.ln() / r).sqrt();
        }
    }
}

/// The C source's literal for the square root of 2, not f64's: the same numbers as its output.
#[allow(clippy::approx_constant)]
const ROOT2: f64 = 1.4142136;

/// `grow_mountain`'s state: the grid size, the roughness and the size factor.
struct Mountain {
    points: f64,
    roughness: f64,
    size: u32,
}

impl Mountain {
    /// `grow_mountain` (recursive, as the C is; its depth is the size factor).
    fn grow(&self, w: &mut Writer, width: i64, (x, y): (i64, i64), z: [f64; 4]) {
        const MOUNTAIN_NO: i64 = 21;
        let [ll, lr, ur, ul] = z;
        if width == 1 {
            let lx = -1.0 + x as f64 * 2.0 / self.points;
            let rx = -1.0 + (x + 1) as f64 * 2.0 / self.points;
            let ly = -1.0 + y as f64 * 2.0 / self.points;
            let uy = -1.0 + (y + 1) as f64 * 2.0 / self.points;
            let corner = [[lx, ly, ll], [rx, ly, lr], [rx, uy, ur], [lx, uy, ul]];
            for tri in 0..2 {
                w.polygon(&[0, 1, 2].map(|v| corner[(v + tri * 2) % 4]));
            }
            return;
        }
        let half = width >> 1;
        let rise = half as f64 * 2.0 / self.points * self.roughness;
        let g = |a: i64, b: i64| rise * gauss_rand(MOUNTAIN_NO + hash_rand(a, b, self.size));
        let lower = (ll + lr) / 2.0 + g(x + half, y);
        let right = (lr + ur) / 2.0 + g(x + width, y + half);
        let upper = (ur + ul) / 2.0 + g(x + half, y + width);
        let left = (ul + ll) / 2.0 + g(x, y + half);
        let middle = (ll + lr + ur + ul) / 4.0 + ROOT2 * g(x + half, y + half);
        self.grow(w, half, (x, y), [ll, lower, middle, left]);
        self.grow(w, half, (x + half, y), [lower, lr, right, middle]);
        self.grow(w, half, (x + half, y + half), [middle, right, ur, upper]);
        self.grow(w, half, (x, y + half), [left, middle, upper, ul]);
    }
}

/// `mount`: a fractal mountain of 2 x 4^size triangles (Carpenter's method) under four glass
/// spheres (default 6: 8,196 objects).
pub fn mount(size: u32) -> String {
    let mut w = Writer::new();
    w.background(SKY);
    w.viewpoint([-1.6, 1.6, 1.7], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 45.0, 0.01, [512, 512]);
    w.light([-100.0, -100.0, 100.0]);
    w.color([1.0, 1.0, 1.0], 0.0, 0.1, 0.1, 0.4, 6.7, 0.9, 1.5);
    // `create_spheres`: a pyramid of four spheres.
    let center = [-0.8, 0.8, 1.00, 0.17];
    let axis = super::nff::normalize([1.0, 1.0, 0.0]);
    let pt = [0.0, 0.0, center[3] * (3.0f64 / 2.0).sqrt()];
    w.sphere([center[0] + pt[0], center[1] + pt[1], center[2] + pt[2], center[3]]);
    let vector =
        |m: &super::nff::Matrix, p: [f64; 3]| [0, 1, 2].map(|j| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j]);
    let new_pt = vector(&super::nff::axis_rotate(axis, (-1.0f64 / 3.0).acos()), pt);
    for i in 0..3 {
        let s = vector(&rotate(Axis::Z, i as f64 * 2.0 * PI / 3.0), new_pt);
        w.sphere([s[0] + center[0], s[1] + center[1], s[2] + center[2], center[3]]);
    }
    w.color([0.5, 0.45, 0.35], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let points = 1i64 << size;
    let ratio = 2.0 / (2.0f64.ln() / (2.2 - 1.0)).exp();
    let mountain = Mountain { points: points as f64, roughness: (ratio * ratio - 1.0).sqrt(), size };
    mountain.grow(&mut w, points, (0, 0), [0.0; 4]);
    w.out
}
