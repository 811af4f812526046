//! Every scene-text error kind, with the message a user sees (line, column, token, reason).

use lattice_rt::scene::Object;
use lattice_rt::{parse, Real};

fn err<R: Real>(text: &str) -> String {
    let mut storage = vec![Object::<R>::default(); 8];
    let mut parts = lattice_rt::Parts::default();
    match parse::<R>(text, &mut storage, &mut parts) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn check(text: &str, want: &str) {
    assert_eq!(err::<f64>(text), want, "for:\n{text}");
}

#[test]
fn unknown_statement() {
    check("sphere\nteapot size 3", "line 2, column 1 at `teapot`: unknown statement (expected camera, ambient, background, depth, light, material, sphere, cylinder, cone, box, triangle, group or end)");
}

#[test]
fn unknown_attribute() {
    check("sphere radius 1 colour red", "line 1, column 17 at `colour`: not an attribute of this statement; it takes center, radius, material, translate, rotate, scale or shear");
    check("box radius 1", "line 1, column 5 at `radius`: not an attribute of this statement; it takes min, max, material, translate, rotate, scale or shear");
    // A word one or two letters off a valid one is named.
    check("sphere raduis 1", "line 1, column 8 at `raduis`: not an attribute of this statement (did you mean `radius`?); it takes center, radius, material, translate, rotate, scale or shear");
    check("camera eyes 0 0 -5\nsphere", "line 1, column 8 at `eyes`: not an attribute of this statement (did you mean `eye`?); it takes eye, look, up or fov");
    check(
        "light point dir 0 1 0\nsphere",
        "line 1, column 13 at `dir`: not an attribute of this statement; it takes pos or intensity",
    );
    check(
        "ambient 0.2 0.3\nsphere",
        "line 1, column 13 at `0.3`: not an attribute of this statement; it takes nothing after its value",
    );
}

#[test]
fn repeated_attribute() {
    check("sphere radius 1 radius 2", "line 1, column 17 at `radius`: attribute given twice in this statement");
    check("camera fov 40 fov 50\nsphere", "line 1, column 15 at `fov`: attribute given twice in this statement");
    check(
        "material m ka 0.1 kd 0.5 ka 0.2\nsphere",
        "line 1, column 26 at `ka`: attribute given twice in this statement",
    );
    check(
        "light directional dir 0 -1 0 intensity 1 intensity 2\nsphere",
        "line 1, column 42 at `intensity`: attribute given twice in this statement",
    );
    // Transforms compose: they may repeat.
    let mut storage = vec![lattice_rt::scene::Object::<f64>::default(); 2];
    let mut parts = lattice_rt::Parts::default();
    assert!(lattice_rt::parse::<f64>(
        "sphere rotate y 10 rotate y 20 translate 1 0 0 translate 0 1 0",
        &mut storage,
        &mut parts
    )
    .is_ok());
}

#[test]
fn expected_number() {
    check("sphere center 0 one 0", "line 1, column 17 at `one`: expected a number");
}

#[test]
fn missing_value() {
    check("  sphere center 0 1", "line 1, column 20: a value is missing at the end of the line");
}

#[test]
fn unknown_material() {
    check("sphere material gold", "line 1, column 17 at `gold`: material not defined before this line");
}

#[test]
fn duplicate_material() {
    check("material a kd 1\nmaterial a kd 0.5", "line 2, column 10 at `a`: material already defined");
}

#[test]
fn unknown_axis() {
    check("sphere rotate w 30", "line 1, column 15 at `w`: axis must be x, y or z");
}

#[test]
fn unknown_light_kind() {
    check("light spot pos 0 0 0", "line 1, column 7 at `spot`: light must be `directional` or `point`");
}

#[test]
fn bad_depth() {
    check("depth 9", "line 1, column 7 at `9`: depth must be a whole number from 0 to 8");
    check("depth -1", "line 1, column 7 at `-1`: depth must be a whole number from 0 to 8");
}

#[test]
fn nan_and_infinity_in_the_text() {
    check("sphere center 0 NaN 0", "line 1, column 17 at `NaN`: number is not finite");
    check("ambient inf", "line 1, column 9 at `inf`: number is not finite");
}

#[test]
fn zero_radius_and_degenerate_sizes() {
    check("sphere radius 0", "line 1, column 15 at `0`: size must be positive");
    check("cylinder height -2", "line 1, column 17 at `-2`: size must be positive");
    check("box min 0 0 0 max 1 0 1", "line 1, column 1 at `box`: size must be positive");
    check("cone top -1", "line 1, column 6 at `top`: size must be positive");
}

#[test]
fn zero_scale_is_a_singular_transform() {
    check("sphere scale 1 0 1", "line 1, column 1 at `sphere`: transform is singular (zero or near-zero scale)");
}

#[test]
fn bad_coefficients() {
    check(
        "material m kd -0.5",
        "line 1, column 15 at `-0.5`: coefficients must be >= 0 and the index of refraction >= 1",
    );
    check(
        "material m ior 0.5",
        "line 1, column 16 at `0.5`: coefficients must be >= 0 and the index of refraction >= 1",
    );
}

#[test]
fn camera_looking_along_its_up_vector() {
    check(
        "camera eye 0 5 0 look 0 0 0 up 0 1 0\nsphere",
        "line 1, column 1 at `camera`: camera looks nowhere or straight along its up vector",
    );
    check(
        "camera eye 0 0 0 look 0 0 0\nsphere",
        "line 1, column 1 at `camera`: camera looks nowhere or straight along its up vector",
    );
}

#[test]
fn bad_field_of_view() {
    // The error points at the angle out of range, not at the statement.
    check("camera fov 180 25\nsphere", "line 1, column 12 at `180`: field of view must be between 0 and 180 degrees");
    check("camera fov 40 0\nsphere", "line 1, column 15 at `0`: field of view must be between 0 and 180 degrees");
    check("camera fov -5\nsphere", "line 1, column 12 at `-5`: field of view must be between 0 and 180 degrees");
}

#[test]
fn degenerate_light() {
    check("light directional dir 0 0 0", "line 1, column 1 at `light`: light direction is zero");
}

#[test]
fn groups_must_nest_properly() {
    check("group a\ngroup b", "line 2, column 1 at `group`: a group cannot be opened inside another group");
    check("end", "line 1, column 1 at `end`: `end` without an open group");
    check("sphere\ngroup a translate 1 0 0\nsphere", "line 2, column 1 at `group`: group not closed with `end`");
    check("group a\nend", "line 2, column 1 at `end`: group has no objects");
}

#[test]
fn too_many_objects_names_the_capacity() {
    let text = "sphere\n".repeat(9);
    check(&text, "line 9, column 1 at `sphere`: too many objects: the scene needs storage for 9, it holds 8");
}

#[test]
fn too_many_materials_and_lights() {
    // The capacities of this build (the host's, with `alloc`; a microcontroller's are 16 and 4).
    use lattice_rt::scene::{MAX_LIGHTS, MAX_MATERIALS};
    let (m, l) = (MAX_MATERIALS, MAX_LIGHTS);
    let mats: String = (0..=m).map(|i| format!("material m{i}\n")).collect();
    check(&mats, &format!("line {}, column 10 at `m{m}`: too many materials (at most {m})", m + 1));
    let lights = "light directional dir 0 -1 0\n".repeat(l + 1);
    check(&lights, &format!("line {}, column 1 at `light`: too many lights (at most {l})", l + 1));
}

#[test]
fn empty_scene() {
    check("# nothing\n", "line 1, column 1: scene has no objects");
}

#[test]
fn out_of_range_for_the_scalar() {
    assert_eq!(
        err::<f32>("sphere center 1e16 0 0"),
        "line 1, column 15 at `1e16`: coordinate out of range for f32: magnitude must stay below 1e15"
    );
}

#[test]
fn comments_blank_lines_and_groups_parse() {
    let text = "# a chair\n\nmaterial wood kd 0.7 # brown\ngroup chair rotate y 20\n  box min 0 0 0 max 1 1 1 material wood\nend\n";
    let mut storage = vec![Object::<f64>::default(); 4];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<f64>(text, &mut storage, &mut parts).unwrap();
    assert_eq!(scene.objects().len(), 1);
    assert_eq!(scene.composites().len(), 1);
}

#[test]
fn fixed_point_refuses_coordinates_beyond_its_range() {
    assert_eq!(
        err::<lattice_rt::Fx>("camera eye 0 0 -9000\nsphere"),
        "line 1, column 16 at `-9000`: coordinate out of range for fixed: magnitude must stay below 8192"
    );
}

#[test]
fn fixed_point_refuses_an_object_too_thin_for_its_length_and_names_its_line() {
    // A needle 10 long and 0.001 across: within twice its length of its box's centre (where a
    // ray is moved before its test), its own coordinates reach 20 / 0.0005 = 40000 (and some),
    // past fixed point's range wherever the scene is.
    let text = "camera eye 0 0 -10\nsphere radius 2\ncylinder base 1 0 0 height 10 radius 0.0005\n";
    assert_eq!(
        err::<lattice_rt::Fx>(text),
        "line 3, column 1 at `cylinder`: object 1 is too small for this scene in fixed: its own coordinates reach 40086 where rays meet it, the limit is 8192 (make it thicker)"
    );
    // The same scene is fine in floating point.
    let mut storage = vec![Object::<f32>::default(); 4];
    let mut parts = lattice_rt::Parts::default();
    assert!(parse::<f32>(text, &mut storage, &mut parts).is_ok());
}

#[test]
fn fixed_point_traces_an_object_small_for_the_scene_from_near_it() {
    // The world box reaches 20000 in the small sphere's own coordinates, past fixed point's
    // 8192: its rays are moved to near it before they are mapped (`Object::distant`).
    let text = "camera eye 0 0 -10\nsphere radius 2\nsphere center 1 0 0 radius 0.0005\n";
    let mut storage = vec![Object::<lattice_rt::Fx>::default(); 4];
    let mut parts = lattice_rt::Parts::default();
    assert!(parse::<lattice_rt::Fx>(text, &mut storage, &mut parts).is_ok());
}

#[test]
fn rotation_about_a_point_is_the_translated_rotation() {
    // `rotate A D about P` is `translate -P rotate A D translate P`, and leaves P in place.
    let bounds = |text: &str| {
        let mut storage = vec![lattice_rt::scene::Object::<f64>::default(); 2];
        let mut parts = lattice_rt::Parts::default();
        let scene = lattice_rt::parse::<f64>(text, &mut storage, &mut parts).unwrap_or_else(|e| panic!("{e}"));
        let b = scene.objects()[0].bounds();
        [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]
    };
    let about = bounds("box min 0 0 0 max 1 2 1 rotate z 90 about 1 0 0");
    let spelled = bounds("box min 0 0 0 max 1 2 1 translate -1 0 0 rotate z 90 translate 1 0 0");
    assert_eq!(about, spelled);
    assert_ne!(about, bounds("box min 0 0 0 max 1 2 1 rotate z 90"));
    // A sphere turned about its centre stays where it was (to the rounding of the turn).
    let (turned, still) = (bounds("sphere center 2 0 0 rotate y 70 about 2 0 0"), bounds("sphere center 2 0 0"));
    assert!(turned.iter().zip(&still).all(|(a, b)| (a - b).abs() < 1e-12), "{turned:?} {still:?}");
    check("sphere rotate y 30 about 1 2\n", "line 1, column 29: a value is missing at the end of the line");
}
