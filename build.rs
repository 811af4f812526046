//! Tables the core's display code uses, computed once at build time (`OUT_DIR/display.rs`), so
//! no board computes them and no float maths is linked for them:
//!
//! * `BLUE_NOISE`: a 16x16 blue-noise threshold mask made by Ulichney's void-and-cluster
//!   method (1993), the ranks 0..=255 of its pixels;
//! * `GAMMA`: tone curves `64 * (l / 64)^(g / 10)` over the 65 gray levels, for g = 5..=20.

use std::fmt::Write as _;
use std::{env, fs, path::PathBuf};

/// Side of the mask.
const N: usize = 16;
/// Width of the Gaussian that measures clustering, in pixels (Ulichney's 1.5).
const SIGMA: f64 = 1.5;

/// Energy at each pixel: the Gaussian-weighted count of the `on` pixels around it (toroidal).
fn energy(on: &[bool]) -> Vec<f64> {
    let mut e = vec![0.0; N * N];
    for (i, _) in on.iter().enumerate().filter(|(_, &b)| b) {
        let (x0, y0) = ((i % N) as i64, (i / N) as i64);
        for (j, ej) in e.iter_mut().enumerate() {
            let d = |a: i64, b: i64| {
                let d = (a - b).rem_euclid(N as i64);
                d.min(N as i64 - d) as f64
            };
            let (dx, dy) = (d((j % N) as i64, x0), d((j / N) as i64, y0));
            *ej += (-(dx * dx + dy * dy) / (2.0 * SIGMA * SIGMA)).exp();
        }
    }
    e
}

/// Among the pixels equal to `want`, the one with the highest energy of the `count` pixels
/// (`count == want`: the tightest cluster) or the lowest (`count != want`: the largest void);
/// ties go to the lowest index.
fn extreme(on: &[bool], want: bool, count: bool, highest: bool) -> usize {
    let e = energy(&on.iter().map(|&b| b == count).collect::<Vec<_>>());
    let mut best = None::<usize>;
    for i in (0..N * N).filter(|&i| on[i] == want) {
        best = match best {
            Some(b) if (highest && e[i] <= e[b]) || (!highest && e[i] >= e[b]) => Some(b),
            _ => Some(i),
        };
    }
    best.expect("a pixel of the kind exists")
}

/// Ranks 0..N*N of the void-and-cluster mask.
fn void_and_cluster() -> Vec<u8> {
    let total = N * N;
    // Initial pattern: a tenth of the pixels, from a fixed pseudo-random sequence.
    let mut on = vec![false; total];
    let mut seed: u32 = 0x2545_f491;
    let mut placed = 0;
    while placed < total / 10 {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let i = (seed >> 8) as usize % total;
        if !on[i] {
            on[i] = true;
            placed += 1;
        }
    }
    // Spread it: move the tightest cluster's pixel into the largest void until that is a no-op.
    loop {
        let c = extreme(&on, true, true, true);
        on[c] = false;
        let v = extreme(&on, false, true, false);
        if v == c {
            on[c] = true;
            break;
        }
        on[v] = true;
    }
    let start = on.clone();
    let mut rank = vec![0u8; total];
    // Phase 1: remove tightest clusters, ranks below the initial count.
    let mut p = start.clone();
    for r in (0..placed).rev() {
        let c = extreme(&p, true, true, true);
        p[c] = false;
        rank[c] = r as u8;
    }
    // Phase 2 and 3: fill the largest voids (the tightest clusters of the off pixels past half,
    // which is the same choice measured from the other side).
    let mut p = start;
    for r in placed..total {
        let v = if r < total / 2 { extreme(&p, false, true, false) } else { extreme(&p, false, false, true) };
        p[v] = true;
        rank[v] = r as u8;
    }
    rank
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let mut s = String::new();
    writeln!(s, "/// Ranks (0..=255) of a 16x16 void-and-cluster blue-noise mask, row by row.").unwrap();
    writeln!(s, "pub const BLUE_NOISE: [[u8; {N}]; {N}] = [").unwrap();
    for row in void_and_cluster().chunks(N) {
        writeln!(s, "    {row:?},").unwrap();
    }
    writeln!(s, "];").unwrap();
    writeln!(s, "/// Tone curves: `GAMMA[g - 5][l]` is level `l` of 64 raised to the power g / 10, rounded.").unwrap();
    writeln!(s, "pub const GAMMA: [[u8; 65]; 16] = [").unwrap();
    for g in 5..=20 {
        let row: Vec<u8> = (0..=64).map(|l| (64.0 * (l as f64 / 64.0).powf(g as f64 / 10.0)).round() as u8).collect();
        writeln!(s, "    {row:?},").unwrap();
    }
    writeln!(s, "];").unwrap();
    fs::write(out.join("display.rs"), s).expect("write display.rs");
    println!("cargo:rerun-if-changed=build.rs");
}
