//! Baked scenes: a validated scene and its built lattice as `static` tables, written at build
//! time, so firmware that shows fixed scenes links no parser, no scene set-up (f64 maths) and
//! no lattice build, and keeps neither the objects nor the lattice in RAM.
//!
//! [`Baked`] is the form the tables take (no_std, in flash); with the `bake` feature,
//! `bake::source` writes one as Rust source from a scene parsed and a lattice built on the
//! host in the firmware's scalar, so the values are the very ones the firmware would have
//! computed: frames are bit-identical to a run-time parse.

use crate::lattice::Lattice;
use crate::scene::Scene;

/// A scene and its lattice as static tables (see the module documentation): the scene's
/// objects, lists and camera and the lattice's cells all in flash, used in place.
#[derive(Debug)]
pub struct Baked<R: 'static> {
    /// The validated scene.
    pub scene: Scene<'static, R>,
    /// Its lattice, built.
    pub lattice: Lattice<'static, R>,
}

#[cfg(feature = "bake")]
pub use writer::{source, Literal};

#[cfg(feature = "bake")]
mod writer {
    use super::*;
    use crate::lattice::SubLattice;
    use crate::math::{Aabb, Vec3};
    use crate::scene::{Camera, Composite, Light, Material, Object};
    use crate::shape::Shape;
    use crate::{F32Micro, F32MicroNewton, Fx, Real};
    use alloc::string::String;
    use core::fmt::Write as _;

    /// Writes a value as a Rust constant expression (the generated code has the core's types
    /// in scope).
    pub trait Literal {
        /// Appends the expression to `out`.
        fn literal(&self, out: &mut String);
    }

    impl Literal for f32 {
        fn literal(&self, out: &mut String) {
            // The bits, so every value (signed zeros, subnormals) comes back exactly.
            let _ = write!(out, "f32::from_bits({:#x})", self.to_bits());
        }
    }
    impl Literal for Fx {
        fn literal(&self, out: &mut String) {
            let _ = write!(out, "Fx({})", self.0);
        }
    }
    impl Literal for F32Micro {
        fn literal(&self, out: &mut String) {
            out.push_str("F32Micro(");
            self.0.literal(out);
            out.push(')');
        }
    }
    impl Literal for F32MicroNewton {
        fn literal(&self, out: &mut String) {
            out.push_str("F32MicroNewton(");
            self.0.literal(out);
            out.push(')');
        }
    }
    macro_rules! plain {
        ($($t:ty),*) => {$(
            impl Literal for $t {
                fn literal(&self, out: &mut String) {
                    let _ = write!(out, "{self}");
                }
            }
        )*};
    }
    plain!(u8, u16, u32, i32, usize, bool);

    impl<T: Literal, const N: usize> Literal for [T; N] {
        fn literal(&self, out: &mut String) {
            list(self, out);
        }
    }

    /// `[a, b, ...]`.
    fn list<T: Literal>(items: &[T], out: &mut String) {
        out.push('[');
        for (i, v) in items.iter().enumerate() {
            if i > 0 {
                out.push_str(", ");
            }
            v.literal(out);
        }
        out.push(']');
    }

    /// `Name { field: value, ... }`.
    fn record(out: &mut String, name: &str, fields: &[(&str, &dyn Literal)]) {
        out.push_str(name);
        out.push_str(" { ");
        for (i, (f, v)) in fields.iter().enumerate() {
            if i > 0 {
                out.push_str(", ");
            }
            out.push_str(f);
            out.push_str(": ");
            v.literal(out);
        }
        out.push_str(" }");
    }

    impl Literal for crate::scene::HullEdge {
        fn literal(&self, out: &mut String) {
            let _ = write!(out, "HullEdge::new({}, {}, {})", self.a, self.b, self.c);
        }
    }
    impl<R: Literal> Literal for crate::scalar::Pow2<R> {
        fn literal(&self, out: &mut String) {
            out.push_str("Pow2(");
            self.0.literal(out);
            out.push(')');
        }
    }
    impl<R: Literal> Literal for Vec3<R> {
        fn literal(&self, out: &mut String) {
            record(out, "Vec3", &[("x", &self.x), ("y", &self.y), ("z", &self.z)]);
        }
    }
    impl<R: Literal> Literal for Aabb<R> {
        fn literal(&self, out: &mut String) {
            record(out, "Aabb", &[("min", &self.min), ("max", &self.max)]);
        }
    }
    impl<R: Literal> Literal for crate::math::Linear<R> {
        fn literal(&self, out: &mut String) {
            record(out, "Linear", &[("m", &self.m)]);
        }
    }
    impl<R: Literal> Literal for Shape<R> {
        fn literal(&self, out: &mut String) {
            match self {
                Shape::Sphere => out.push_str("Shape::Sphere"),
                Shape::Cylinder => out.push_str("Shape::Cylinder"),
                Shape::Cone { top } => record(out, "Shape::Cone", &[("top", top)]),
                Shape::Box => out.push_str("Shape::Box"),
                Shape::Open { top } => record(out, "Shape::Open", &[("top", top)]),
                Shape::Triangle => out.push_str("Shape::Triangle"),
            }
        }
    }
    impl<R: Literal> Literal for crate::scene::Smooth<R> {
        fn literal(&self, out: &mut String) {
            let [a, b, c] = &self.normals;
            let _ = write!(out, "Smooth {{ object: {}, normals: [", self.object);
            for (k, n) in [a, b, c].into_iter().enumerate() {
                if k > 0 {
                    out.push_str(", ");
                }
                n.literal(out);
            }
            out.push_str("] }");
        }
    }
    impl Literal for crate::Effects {
        fn literal(&self, out: &mut String) {
            let _ = write!(out, "Effects::from_bits({})", self.bits());
        }
    }
    impl<R: Literal> Literal for Material<R> {
        fn literal(&self, out: &mut String) {
            record(
                out,
                "Material",
                &[
                    ("ka", &self.ka),
                    ("kd", &self.kd),
                    ("ks", &self.ks),
                    ("kt", &self.kt),
                    ("ior", &self.ior),
                    ("shine", &self.shine),
                ],
            );
        }
    }
    impl<R: Literal> Literal for Light<R> {
        fn literal(&self, out: &mut String) {
            match self {
                Light::Directional { to_light, intensity } => {
                    record(out, "Light::Directional", &[("to_light", to_light), ("intensity", intensity)])
                }
                Light::Point { pos, intensity } => {
                    record(out, "Light::Point", &[("pos", pos), ("intensity", intensity)])
                }
            }
        }
    }
    impl<R: Literal> Literal for Composite<R> {
        fn literal(&self, out: &mut String) {
            record(out, "Composite", &[("first", &self.first), ("len", &self.len), ("bounds", &self.bounds)]);
        }
    }
    impl<R: Literal> Literal for Camera<R> {
        fn literal(&self, out: &mut String) {
            record(
                out,
                "Camera",
                &[
                    ("eye", &self.eye),
                    ("forward", &self.forward),
                    ("right", &self.right),
                    ("up", &self.up),
                    ("resolves", &self.resolves),
                    ("shape", &self.shape),
                ],
            );
        }
    }
    impl<R: Literal> Literal for SubLattice<R> {
        fn literal(&self, out: &mut String) {
            record(
                out,
                "SubLattice",
                &[
                    ("bounds", &self.bounds),
                    ("n", &self.n),
                    ("coord_start", &self.coord_start),
                    ("cell_start", &self.cell_start),
                    ("dense_cell", &self.dense_cell),
                ],
            )
        }
    }
    /// An object with its eye and first light in its own space, as the scene's set-up computes
    /// them ([`Object::local_eye_and_light`]): written whole whether or not this build keeps
    /// them (`lean-objects`), so the tables are the same for every build that includes them
    /// (but for the shadow window, which a core with `lean-objects` never made: it writes the
    /// whole plane, which such an image does not keep either).
    struct Whole<'a, R>(&'a Object<R>, Vec3<R>, Vec3<R>);

    impl<R: Real + Literal> Literal for Whole<'_, R> {
        fn literal(&self, out: &mut String) {
            let Whole(o, eye_local, light_local) = self;
            out.push_str("Object::from_tables(");
            let shadow_window = o.region.shadow_window();
            let parts: [&dyn Literal; 17] = [
                &o.shape,
                &o.origin,
                &o.unscale,
                &o.dir_factor,
                &o.dir_scale,
                &o.inv_dir_scale,
                &o.material,
                &o.flags,
                &o.composite,
                &o.to_object,
                &o.to_world,
                &o.bounds,
                eye_local,
                light_local,
                o.region.eye_window(),
                o.region.eye_hull(),
                &shadow_window,
            ];
            for (i, p) in parts.iter().enumerate() {
                if i > 0 {
                    out.push_str(", ");
                }
                p.literal(out);
            }
            out.push(')');
        }
    }
    impl<R: Literal> Literal for Option<(Vec3<R>, Vec3<R>)> {
        fn literal(&self, out: &mut String) {
            match self {
                None => out.push_str("None"),
                Some((a, b)) => {
                    out.push_str("Some((");
                    a.literal(out);
                    out.push_str(", ");
                    b.literal(out);
                    out.push_str("))");
                }
            }
        }
    }

    /// Rust source of a `static {name}: Baked<{scalar}>` holding `scene` and `lattice`, or an
    /// empty lattice for `None` (a build whose tracer never asks it: every ray is answered by
    /// the windows, [`EyeRays::serve_every_ray`](crate::EyeRays::serve_every_ray)). The code
    /// that includes it must have the types of [`prelude`](super::prelude) and the scalar
    /// `scalar` in scope.
    pub fn source<R: Real + Literal>(
        name: &str,
        scalar: &str,
        scene: &Scene<'_, R>,
        lattice: Option<&Lattice<'_, R>>,
    ) -> String {
        let mut out = String::new();
        let _ = write!(
            out,
            "/// The scene `{name}`, baked.\n\
             pub static {name}: Baked<{scalar}> = Baked {{\n    scene: Scene::from_tables(\n        &"
        );
        let objects: alloc::vec::Vec<Whole<'_, R>> = scene
            .objects
            .iter()
            .map(|o| {
                let (eye, light) = o.local_eye_and_light(scene.camera.eye, scene.lights);
                Whole(o, eye, light)
            })
            .collect();
        list(&objects, &mut out);
        let arg = |out: &mut String, v: &dyn Literal| {
            out.push_str(",\n        ");
            v.literal(out);
        };
        arg(&mut out, &Slice(scene.composites));
        arg(&mut out, &Slice(scene.materials));
        arg(&mut out, &Slice(scene.lights));
        arg(&mut out, &scene.ambient);
        arg(&mut out, &scene.background);
        arg(&mut out, &scene.camera);
        arg(&mut out, &scene.max_depth);
        arg(&mut out, &scene.world);
        arg(&mut out, &scene.shadow_basis);
        arg(&mut out, &scene.effects);
        arg(&mut out, &Slice(scene.smooth));
        out.push_str(",\n    ),\n    lattice: Lattice::from_tables(\n        ");
        let empty = Lattice::from_tables(&[], &[], (&[], &[]), (0, 0), true, scene.objects.len());
        let (lattices, coords, (cells, refs), entries, narrow) = lattice.unwrap_or(&empty).tables();
        Slice(lattices).literal(&mut out);
        arg(&mut out, &Slice(coords));
        arg(&mut out, &Pair(Slice(cells), Slice(refs)));
        arg(&mut out, &Pair(entries.0, entries.1));
        arg(&mut out, &narrow);
        arg(&mut out, &scene.objects.len());
        out.push_str(",\n    ),\n};\n");
        out
    }

    /// `&[a, b, ...]`.
    struct Slice<'a, T>(&'a [T]);
    impl<T: Literal> Literal for Slice<'_, T> {
        fn literal(&self, out: &mut String) {
            out.push('&');
            list(self.0, out);
        }
    }

    /// `(a, b)`.
    struct Pair<A, B>(A, B);
    impl<A: Literal, B: Literal> Literal for Pair<A, B> {
        fn literal(&self, out: &mut String) {
            out.push('(');
            self.0.literal(out);
            out.push_str(", ");
            self.1.literal(out);
            out.push(')');
        }
    }
}

/// What the code that includes baked source needs in scope.
pub mod prelude {
    pub use super::Baked;
    pub use crate::lattice::{Lattice, SubLattice};
    pub use crate::math::{Aabb, Affine, Linear, Vec3};
    pub use crate::scalar::Pow2;
    pub use crate::scene::Effects;
    pub use crate::scene::Scene;
    pub use crate::scene::{Camera, Composite, HullEdge, Light, Material, Object, Smooth};
    pub use crate::shape::Shape;
    pub use crate::{F32Micro, F32MicroNewton, Fx};
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Accelerator, Query};
    use crate::generate::{random_scene, RandomScene, Rng};
    use crate::lattice::{LatticeConfig, LatticeStorage, SubLattice};
    use crate::math::{Ray, Vec3};
    use crate::scene::{Object, SceneBuilder};
    use crate::{Fx, Real};
    use std::vec;

    #[test]
    fn tables_answer_as_the_lattice_they_were_taken_from_and_the_source_names_every_object() {
        let mut st = vec![Object::<Fx>::default(); 40];
        let mut parts = crate::Parts::default();
        let mut b = SceneBuilder::new(&mut st, &mut parts);
        random_scene(&mut b, &RandomScene { objects: 40, composite_size: 8, spread: 0.0, seed: 9 }).unwrap();
        let scene = b.finish().unwrap();
        let cfg = LatticeConfig::default();
        let s = Lattice::plan(&scene, &cfg);
        let (mut g, mut c, mut w) = (vec![SubLattice::EMPTY; s.lattices], vec![Fx(0); s.coords], vec![0; s.words()]);
        let lattice =
            Lattice::build(&scene, &cfg, LatticeStorage { lattices: &mut g, coords: &mut c, words: &mut w }).unwrap();
        let (l, co, words, entries, narrow) = lattice.tables();
        let copy = Lattice::from_tables(l, co, words, entries, narrow, scene.objects.len());
        let tables = Scene::from_tables(
            scene.objects,
            scene.composites,
            scene.materials,
            scene.lights,
            scene.ambient,
            scene.background,
            scene.camera,
            scene.max_depth,
            scene.world,
            scene.shadow_basis,
            scene.effects,
            scene.smooth,
        );
        let mut mb = vec![0; Query::mailbox_len(&scene)];
        let mut rng = Rng::new(4);
        let w = scene.world;
        for _ in 0..500 {
            let mut p = || {
                let mut c = |lo: Fx, hi: Fx| Fx::from_f64(rng.range(lo.to_f64(), hi.to_f64()));
                Vec3::new(c(w.min.x, w.max.x), c(w.min.y, w.max.y), c(w.min.z, w.max.z))
            };
            let (a, b) = (p(), p());
            let ray = Ray::new(a, b - a);
            let hit = |s: &Scene<'_, Fx>, l: &Lattice<'_, Fx>, mb: &mut [u32]| {
                l.nearest(s, &ray, Fx(0), Fx::MAX, &mut Query::new(mb)).map(|h| (h.object, h.t))
            };
            assert_eq!(hit(&scene, &lattice, &mut mb), hit(&tables, &copy, &mut mb));
        }
        #[cfg(feature = "bake")]
        {
            let src = source("TEST", "Fx", &scene, Some(&lattice));
            assert!(source("TEST", "Fx", &scene, None)
                .contains("lattice: Lattice::from_tables(\n        &[],\n        &[],"));
            assert_eq!(src.matches("Object::from_tables(").count(), scene.objects.len());
            assert!(src.starts_with("/// The scene `TEST`, baked.\npub static TEST: Baked<Fx> = Baked {"));
            let mut f = std::string::String::new();
            (-0.0f32).literal(&mut f);
            assert_eq!(f, "f32::from_bits(0x80000000)", "a literal keeps the bits, signed zeros too");
        }
    }
}
