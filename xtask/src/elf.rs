//! The firmware's ELF images as the reports read them: each read and parsed in one place, and
//! the questions the reports ask of it (a symbol's address, a section's size, the code symbols
//! by address, flash and RAM, the bytes of a family of symbols).

use anyhow::{Context, Result};
use object::{Object, ObjectSection, ObjectSymbol, SectionFlags, SymbolKind};
use std::path::Path;

/// An ELF image's bytes, read once.
pub(crate) struct Elf {
    bytes: Vec<u8>,
}

impl Elf {
    /// The image at `path`.
    pub(crate) fn read(path: &Path) -> Result<Elf> {
        Ok(Elf { bytes: std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))? })
    }

    /// The image's bytes.
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The image parsed.
    pub(crate) fn file(&self) -> Result<object::File<'_>> {
        Ok(object::File::parse(&*self.bytes)?)
    }

    /// The address of symbol `name`, if the image has it.
    pub(crate) fn symbol_address(&self, name: &str) -> Result<Option<u64>> {
        Ok(self.file()?.symbols().find(|s| s.name() == Ok(name)).map(|s| s.address()))
    }

    /// Bytes of section `name` (0 when there is none).
    pub(crate) fn section_size(&self, name: &str) -> Result<u64> {
        Ok(self.file()?.section_by_name(name).map_or(0, |s| s.size()))
    }

    /// The code symbols with a size, by address: the address (without the Thumb bit), the size
    /// and the demangled name.
    pub(crate) fn code_symbols(&self) -> Result<Vec<(u64, u64, String)>> {
        let mut syms: Vec<(u64, u64, String)> = self
            .file()?
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
            .filter_map(|s| Some((s.address() & !1, s.size(), demangled(s.name().ok()?))))
            .collect();
        syms.sort();
        Ok(syms)
    }

    /// Flash bytes (every allocated section with contents, `.data` counted at its load address)
    /// and static RAM bytes (`.data`, `.bss`, `.uninit`).
    pub(crate) fn sizes(&self) -> Result<(u64, u64)> {
        let (mut flash, mut ram) = (0, 0);
        for s in self.file()?.sections() {
            let SectionFlags::Elf { sh_flags } = s.flags() else { continue };
            if sh_flags & object::elf::SHF_ALLOC as u64 == 0 || s.size() == 0 {
                continue;
            }
            if s.file_range().is_some() {
                flash += s.size();
            }
            if (0x2000_0000..0x3000_0000).contains(&s.address()) {
                ram += s.size();
            }
        }
        Ok((flash, ram))
    }

    /// Every word of the data symbols whose demangled names start with `prefix` that points
    /// into flash, with the word after it: as a `&[T]` lies in memory (pointer, then length),
    /// the slices of those symbols are among these pairs, with whatever else happens to match;
    /// the caller picks the table it knows by its length.
    pub(crate) fn slices_in(&self, prefix: &str) -> Result<Vec<(u64, u64)>> {
        let file = self.file()?;
        let mut slices = Vec::new();
        for s in file
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Data && demangled(s.name().unwrap_or("")).starts_with(prefix))
        {
            let Some(section) = s.section_index().and_then(|i| file.section_by_index(i).ok()) else { continue };
            let Ok(data) = section.data() else { continue };
            let start = (s.address() - section.address()) as usize;
            let Some(bytes) = data.get(start..start + s.size() as usize) else { continue };
            let words: Vec<u64> =
                bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]).into()).collect();
            slices.extend(words.windows(2).filter(|w| FLASH.contains(&w[0])).map(|w| (w[0], w[1])));
        }
        Ok(slices)
    }

    /// The address ranges of the executable sections that lie in flash (code run from there,
    /// through the XIP cache).
    pub(crate) fn flash_code(&self) -> Result<Vec<std::ops::Range<u64>>> {
        Ok(self
            .file()?
            .sections()
            .filter(|s| matches!(s.flags(), SectionFlags::Elf { sh_flags } if sh_flags & object::elf::SHF_EXECINSTR as u64 != 0))
            .filter(|s| FLASH.contains(&s.address()))
            .map(|s| s.address()..s.address() + s.size())
            .collect())
    }

    /// Bytes of the symbols whose demangled names start with `prefix`.
    pub(crate) fn symbol_bytes(&self, prefix: &str) -> Result<u64> {
        Ok(self
            .file()?
            .symbols()
            .filter(|s| demangled(s.name().unwrap_or("")).starts_with(prefix))
            .map(|s| s.size())
            .sum())
    }
}

/// The RP2040's flash as its XIP window maps it.
const FLASH: std::ops::Range<u64> = 0x1000_0000..0x1100_0000;

/// A symbol's name demangled, without its hash.
pub(crate) fn demangled(name: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(name))
}
