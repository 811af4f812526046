//! Where statements are in scene text, for errors found outside the parser and for the storage
//! a parse needs: the object statements (counted, and the `index`-th found) and the camera.

use super::words::{lines, Words};

/// The keywords of the statements that add one object.
pub const OBJECT_KEYWORDS: [&str; 5] = ["sphere", "cylinder", "cone", "box", "triangle"];

/// The number of object statements ([`OBJECT_KEYWORDS`]) in scene text: the object storage
/// [`parse`](super::parse) needs for it (line endings and comments as it reads them).
pub fn object_count(text: &str) -> usize {
    lines(text).filter(|line| Words::new(line, 0).next().is_some_and(|(_, k)| OBJECT_KEYWORDS.contains(&k))).count()
}

/// The line, column and word of the `camera` statement of `text` (the scene format), if any:
/// what a view refused outside the parser (a render's frame) is blamed on.
pub fn camera_statement(text: &str) -> Option<(u32, u32, &str)> {
    lines(text).enumerate().find_map(|(i, line)| {
        let mut w = Words::new(line, i as u32 + 1);
        w.next().filter(|(_, key)| *key == "camera").map(|(col, key)| (i as u32 + 1, col, key))
    })
}

/// Line, column and keyword of the `index`-th object statement (for errors found after
/// parsing, by the parser or by tools that use the scene).
pub fn object_statement(text: &str, index: usize) -> (u32, u32, &str) {
    let mut seen = 0;
    for (i, line) in lines(text).enumerate() {
        let mut w = Words::new(line, i as u32 + 1);
        if let Some((col, key)) = w.next() {
            if OBJECT_KEYWORDS.contains(&key) {
                if seen == index {
                    return (i as u32 + 1, col, key);
                }
                seen += 1;
            }
        }
    }
    (1, 1, "")
}
