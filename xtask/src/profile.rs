//! `cargo xtask profile`: where a QEMU firmware build's instructions go, counted exactly rather
//! than sampled. QEMU logs every translated block's instructions (`-d in_asm`) and every
//! execution of a block (`-d exec,nochain`, so no block chains into the next unlogged); each
//! executed instruction is credited to its function and to every function it was inlined from
//! (the ELF's DWARF, read with `addr2line`). With `-icount shift=0` the counts are the same on
//! every machine, like the firmware report's.

use crate::firmware;
use anyhow::{bail, Context, Result};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::Stdio;

/// What `cargo xtask profile` was asked.
pub struct ProfileArgs {
    /// A variant of `cargo xtask firmware` that runs in QEMU.
    pub variant: String,
    /// The one scene the profiled image embeds.
    pub scene: String,
    /// Rows per table.
    pub top: usize,
    /// A function whose instructions are broken down by what it inlined or its own lines.
    pub under: Option<String>,
}

/// Functions of the QEMU harness, not of the frame: the calibration loop that times SysTick
/// and the stack painting that measures the high-water mark. Instructions in them (or in code
/// inlined into them), and start-up code without debug information, are left out of the shares.
const HARNESS: [&str; 2] = ["spin", "high_water"];

/// Builds the variant with the scene alone, runs it in QEMU with block logging and prints
/// the instruction profile.
pub fn profile_cmd(root: &Path, args: &ProfileArgs) -> Result<()> {
    let v = firmware::profiled_variant(&args.variant, &args.scene)?;
    let machine = v.machine.context("that variant does not run in QEMU")?;
    eprintln!("building {} with only {} ...", v.name, args.scene);
    firmware::build(root, &v)?;
    let elf = firmware::elf_path(root, &v);
    eprintln!("running {} on {machine} with every block logged ...", elf.display());
    let counts = run_logged(&elf, machine)?;
    let profile = Profile::of(&elf, &counts)?;
    print!("{}", profile.report(&v.name, &args.scene, args.top, args.under.as_deref())?);
    Ok(())
}

/// Runs `elf` on QEMU `machine` with every block's translation and execution logged to its
/// standard error, read as it comes (a frame of the Whitted scene logs gigabytes), and returns
/// how often each instruction address ran.
fn run_logged(elf: &Path, machine: &str) -> Result<HashMap<u32, u64>> {
    let mut child = firmware::qemu(elf, machine, &["-d", "in_asm,exec,nochain", "-D", "/dev/stderr"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start qemu-system-arm (Debian package qemu-system-arm)")?;
    let log = BufReader::with_capacity(1 << 20, child.stderr.take().context("no QEMU log")?);
    // Each block by its host address: its guest instructions, and how often it ran.
    let mut blocks: HashMap<u64, (Vec<u32>, u64)> = HashMap::new();
    let mut listing: Option<Vec<u32>> = None;
    for line in log.lines() {
        let line = line.context("cannot read QEMU's log")?;
        if line.starts_with("IN:") {
            listing = Some(Vec::new());
        } else if let (Some(list), Some(rest)) = (listing.as_mut(), line.strip_prefix("0x")) {
            if let Some(pc) = rest.split(':').next().and_then(|h| u32::from_str_radix(h, 16).ok()) {
                list.push(pc);
            }
        } else if let Some(rest) = line.strip_prefix("Trace ") {
            // `Trace 0: 0x7f... [flags/pc/...] name`: the block's host address names it.
            let host =
                rest.split_whitespace().nth(1).and_then(|h| u64::from_str_radix(h.trim_start_matches("0x"), 16).ok());
            let Some(host) = host else { continue };
            let entry = blocks.entry(host).or_default();
            if let Some(list) = listing.take() {
                entry.0 = list;
            }
            entry.1 += 1;
        }
    }
    let status = child.wait()?;
    if !status.success() {
        bail!("{} failed in QEMU ({status})", elf.display());
    }
    let mut counts: HashMap<u32, u64> = HashMap::new();
    for (pcs, runs) in blocks.values() {
        for &pc in pcs {
            *counts.entry(pc).or_default() += runs;
        }
    }
    Ok(counts)
}

/// Instructions per function.
struct Profile {
    /// Every instruction run.
    run: u64,
    /// Of those, the harness's ([`HARNESS`]) and start-up code's.
    harness: u64,
    /// Per function, the instructions of its own code and of code inlined into it.
    inclusive: HashMap<String, u64>,
    /// Per function, the instructions of its own code (the innermost frame).
    own: HashMap<String, u64>,
    /// Per address, its frames (innermost first) and count, for the breakdown under a function.
    frames: Vec<(Vec<(String, String)>, u64)>,
}

impl Profile {
    fn of(elf: &Path, counts: &HashMap<u32, u64>) -> Result<Profile> {
        let loader = addr2line::Loader::new(elf)
            .map_err(|e| anyhow::anyhow!("cannot read the debug information of {}: {e}", elf.display()))?;
        let mut p = Profile { run: 0, harness: 0, inclusive: HashMap::new(), own: HashMap::new(), frames: Vec::new() };
        for (&pc, &n) in counts {
            p.run += n;
            let mut chain = Vec::new();
            let mut frames = loader.find_frames(u64::from(pc)).map_err(|e| anyhow::anyhow!("{e}"))?;
            while let Ok(Some(f)) = frames.next() {
                let name = f
                    .function
                    .as_ref()
                    .and_then(|n| n.demangle().ok())
                    .map_or_else(|| "(unknown)".to_string(), |n| short_name(&n));
                let at = f.location.as_ref().map_or_else(String::new, |l| {
                    format!("{}:{}", l.file.map_or("?", |f| f.rsplit('/').next().unwrap_or(f)), l.line.unwrap_or(0))
                });
                chain.push((name, at));
            }
            if chain.is_empty() || chain.iter().any(|(name, _)| HARNESS.iter().any(|h| name.ends_with(h))) {
                p.harness += n;
                continue;
            }
            *p.own.entry(chain[0].0.clone()).or_default() += n;
            let mut seen: Vec<&str> = Vec::new();
            for (name, _) in &chain {
                if !seen.contains(&name.as_str()) {
                    seen.push(name);
                    *p.inclusive.entry(name.clone()).or_default() += n;
                }
            }
            p.frames.push((chain, n));
        }
        Ok(p)
    }

    fn report(&self, variant: &str, scene: &str, top: usize, under: Option<&str>) -> Result<String> {
        let frame = self.run - self.harness;
        let mut md = String::new();
        writeln!(
            md,
            "# Instructions of `{variant}` rendering the {scene} (QEMU, `-icount shift=0`, every block logged)\n"
        )?;
        writeln!(
            md,
            "{} instructions ran; {} of them are the frame's, the rest the harness's ({}) and start-up code.",
            self.run,
            frame,
            HARNESS.join(", ")
        )?;
        writeln!(md, "Shares are of the frame's instructions.\n")?;
        let table = |md: &mut String, title: &str, map: &HashMap<String, u64>| -> Result<()> {
            writeln!(md, "## {title}\n\n| instructions | share | function |\n|---:|---:|---|")?;
            let mut rows: Vec<(&String, &u64)> = map.iter().collect();
            rows.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
            for (name, n) in rows.into_iter().take(top) {
                writeln!(md, "| {n} | {:.1} % | `{name}` |", 100.0 * *n as f64 / frame.max(1) as f64)?;
            }
            writeln!(md)?;
            Ok(())
        };
        table(&mut md, "With the code inlined into each function", &self.inclusive)?;
        table(&mut md, "Each function's own code", &self.own)?;
        if let Some(func) = under {
            let mut parts: HashMap<String, u64> = HashMap::new();
            for (chain, n) in &self.frames {
                let Some(k) = chain.iter().rposition(|(name, _)| name.ends_with(func)) else { continue };
                let part = match k.checked_sub(1) {
                    Some(inner) => chain[inner].0.clone(),
                    None => format!("(own code, {})", chain[k].1),
                };
                *parts.entry(part).or_default() += n;
            }
            if parts.is_empty() {
                bail!("no instruction of the frame ran in a function named `{func}`");
            }
            table(&mut md, &format!("Under `{func}`: what it inlined, and its own lines"), &parts)?;
        }
        Ok(md)
    }
}

/// A demangled function name without generic arguments, hash or crate path: the type (if a
/// method) and the function, as `Shape::intersect` or `render_tiles::{{closure}}`.
fn short_name(full: &str) -> String {
    let mut plain = String::new();
    let mut depth = 0;
    for c in full.chars() {
        match c {
            '<' => depth += 1,
            '>' => depth -= 1,
            _ if depth == 0 => plain.push(c),
            _ => {}
        }
    }
    // Symbol hashes (`h` and 16 hex digits) are dropped with the empty segments.
    let hash = |p: &str| p.len() == 17 && p.starts_with('h');
    let parts: Vec<&str> = plain.split("::").filter(|p| !p.is_empty() && !hash(p)).collect();
    parts[parts.len().saturating_sub(2)..].join("::")
}

#[cfg(test)]
mod tests {
    use super::short_name;

    #[test]
    fn names_keep_type_and_function() {
        assert_eq!(short_name("lattice_rt::shape::Shape<f32>::intersect"), "Shape::intersect");
        assert_eq!(short_name("<lattice_rt::fixed::Fx as core::ops::arith::Mul>::mul"), "mul");
        assert_eq!(short_name("lattice_rt::render::render_tiles::{{closure}}"), "render_tiles::{{closure}}");
        assert_eq!(short_name("qemu::spin"), "qemu::spin");
    }
}
