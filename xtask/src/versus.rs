//! `cargo xtask bench`'s POV-Ray columns: host-sim's render time on one core against POV-Ray 3.7's
//! own "Trace Time" for the same scene (exported with `export --pov`), the same size, one
//! thread (`+WT1`), no anti-aliasing, with and without shadows.

use anyhow::{bail, Context, Result};
use host_sim::pov::{export, PovMode};
use host_sim::run::render_band;
use host_sim::shared::median;
use lattice_rt::{Accelerator, Effects, Frame, Scene, Tracer};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// Width and height of the comparison (large enough for POV-Ray's millisecond clock).
pub const SIZE: (u16, u16) = (480, 300);
/// The speed-up over POV-Ray the issue asks for on every scene.
pub const TARGET: f64 = 2.0;
/// The speed-up over POV-Ray the issue asks for on the paper's scenes.
pub const PAPER_TARGET: f64 = 3.0;
/// The paper's scenes, by the names the comparison gives them.
const PAPER_SCENES: [&str; 4] = ["chair", "desk", "polyhedron", "spheres"];

/// Whether `povray` can be run here.
pub fn available() -> bool {
    Command::new("povray").arg("--version").output().is_ok_and(|o| o.status.success() || !o.stderr.is_empty())
}

/// One scene of the comparison.
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Primitives.
    pub n: usize,
    /// Shadow rays cast.
    pub shadows: bool,
    /// host-sim's render time (median).
    pub ours: Duration,
    /// POV-Ray's trace time (median).
    pub pov: Duration,
    /// host-sim's object tests per ray, all rays.
    pub tests: f64,
}

impl Row {
    /// How many times faster host-sim is.
    pub fn speedup(&self) -> f64 {
        self.pov.as_secs_f64() / self.ours.as_secs_f64().max(1e-9)
    }
}

/// `pov` with every light made `shadowless`.
fn shadowless(pov: &str) -> String {
    pov.lines()
        .map(|l| match l.strip_prefix("light_source {").and_then(|r| r.strip_suffix('}')) {
            Some(body) => format!("light_source {{{body}shadowless }}\n"),
            None => format!("{l}\n"),
        })
        .collect()
}

/// POV-Ray's "Trace Time" in its statistics on stderr: `... (0.123 seconds)`.
fn trace_time(stderr: &str) -> Option<Duration> {
    let line = stderr.lines().find(|l| l.trim_start().starts_with("Trace Time:"))?;
    let secs = line.rsplit('(').next()?.split_whitespace().next()?.parse::<f64>().ok()?;
    Some(Duration::from_secs_f64(secs))
}

/// Renders `pov` with POV-Ray (one thread, no anti-aliasing, no file written) and returns its
/// trace time.
fn povray(pov: &str, work: &Path, name: &str, size: (u16, u16)) -> Result<Duration> {
    let src = work.join(format!("{}.pov", name.replace(' ', "-")));
    std::fs::write(&src, pov).with_context(|| format!("cannot write {}", src.display()))?;
    let out = Command::new("povray")
        .arg(format!("+I{}", src.display()))
        .args([format!("+W{}", size.0), format!("+H{}", size.1), "-D".into(), "-F".into(), "-A".into(), "+WT1".into()])
        .env("HOME", work)
        .output()
        .context("cannot run povray (Debian package povray)")?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        bail!("povray failed on {}: {}", src.display(), stderr.lines().rev().take(5).collect::<Vec<_>>().join(" / "));
    }
    trace_time(&stderr).with_context(|| format!("povray printed no Trace Time for {}", src.display()))
}

/// Renders `pov` with POV-Ray at `size` into the PNG `png` (one thread, no anti-aliasing).
pub fn povray_picture(pov: &str, png: &Path, size: (u16, u16)) -> Result<()> {
    let work = std::env::temp_dir().join("lattice-rt-pov-picture");
    std::fs::create_dir_all(&work)?;
    let src = work.join("scene.pov");
    std::fs::write(&src, pov).with_context(|| format!("cannot write {}", src.display()))?;
    let out = Command::new("povray")
        .arg(format!("+I{}", src.display()))
        .arg(format!("+O{}", png.display()))
        .args([format!("+W{}", size.0), format!("+H{}", size.1), "-D".into(), "+FN".into(), "-A".into(), "+WT1".into()])
        .env("HOME", &work)
        .output()
        .context("cannot run povray (Debian package povray)")?;
    if !out.status.success() {
        bail!("povray failed on {}", src.display());
    }
    Ok(())
}

/// Times `scene` in host-sim (its default tracer over `accel`, one core) and, given a work
/// folder, in POV-Ray, interleaved `runs` times, with and without shadows (POV-Ray's time is
/// zero without one), at [`SIZE`].
pub fn compare(
    name: &str,
    scene: &Scene<'_, f64>,
    accel: &(dyn Accelerator<f64> + Sync),
    runs: usize,
    work: Option<&Path>,
) -> Result<Vec<Row>> {
    compare_at(name, scene, accel, (runs, SIZE, true), work)
}

/// [`compare`] at `size`, `runs` times, also without shadows when `unshadowed` (the scene's
/// camera must be fitted to the size's shape). host-sim's frame is `Frame::new`'s: one ray per
/// pixel, no silhouette lines (POV-Ray draws none).
pub fn compare_at(
    name: &str,
    scene: &Scene<'_, f64>,
    accel: &(dyn Accelerator<f64> + Sync),
    (runs, size, unshadowed): (usize, (u16, u16), bool),
    work: Option<&Path>,
) -> Result<Vec<Row>> {
    if let Some(work) = work {
        std::fs::create_dir_all(work).with_context(|| format!("cannot create {}", work.display()))?;
    }
    let full = export(scene, PovMode::Full)?;
    let frame = Frame::new(size.0, size.1);
    let mut rows = Vec::new();
    for shadows in [true, false].into_iter().take(if unshadowed { 2 } else { 1 }) {
        let pov_text = if shadows { full.clone() } else { shadowless(&full) };
        let mut tracer = Tracer::new(scene, accel);
        if !shadows {
            tracer.set_effects(tracer.effects() - Effects::SHADOWS);
        }
        let (mut ours, mut pov, mut tests) = (Vec::new(), Vec::new(), 0.0);
        for _ in 0..runs.max(1) {
            let r = render_band(&tracer, &frame, false)?;
            ours.push(r.elapsed);
            tests = r.stats.object_tests as f64 / r.stats.total_rays().max(1) as f64;
            if let Some(work) = work {
                pov.push(povray(&pov_text, work, name, size)?);
            }
        }
        rows.push(Row {
            scene: name.to_string(),
            n: scene.objects().len(),
            shadows,
            ours: median(ours),
            pov: if pov.is_empty() { Duration::ZERO } else { median(pov) },
            tests,
        });
    }
    Ok(rows)
}

/// The section of docs/performance.md.
pub fn section(rows: &[Row], runs: usize) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "## Against POV-Ray 3.7\n")?;
    writeln!(
        md,
        "Each scene exported with `host-sim export --pov` and rendered by POV-Ray at {}x{}, one thread",
        SIZE.0, SIZE.1
    )?;
    writeln!(md, "(`+WT1`), no anti-aliasing, no output file; POV-Ray's own *Trace Time* (parsing and bounding")?;
    writeln!(md, "left out) against host-sim's render time on one core (lattice built before, f64, the tracer's")?;
    writeln!(md, "defaults, dithering and 1-bit output included). Medians of {runs} runs, the two interleaved.")?;
    writeln!(md, "Without shadows: POV-Ray's lights `shadowless`, host-sim's shadow effect off. Generated scenes")?;
    writeln!(md, "as in *Scaling* below (random; clustered: the teapot in a stadium). Target: host-sim at least")?;
    writeln!(md, "{TARGET}x faster on every scene, {PAPER_TARGET}x on the paper's.\n")?;
    writeln!(md, "| scene | N | shadows | host-sim ms | POV-Ray trace ms | host-sim faster by | object tests/ray |\n|---|---:|---|---:|---:|---:|---:|")?;
    for r in rows {
        let (pov, by) = if r.pov.is_zero() {
            ("-".into(), "-".into())
        } else {
            (format!("{:.1}", r.pov.as_secs_f64() * 1e3), format!("{:.2}x", r.speedup()))
        };
        writeln!(
            md,
            "| {} | {} | {} | {:.1} | {pov} | {by} | {:.2} |",
            r.scene,
            r.n,
            if r.shadows { "yes" } else { "no" },
            r.ours.as_secs_f64() * 1e3,
            r.tests
        )?;
    }
    let timed: Vec<&Row> = rows.iter().filter(|r| !r.pov.is_zero()).collect();
    if let (Some(lo), Some(hi)) = (
        timed.iter().min_by(|a, b| a.speedup().total_cmp(&b.speedup())),
        timed.iter().max_by(|a, b| a.speedup().total_cmp(&b.speedup())),
    ) {
        let met = timed.iter().filter(|r| r.speedup() >= TARGET).count();
        let paper: Vec<&&Row> = timed.iter().filter(|r| PAPER_SCENES.contains(&r.scene.as_str())).collect();
        let paper_met = paper.iter().filter(|r| r.speedup() >= PAPER_TARGET).count();
        writeln!(
            md,
            "\nhost-sim is {:.2}x ({}, {} shadows) to {:.2}x ({}) faster than POV-Ray; the {TARGET}x target holds on {met} of {} scenes, the {PAPER_TARGET}x target on {paper_met} of the {} paper scene rows.\n",
            lo.speedup(),
            lo.scene,
            if lo.shadows { "with" } else { "without" },
            hi.speedup(),
            hi.scene,
            timed.len(),
            paper.len()
        )?;
    }
    // Loose clusters against the same scenes with the cluster declared a composite.
    for r in rows.iter().filter(|r| r.scene.starts_with("loose clustered ")) {
        let declared = format!("clustered {}", r.n);
        if let Some(d) = rows.iter().find(|d| d.scene == declared && d.shadows == r.shadows) {
            writeln!(
                md,
                "{} ({} shadows): {:.2} object tests per ray, {:.2}x those with the cluster declared a composite (target: at most {LOOSE_TARGET}x).",
                r.scene,
                if r.shadows { "with" } else { "without" },
                r.tests,
                r.tests / d.tests.max(1e-9)
            )?;
        }
    }
    Ok(md)
}

/// How many times the object tests per ray of a loose cluster may be those of the declared one.
pub const LOOSE_TARGET: f64 = 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_trace_time_and_makes_lights_shadowless() {
        let err = "Render Time:\n  Photon Time:      No photons\n  Trace Time:       0 hours  0 minutes  1 seconds (1.250 seconds)\n";
        assert_eq!(trace_time(err), Some(Duration::from_millis(1250)));
        assert_eq!(trace_time("nothing"), None);
        let pov = "background { rgb 0 }\nlight_source { <1, 2, 3> color rgb 1 parallel point_at <0, 0, 0> }\nsphere { <0, 0, 0>, 1 }\n";
        let s = shadowless(pov);
        assert!(s.contains("point_at <0, 0, 0> shadowless }"), "{s}");
        assert!(s.contains("sphere { <0, 0, 0>, 1 }"));
    }
}
