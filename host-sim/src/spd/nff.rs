//! What the SPD's library (`libpr1.c`, `libpr2.c`, `libvec.c`, `libtx.c`) does for the
//! generators that NFF output needs: its 4x4 matrices (row vectors, `p' = p M`), its transform
//! stack, and its NFF writer, with C's `%g` for every number.

/// A 4x4 matrix, row-major, applied to row vectors as the SPD's library applies it.
pub type Matrix = [[f64; 4]; 4];
/// A point or direction, and a fourth value (a radius, or the homogeneous coordinate).
pub type Coord4 = [f64; 4];

/// The identity.
pub const IDENTITY: Matrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

/// The three axes, as `lib_create_rotate_matrix` numbers them.
#[derive(Clone, Copy)]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

/// `lib_create_rotate_matrix`: a rotation by `angle` radians about an axis.
pub fn rotate(axis: Axis, angle: f64) -> Matrix {
    let (c, s) = (angle.cos(), angle.sin());
    let mut m = [[0.0; 4]; 4];
    let (i, j, k) = match axis {
        Axis::X => (0, 1, 2),
        Axis::Y => (1, 2, 0),
        Axis::Z => (2, 0, 1),
    };
    m[i][i] = 1.0;
    m[j][j] = c;
    m[k][k] = c;
    m[j][k] = s;
    m[k][j] = -s;
    m[3][3] = 1.0;
    m
}

/// `lib_create_axis_rotate_matrix`: a rotation by `angle` radians about the unit `axis`.
pub fn axis_rotate(a: [f64; 3], angle: f64) -> Matrix {
    let (c, s) = (angle.cos(), angle.sin());
    let t = 1.0 - c;
    let sq = |v: f64| v * v;
    [
        [sq(a[0]) + (1.0 - sq(a[0])) * c, a[0] * a[1] * t + a[2] * s, a[0] * a[2] * t - a[1] * s, 0.0],
        [a[0] * a[1] * t - a[2] * s, sq(a[1]) + (1.0 - sq(a[1])) * c, a[1] * a[2] * t + a[0] * s, 0.0],
        [a[0] * a[2] * t + a[1] * s, a[1] * a[2] * t - a[0] * s, sq(a[2]) + (1.0 - sq(a[2])) * c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// `lib_matrix_multiply`: `a b`.
pub fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    m
}

/// `lib_transform_point`: `p M` with `p`'s fourth coordinate 1 (the fourth value kept).
pub fn transform_point(p: Coord4, m: &Matrix) -> Coord4 {
    let r = |j: usize| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j] + m[3][j];
    [r(0), r(1), r(2), p[3]]
}

/// `lib_transform_coord`: `p M` in four coordinates.
pub fn transform_coord(p: Coord4, m: &Matrix) -> Coord4 {
    let r = |j: usize| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j] + p[3] * m[3][j];
    [r(0), r(1), r(2), r(3)]
}

/// `lib_normalize_vector` of the first three coordinates.
pub fn normalize(v: [f64; 3]) -> [f64; 3] {
    let d = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if d > 0.0 {
        [v[0] / d, v[1] / d, v[2] / d]
    } else {
        v
    }
}

/// C's `printf("%g")`: six significant digits, trailing zeros dropped, an exponent of at least
/// two digits below 1e-4 and from 1e6.
pub fn g(x: f64) -> String {
    if x == 0.0 {
        return if x.is_sign_negative() { "-0".into() } else { "0".into() };
    }
    if !x.is_finite() {
        return if x.is_nan() {
            "nan".into()
        } else if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    let sci = format!("{x:.5e}");
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let trim = |s: &str| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if !(-4..6).contains(&exp) {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa), exp.abs())
    } else {
        trim(&format!("{x:.*}", (5 - exp) as usize))
    }
}

/// The NFF the SPD's library writes (`-r 1`), and its transform stack (`lib_tx_*`).
#[derive(Default)]
pub struct Writer {
    /// The text so far.
    pub out: String,
    /// The current transform and the stack below it.
    tx: Vec<Matrix>,
}

impl Writer {
    /// An empty file with the identity transform.
    pub fn new() -> Self {
        Writer { out: String::new(), tx: vec![IDENTITY] }
    }

    fn line(&mut self, words: &[f64]) {
        let text: Vec<String> = words.iter().map(|&v| g(v)).collect();
        self.out.push_str(&text.join(" "));
        self.out.push('\n');
    }

    /// `b R G B`.
    pub fn background(&mut self, c: [f64; 3]) {
        self.out.push_str("b ");
        self.line(&c);
    }

    /// The `v` block.
    #[allow(clippy::too_many_arguments)]
    pub fn viewpoint(&mut self, from: [f64; 3], at: [f64; 3], up: [f64; 3], angle: f64, hither: f64, res: [u32; 2]) {
        self.out.push_str("v\nfrom ");
        self.line(&from);
        self.out.push_str("at ");
        self.line(&at);
        self.out.push_str("up ");
        self.line(&up);
        self.out.push_str("angle ");
        self.line(&[angle]);
        self.out.push_str("hither ");
        self.line(&[hither]);
        self.out.push_str(&format!("resolution {} {}\n", res[0], res[1]));
    }

    /// `l X Y Z`.
    pub fn light(&mut self, p: [f64; 3]) {
        self.out.push_str("l ");
        self.line(&p);
    }

    /// `lib_output_color`: `f R G B Kd Ks Shine T ior`, the Phong power from the highlight's
    /// half angle `ang` in degrees.
    #[allow(clippy::too_many_arguments)]
    pub fn color(&mut self, c: [f64; 3], _ka: f64, kd: f64, ks: f64, _ks_spec: f64, ang: f64, kt: f64, ior: f64) {
        let rad = std::f64::consts::PI * ang / 180.0;
        let power = if rad <= 0.0 {
            100000.0
        } else if rad >= std::f64::consts::PI / 2.0 {
            1.0
        } else {
            0.5f64.ln() / rad.cos().ln()
        };
        self.out.push_str("f ");
        self.line(&[c[0], c[1], c[2], kd, ks, power, kt, ior]);
    }

    /// The current transform and, when it is not the identity, the scale of its first row
    /// (`lib_tx_unwind`'s `U_SCALEX`) that radii are multiplied by.
    fn placed(&self, p: Coord4) -> Coord4 {
        let m = self.tx.last().unwrap_or(&IDENTITY);
        if *m == IDENTITY {
            return p;
        }
        let scale = (m[0][0] * m[0][0] + m[0][1] * m[0][1] + m[0][2] * m[0][2]).sqrt() / m[3][3];
        let q = transform_point(p, m);
        [q[0], q[1], q[2], p[3] * scale.abs()]
    }

    /// `s X Y Z r`.
    pub fn sphere(&mut self, c: Coord4) {
        let c = self.placed(c);
        self.out.push_str("s ");
        self.line(&c);
    }

    /// `c` with base and apex (point and radius), on one line as the library writes it.
    pub fn cylcone(&mut self, base: Coord4, apex: Coord4) {
        let (b, a) = (self.placed(base), self.placed(apex));
        self.out.push_str("c ");
        self.line(&[b[0], b[1], b[2], b[3], a[0], a[1], a[2], a[3]]);
    }

    /// `p n` and the vertices.
    pub fn polygon(&mut self, vertices: &[[f64; 3]]) {
        self.out.push_str(&format!("p {}\n", vertices.len()));
        for v in vertices {
            self.line(v);
        }
    }

    /// `pp 3` and the triangle's corners, each with its normal (`lib_output_polypatch` of a
    /// triangle, untransformed).
    pub fn patch(&mut self, corners: &[([f64; 3], [f64; 3]); 3]) {
        self.out.push_str("pp 3\n");
        for (v, n) in corners {
            self.line(&[v[0], v[1], v[2], n[0], n[1], n[2]]);
        }
    }

    /// `lib_tx_push`.
    pub fn push(&mut self) {
        let top = *self.tx.last().unwrap_or(&IDENTITY);
        self.tx.push(top);
    }

    /// `lib_tx_pop`.
    pub fn pop(&mut self) {
        if self.tx.len() > 1 {
            self.tx.pop();
        }
    }

    /// `lib_tx_rotate`, `lib_tx_scale`, `lib_tx_translate`: `m` applied before the current
    /// transform.
    pub fn apply(&mut self, m: &Matrix) {
        if let Some(top) = self.tx.last_mut() {
            *top = multiply(m, top);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::g;

    #[test]
    fn numbers_print_as_c_prints_them_with_percent_g() {
        for (x, want) in [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (0.078, "0.078"),
            (-2.613_125_929_752_753, "-2.61313"),
            (1.1102230246251565e-16, "1.11022e-16"),
            (100000.0, "100000"),
            (1234567.0, "1.23457e+06"),
            (0.0001, "0.0001"),
            (0.00001234, "1.234e-05"),
            (3.0827, "3.0827"),
            (999999.5, "1e+06"),
        ] {
            assert_eq!(g(x), want, "{x}");
        }
    }
}
