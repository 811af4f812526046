//! Index width: a lattice's cell starts and references are 32-bit words, or 16-bit halves two
//! to a word when the scene is small enough, which halves the lattice's index memory (compact
//! grids store exactly these two arrays, one index per cell and one per reference).

/// Marks a wide reference to a sub-lattice (composite) rather than an object.
pub(super) const SUB_FLAG: u32 = 1 << 31;
/// Marks a narrow reference to a sub-lattice.
const SUB_FLAG16: u32 = 1 << 15;

/// Whether `refs` references to `objects` objects and `composites` composites fit 16-bit
/// indices (cell starts run up to `refs`; a reference needs one bit for the sub-lattice flag).
pub(super) fn fits16(refs: usize, objects: usize, composites: usize) -> bool {
    refs <= u16::MAX as usize && objects < SUB_FLAG16 as usize && composites < SUB_FLAG16 as usize
}

/// Words that `n` indices take.
pub(super) fn words(n: usize, narrow: bool) -> usize {
    if narrow {
        n.div_ceil(2)
    } else {
        n
    }
}

/// Index `i` of a packed array.
#[inline(always)]
pub(super) fn get(words: &[u32], narrow: bool, i: usize) -> u32 {
    // Branch-free: one copy of the code serves both widths.
    let s = narrow as usize;
    (words[i >> s] >> ((i & s) << 4)) & (u32::MAX >> (s << 4))
}

/// Sets index `i` of a packed array to `v` (which fits its width).
#[inline(never)]
pub(super) fn set(words: &mut [u32], narrow: bool, i: usize, v: u32) {
    if narrow {
        let shift = (i & 1) * 16;
        let w = &mut words[i >> 1];
        *w = (*w & !(0xFFFF << shift)) | (v << shift);
    } else {
        words[i] = v;
    }
}

/// A reference as stored: an item (object index, or [`SUB_FLAG`] | composite index) in the
/// array's width.
pub(super) fn encode(item: u32, narrow: bool) -> u32 {
    if narrow && item & SUB_FLAG != 0 {
        (item & !SUB_FLAG) | SUB_FLAG16
    } else {
        item
    }
}

/// A stored reference read back: `Err(composite)` for a sub-lattice, `Ok(object)` otherwise.
#[inline(always)]
pub(super) fn decode(r: u32, narrow: bool) -> Result<usize, usize> {
    let flag = if narrow { SUB_FLAG16 } else { SUB_FLAG };
    if r & flag == 0 {
        Ok(r as usize)
    } else {
        Err((r & !flag) as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_indices_read_back_what_was_set_in_both_widths() {
        for narrow in [false, true] {
            let mut w = [0u32; 5];
            let n = if narrow { 10 } else { 5 };
            for i in 0..n {
                set(&mut w, narrow, i, (i as u32 * 7919) & 0xFFFF);
            }
            for i in (0..n).rev() {
                assert_eq!(get(&w, narrow, i), (i as u32 * 7919) & 0xFFFF);
            }
            for item in [0, 1, 32_766, SUB_FLAG, SUB_FLAG | 32_766] {
                let want = if item & SUB_FLAG != 0 { Err((item & !SUB_FLAG) as usize) } else { Ok(item as usize) };
                assert_eq!(decode(encode(item, narrow), narrow), want);
            }
        }
        assert_eq!((words(7, true), words(7, false)), (4, 7));
        assert!(fits16(65_535, 32_767, 32_767) && !fits16(65_536, 1, 1) && !fits16(1, 32_768, 0));
    }
}
