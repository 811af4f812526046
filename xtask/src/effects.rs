//! `cargo xtask effects`: what simulating only the effects a scene calls for saves, in rays, host
//! time, Cortex-M instructions and flash, and what the contribution cutoff (Hall and
//! Greenberg's adaptive tree depth) saves and costs. Writes `docs/effects.md`.

use anyhow::{Context, Result};
use host_sim::load::{object_storage, parse_scene, read};
use host_sim::run::render_text;
use host_sim::shared::median;
use lattice_rt::{Effects, Frame, Stats};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

struct Shot {
    bits: Vec<u8>,
    stats: Stats,
    time: Duration,
}

fn shoot(path: &Path, text: &str, all: bool, cutoff: f64) -> Result<Shot> {
    let r = render_text::<f64>(path, text, &Frame::new(128, 64), |t| {
        if all {
            t.set_effects(Effects::ALL);
        }
        t.set_cutoff(cutoff);
    })?;
    Ok(Shot { bits: r.bits, stats: r.stats, time: r.elapsed })
}

fn differ(a: &[u8], b: &[u8]) -> u32 {
    a.iter().zip(b).map(|(x, y)| (x ^ y).count_ones()).sum()
}

fn kinds(s: &Stats) -> String {
    format!("{} / {} / {} / {}", s.rays[0], s.rays[1], s.rays[2], s.rays[3])
}

/// The command.
pub fn effects_cmd(scenes: &[PathBuf], runs: usize, out: &Path, firmware_csv: &Path) -> Result<()> {
    let fw = firmware_figures(firmware_csv);
    let mut md = String::new();
    writeln!(md, "# Simulating only the effects a scene calls for\n")?;
    writeln!(md, "Written by `cargo xtask effects` (128x64, f64 on the host, median of {} interleaved\nruns; Cortex-M figures from `docs/firmware.csv`, written by `cargo xtask firmware`: QEMU `-icount\nshift=0`, fixed point, Cortex-M0+ build, the boards' frames: they leave out mirror, glass and\nshadow rays weighing less than half a gray step, the contribution cutoff of 1/128 below; the host's\nrays trace them all).\n", runs.max(1))?;
    writeln!(md, "## Derived effect set against every effect forced on\n\nRays are primary / shadow / reflection / refraction. \"All\" forces every effect on at run time\n(and, on the Cortex-M, compiles every effect in).\n")?;
    writeln!(md, "| scene | effect set | rays, derived | rays, all | host ms derived | host ms all | all / derived | same image | M0 Minstr derived | M0 Minstr all |\n|---|---|---|---|---|---|---|---|---|---|")?;
    let mut cut_rows = Vec::new();
    let bar = host_sim::progress::bar(scenes.len(), "scenes");
    for path in scenes {
        let name = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
        bar.set_message(name.clone());
        bar.inc(1);
        let text = read(path)?;
        let mut storage = object_storage::<f64>(&text)?;
        let fx = Effects::of(&parse_scene::<f64>(path, &text, &mut storage, &Frame::new(128, 64))?);
        let (mut td, mut ta) = (Vec::new(), Vec::new());
        let (mut d, mut a) = (None, None);
        for _ in 0..runs.max(1) {
            let x = shoot(path, &text, false, 0.0)?;
            td.push(x.time);
            d = Some(x);
            let y = shoot(path, &text, true, 0.0)?;
            ta.push(y.time);
            a = Some(y);
        }
        let (d, a) = (d.expect("ran"), a.expect("ran"));
        let (md_, ma) = (median(td), median(ta));
        let ins = |v: &str| {
            fw.get(&(v.to_string(), name.clone())).map_or("-".to_string(), |x| format!("{:.1}", x.0 as f64 / 1e6))
        };
        writeln!(
            md,
            "| {name} | {fx} | {} | {} | {:.2} | {:.2} | {:.2} | {} | {} | {} |",
            kinds(&d.stats),
            kinds(&a.stats),
            md_.as_secs_f64() * 1e3,
            ma.as_secs_f64() * 1e3,
            ma.as_secs_f64() / md_.as_secs_f64(),
            if d.bits == a.bits { "yes" } else { "NO" },
            ins("qemu-m0-fixed"),
            ins("qemu-m0-fixed-allfx")
        )?;
        let mut row = (name.clone(), d.stats.total_rays(), Vec::new());
        for c in [1.0 / 128.0, 1.0 / 64.0] {
            let s = shoot(path, &text, false, c)?;
            row.2.push((c, s.stats.total_rays(), differ(&s.bits, &d.bits)));
        }
        cut_rows.push(row);
    }
    cutoff_section(&mut md, &cut_rows)?;
    highlights_section(&mut md, runs)?;
    flash_section(&mut md, &fw)?;
    std::fs::create_dir_all(out.parent().unwrap_or(Path::new(".")))?;
    std::fs::write(out, md).with_context(|| format!("cannot write {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}

/// Instructions and flash bytes per (variant, scene), from `docs/firmware.csv` (empty without it).
fn firmware_figures(firmware_csv: &Path) -> BTreeMap<(String, String), (u64, u64)> {
    let csv = std::fs::read_to_string(firmware_csv).unwrap_or_default();
    let mut fw = BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() >= 7 {
            fw.insert((f[5].to_string(), f[0].to_string()), (f[3].parse().unwrap_or(0), f[6].parse().unwrap_or(0)));
        }
    }
    fw
}

/// Rays of each scene, and the cutoff's rays and changed pixels at each cutoff.
type CutRow = (String, u64, Vec<(f64, u64, u32)>);

/// What the contribution cutoff saves and changes.
/// Phong highlights, simulated where a material has `Ks > 0` and a `shine` power: the SPD's
/// sphereflake at size 2 (its spheres' NFF `Shine` is 3.08, rounded to 3) with and without them.
fn highlights_section(md: &mut String, runs: usize) -> Result<()> {
    let g = host_sim::spd::Generator::Balls;
    let text = g.nff(2)?;
    let path = Path::new("balls-2.nff");
    let shot = |on: bool| {
        render_text::<f64>(path, &text, &Frame::new(128, 64), |t| {
            if !on {
                t.set_effects(t.effects() - Effects::HIGHLIGHTS);
            }
        })
    };
    let (mut with, mut without) = (Vec::new(), Vec::new());
    let (mut a, mut b) = (None, None);
    for _ in 0..runs.max(1) {
        let x = shot(true)?;
        with.push(x.elapsed);
        a = Some(x);
        let y = shot(false)?;
        without.push(y.elapsed);
        b = Some(y);
    }
    let (a, b) = (a.context("no run")?, b.context("no run")?);
    writeln!(md, "\n## Highlights\n")?;
    writeln!(md, "A material with `ks` above 0 and a `shine` power gets a Phong highlight at each light (NFF's `Shine`); scenes without one do not compile it in. The SPD's sphereflake at size 2 (`host-sim spd balls --size 2`: 91 mirror spheres of `Shine` 3.08, rounded to 3), 128x64, with the highlights and without (`set_effects` without `highlights`):\n")?;
    writeln!(md, "| | rays | host ms | pixels differing from without |\n|---|---|---|---|")?;
    writeln!(
        md,
        "| with highlights | {} | {:.2} | {} |",
        kinds(&a.stats),
        median(with).as_secs_f64() * 1e3,
        differ(&a.bits, &b.bits)
    )?;
    writeln!(md, "| without | {} | {:.2} | 0 |\n", kinds(&b.stats), median(without).as_secs_f64() * 1e3)?;
    writeln!(md, "The same rays: a highlight is a term of each light's shadow-ray answer, no ray of its own.\n")?;
    Ok(())
}

fn cutoff_section(md: &mut String, cut_rows: &[CutRow]) -> Result<()> {
    writeln!(md, "\n## Contribution cutoff\n\nA branch of the intersection tree is not traced when its weight (the product of `Ks`/`Kt`\nalong the path) is below the cutoff; 1/64 is one of the 65 gray levels, 1/128 half of one.\nPixels are those of the 1-bit frame that differ from the frame without cutoff.\n")?;
    writeln!(md, "| scene | rays, no cutoff | rays, 1/128 | fewer | px changed | rays, 1/64 | fewer | px changed |\n|---|---|---|---|---|---|---|---|")?;
    let npx = 128.0 * 64.0;
    for (name, base, cuts) in cut_rows {
        let mut row = format!("| {name} | {base} |");
        for (_, rays, px) in cuts {
            write!(
                row,
                " {rays} | {:.1} % | {px} ({:.2} %) |",
                100.0 * (1.0 - *rays as f64 / *base as f64),
                100.0 * *px as f64 / npx
            )?;
        }
        writeln!(md, "{row}")?;
    }
    Ok(())
}

/// The flash the derived effect set saves against every effect compiled in.
fn flash_section(md: &mut String, fw: &BTreeMap<(String, String), (u64, u64)>) -> Result<()> {
    writeln!(md, "\n## Flash: code for effects a scene does not need\n\nThe same scenes built with the effects they call for and with every effect compiled in\n(`firmware/build.rs` derives the set from the embedded scenes; a const parameter of the tracer\nremoves the rest).\n")?;
    writeln!(md, "| scenes | derived effects | flash bytes, derived | flash bytes, every effect | saved |\n|---|---|---|---|---|")?;
    for (label, derived, all, fx) in [
        ("chair, desk, polyhedron (matte)", "qemu-m0-fixed-matte", "qemu-m0-fixed-matte-allfx", "shadows, composites"),
        ("all five", "qemu-m0-fixed", "qemu-m0-fixed-allfx", "shadows, reflection, refraction, composites"),
    ] {
        let flash = |v: &str| fw.iter().find(|((var, _), _)| var == v).map(|(_, x)| x.1);
        match (flash(derived), flash(all)) {
            (Some(d), Some(a)) => writeln!(
                md,
                "| {label} | {fx} | {d} | {a} | {} bytes ({:.1} %) |",
                a as i64 - d as i64,
                100.0 * (1.0 - d as f64 / a as f64)
            )?,
            _ => writeln!(md, "| {label} | {fx} | - | - | (run `cargo xtask firmware` first) |")?,
        }
    }
    Ok(())
}
