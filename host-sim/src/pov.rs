//! POV-Ray export and the cross-check against it. See docs/povray.md for the mapping.

#[cfg(test)]
use anyhow::Context;
use anyhow::{bail, Result};
use lattice_rt::scene::Light;
use lattice_rt::shape::Shape;
use lattice_rt::{Affine, Scene, Vec3};
use std::fmt::Write as _;
#[cfg(test)]
use std::path::Path;
#[cfg(test)]
use std::process::Command;

/// What the exported scene shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PovMode {
    /// The full model: eq. (1) as POV-Ray finishes, lights, shadows, reflection, refraction.
    Full,
    /// Each object a flat distinct gray (ambient only), background black: object masks.
    Ids,
}

fn v(p: Vec3<f64>) -> String {
    format!("<{:e}, {:e}, {:e}>", p.x, p.y, p.z)
}

/// Most objects an id export tells apart (24-bit colours, black for the background).
pub const MAX_ID_OBJECTS: usize = (1 << 24) - 2;

/// Spacing of id colours for `n` objects: spread over the 24-bit range so few objects get
/// clearly different colours.
fn id_step(n: usize) -> usize {
    (((1usize << 24) - 1) / (n + 1)).max(1)
}

/// Colour (8 bits per channel) of object `i` of `n` in [`PovMode::Ids`].
pub fn id_rgb(i: usize, n: usize) -> [u8; 3] {
    let k = (i + 1) * id_step(n);
    [(k >> 16) as u8, (k >> 8) as u8, k as u8]
}

/// The object an id colour stands for (`None`: background).
#[cfg(test)]
pub fn rgb_id(c: [u8; 3], n: usize) -> Option<usize> {
    let k = (c[0] as usize) << 16 | (c[1] as usize) << 8 | c[2] as usize;
    let step = id_step(n);
    let i = (k + step / 2) / step;
    (i >= 1 && i <= n).then(|| i - 1)
}

/// The smallest magnitude POV-Ray keeps in a matrix column (smaller columns it reads as a
/// scale by zero and replaces; its `EPSILON`, 1e-10), with a margin of ten.
const POV_SMALLEST: f64 = 1e-9;

/// An object the POV-Ray export cannot represent.
#[derive(Debug)]
pub struct Unrepresentable {
    /// Index of the object.
    pub object: usize,
    /// Why.
    pub why: String,
}

impl std::fmt::Display for Unrepresentable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "object {}: {}", self.object, self.why)
    }
}

impl std::error::Error for Unrepresentable {}

/// The POV-Ray scene text of a scene.
pub fn export(scene: &Scene<'_, f64>, mode: PovMode) -> Result<String> {
    if scene.objects().len() > MAX_ID_OBJECTS && mode == PovMode::Ids {
        bail!("an id export holds at most {MAX_ID_OBJECTS} objects");
    }
    let mut s = String::new();
    let c = &scene.camera();
    writeln!(s, "// Exported by host-sim (lattice-rt). Left-handed like lattice-rt: x right, y up, z forward.")?;
    let (ambient, trace) = match mode {
        PovMode::Full => (scene.ambient(), scene.max_depth() as u32 + 1),
        PovMode::Ids => (1.0, 1),
    };
    writeln!(s, "global_settings {{ assumed_gamma 1.0 max_trace_level {trace} ambient_light rgb {ambient} }}")?;
    writeln!(s, "background {{ rgb {} }}", if mode == PovMode::Full { scene.background() } else { 0.0 })?;
    // The same image plane: direction, and right/up spanning twice tan(fov/2).
    writeln!(
        s,
        "camera {{ perspective location {} direction {} right {} up {} }}",
        v(c.eye),
        v(c.forward),
        v(c.right * 2.0),
        v(c.up * 2.0)
    )?;
    if mode == PovMode::Full {
        for l in scene.lights().iter() {
            match *l {
                Light::Directional { to_light, intensity } => writeln!(
                    s,
                    "light_source {{ {} color rgb {intensity} parallel point_at <0, 0, 0> }}",
                    v(to_light * 1.0e5)
                )?,
                Light::Point { pos, intensity } => writeln!(s, "light_source {{ {} color rgb {intensity} }}", v(pos))?,
            }
        }
    }
    for i in 0..scene.objects().len() {
        object(&mut s, scene, i, mode)?;
    }
    Ok(s)
}

/// Object `i` of `scene` as POV-Ray text: its primitive, its look (the material, or in an id
/// export its id colour) and its placement as a matrix.
fn object(s: &mut String, scene: &Scene<'_, f64>, i: usize, mode: PovMode) -> Result<()> {
    let (o, n) = (&scene.objects()[i], scene.objects().len());
    // object = A (world - origin), A = to_object * unscale; so world = A^-1 object + origin.
    let a = o.world_to_object();
    let unrepresentable = |why: String| Unrepresentable { object: i, why };
    let inv = a.inverse().ok_or_else(|| unrepresentable("its transform has no inverse".into()))?;
    let m = Affine { m: inv.m };
    for j in 0..3 {
        let col = (0..3).map(|r| m.m[r][j].abs()).fold(0.0, f64::max);
        if col < POV_SMALLEST {
            return Err(unrepresentable(format!(
                "POV-Ray cannot represent its transform: it scales a direction by {col:e}, and POV-Ray reads a matrix column below {POV_SMALLEST:e} as a scale by zero"
            ))
            .into());
        }
    }
    let prim = match o.shape() {
        Shape::Sphere => "sphere { <0, 0, 0>, 1".to_string(),
        Shape::Cylinder => "cylinder { <0, 0, 0>, <0, 1, 0>, 1".to_string(),
        Shape::Cone { top } => format!("cone {{ <0, 0, 0>, 1, <0, 1, 0>, {top}"),
        Shape::Box => "box { <0, 0, 0>, <1, 1, 1>".to_string(),
        Shape::Open { top: 1.0 } => "cylinder { <0, 0, 0>, <0, 1, 0>, 1 open".to_string(),
        Shape::Open { top } => format!("cone {{ <0, 0, 0>, 1, <0, 1, 0>, {top} open"),
        Shape::Triangle => match scene.smooth_of(i as u32) {
            // The world normals in canonical space (the placement's transpose), which POV-Ray's
            // matrix maps back by its inverse transpose.
            Some(sm) => {
                let n = sm.normals.map(|n| {
                    let c = |j: usize| m.m[0][j] * n.x + m.m[1][j] * n.y + m.m[2][j] * n.z;
                    format!("<{:e}, {:e}, {:e}>", c(0), c(1), c(2))
                });
                format!("smooth_triangle {{ <0, 0, 0>, {}, <1, 0, 0>, {}, <0, 0, 1>, {}", n[0], n[1], n[2])
            }
            None => "triangle { <0, 0, 0>, <1, 0, 0>, <0, 0, 1>".to_string(),
        },
    };
    let mat = &scene.materials()[o.material() as usize];
    let look = match mode {
        PovMode::Ids => {
            let [r, g, b] = id_rgb(i, n).map(|c| c as f64 / 255.0);
            format!("pigment {{ rgb <{r:e}, {g:e}, {b:e}> }} finish {{ ambient 1 diffuse 0 }}")
        }
        PovMode::Full => {
            let pig = if mat.kt > 0.0 { format!("rgbt <1, 1, 1, {}>", mat.kt) } else { "rgb 1".into() };
            let interior = if mat.kt > 0.0 { format!(" interior {{ ior {} }}", mat.ior) } else { String::new() };
            // A highlight: POV-Ray's Phong of weight Ks and size the power (its phong_size is
            // the cosine's power, as ours).
            let phong = if mat.shine > 0 && mat.ks > 0.0 {
                format!("phong {} phong_size {}", mat.ks, mat.shine)
            } else {
                "phong 0".into()
            };
            format!(
                "pigment {{ {pig} }} finish {{ ambient {} diffuse {} specular 0 {phong} reflection {{ {} }} }}{interior}",
                mat.ka, mat.kd, mat.ks
            )
        }
    };
    // Shortest round-trip scientific notation: every f64 exactly, however small or large.
    let matrix = format!(
        "matrix <{:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}>",
        m.m[0][0],
        m.m[1][0],
        m.m[2][0],
        m.m[0][1],
        m.m[1][1],
        m.m[2][1],
        m.m[0][2],
        m.m[1][2],
        m.m[2][2],
        m.m[0][3] + o.origin().x,
        m.m[1][3] + o.origin().y,
        m.m[2][3] + o.origin().z
    );
    if mode == PovMode::Full && mat.kt > 0.0 {
        // Whitted's shadow rays stop at glass; POV-Ray would let filtered light through.
        // The visible glass casts no shadow, an invisible opaque twin casts the shadow.
        writeln!(s, "{prim} {look} no_shadow\n  {matrix} }}")?;
        writeln!(s, "{prim} pigment {{ rgb 0 }} no_image no_reflection\n  {matrix} }}")?;
    } else {
        writeln!(s, "{prim} {look}\n  {matrix} }}")?;
    }
    Ok(())
}

/// Renders POV-Ray text to 8-bit gray values (`w x h`, red channel) with `povray`.
#[cfg(test)]
pub fn render_povray(pov: &str, w: u32, h: u32, work: &Path, name: &str) -> Result<Vec<u8>> {
    Ok(render_povray_rgb(pov, w, h, work, name)?.into_iter().map(|p| p[0]).collect())
}

/// Renders POV-Ray text to 8-bit RGB pixels (`w x h`) with `povray`.
#[cfg(test)]
pub fn render_povray_rgb(pov: &str, w: u32, h: u32, work: &Path, name: &str) -> Result<Vec<[u8; 3]>> {
    std::fs::create_dir_all(work)?;
    let src = work.join(format!("{name}.pov"));
    let png = work.join(format!("{name}-povray.png"));
    std::fs::write(&src, pov)?;
    let out = Command::new("povray")
        .arg(format!("+I{}", src.display()))
        .arg(format!("+O{}", png.display()))
        .args([
            format!("+W{w}"),
            format!("+H{h}"),
            "-D".into(),
            "+FN".into(),
            "-V".into(),
            "-A".into(),
            "File_Gamma=1.0".into(),
        ])
        .env("HOME", work)
        .output()
        .context("cannot run povray (Debian package povray)")?;
    if !out.status.success() {
        bail!("povray failed on {}: {}", src.display(), String::from_utf8_lossy(&out.stderr));
    }
    image_rgb(&png)
}

#[cfg(test)]
fn image_rgb(path: &Path) -> Result<Vec<[u8; 3]>> {
    let bytes = std::fs::read(path)?;
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info()?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader.next_frame(&mut buf)?;
    let ch = info.color_type.samples();
    let depth = if info.bit_depth == png::BitDepth::Sixteen { 2 } else { 1 };
    let px = |p: &[u8], c: usize| p[c.min(ch.saturating_sub(1)) * depth];
    Ok(buf[..info.buffer_size()].chunks(ch * depth).map(|p| [px(p, 0), px(p, 1), px(p, 2)]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{build_lattice, lattice_storage, object_storage, parse_scene, read};
    use crate::run::render_with;
    use crate::spd::Generator;
    use lattice_rt::generate::{random_scene, RandomScene};
    use lattice_rt::scene::Object;
    use lattice_rt::{Accelerator, BruteForce, Frame, LatticeConfig, Query, SceneBuilder, Tracer};
    use std::path::PathBuf;

    const W: u32 = 160;
    const H: u32 = 100;

    fn have_povray() -> bool {
        let ok = Command::new("povray").arg("--version").output().is_ok();
        if !ok {
            assert!(
                std::env::var("CI").is_err(),
                "POV-Ray is not installed: the cross-check cannot run (apt-get install povray)"
            );
            eprintln!("POV-Ray is not installed: skipping the cross-check (apt-get install povray)");
        }
        ok
    }

    fn work() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/povray")
    }

    fn write_pgm(path: &Path, px: &[u8]) {
        let mut out = format!("P5\n{W} {H}\n255\n").into_bytes();
        out.extend_from_slice(px);
        std::fs::write(path, out).unwrap();
    }

    /// Coverage (share of pixels where both name the same object) and shading agreement
    /// (mean absolute gray difference in levels of 64, share off by more than 8 levels, over
    /// the pixels whose object is opaque).
    fn compare(name: &str, scene: &Scene<'_, f64>) -> (f64, f64, f64) {
        let n = scene.objects().len();
        let ids =
            render_povray_rgb(&export(scene, PovMode::Ids).unwrap(), W, H, &work(), &format!("{name}-ids")).unwrap();
        let mut mb = vec![0; lattice_rt::Query::mailbox_len(scene)];
        let mut q = Query::new(&mut mb);
        let ours: Vec<Option<usize>> = (0..(W * H) as i32)
            .map(|i| {
                let r = scene.camera().ray(2 * (i % W as i32) + 1, 2 * (i / W as i32) + 1, 2 * W as i32, 2 * H as i32);
                BruteForce.nearest(scene, &r, 0.0, f64::MAX, &mut q).map(|h| h.object as usize)
            })
            .collect();
        let agree = ours.iter().zip(&ids).filter(|(o, g)| **o == rgb_id(**g, n)).count() as f64 / ours.len() as f64;
        let pov = render_povray(&export(scene, PovMode::Full).unwrap(), W, H, &work(), name).unwrap();
        let cfg = LatticeConfig::default();
        let mut bufs = lattice_storage(scene, &cfg).expect("lattice fits");
        let lat = build_lattice(&mut bufs, scene, &cfg).unwrap();
        let mine = render_with(&Tracer::new(scene, &lat), &Frame::new(W as u16, H as u16), false).unwrap().gray;
        let opaque: Vec<usize> = (0..mine.len())
            .filter(|&i| ours[i].is_none_or(|o| scene.materials()[scene.objects()[o].material() as usize].kt == 0.0))
            .collect();
        let diff: Vec<f64> = opaque.iter().map(|&i| (mine[i] as f64 - pov[i] as f64 * 64.0 / 255.0).abs()).collect();
        let mean = diff.iter().sum::<f64>() / diff.len().max(1) as f64;
        let far = diff.iter().filter(|&&d| d > 8.0).count() as f64 / diff.len().max(1) as f64;
        // Both images and a diff for a person to look at.
        write_pgm(
            &work().join(format!("{name}-ours.pgm")),
            &mine.iter().map(|&l| (l as u32 * 255 / 64) as u8).collect::<Vec<_>>(),
        );
        write_pgm(&work().join(format!("{name}-povray.pgm")), &pov);
        write_pgm(
            &work().join(format!("{name}-diff.pgm")),
            &mine
                .iter()
                .zip(&pov)
                .map(|(&a, &b)| ((a as f64 * 255.0 / 64.0 - b as f64).abs() * 4.0).min(255.0) as u8)
                .collect::<Vec<_>>(),
        );
        (agree, mean, far)
    }

    #[test]
    fn every_scene_agrees_with_povray() {
        if !have_povray() {
            return;
        }
        let mut failures = Vec::new();
        let mut report = String::new();
        let mut names: Vec<PathBuf> = std::fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes"))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "scene"))
            .collect();
        names.sort();
        // One line of the report per scene; a scene out of agreement is a failure.
        let mut check = |name: &str, scene: &Scene<'_, f64>| {
            let (agree, mean, far) = compare(name, scene);
            report.push_str(&format!(
                "{name}: coverage {:.2} %, mean |gray diff| {mean:.2} levels, {:.2} % off by > 8\n",
                agree * 100.0,
                far * 100.0
            ));
            if agree < 0.995 || mean > 2.0 || far > 0.01 {
                failures.push(name.to_string());
            }
        };
        for path in &names {
            let name = path.file_stem().unwrap().to_string_lossy().to_string();
            let text = read(path).unwrap();
            let mut storage = object_storage::<f64>(&text).unwrap();
            let scene = parse_scene::<f64>(path, &text, &mut storage, &Frame::new(W as u16, H as u16)).unwrap();
            check(&name, &scene);
        }
        // The Standard Procedural Databases' scenes, small sizes, as `host-sim spd` writes them.
        for (g, size) in [
            (Generator::Balls, 2),
            (Generator::Rings, 1),
            (Generator::Tree, 5),
            (Generator::Lattice, 2),
            (Generator::Jacks, 1),
            (Generator::Shells, 1),
            (Generator::Tetra, 3),
            (Generator::Gears, 1),
            (Generator::Mount, 3),
            (Generator::Teapot, 4),
        ] {
            let name = format!("spd-{}-{size}", g.name());
            let text = g.nff(size).unwrap();
            let mut storage = object_storage::<f64>(&text).unwrap();
            let path = PathBuf::from(&name);
            let scene = parse_scene::<f64>(&path, &text, &mut storage, &Frame::new(W as u16, H as u16)).unwrap();
            check(&name, &scene);
        }
        // A generated random scene too.
        let mut storage = vec![Object::<f64>::default(); 30];
        let mut parts = lattice_rt::Parts::default();
        let mut b = SceneBuilder::new(&mut storage, &mut parts);
        random_scene(&mut b, &RandomScene { objects: 30, composite_size: 0, spread: 0.0, seed: 42 }).unwrap();
        b.camera.frame = [W, H];
        let scene = b.finish().unwrap();
        check("random30", &scene);
        eprintln!("{report}images under {}", work().display());
        std::fs::write(work().join("report.txt"), &report).unwrap();
        assert!(
            failures.is_empty(),
            "POV-Ray disagrees on {failures:?}:\n{report}images and diffs: {}",
            work().display()
        );
    }
}
