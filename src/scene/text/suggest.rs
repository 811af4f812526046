//! What each statement takes, and the nearest word to one it does not: the attribute lists
//! errors name, and the edit distance their suggestion is chosen by.

/// The attributes each statement takes (by its keyword, and a light by its kind).
pub(super) fn attributes(key: &str, light: Option<&str>) -> &'static [&'static str] {
    const TRANSFORMS: [&str; 4] = ["translate", "rotate", "scale", "shear"];
    match (key, light) {
        ("camera", _) => &["eye", "look", "up", "fov"],
        ("light", Some("directional")) => &["dir", "intensity"],
        ("light", Some("point")) => &["pos", "intensity"],
        ("material", _) => &["ka", "kd", "ks", "kt", "ior", "shine"],
        ("sphere", _) => &["center", "radius", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("cylinder", _) => &[
            "base",
            "radius",
            "height",
            "open",
            "material",
            TRANSFORMS[0],
            TRANSFORMS[1],
            TRANSFORMS[2],
            TRANSFORMS[3],
        ],
        ("cone", _) => &[
            "base",
            "radius",
            "height",
            "top",
            "open",
            "material",
            TRANSFORMS[0],
            TRANSFORMS[1],
            TRANSFORMS[2],
            TRANSFORMS[3],
        ],
        ("triangle", _) => &["a", "b", "c", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("box", _) => &["min", "max", "material", TRANSFORMS[0], TRANSFORMS[1], TRANSFORMS[2], TRANSFORMS[3]],
        ("group", _) => &TRANSFORMS,
        _ => &[],
    }
}

/// Levenshtein distance of two short words (at most 16 bytes of `b` counted; longer words are
/// never near).
pub(super) fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if b.len() > 16 || a.len() > 32 {
        return usize::MAX;
    }
    let mut row = [0usize; 17];
    for (j, r) in row.iter_mut().enumerate().take(b.len() + 1) {
        *r = j;
    }
    for (i, &ca) in a.iter().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(ca != cb)).min(row[j] + 1).min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}
