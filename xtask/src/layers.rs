//! `cargo xtask layers`: the house's layers, read from the code. Every crate of the repository
//! (the core, host-sim, the firmware's library and binaries, xtask, the board records) is a tree
//! of modules; a module that names another (`crate::a::b`, `super::c`) depends on it. Within
//! each folder the dependencies between its modules must form no circle, so each folder is a
//! stack of layers; and ARCHITECTURE.md, the map, must name every module of every crate.
//!
//! The imports are read as text: `crate::` and `super::` paths outside comments and outside
//! test modules (`tests.rs`, and a file's `#[cfg(test)] mod tests` onwards). A name a file
//! takes from its own folder's `mod.rs` (the folder's face) is no dependency between siblings.

use anyhow::{bail, Context, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A crate root as the map names it: its heading's folder in ARCHITECTURE.md, the folder its
/// modules live in, its root file, and the folders beside it that belong to other roots.
struct Root {
    /// The folder named in the map's heading for this crate (`src/`, `host-sim/src/`, ...).
    heading: &'static str,
    /// The folder of the root file, from the repository's top.
    dir: &'static str,
    /// Folders under `dir` that are not this root's modules (another root's).
    skip: &'static [&'static str],
}

/// Every crate root of the repository whose modules the map must name.
const ROOTS: &[Root] = &[
    Root { heading: "src/", dir: "src", skip: &[] },
    Root { heading: "host-sim/src/", dir: "host-sim/src", skip: &[] },
    Root { heading: "records/src/", dir: "records/src", skip: &[] },
    Root { heading: "firmware/src/", dir: "firmware/src", skip: &["bin"] },
    Root { heading: "firmware/src/bin/pico/", dir: "firmware/src/bin/pico", skip: &[] },
    Root { heading: "xtask/src/", dir: "xtask/src", skip: &[] },
];

/// Files that are crate roots, not modules.
const ROOT_FILES: &[&str] = &["lib.rs", "main.rs"];

/// One module: its path (`scene::region`) and its file.
#[derive(Debug)]
struct Module {
    path: Vec<String>,
    file: PathBuf,
}

/// The modules of a crate root: every `.rs` file below its folder but the root files, test
/// files and other roots' folders. A single-file binary (`bin/qemu.rs`) is a root of its own
/// with no modules.
fn modules(top: &Path, root: &Root) -> Result<Vec<Module>> {
    let mut out = Vec::new();
    let base = top.join(root.dir);
    let mut stack = vec![base.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).with_context(|| format!("cannot read {}", dir.display()))? {
            let path = entry?.path();
            let rel = path.strip_prefix(&base)?.to_path_buf();
            if path.is_dir() {
                if !root.skip.iter().any(|s| rel == Path::new(s)) {
                    stack.push(path);
                }
                continue;
            }
            let name = rel.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            if !name.ends_with(".rs")
                || name == "tests.rs"
                || (rel.parent() == Some(Path::new("")) && ROOT_FILES.contains(&name))
            {
                continue;
            }
            let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            let last = parts.pop().unwrap_or_default();
            if last != "mod.rs" {
                parts.push(last.trim_end_matches(".rs").to_owned());
            }
            out.push(Module { path: parts, file: path });
        }
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(out)
}

/// A file's code as the import reader sees it: comments dropped, and nothing from its test
/// module on.
fn code_of(text: &str) -> Vec<(usize, String)> {
    let mut lines: Vec<(usize, String)> = Vec::new();
    let mut it = text.lines().enumerate().peekable();
    while let Some((i, line)) = it.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]") && it.peek().is_some_and(|(_, l)| l.trim_start().starts_with("mod tests")) {
            break;
        }
        let code = line.find("//").map_or(line, |k| &line[..k]);
        // A `use` that runs over several lines is read as one, at its first line.
        match lines.last_mut() {
            Some((_, open)) if open_use(open) => open.push_str(code.trim()),
            _ => lines.push((i + 1, code.to_owned())),
        }
    }
    lines
}

/// Whether `code` starts a `use` its line does not finish.
fn open_use(code: &str) -> bool {
    let t = code.trim_start();
    let t = t.strip_prefix("pub").map_or(t, |r| r.trim_start_matches(|c: char| c != ' ').trim_start());
    t.starts_with("use ") && !t.contains(';')
}

/// The module paths a line of code names: each `crate::` and `super::` path, resolved from
/// module `from` (a `use` group's members each count: `super::{a, b::c}`).
fn named(from: &[String], line: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for start in ["crate::", "super::"] {
        let mut rest = line;
        while let Some(k) = rest.find(start) {
            let before = rest[..k].chars().last();
            let tail = &rest[k..];
            rest = &rest[k + start.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let (base, tail) = if start == "crate::" {
                (Vec::new(), &tail["crate::".len()..])
            } else {
                let mut base = from.to_vec();
                let mut tail = tail;
                while let Some(t) = tail.strip_prefix("super::") {
                    base.pop();
                    tail = t;
                }
                (base, tail)
            };
            for path in expand(tail) {
                let mut p = base.clone();
                p.extend(path);
                out.push(p);
            }
        }
    }
    out
}

/// The paths a `use` tail names: `a::b::C` gives `[a, b, C]`; `{a, b::c}` gives `[a]` and
/// `[b, c]` (one level of braces, enough for the module names).
fn expand(tail: &str) -> Vec<Vec<String>> {
    let ident = |s: &str| s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>();
    let mut path = Vec::new();
    let mut s = tail;
    loop {
        if let Some(group) = s.strip_prefix('{') {
            // The group's members, split at its own commas (not a nested group's).
            let (mut members, mut depth, mut from) = (Vec::new(), 0, 0);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        members.push(&group[from..i]);
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        members.push(&group[from..i]);
                        from = i + 1;
                    }
                    _ => {}
                }
            }
            return members
                .into_iter()
                .map(|m| {
                    let mut p = path.clone();
                    p.extend(m.trim().split("::").map(ident).take_while(|w| !w.is_empty()));
                    p
                })
                .collect();
        }
        let word = ident(s);
        if word.is_empty() {
            break;
        }
        s = &s[word.len()..];
        path.push(word);
        match s.strip_prefix("::") {
            Some(t) => s = t,
            None => break,
        }
    }
    vec![path]
}

/// A dependency between two modules of one folder, and where the code takes it.
type Edges = BTreeMap<(String, String), Vec<String>>;

/// The dependencies of one circle, with where the code takes each.
type Circle<'e> = Vec<(&'e (String, String), &'e Vec<String>)>;

/// The dependencies of a crate root, per folder (the module path of the folder, `""` for the
/// root): between the folder's children, each named by the child a path goes through.
fn dependencies(top: &Path, mods: &[Module]) -> Result<BTreeMap<Vec<String>, Edges>> {
    let known: BTreeSet<&[String]> = mods.iter().map(|m| m.path.as_slice()).collect();
    let mut graphs: BTreeMap<Vec<String>, Edges> = BTreeMap::new();
    for m in mods {
        let text = std::fs::read_to_string(&m.file).with_context(|| format!("cannot read {}", m.file.display()))?;
        let rel = m.file.strip_prefix(top).unwrap_or(&m.file).display().to_string();
        for (line_no, code) in code_of(&text) {
            for target in named(&m.path, &code) {
                // The longest prefix of the path that is a module.
                let Some(target) = (1..=target.len()).rev().map(|n| &target[..n]).find(|p| known.contains(p)) else {
                    continue;
                };
                let common = m.path.iter().zip(target).take_while(|(a, b)| a == b).count();
                if common >= m.path.len().min(target.len()) {
                    continue; // a module and its own folder or child: not two siblings
                }
                let edge = (m.path[common].clone(), target[common].clone());
                graphs
                    .entry(m.path[..common].to_vec())
                    .or_default()
                    .entry(edge)
                    .or_default()
                    .push(format!("{rel}:{line_no}"));
            }
        }
    }
    Ok(graphs)
}

/// The circles of one folder's graph: each strongly connected set of two or more modules,
/// with the edges inside it.
fn circles(edges: &Edges) -> Vec<Circle<'_>> {
    let nodes: BTreeSet<&String> = edges.keys().flat_map(|(a, b)| [a, b]).collect();
    let reach = |from: &String| {
        let mut seen = BTreeSet::from([from.clone()]);
        let mut todo = vec![from.clone()];
        while let Some(n) = todo.pop() {
            for (a, b) in edges.keys() {
                if *a == n && seen.insert(b.clone()) {
                    todo.push(b.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> = nodes.iter().map(|n| (*n, reach(n))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for n in &nodes {
        if done.contains(*n) {
            continue;
        }
        let set: BTreeSet<&String> =
            nodes.iter().copied().filter(|m| reaches[n].contains(*m) && reaches[m].contains(*n)).collect();
        done.extend(set.iter().map(|s| (*s).clone()));
        if set.len() > 1 {
            out.push(edges.iter().filter(|((a, b), _)| set.contains(a) && set.contains(b)).collect());
        }
    }
    out
}

/// The map's section for a crate root: from its heading (a line starting `#` that names the
/// folder in backticks) to the next heading of the same or a higher level.
fn section<'m>(map: &'m str, heading: &str) -> Option<&'m str> {
    let tag = format!("`{heading}`");
    let start = map.lines().position(|l| l.starts_with('#') && l.contains(&tag))?;
    let level = map.lines().nth(start)?.chars().take_while(|c| *c == '#').count();
    let lines: Vec<&str> = map.lines().collect();
    let end = (start + 1..lines.len())
        .find(|&i| {
            let l = lines[i];
            l.starts_with('#') && l.chars().take_while(|c| *c == '#').count() <= level
        })
        .unwrap_or(lines.len());
    let from = map.lines().take(start).map(|l| l.len() + 1).sum::<usize>();
    let to = map.lines().take(end).map(|l| l.len() + 1).sum::<usize>().min(map.len());
    Some(&map[from..to])
}

/// What the check found: each root's folders as layers (bottom first), its circles and the
/// modules the map leaves out.
pub struct Findings {
    /// The report, as `cargo xtask layers` prints it.
    pub report: String,
    /// One line per circle and per module the map does not name.
    pub problems: Vec<String>,
}

/// Reads every crate root of the repository at `top` and its map.
pub fn check(top: &Path) -> Result<Findings> {
    let map = std::fs::read_to_string(top.join("ARCHITECTURE.md")).context("cannot read ARCHITECTURE.md")?;
    let mut report = String::new();
    let mut problems = Vec::new();
    for root in ROOTS {
        let mods = modules(top, root)?;
        writeln!(report, "## {} ({} modules)", root.heading, mods.len())?;
        let mut graphs = dependencies(top, &mods)?;
        let mut children: BTreeMap<Vec<String>, BTreeSet<String>> = BTreeMap::new();
        for m in &mods {
            let (last, folder) = m.path.split_last().expect("a module has a name");
            children.entry(folder.to_vec()).or_default().insert(last.clone());
            graphs.entry(folder.to_vec()).or_default();
        }
        for (folder, edges) in &graphs {
            let name = if folder.is_empty() { "crate".to_owned() } else { folder.join("::") };
            for circle in circles(edges) {
                let mut why = format!("{}: a circle in `{name}`:", root.heading);
                for ((a, b), at) in circle {
                    write!(why, " {a} -> {b} ({});", at.join(", "))?;
                }
                problems.push(why);
            }
            writeln!(report, "- `{name}`: {}", layers(&children[folder], edges).join(" < "))?;
        }
        match section(&map, root.heading) {
            None => problems.push(format!("ARCHITECTURE.md has no section headed `{}`", root.heading)),
            Some(text) => {
                for m in &mods {
                    let path = m.path.join("::");
                    if !text.contains(&format!("`{path}`")) {
                        problems.push(format!(
                            "ARCHITECTURE.md's `{}` section does not name module `{path}`",
                            root.heading
                        ));
                    }
                }
            }
        }
    }
    Ok(Findings { report, problems })
}

/// A folder's modules as layers, lowest first: each layer depends only on layers below it
/// (modules in a circle share a layer, marked with `*`).
fn layers(modules: &BTreeSet<String>, edges: &Edges) -> Vec<String> {
    let nodes: BTreeSet<&String> = modules.iter().chain(edges.keys().flat_map(|(a, b)| [a, b])).collect();
    let mut placed: BTreeMap<&String, usize> = BTreeMap::new();
    let mut rows: Vec<Vec<String>> = Vec::new();
    while placed.len() < nodes.len() {
        let ready: Vec<&String> = nodes
            .iter()
            .copied()
            .filter(|n| !placed.contains_key(n))
            .filter(|n| edges.keys().all(|(a, b)| a != *n || b == *n || placed.contains_key(b)))
            .collect();
        let (row, mark) = if ready.is_empty() {
            (nodes.iter().copied().filter(|n| !placed.contains_key(n)).collect::<Vec<_>>(), "*")
        } else {
            (ready, "")
        };
        for n in &row {
            placed.insert(n, rows.len());
        }
        rows.push(row.iter().map(|n| format!("{n}{mark}")).collect());
    }
    rows.into_iter().map(|r| r.join(" ")).collect()
}

/// `cargo xtask layers`: prints each folder's layers; fails on a circle or a module the map
/// leaves out.
pub fn layers_cmd(top: &Path) -> Result<()> {
    let f = check(top)?;
    print!("{}", f.report);
    if !f.problems.is_empty() {
        for p in &f.problems {
            eprintln!("error: {p}");
        }
        bail!(
            "{} problem(s): the layers must form no circle and ARCHITECTURE.md must name every module",
            f.problems.len()
        );
    }
    println!("no circle; ARCHITECTURE.md names every module");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn top() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lies in the repository").to_path_buf()
    }

    #[test]
    fn the_house_has_no_circle_and_its_map_names_every_module() {
        let f = check(&top()).expect("the repository reads");
        assert!(f.problems.is_empty(), "{}", f.problems.join("\n"));
    }

    #[test]
    fn paths_resolve_from_the_module_that_names_them() {
        let from: Vec<String> = ["lattice", "cluster"].map(String::from).to_vec();
        let got = named(&from, "use super::{planes::{span, Planes}, locate_by}; let x = crate::scene::Scene::new();");
        let want: Vec<Vec<&str>> =
            vec![vec!["scene", "Scene", "new"], vec!["lattice", "planes"], vec!["lattice", "locate_by"]];
        assert_eq!(got, want.iter().map(|p| p.iter().map(|s| s.to_string()).collect::<Vec<_>>()).collect::<Vec<_>>());
    }

    #[test]
    fn a_circle_is_found_and_a_chain_is_not() {
        let edge = |a: &str, b: &str| ((a.to_owned(), b.to_owned()), vec![format!("{a}.rs:1")]);
        let chain: Edges = [edge("a", "b"), edge("b", "c")].into_iter().collect();
        assert!(circles(&chain).is_empty());
        let modules = ["a", "b", "c", "e"].map(String::from).into_iter().collect();
        assert_eq!(layers(&modules, &chain), ["c e", "b", "a"]);
        let circle: Edges = [edge("a", "b"), edge("b", "c"), edge("c", "a"), edge("d", "a")].into_iter().collect();
        let found = circles(&circle);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].len(), 3);
    }

    #[test]
    fn test_modules_and_comments_are_not_read() {
        let code = code_of("use crate::a::B; // crate::c\n#[cfg(test)]\nmod tests {\n    use crate::d;\n}\n");
        assert_eq!(code, vec![(1, "use crate::a::B; ".to_owned())]);
        let code = code_of("pub(crate) use super::{\n    a::X,\n    b,\n};\nfn f() {}\n");
        assert_eq!(code, vec![(1, "pub(crate) use super::{a::X,b,};".to_owned()), (5, "fn f() {}".to_owned())]);
    }
}
