//! A shared library file checked before it is loaded: an ELF file whose
//! headers and loadable segments end inside it. A truncated library,
//! mapped, kills the process with SIGBUS when a missing page is touched;
//! the loader itself does not check.

use std::path::Path;

/// Checks that the ELF file `path` holds what its headers say it does: its
/// program and section headers and every segment to be mapped end inside
/// the file. Other formats (Mach-O, PE) are left to their loader.
pub(crate) fn check_library(path: &Path) -> Result<(), String> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let len = f.metadata().map_err(|e| e.to_string())?.len();
    let mut head = Vec::with_capacity(64);
    (&mut f)
        .take(64)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    if !head.starts_with(b"\x7fELF") {
        return Ok(());
    }
    let elf = Elf::new(&head).ok_or("truncated: the file ends inside its ELF header")?;
    let short = |what: &str, end: u64| {
        format!("truncated: the file has {len} bytes, its {what} ends at byte {end}")
    };
    let table =
        |offset: u64, count: u64, size: u64| offset.saturating_add(count.saturating_mul(size));
    let (ph_end, sh_end) = (
        table(elf.phoff, elf.phnum, elf.phentsize),
        table(elf.shoff, elf.shnum, elf.shentsize),
    );
    if ph_end > len {
        return Err(short("program header table", ph_end));
    }
    if elf.shoff != 0 && sh_end > len {
        return Err(short("section header table", sh_end));
    }
    // The program headers: at most 65535 of at most 65535 bytes each, and
    // inside the file (checked above).
    let mut ph = vec![0u8; (ph_end - elf.phoff) as usize];
    std::io::Seek::seek(&mut f, std::io::SeekFrom::Start(elf.phoff)).map_err(|e| e.to_string())?;
    f.read_exact(&mut ph).map_err(|e| e.to_string())?;
    for entry in ph.chunks_exact(elf.phentsize.max(1) as usize) {
        if let Some((offset, size)) = elf.loaded(entry) {
            let end = offset.saturating_add(size);
            if end > len {
                return Err(short("loadable segment", end));
            }
        }
    }
    Ok(())
}

/// The fields of an ELF header that say where the rest lies.
struct Elf {
    wide: bool,
    little: bool,
    phoff: u64,
    phentsize: u64,
    phnum: u64,
    shoff: u64,
    shentsize: u64,
    shnum: u64,
}

impl Elf {
    /// The header's fields, if `head` holds them.
    fn new(head: &[u8]) -> Option<Self> {
        let wide = match head.get(4)? {
            1 => false,
            2 => true,
            _ => return None,
        };
        let little = *head.get(5)? != 2;
        let mut elf = Elf {
            wide,
            little,
            phoff: 0,
            phentsize: 0,
            phnum: 0,
            shoff: 0,
            shentsize: 0,
            shnum: 0,
        };
        let (ph, sh, sizes) = if wide {
            (0x20, 0x28, 0x36)
        } else {
            (0x1c, 0x20, 0x2a)
        };
        elf.phoff = elf.word(head, ph)?;
        elf.shoff = elf.word(head, sh)?;
        elf.phentsize = elf.half(head, sizes)?;
        elf.phnum = elf.half(head, sizes + 2)?;
        elf.shentsize = elf.half(head, sizes + 4)?;
        elf.shnum = elf.half(head, sizes + 6)?;
        Some(elf)
    }

    /// An unsigned field of `n` bytes at `at`, in the file's byte order.
    fn unsigned(&self, bytes: &[u8], at: usize, n: usize) -> Option<u64> {
        let b = bytes.get(at..at + n)?;
        let mut v = 0u64;
        for i in 0..n {
            let byte = if self.little { b[n - 1 - i] } else { b[i] };
            v = (v << 8) | u64::from(byte);
        }
        Some(v)
    }

    fn half(&self, bytes: &[u8], at: usize) -> Option<u64> {
        self.unsigned(bytes, at, 2)
    }

    /// An address or offset: 8 bytes in a 64-bit file, 4 in a 32-bit one.
    fn word(&self, bytes: &[u8], at: usize) -> Option<u64> {
        self.unsigned(bytes, at, if self.wide { 8 } else { 4 })
    }

    /// A program header's file offset and size, if it is a loadable
    /// segment (`PT_LOAD`).
    fn loaded(&self, entry: &[u8]) -> Option<(u64, u64)> {
        if self.unsigned(entry, 0, 4)? != 1 {
            return None;
        }
        if self.wide {
            Some((self.word(entry, 8)?, self.word(entry, 0x20)?))
        } else {
            Some((self.word(entry, 4)?, self.word(entry, 0x10)?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64-bit little-endian ELF header whose one program header (at 64)
    /// is a loadable segment of `segment` bytes from offset 0, padded to
    /// `len` bytes.
    fn elf(segment: u64, len: usize) -> Vec<u8> {
        let mut b = vec![0u8; 64 + 56];
        b[..6].copy_from_slice(b"\x7fELF\x02\x01");
        b[0x20..0x28].copy_from_slice(&64u64.to_le_bytes());
        b[0x36..0x38].copy_from_slice(&56u16.to_le_bytes());
        b[0x38..0x3a].copy_from_slice(&1u16.to_le_bytes());
        b[64..68].copy_from_slice(&1u32.to_le_bytes());
        b[64 + 0x20..64 + 0x28].copy_from_slice(&segment.to_le_bytes());
        b.resize(len, 0);
        b
    }

    #[test]
    fn a_truncated_library_is_refused_before_it_is_mapped() {
        let dir = std::env::temp_dir().join(format!("errp-lsl-elf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let check = |bytes: &[u8]| {
            let path = dir.join("liblsl.so");
            std::fs::write(&path, bytes).unwrap();
            check_library(&path)
        };
        assert_eq!(check(&elf(4096, 4096)), Ok(()));
        assert_eq!(
            check(&elf(4096, 1000)).unwrap_err(),
            "truncated: the file has 1000 bytes, its loadable segment ends at byte 4096"
        );
        let e = check(&elf(4096, 4096)[..90]).unwrap_err();
        assert!(
            e.contains("its program header table ends at byte 120"),
            "{e}"
        );
        let e = check(&elf(4096, 4096)[..40]).unwrap_err();
        assert!(e.contains("inside its ELF header"), "{e}");
        // Not ELF: left to the loader.
        assert_eq!(check(b"not a library"), Ok(()));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
