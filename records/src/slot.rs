//! The scene slot: a region of the Pico's flash that holds scene text, written beside a
//! prebuilt image (`host-sim uf2 --scene FILE`, or the playground) so that a user's scene
//! reaches the board without a Rust toolchain. The `slot` image parses it on the board.
//!
//! Layout at [`ADDRESS`]: [`MAGIC`] (8 bytes), the text's length and its CRC-32 (IEEE, as zip
//! and PNG compute it), both little-endian `u32`, then the text (UTF-8). An erased slot reads as
//! `0xFF` bytes: [`SlotError::Empty`].

/// Bytes every `slot` image holds in its flash (and no other image does): what tells a slot
/// image's UF2 file from another's.
pub const IMAGE_MARK: [u8; 16] = *b"lattice-rt slot1";

/// Where the slot starts: 1 MiB into the flash (the image ends below it; the SRAM code's copy
/// lives at 1.5 MiB).
pub const ADDRESS: u32 = 0x1010_0000;
/// The most bytes of the slot: header and text.
pub const SIZE: usize = 64 * 1024;
/// The slot's first bytes when it holds a scene.
pub const MAGIC: [u8; 8] = *b"LRTSCENE";
/// Bytes before the text.
pub const HEADER: usize = 16;
/// The most bytes of scene text a slot holds.
pub const MAX_TEXT: usize = SIZE - HEADER;

/// The storage the `slot` image has for the scene it reads: a scene that needs more of any is
/// refused (by `host-sim uf2 --scene` before it is written, and by the board with a message).
pub const ROOM: lattice_rt::Sizes = lattice_rt::Sizes {
    objects: 64,
    lattices: 1 + lattice_rt::scene::MAX_COMPOSITES,
    coords: 1024,
    words: 8192,
    rows: 0,
};

/// Whether a scene that needs `needs` fits [`ROOM`] (rows are the frame's, not the scene's).
pub fn fits(needs: &lattice_rt::Sizes) -> Result<(), (&'static str, usize, usize)> {
    let room = ROOM;
    for (what, need, have) in [
        ("objects", needs.objects, room.objects),
        ("lattices", needs.lattices, room.lattices),
        ("lattice coordinates", needs.coords, room.coords),
        ("lattice words (cells, references, mailbox)", needs.words, room.words),
    ] {
        if need > have {
            return Err((what, need, have));
        }
    }
    Ok(())
}

/// Why the slot holds no scene to show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotError {
    /// No scene was written (the slot does not start with [`MAGIC`]).
    Empty,
    /// The length written is more than a slot holds.
    TooLong {
        /// The length the header gives.
        length: u32,
    },
    /// The text is not what was written: its checksum differs.
    Corrupt {
        /// The CRC-32 the header gives.
        stored: u32,
        /// The CRC-32 of the text as read.
        computed: u32,
    },
    /// The text is not UTF-8.
    NotText,
}

impl core::fmt::Display for SlotError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SlotError::Empty => write!(f, "no scene in the slot: write one with host-sim uf2 --scene FILE"),
            SlotError::TooLong { length } => {
                write!(f, "scene slot corrupt: length {length} is more than the {MAX_TEXT} bytes a slot holds")
            }
            SlotError::Corrupt { stored, computed } => {
                write!(f, "scene slot corrupt: checksum {computed:08x}, written {stored:08x}")
            }
            SlotError::NotText => write!(f, "scene slot corrupt: not UTF-8 text"),
        }
    }
}

/// The CRC-32 the header keeps of the text.
pub fn checksum(text: &[u8]) -> u32 {
    crc32fast::hash(text)
}

/// The header of a slot holding `text` (at most [`MAX_TEXT`] bytes).
pub fn header(text: &[u8]) -> [u8; HEADER] {
    let mut h = [0u8; HEADER];
    h[..8].copy_from_slice(&MAGIC);
    h[8..12].copy_from_slice(&(text.len() as u32).to_le_bytes());
    h[12..16].copy_from_slice(&checksum(text).to_le_bytes());
    h
}

/// The scene text a slot's bytes hold (`bytes` from [`ADDRESS`], at most [`SIZE`] of them).
pub fn read(bytes: &[u8]) -> Result<&str, SlotError> {
    if bytes.len() < HEADER || bytes[..8] != MAGIC {
        return Err(SlotError::Empty);
    }
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let (length, stored) = (word(8), word(12));
    let text = bytes
        .get(HEADER..HEADER + length as usize)
        .filter(|_| length as usize <= MAX_TEXT)
        .ok_or(SlotError::TooLong { length })?;
    let computed = checksum(text);
    if computed != stored {
        return Err(SlotError::Corrupt { stored, computed });
    }
    core::str::from_utf8(text).map_err(|_| SlotError::NotText)
}

/// The UF2 format (microsoft/uf2): 512-byte blocks of 256 bytes of flash each.
pub mod uf2 {
    /// A UF2 block's size.
    pub const BLOCK: usize = 512;
    /// Flash bytes each block carries (what the RP2040's bootrom writes).
    pub const PAYLOAD: usize = 256;
    /// The RP2040's family id.
    pub const RP2040_FAMILY: u32 = 0xe48b_ff56;
    const MAGIC_START: [u32; 2] = [0x0A32_4655, 0x9E5D_5157];
    const MAGIC_END: u32 = 0x0AB1_6F30;
    /// Flag: the family id field is set.
    const FAMILY_PRESENT: u32 = 0x2000;

    /// A block writing `data` (at most [`PAYLOAD`] bytes) at `address`, numbered `index` of
    /// `count`.
    pub fn block(address: u32, data: &[u8], index: u32, count: u32) -> [u8; BLOCK] {
        let mut b = [0u8; BLOCK];
        let words =
            [MAGIC_START[0], MAGIC_START[1], FAMILY_PRESENT, address, PAYLOAD as u32, index, count, RP2040_FAMILY];
        for (i, w) in words.iter().enumerate() {
            b[4 * i..4 * i + 4].copy_from_slice(&w.to_le_bytes());
        }
        let n = data.len().min(PAYLOAD);
        b[32..32 + n].copy_from_slice(&data[..n]);
        b[BLOCK - 4..].copy_from_slice(&MAGIC_END.to_le_bytes());
        b
    }

    /// Whether `b` is a UF2 block (both start magics and the end magic).
    pub fn is_block(b: &[u8]) -> bool {
        let word = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        b.len() == BLOCK && word(0) == MAGIC_START[0] && word(4) == MAGIC_START[1] && word(BLOCK - 4) == MAGIC_END
    }

    /// The flash address block `b` writes.
    pub fn address(b: &[u8]) -> u32 {
        u32::from_le_bytes([b[12], b[13], b[14], b[15]])
    }

    /// Renumbers block `b` as `index` of `count`.
    pub fn renumber(b: &mut [u8], index: u32, count: u32) {
        b[20..24].copy_from_slice(&index.to_le_bytes());
        b[24..28].copy_from_slice(&count.to_le_bytes());
    }

    /// Blocks a slot of `text` takes: its header and text in pages of [`PAYLOAD`] bytes.
    pub fn slot_blocks(text: &[u8]) -> usize {
        (super::HEADER + text.len()).div_ceil(PAYLOAD)
    }

    /// Block `k` of the slot holding `text` ([`slot_blocks`] of them), numbered `index` of
    /// `count` in the file; the last page is padded with `0xFF`, as erased flash reads.
    pub fn slot_block(text: &[u8], k: usize, index: u32, count: u32) -> [u8; BLOCK] {
        let header = super::header(text);
        let mut page = [0xFFu8; PAYLOAD];
        for (i, p) in page.iter_mut().enumerate() {
            let at = k * PAYLOAD + i;
            if at < super::HEADER {
                *p = header[at];
            } else if let Some(&c) = text.get(at - super::HEADER) {
                *p = c;
            }
        }
        block(super::ADDRESS + (k * PAYLOAD) as u32, &page, index, count)
    }
}

/// Checks scene text as the `slot` image will read it: at most [`MAX_TEXT`] bytes, in the
/// scene format (the image reads no NFF), a valid scene in the Pico's fixed point fitted to its
/// 128x64 panel, with a view its render takes, with at most a board's materials and lights
/// ([`lattice_rt::scene::BOARD_MATERIALS`], [`lattice_rt::scene::BOARD_LIGHTS`]), within
/// [`ROOM`]. The error says where and why, as the board would show it.
#[cfg(feature = "alloc")]
pub fn check_scene(text: &str) -> Result<(), alloc::string::String> {
    use alloc::format;
    use lattice_rt::scene::text::{object_count, parse_with};
    use lattice_rt::scene::{Format, BOARD_LIGHTS, BOARD_MATERIALS};
    use lattice_rt::{Fx, LatticeConfig, Sizes};
    if text.len() > MAX_TEXT {
        return Err(format!("the scene is {} bytes, more than the {MAX_TEXT} a slot holds", text.len()));
    }
    if Format::of(text) == Format::Nff {
        return Err(alloc::string::String::from(
            "line 1: NFF, which the slot image does not read (it is built without the NFF reader, to fit \
             the Pico's flash): write the scene in the scene format (docs/scene-format.md), or bake the \
             NFF file into an image of its own with `host-sim uf2 --bake FILE`",
        ));
    }
    let frame = crate::frame::rendered(crate::frame::PICO);
    let mut objects = alloc::vec![lattice_rt::scene::Object::<Fx>::default(); object_count(text).max(1)];
    let mut parts = lattice_rt::Parts::default();
    let scene =
        parse_with::<Fx>(text, &mut objects, &mut parts, |c| c.frame = frame.size()).map_err(|e| format!("{e}"))?;
    // A view the board's render refuses (too narrow for fixed point on its panel), at the
    // camera statement.
    frame.check_scene_view(text, scene.camera()).map_err(|e| format!("{e}"))?;
    // The host's build holds more materials and lights than a board's: the statement that
    // goes past the board's is refused where the board refuses it.
    for (word, blamed, have, most) in
        [("material", 1, scene.materials().len(), BOARD_MATERIALS), ("light", 0, scene.lights().len(), BOARD_LIGHTS)]
    {
        if have > most {
            let (line, col, w) = statement_at(text, word, most + 1, blamed).unwrap_or((1, 1, word));
            return Err(format!("line {line}, column {col} at `{w}`: too many {word}s (at most {most})"));
        }
    }
    let needs = Sizes::of(&scene, Some(&LatticeConfig::default()), &frame);
    fits(&needs)
        .map_err(|(what, need, have)| format!("the scene needs {need} {what}; the slot image has room for {have}"))
}

/// Where the board's parser blames the `n`-th statement of `text` whose first word is `word`:
/// its line, and the column and word of its `blamed`-th word (0: the statement's own word; a
/// material is blamed on its name, the 1st). Lines end at LF, CR LF or a lone CR, as the scene
/// format's do.
#[cfg(feature = "alloc")]
fn statement_at<'t>(text: &'t str, word: &str, n: usize, blamed: usize) -> Option<(usize, usize, &'t str)> {
    let (i, line) = text
        .split('\n')
        .flat_map(|l| l.strip_suffix('\r').unwrap_or(l).split('\r'))
        .enumerate()
        .filter(|(_, l)| l.split('#').next().unwrap_or("").split_whitespace().next() == Some(word))
        .nth(n - 1)?;
    let w = line.split_whitespace().nth(blamed)?;
    // `w` is a slice of `line`: its byte offset gives its column in characters.
    let at = w.as_ptr() as usize - line.as_ptr() as usize;
    Some((i + 1, line[..at].chars().count() + 1, w))
}

/// UF2 files with a scene: the blocks of a slot image's file, and the slot's.
#[cfg(feature = "alloc")]
pub mod with {
    use super::uf2;
    use alloc::string::String;
    use alloc::vec::Vec;

    /// `image` (a `slot` image's UF2 file) with `text` in its slot: the image's blocks (any
    /// scene it held dropped), then the slot's, all renumbered. `text` is checked first
    /// ([`super::check_scene`]); an image that is not a slot image's is refused.
    pub fn scene(image: &[u8], text: &str) -> Result<Vec<u8>, String> {
        super::check_scene(text)?;
        unchecked(image, text)
    }

    /// [`scene`] without checking the text: what a board must refuse by itself (its tests).
    pub fn unchecked(image: &[u8], text: &str) -> Result<Vec<u8>, String> {
        if image.is_empty() || !image.len().is_multiple_of(uf2::BLOCK) {
            return Err(alloc::format!("not a UF2 file: {} bytes, not a whole number of 512-byte blocks", image.len()));
        }
        let mut blocks: Vec<&[u8]> = Vec::new();
        for (i, b) in image.chunks(uf2::BLOCK).enumerate() {
            if !uf2::is_block(b) {
                return Err(alloc::format!("not a UF2 file: block {i} has no UF2 magic"));
            }
            if !(super::ADDRESS..super::ADDRESS + super::SIZE as u32).contains(&uf2::address(b)) {
                blocks.push(b);
            }
        }
        let marked = blocks
            .iter()
            .any(|b| b[32..32 + uf2::PAYLOAD].windows(super::IMAGE_MARK.len()).any(|w| w == super::IMAGE_MARK));
        if !marked {
            return Err(String::from("this UF2 file is not the slot image (build it with `host-sim uf2 --features slot`, or download it from the playground)"));
        }
        let slot = uf2::slot_blocks(text.as_bytes());
        let count = (blocks.len() + slot) as u32;
        let mut out = Vec::with_capacity(count as usize * uf2::BLOCK);
        for (i, b) in blocks.iter().enumerate() {
            let mut b: [u8; uf2::BLOCK] = (*b).try_into().expect("a whole block");
            uf2::renumber(&mut b, i as u32, count);
            out.extend_from_slice(&b);
        }
        for k in 0..slot {
            out.extend_from_slice(&uf2::slot_block(text.as_bytes(), k, (blocks.len() + k) as u32, count));
        }
        Ok(out)
    }
}

#[cfg(all(test, feature = "alloc"))]
mod board_checks {
    use super::check_scene;
    use alloc::format;
    use alloc::string::String;

    /// A scene with `materials` materials and `lights` lights, lines ending with `eol`.
    fn scene(materials: usize, lights: usize, eol: &str) -> String {
        let mut t = format!("camera eye 0 0 -4{eol}");
        for i in 0..lights {
            t += &format!("light point pos {i} 2 -3 intensity 0.2{eol}");
        }
        for i in 0..materials {
            t += &format!("material m{i} kd 0.5{eol}");
        }
        t + &format!("box{eol}")
    }

    /// The same message whether the host's build (with `alloc`: more materials and lights) or a
    /// board's (`cargo test -p board-records --features alloc` alone builds the core without
    /// `alloc`) checks the scene.
    #[test]
    fn a_board_s_materials_and_lights_are_the_slot_s() {
        for eol in ["\n", "\r\n", "\r"] {
            assert_eq!(check_scene(&scene(16, 4, eol)), Ok(()));
            assert_eq!(
                check_scene(&scene(20, 1, eol)),
                Err(String::from("line 19, column 10 at `m16`: too many materials (at most 16)"))
            );
            assert_eq!(
                check_scene(&scene(1, 7, eol)),
                Err(String::from("line 6, column 1 at `light`: too many lights (at most 4)"))
            );
        }
    }

    #[test]
    fn a_view_too_narrow_for_the_board_is_refused_at_the_camera() {
        let e = check_scene("material m kd 0.5\ncamera eye 0 0 -4 fov 1e-9 1e-9\nbox\n").unwrap_err();
        assert!(e.starts_with("line 2, column 1 at `camera`: the view is too narrow for fixed"), "{e}");
        assert_eq!(check_scene("material m kd 0.5\ncamera eye 0 0 -4 fov 40\nbox\n"), Ok(()));
    }

    #[test]
    fn nff_is_refused_with_what_to_do() {
        let e = check_scene("v from 0 -5 0 at 0 0 0 up 0 0 1 angle 40\ns 0 0 0 1\n").unwrap_err();
        assert!(e.starts_with("line 1: NFF, which the slot image does not read"), "{e}");
        assert!(e.contains("host-sim uf2 --bake"), "{e}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_slot_reads_back_and_damage_is_found() {
        let text = b"camera eye 0 0 -5\nsphere\n";
        let mut slot = [0xFFu8; 256];
        assert_eq!(read(&slot), Err(SlotError::Empty));
        slot[..HEADER].copy_from_slice(&header(text));
        slot[HEADER..HEADER + text.len()].copy_from_slice(text);
        assert_eq!(read(&slot), Ok("camera eye 0 0 -5\nsphere\n"));
        slot[HEADER + 3] ^= 1;
        assert!(matches!(read(&slot), Err(SlotError::Corrupt { .. })));
        slot[HEADER + 3] ^= 1;
        slot[8..12].copy_from_slice(&(MAX_TEXT as u32 + 1).to_le_bytes());
        assert_eq!(read(&slot), Err(SlotError::TooLong { length: MAX_TEXT as u32 + 1 }));
        // The checksum is the common CRC-32 (zip, PNG): "123456789" gives cbf43926.
        assert_eq!(checksum(b"123456789"), 0xcbf4_3926);
    }

    #[test]
    fn slot_blocks_carry_the_header_and_text_page_by_page() {
        let text = [b'x'; 300];
        assert_eq!(uf2::slot_blocks(&text), 2);
        let (a, b) = (uf2::slot_block(&text, 0, 5, 7), uf2::slot_block(&text, 1, 6, 7));
        assert!(uf2::is_block(&a) && uf2::is_block(&b));
        assert_eq!((uf2::address(&a), uf2::address(&b)), (ADDRESS, ADDRESS + 256));
        let mut flash = [0u8; 512];
        flash[..256].copy_from_slice(&a[32..288]);
        flash[256..].copy_from_slice(&b[32..288]);
        assert_eq!(read(&flash).map(str::len), Ok(300));
        assert_eq!(flash[HEADER + 300], 0xFF);
    }
}
