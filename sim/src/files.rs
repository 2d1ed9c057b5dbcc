//! Opening the files the program reads or appends to without ever
//! blocking on a special file.
//!
//! `open(2)` on a FIFO waits for its other end, and reading a device or a
//! socket can wait forever. Where the program expects a regular file (a
//! scenario, a sweep's `episodes.csv`, `sweep.json` or lock, a cache
//! entry), the file is opened non-blocking and refused unless it is a
//! regular file, with an error naming what it is.

use std::fs::{File, OpenOptions};
use std::io::{self, Read};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// Opens `path` for reading; a FIFO, socket or device is refused (an
/// [`io::ErrorKind::InvalidInput`] error saying which), without waiting for
/// it.
pub fn open_regular(path: &Path) -> io::Result<File> {
    open_regular_with(OpenOptions::new().read(true), path)
}

/// Opens the existing `path` for appending; refused as [`open_regular`]
/// refuses.
pub fn append_regular(path: &Path) -> io::Result<File> {
    open_regular_with(OpenOptions::new().append(true), path)
}

/// Opens the existing `path` for writing in place; refused as
/// [`open_regular`] refuses.
pub fn write_regular(path: &Path) -> io::Result<File> {
    open_regular_with(OpenOptions::new().write(true), path)
}

/// Opens `path` with `options`; refused as [`open_regular`] refuses.
pub fn open_regular_with(options: &mut OpenOptions, path: &Path) -> io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // Opening a FIFO non-blocking returns at once (for writing with no
        // reader it fails with ENXIO, also at once).
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| match e.raw_os_error() {
        #[cfg(unix)]
        // (A socket, or a FIFO with no reader: say which, from its kind.)
        Some(libc::ENXIO) => not_regular(
            std::fs::metadata(path)
                .map(|m| describe(&m.file_type()))
                .unwrap_or("a FIFO, a socket or a device"),
        ),
        _ => e,
    })?;
    let kind = file.metadata()?.file_type();
    if !kind.is_file() {
        return Err(not_regular(describe(&kind)));
    }
    // O_NONBLOCK stays set: it has no effect on a regular file's reads
    // and writes (they never wait), and the file is nothing else.
    Ok(file)
}

/// True if `path` is a regular file that errp must not replace: it is not
/// empty and does not begin with `magic` (the signature of the format errp
/// would write there). A missing, unreadable or special file is not
/// foreign: the writer refuses what it cannot replace.
pub fn is_foreign(path: &Path, magic: &[u8]) -> bool {
    use std::io::Read;
    let Ok(file) = open_regular(path) else {
        return false;
    };
    let mut head = Vec::with_capacity(magic.len());
    if file
        .take(magic.len() as u64)
        .read_to_end(&mut head)
        .is_err()
    {
        return false;
    }
    !head.is_empty() && head != magic
}

/// What a file that is not regular is, for an error message.
fn describe(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_socket() {
            return "a socket";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

fn not_regular(what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("it is {what}, not a regular file"),
    )
}

/// What identifies a file's content: its name as given, its size and its
/// SHA-256.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileDigest {
    /// The file's name, as the scenario writes it.
    pub name: String,
    /// Its size in bytes.
    pub bytes: u64,
    /// Its SHA-256, in lower-case hex.
    pub sha256: String,
}

/// A reader that hashes and counts what it reads.
pub(crate) struct Hashing<R> {
    inner: R,
    hash: Sha256,
    bytes: u64,
}

impl<R> Hashing<R> {
    /// Hashes what is read from `inner`.
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            hash: Sha256::new(),
            bytes: 0,
        }
    }

    /// What was read, as the digest of the file called `name`.
    pub(crate) fn digest(self, name: &str) -> FileDigest {
        FileDigest {
            name: name.to_string(),
            bytes: self.bytes,
            sha256: format!("{:x}", self.hash.finalize()),
        }
    }
}

impl<R: Read> Read for Hashing<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hash.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("errp-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("a scratch directory");
        dir
    }

    #[test]
    fn a_fifo_is_refused_at_once_for_reading_and_appending() {
        let dir = scratch("fifo");
        let fifo = dir.join("episodes.csv");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        for result in [
            open_regular(&fifo),
            append_regular(&fifo),
            write_regular(&fifo),
        ] {
            let e = result.unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{e}");
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn devices_and_directories_are_refused_and_regular_files_read() {
        let e = open_regular(Path::new("/dev/null")).unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
        let dir = scratch("dir");
        let e = open_regular(&dir).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        std::fs::write(dir.join("a.txt"), "text").unwrap();
        let mut text = String::new();
        use std::io::Read;
        open_regular(&dir.join("a.txt"))
            .unwrap()
            .read_to_string(&mut text)
            .unwrap();
        assert_eq!(text, "text");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_digest_is_sha_256() {
        let mut r = Hashing::new(&b"abc"[..]);
        io::copy(&mut r, &mut io::sink()).unwrap();
        let d = r.digest("abc.edf");
        assert_eq!((d.name.as_str(), d.bytes), ("abc.edf", 3));
        assert_eq!(
            d.sha256,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
