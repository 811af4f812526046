//! The core built without its default features (no `spheres`, `cones`, `tile-lists`, ...), as
//! the firmware's tiny image has it. Its tests check that a scene with a shape the build leaves
//! out is refused where the shape is written, and that the shapes every build has still parse.

#[cfg(test)]
mod tests {
    use lattice_rt::scene::Object;
    use lattice_rt::{parse, Parts, Shape};

    const FLOOR: &str = "box min -2 -0.1 -2 max 2 0 2\n";

    fn error(text: &str) -> Option<String> {
        let mut storage = [Object::<f64>::default(); 4];
        let mut parts = Parts::default();
        parse::<f64>(text, &mut storage, &mut parts).err().map(|e| e.to_string())
    }

    #[test]
    fn left_out_shapes_are_refused_at_their_statement() {
        assert_eq!(Shape::<f64>::Sphere.left_out(), Some("spheres"));
        assert_eq!(Shape::<f64>::Cone { top: 0.5 }.left_out(), Some("cones"));
        let sphere = error(&format!("{FLOOR}sphere center 0 1 0 radius 0.5\n")).expect("a sphere is refused");
        assert!(sphere.starts_with("line 2, column 1") && sphere.contains("this build leaves out spheres"), "{sphere}");
        let cone =
            error(&format!("{FLOOR}\n  cone base 0 0 0 height 1 radius 0.5 top 0.2\n")).expect("a cone is refused");
        assert!(cone.starts_with("line 3, column 3") && cone.contains("this build leaves out cones"), "{cone}");
    }

    #[test]
    fn boxes_and_cylinders_are_always_in() {
        assert_eq!(Shape::<f64>::Box.left_out(), None);
        assert_eq!(Shape::<f64>::Cylinder.left_out(), None);
        assert_eq!(error(&format!("{FLOOR}cylinder base 0 0 0 height 1 radius 0.2\n")), None);
    }
}
