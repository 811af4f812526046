//! POV-Ray export and the cross-check against it. See docs/povray.md for the mapping.

use anyhow::{bail, Context, Result};
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
    format!("<{:.9}, {:.9}, {:.9}>", p.x, p.y, p.z)
}

/// Gray value (0..=255) of object `i` in [`PovMode::Ids`].
pub fn id_gray(i: usize, n: usize) -> u8 {
    ((i + 1) * (255 / (n + 1)).max(1)) as u8
}

/// The object an id gray stands for (`None`: background).
#[cfg(test)]
pub fn gray_id(g: u8, n: usize) -> Option<usize> {
    let step = (255 / (n + 1)).max(1) as f64;
    let k = (g as f64 / step).round() as usize;
    (k >= 1 && k <= n).then(|| k - 1)
}

/// The POV-Ray scene text of a scene.
pub fn export(scene: &Scene<'_, f64>, mode: PovMode) -> Result<String> {
    if scene.objects.len() > 254 && mode == PovMode::Ids {
        bail!("an id export holds at most 254 objects");
    }
    let mut s = String::new();
    let c = &scene.camera;
    writeln!(s, "// Exported by host-sim (lattice-rt). Left-handed like lattice-rt: x right, y up, z forward.")?;
    let (ambient, trace) = match mode {
        PovMode::Full => (scene.ambient, scene.max_depth as u32 + 1),
        PovMode::Ids => (1.0, 1),
    };
    writeln!(s, "global_settings {{ assumed_gamma 1.0 max_trace_level {trace} ambient_light rgb {ambient} }}")?;
    writeln!(s, "background {{ rgb {} }}", if mode == PovMode::Full { scene.background } else { 0.0 })?;
    // The same image plane: direction, and right/up spanning twice tan(fov/2).
    writeln!(s, "camera {{ perspective location {} direction {} right {} up {} }}", v(c.eye), v(c.forward), v(c.right * 2.0), v(c.up * 2.0))?;
    if mode == PovMode::Full {
        for l in scene.lights.iter() {
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
    let n = scene.objects.len();
    for (i, o) in scene.objects.iter().enumerate() {
        // object = A (world - origin), A = to_object * unscale; so world = A^-1 object + origin.
        let mut a = o.to_object;
        a.m.iter_mut().flatten().for_each(|x| *x *= o.unscale);
        let inv = a.inverse().context("an object transform has no inverse")?;
        let m = Affine { m: inv.m };
        let prim = match o.shape {
            Shape::Sphere => "sphere { <0, 0, 0>, 1".to_string(),
            Shape::Cylinder => "cylinder { <0, 0, 0>, <0, 1, 0>, 1".to_string(),
            Shape::Cone { top } => format!("cone {{ <0, 0, 0>, 1, <0, 1, 0>, {top}"),
            Shape::Box => "box { <0, 0, 0>, <1, 1, 1>".to_string(),
        };
        let mat = &scene.materials[o.material as usize];
        let look = match mode {
            PovMode::Ids => {
                let g = id_gray(i, n) as f64 / 255.0;
                format!("pigment {{ rgb {g} }} finish {{ ambient 1 diffuse 0 }}")
            }
            PovMode::Full => {
                let pig = if mat.kt > 0.0 { format!("rgbt <1, 1, 1, {}>", mat.kt) } else { "rgb 1".into() };
                let interior = if mat.kt > 0.0 { format!(" interior {{ ior {} }}", mat.ior) } else { String::new() };
                format!(
                    "pigment {{ {pig} }} finish {{ ambient {} diffuse {} specular 0 phong 0 reflection {{ {} }} }}{interior}",
                    mat.ka, mat.kd, mat.ks
                )
            }
        };
        let matrix = format!(
            "matrix <{:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}>",
            m.m[0][0], m.m[1][0], m.m[2][0], m.m[0][1], m.m[1][1], m.m[2][1], m.m[0][2], m.m[1][2], m.m[2][2],
            m.m[0][3] + o.origin.x, m.m[1][3] + o.origin.y, m.m[2][3] + o.origin.z
        );
        if mode == PovMode::Full && mat.kt > 0.0 {
            // Whitted's shadow rays stop at glass; POV-Ray would let filtered light through.
            // The visible glass casts no shadow, an invisible opaque twin casts the shadow.
            writeln!(s, "{prim} {look} no_shadow\n  {matrix} }}")?;
            writeln!(s, "{prim} pigment {{ rgb 0 }} no_image no_reflection\n  {matrix} }}")?;
        } else {
            writeln!(s, "{prim} {look}\n  {matrix} }}")?;
        }
    }
    Ok(s)
}

/// Renders POV-Ray text to 8-bit gray values (`w x h`, red channel) with `povray`.
#[cfg(test)]
pub fn render_povray(pov: &str, w: u32, h: u32, work: &Path, name: &str) -> Result<Vec<u8>> {
    std::fs::create_dir_all(work)?;
    let src = work.join(format!("{name}.pov"));
    let png = work.join(format!("{name}-povray.png"));
    std::fs::write(&src, pov)?;
    let out = Command::new("povray")
        .arg(format!("+I{}", src.display()))
        .arg(format!("+O{}", png.display()))
        .args([format!("+W{w}"), format!("+H{h}"), "-D".into(), "+FN".into(), "-V".into(), "-A".into(), "File_Gamma=1.0".into()])
        .env("HOME", work)
        .output()
        .context("cannot run povray (Debian package povray)")?;
    if !out.status.success() {
        bail!("povray failed on {}: {}", src.display(), String::from_utf8_lossy(&out.stderr));
    }
    let img = image_gray(&png)?;
    Ok(img)
}

#[cfg(test)]
fn image_gray(path: &Path) -> Result<Vec<u8>> {
    let bytes = std::fs::read(path)?;
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info()?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader.next_frame(&mut buf)?;
    let ch = info.color_type.samples();
    let depth = if info.bit_depth == png::BitDepth::Sixteen { 2 } else { 1 };
    Ok(buf[..info.buffer_size()].chunks(ch * depth).map(|p| p[0]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{object_storage, parse_scene, read, LatticeBufs};
    use crate::run::render_with;
    use lattice_rt::generate::{random_scene, RandomScene};
    use lattice_rt::scene::Object;
    use lattice_rt::{Accelerator, BruteForce, Frame, LatticeConfig, Query, SceneBuilder, Tracer};
    use std::path::PathBuf;

    const W: u32 = 160;
    const H: u32 = 100;

    fn have_povray() -> bool {
        let ok = Command::new("povray").arg("--version").output().is_ok();
        if !ok {
            assert!(std::env::var("CI").is_err(), "POV-Ray is not installed: the cross-check cannot run (apt-get install povray)");
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
        let n = scene.objects.len();
        let ids = render_povray(&export(scene, PovMode::Ids).unwrap(), W, H, &work(), &format!("{name}-ids")).unwrap();
        let mut mb = vec![0; lattice_rt::Query::mailbox_len(scene)];
        let mut q = Query::new(&mut mb);
        let ours: Vec<Option<usize>> = (0..(W * H) as i32)
            .map(|i| {
                let r = scene.camera.ray(2 * (i % W as i32) + 1, 2 * (i / W as i32) + 1, 2 * W as i32, 2 * H as i32);
                BruteForce.nearest(scene, &r, 0.0, f64::MAX, &mut q).map(|h| h.object as usize)
            })
            .collect();
        let agree = ours.iter().zip(&ids).filter(|(o, g)| **o == gray_id(**g, n)).count() as f64 / ours.len() as f64;
        let pov = render_povray(&export(scene, PovMode::Full).unwrap(), W, H, &work(), name).unwrap();
        let cfg = LatticeConfig::default();
        let mut bufs = LatticeBufs::for_scene(scene, &cfg).expect("lattice fits");
        let lat = bufs.build(scene, &cfg).unwrap();
        let mine = render_with(&Tracer::new(scene, &lat), &Frame::new(W as u16, H as u16), false).unwrap().gray;
        let opaque: Vec<usize> = (0..mine.len()).filter(|&i| ours[i].map_or(true, |o| scene.materials[scene.objects[o].material as usize].kt == 0.0)).collect();
        let diff: Vec<f64> = opaque.iter().map(|&i| (mine[i] as f64 - pov[i] as f64 * 64.0 / 255.0).abs()).collect();
        let mean = diff.iter().sum::<f64>() / diff.len().max(1) as f64;
        let far = diff.iter().filter(|&&d| d > 8.0).count() as f64 / diff.len().max(1) as f64;
        // Both images and a diff for a person to look at.
        write_pgm(&work().join(format!("{name}-ours.pgm")), &mine.iter().map(|&l| (l as u32 * 255 / 64) as u8).collect::<Vec<_>>());
        write_pgm(&work().join(format!("{name}-povray.pgm")), &pov);
        write_pgm(&work().join(format!("{name}-diff.pgm")), &mine.iter().zip(&pov).map(|(&a, &b)| ((a as f64 * 255.0 / 64.0 - b as f64).abs() * 4.0).min(255.0) as u8).collect::<Vec<_>>());
        (agree, mean, far)
    }

    #[test]
    fn every_scene_agrees_with_povray() {
        if !have_povray() {
            return;
        }
        let mut failures = Vec::new();
        let mut report = String::new();
        let mut names: Vec<PathBuf> = std::fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes")).unwrap().flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|e| e == "scene")).collect();
        names.sort();
        for path in &names {
            let name = path.file_stem().unwrap().to_string_lossy().to_string();
            let text = read(path).unwrap();
            let mut storage = object_storage::<f64>(&text);
            let scene = parse_scene::<f64>(path, &text, &mut storage).unwrap();
            let (agree, mean, far) = compare(&name, &scene);
            report.push_str(&format!("{name}: coverage {:.2} %, mean |gray diff| {mean:.2} levels, {:.2} % off by > 8\n", agree * 100.0, far * 100.0));
            if agree < 0.995 || mean > 2.0 || far > 0.01 {
                failures.push(name);
            }
        }
        // A generated random scene too.
        let mut storage = vec![Object::<f64>::default(); 30];
        let mut b = SceneBuilder::new(&mut storage);
        random_scene(&mut b, &RandomScene { objects: 30, group_size: 0, spread: 0.0, seed: 42 }).unwrap();
        let scene = b.finish().unwrap();
        let (agree, mean, far) = compare("random30", &scene);
        report.push_str(&format!("random30: coverage {:.2} %, mean |gray diff| {mean:.2} levels, {:.2} % off by > 8\n", agree * 100.0, far * 100.0));
        if agree < 0.995 || mean > 2.0 || far > 0.01 {
            failures.push("random30".into());
        }
        eprintln!("{report}images under {}", work().display());
        std::fs::write(work().join("report.txt"), &report).unwrap();
        assert!(failures.is_empty(), "POV-Ray disagrees on {failures:?}:\n{report}images and diffs: {}", work().display());
    }
}
