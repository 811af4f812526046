//! What the commands share: the scene lists, the accelerator names and the median of timings.

use std::path::{Path, PathBuf};
use std::time::Duration;

/// The paper's four scenes.
pub const PAPER_SCENES: [&str; 4] = ["chair", "desk", "polyhedron", "spheres"];

/// The scenes the studies and the firmware use by default: the paper's four and the Whitted
/// showcase, as listed once in `firmware/default-scenes.txt` (which `firmware/build.rs` reads).
pub fn default_scene_paths() -> Vec<PathBuf> {
    include_str!("../../firmware/default-scenes.txt")
        .split(',')
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .map(|n| PathBuf::from(format!("scenes/{n}.scene")))
        .collect()
}

/// The median of timings (the upper one of an even count).
pub fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// How a report at `report` links to a plot at `plot`: by file name when both are in one
/// directory, else by the plot's path.
pub fn plot_link(report: &Path, plot: &Path) -> String {
    match (report.parent(), plot.parent(), plot.file_name()) {
        (Some(a), Some(b), Some(name)) if a == b => name.to_string_lossy().into_owned(),
        _ => plot.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_scenes_start_with_the_papers_four() {
        let names: Vec<String> =
            default_scene_paths().iter().map(|p| p.file_stem().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(names[..4], PAPER_SCENES.map(String::from));
    }

    #[test]
    fn a_plot_beside_its_report_is_linked_by_name() {
        assert_eq!(plot_link(Path::new("docs/a.md"), Path::new("docs/a.svg")), "a.svg");
        assert_eq!(plot_link(Path::new("docs/a.md"), Path::new("out/a.svg")), "out/a.svg");
    }
}
