//! Deterministic generated scenes (random mixes of the four primitives), for property tests
//! and scaling benchmarks. A tiny xorshift generator keeps it `no_std` and reproducible.

use crate::math::{Affine, Vec3};
use crate::scalar::Real;
use crate::scene::{Light, Material, SceneBuilder, SceneError};
use crate::shape::Shape;

/// Xorshift64* pseudo-random numbers.
// Not `Copy`: a copy would silently repeat the sequence.
#[allow(missing_copy_implementations)]
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (any value; zero is remapped).
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform integer in `0..n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }
}

/// Shape of a generated scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RandomScene {
    /// Number of primitives.
    pub objects: usize,
    /// Objects per composite (0: no composites).
    pub composite_size: usize,
    /// Side of the cube the objects are scattered in (0: grows as the cube root of the count).
    pub spread: f64,
    /// Seed.
    pub seed: u64,
}

/// A random primitive placed around `center` with size about `size`.
pub fn random_object(rng: &mut Rng, center: Vec3<f64>, size: f64) -> (Shape<f64>, Affine<f64>) {
    let shape = match rng.below(4) {
        0 => Shape::Sphere,
        1 => Shape::Cylinder,
        2 => Shape::Cone { top: rng.range(0.0, 0.8) },
        _ => Shape::Box,
    };
    let s = Vec3::new(rng.range(0.3, 1.0), rng.range(0.3, 1.0), rng.range(0.3, 1.0)) * size;
    let t = Affine::translate(center)
        .after(&Affine::rotate(0, rng.range(0.0, 360.0)))
        .after(&Affine::rotate(1, rng.range(0.0, 360.0)))
        .after(&Affine::scale(s));
    (shape, t)
}

/// Fills a builder with a random scene: objects, a few materials, a light and a camera that
/// looks at the whole.
pub fn random_scene<R: Real>(b: &mut SceneBuilder<'_, R>, p: &RandomScene) -> Result<(), SceneError> {
    let mut rng = Rng::new(p.seed);
    let side = if p.spread > 0.0 { p.spread } else { 4.0 * libm::cbrt(p.objects.max(1) as f64) };
    let matte = b.add_material(Material { ka: 0.2, kd: 0.8, ks: 0.0, kt: 0.0, ior: 1.0, shine: 0 })?;
    let mirror = b.add_material(Material { ka: 0.1, kd: 0.5, ks: 0.4, kt: 0.0, ior: 1.0, shine: 0 })?;
    let glass = b.add_material(Material { ka: 0.05, kd: 0.1, ks: 0.1, kt: 0.7, ior: 1.5, shine: 0 })?;
    b.add_light(Light::Directional { to_light: Vec3::new(0.4, 1.0, -0.5), intensity: 1.0 })?;
    let mut in_composite = 0;
    for i in 0..p.objects {
        if p.composite_size > 0 && in_composite == 0 {
            let c = Vec3::new(rng.range(0.0, side), rng.range(0.0, side), rng.range(0.0, side));
            b.begin_composite(Affine::translate(c))?;
        }
        let center = if p.composite_size > 0 {
            Vec3::new(rng.range(-1.5, 1.5), rng.range(-1.5, 1.5), rng.range(-1.5, 1.5))
        } else {
            Vec3::new(rng.range(0.0, side), rng.range(0.0, side), rng.range(0.0, side))
        };
        let (shape, t) = random_object(&mut rng, center, 0.8);
        let m = match rng.below(6) {
            0 => mirror,
            1 => glass,
            _ => matte,
        };
        b.add_object(shape, t, m)?;
        if p.composite_size > 0 {
            in_composite += 1;
            if in_composite == p.composite_size || i + 1 == p.objects {
                b.end_composite()?;
                in_composite = 0;
            }
        }
    }
    let c = side / 2.0;
    b.camera.eye = Vec3::new(c + 0.3 * side, c + 0.4 * side, -1.2 * side);
    b.camera.look = Vec3::new(c, c, c);
    Ok(())
}
