//! Lab Streaming Layer (LSL) for the ErrP testbed: outlets that publish
//! the simulated user's EEG, markers and state, and the inlet that takes a
//! lab's decoder output back.
//!
//! liblsl is not built here. Its C API is loaded at run time
//! ([`Lsl::find`]) from the copy the lab already has: a path given
//! (`--liblsl`, `ERRP_LIBLSL`, pylsl's `PYLSL_LIB`), the system's
//! `liblsl.so`, or the one bundled in the `pylsl` wheel. The build needs
//! neither cmake nor liblsl, and a program that never streams never loads
//! it. All unsafe code (the calls) is in the private `ffi` module.
//!
//! A marker stream described, then published where liblsl is found (the
//! description is plain data; nothing touches liblsl before
//! [`Lsl::find`]):
//!
//! ```
//! use errp_lsl::{Element, Format, Lsl, StreamSpec};
//!
//! let spec = StreamSpec {
//!     name: "example-markers".into(),
//!     kind: "Markers".into(),
//!     channels: 1,
//!     rate_hz: 0.0, // irregular
//!     format: Format::String,
//!     source_id: "example-markers-1".into(),
//!     desc: vec![Element::node(
//!         "example",
//!         vec![Element::leaf("version", 1)],
//!     )],
//! };
//! assert_eq!(spec.format.name(), "string");
//! assert_eq!(spec.desc[0].children[0].value.as_deref(), Some("1"));
//!
//! // With ERRP_LIBLSL set (or pylsl installed), publish one marker.
//! if std::env::var_os("ERRP_LIBLSL").is_some() {
//!     let lsl = Lsl::find(None)?;
//!     let outlet = lsl.outlet(&spec)?;
//!     outlet.push_text("{\"event\":\"hello\"}", lsl.clock())?;
//! }
//! # Ok::<(), errp_lsl::LslError>(())
//! ```

#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]
// No function over 100 lines of code (clippy.toml) outside the tests.
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod elf;
mod ffi;

use ffi::{Api, Info, LSL_LOST, LSL_TIMEOUT, RawInlet, RawOutlet};

/// The oldest liblsl accepted: 1.14 (`lsl_library_version` 114).
pub const MIN_VERSION: i32 = 114;

/// What can go wrong with LSL.
#[derive(Debug, thiserror::Error)]
pub enum LslError {
    /// liblsl could not be loaded from a path.
    #[error("cannot load liblsl from {}: {why}", path.display())]
    Load {
        /// The file or name tried.
        path: PathBuf,
        /// The loader's reason.
        why: String,
    },
    /// No liblsl was found where it was looked for.
    #[error("{0}")]
    NotFound(String),
    /// An argument liblsl cannot take.
    #[error("{0}")]
    Argument(String),
    /// A stream could not be opened or used.
    #[error("{0}")]
    Stream(String),
    /// A stream's sender went away.
    #[error("{0}")]
    Lost(String),
}

/// A channel format of LSL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// 32-bit floats (EEG in µV).
    Float32,
    /// 64-bit floats.
    Double64,
    /// Strings (markers).
    String,
    /// 32-bit integers.
    Int32,
    /// 16-bit integers.
    Int16,
    /// 8-bit integers.
    Int8,
    /// 64-bit integers.
    Int64,
}

impl Format {
    fn code(self) -> i32 {
        match self {
            Format::Float32 => 1,
            Format::Double64 => 2,
            Format::String => 3,
            Format::Int32 => 4,
            Format::Int16 => 5,
            Format::Int8 => 6,
            Format::Int64 => 7,
        }
    }

    fn from_code(code: i32) -> Option<Self> {
        Some(match code {
            1 => Format::Float32,
            2 => Format::Double64,
            3 => Format::String,
            4 => Format::Int32,
            5 => Format::Int16,
            6 => Format::Int8,
            7 => Format::Int64,
            _ => return None,
        })
    }

    /// LSL's name of the format (`float32`, `string`...).
    pub fn name(self) -> &'static str {
        match self {
            Format::Float32 => "float32",
            Format::Double64 => "double64",
            Format::String => "string",
            Format::Int32 => "int32",
            Format::Int16 => "int16",
            Format::Int8 => "int8",
            Format::Int64 => "int64",
        }
    }
}

/// An element of a stream's XML description: a value, or children.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// The tag.
    pub name: String,
    /// Its text, for a leaf.
    pub value: Option<String>,
    /// Its children.
    pub children: Vec<Element>,
}

impl Element {
    /// `<name>value</name>`.
    pub fn leaf(name: &str, value: impl ToString) -> Self {
        Self {
            name: name.into(),
            value: Some(value.to_string()),
            children: Vec::new(),
        }
    }

    /// `<name>children</name>`.
    pub fn node(name: &str, children: Vec<Element>) -> Self {
        Self {
            name: name.into(),
            value: None,
            children,
        }
    }
}

/// What an outlet publishes.
#[derive(Debug, Clone)]
pub struct StreamSpec {
    /// The stream's name (how labs resolve it).
    pub name: String,
    /// Its type (`EEG`, `Markers`...).
    pub kind: String,
    /// Channels per sample.
    pub channels: u32,
    /// Nominal rate (Hz); 0 for irregular streams.
    pub rate_hz: f64,
    /// The channel format.
    pub format: Format,
    /// A source id, so that a recorder reconnects to the same stream.
    pub source_id: String,
    /// The `<desc>` element's children.
    pub desc: Vec<Element>,
}

/// liblsl, loaded.
#[derive(Clone)]
pub struct Lsl {
    api: Arc<Api>,
}

impl std::fmt::Debug for Lsl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Lsl({})", self.api.path.display())
    }
}

/// Where [`Lsl::find`] looks, in order, after a path given.
pub const SEARCH: &str = "ERRP_LIBLSL, PYLSL_LIB, the system's liblsl.so, then the copy in \
     pylsl's wheel (found by `python3 -c 'import pylsl'`)";

impl Lsl {
    /// Loads liblsl from `path`, or else from the first of [`SEARCH`] that
    /// loads.
    pub fn find(path: Option<&Path>) -> Result<Self, LslError> {
        if let Some(p) = path {
            return Self::open(p);
        }
        for var in ["ERRP_LIBLSL", "PYLSL_LIB"] {
            if let Some(p) = std::env::var_os(var).filter(|p| !p.is_empty()) {
                return Self::open(Path::new(&p))
                    .map_err(|e| LslError::NotFound(format!("{var}: {e}")));
            }
        }
        for name in ["liblsl.so", "liblsl.so.2", "liblsl.dylib"] {
            // A bare name: the system's loader searches its own path.
            if let Ok(l) = Self::load(Path::new(name)) {
                return Ok(l);
            }
        }
        match pylsl_copy() {
            Some(p) => Self::open(&p),
            None => Err(LslError::NotFound(format!(
                "liblsl not found (looked in {SEARCH}): install pylsl (pip install pylsl), \
                 which bundles it, or give its path with --liblsl or ERRP_LIBLSL"
            ))),
        }
    }

    /// Loads liblsl from the file `path` (a name without a directory is a
    /// file in the current one, never one the system's loader finds
    /// elsewhere). It must be a regular file (a special file is never
    /// opened) whose headers fit in it (a truncated library, mapped, would
    /// kill the process when a missing page is touched). Without a
    /// configuration of the lab's own (`LSLAPICFG`, or an `lsl_api.cfg`
    /// where liblsl looks), liblsl logs only what is fatal: errp names
    /// every failure itself (a lost stream, a peer that never came), so
    /// liblsl's own lines (its start-up notes, "Stream transmission broke
    /// off; re-connecting...") would only come before errp's message.
    pub fn open(path: &Path) -> Result<Self, LslError> {
        let file = if path.components().count() == 1 {
            Path::new(".").join(path)
        } else {
            path.to_path_buf()
        };
        let refuse = |why: String| LslError::Load {
            path: path.to_path_buf(),
            why,
        };
        if !file.is_file() {
            return Err(refuse(if file.exists() {
                "not a regular file".into()
            } else {
                "no such file".into()
            }));
        }
        elf::check_library(&file).map_err(refuse)?;
        Self::load(&file).map_err(|e| match e {
            LslError::Load { why, .. } => refuse(why),
            other => other,
        })
    }

    /// Loads liblsl from `path` as the system's loader finds it.
    fn load(path: &Path) -> Result<Self, LslError> {
        let api = Api::load(path)?;
        if !lab_configuration() {
            api.configure("[log]\nlevel = -3\n");
        }
        let v = api.version();
        if v < MIN_VERSION {
            return Err(LslError::Load {
                path: path.to_path_buf(),
                why: format!(
                    "liblsl {}.{} is too old, expected 1.14 or later",
                    v / 100,
                    v % 100
                ),
            });
        }
        Ok(Self { api })
    }

    /// The file it was loaded from.
    pub fn path(&self) -> &Path {
        &self.api.path
    }

    /// liblsl's version as `major * 100 + minor` (118 for 1.18).
    pub fn version(&self) -> i32 {
        self.api.version()
    }

    /// LSL's clock (s): the one every timestamp is on.
    pub fn clock(&self) -> f64 {
        self.api.clock()
    }

    /// Opens an outlet for `spec`.
    pub fn outlet(&self, spec: &StreamSpec) -> Result<Outlet, LslError> {
        let info = Info::create(
            &self.api,
            &spec.name,
            &spec.kind,
            spec.channels,
            spec.rate_hz,
            spec.format.code(),
            &spec.source_id,
        )?;
        fn add(info: &Info, parent: ffi::Handle, e: &Element) -> Result<(), LslError> {
            let node = info.append(parent, &e.name, e.value.as_deref())?;
            for c in &e.children {
                add(info, node, c)?;
            }
            Ok(())
        }
        let root = info.desc();
        for e in &spec.desc {
            add(&info, root, e)?;
        }
        Ok(Outlet {
            raw: RawOutlet::create(&info)?,
            channels: spec.channels as usize,
            format: spec.format,
            name: spec.name.clone(),
        })
    }

    /// The streams whose `prop` (`name`, `type`, `source_id`...) is
    /// `value`, waiting up to `timeout_secs` for the first.
    pub fn resolve(
        &self,
        prop: &str,
        value: &str,
        timeout_secs: f64,
    ) -> Result<Vec<Found>, LslError> {
        Ok(ffi::resolve(&self.api, prop, value, timeout_secs)?
            .into_iter()
            .map(|info| Found { info })
            .collect())
    }
}

/// True if the lab configures liblsl itself: `LSLAPICFG`, or an
/// `lsl_api.cfg` in the working directory, `~/lsl_api/` or `/etc/lsl_api/`.
fn lab_configuration() -> bool {
    if std::env::var_os("LSLAPICFG").is_some() {
        return true;
    }
    let home = std::env::var_os("HOME").map(PathBuf::from);
    [
        Some(PathBuf::from("lsl_api.cfg")),
        home.map(|h| h.join("lsl_api").join("lsl_api.cfg")),
        Some(PathBuf::from("/etc/lsl_api/lsl_api.cfg")),
    ]
    .into_iter()
    .flatten()
    .any(|p| p.is_file())
}

/// The copy of liblsl in pylsl's wheel, if `python3` imports pylsl.
fn pylsl_copy() -> Option<PathBuf> {
    let python = std::env::var_os("ERRP_PYTHON").unwrap_or_else(|| "python3".into());
    let out = std::process::Command::new(python)
        .args([
            "-c",
            "import os, pylsl.lib as l; print(os.path.dirname(l.__file__))",
        ])
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let dir = PathBuf::from(String::from_utf8(out.stdout).ok()?.trim());
    ["liblsl.so", "liblsl.dylib", "lsl.dll"]
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.is_file())
}

/// A stream being published.
pub struct Outlet {
    raw: RawOutlet,
    channels: usize,
    format: Format,
    name: String,
}

impl Outlet {
    /// Pushes one numeric sample at `stamp` (LSL clock).
    pub fn push(&self, values: &[f32], stamp: f64) -> Result<(), LslError> {
        if values.len() != self.channels || self.format == Format::String {
            return Err(LslError::Argument(format!(
                "{}: a sample of {} values for {} {} channels",
                self.name,
                values.len(),
                self.channels,
                self.format.name()
            )));
        }
        self.check(self.raw.push_f32(values, stamp))
    }

    /// Pushes one text sample (a one-channel string stream) at `stamp`.
    pub fn push_text(&self, text: &str, stamp: f64) -> Result<(), LslError> {
        if self.channels != 1 || self.format != Format::String {
            return Err(LslError::Argument(format!(
                "{}: text for {} {} channels",
                self.name,
                self.channels,
                self.format.name()
            )));
        }
        let c: CString = ffi::c_string("a marker", text)?;
        self.check(self.raw.push_str(&c, stamp))
    }

    fn check(&self, code: i32) -> Result<(), LslError> {
        if code < 0 {
            return Err(LslError::Stream(format!(
                "{}: liblsl could not push a sample (error {code})",
                self.name
            )));
        }
        Ok(())
    }

    /// True if an inlet reads the stream.
    pub fn has_consumers(&self) -> bool {
        self.raw.have_consumers()
    }

    /// Waits up to `timeout_secs` for an inlet; true if one came.
    pub fn wait_for_consumers(&self, timeout_secs: f64) -> bool {
        self.raw.wait_for_consumers(timeout_secs)
    }

    /// The stream's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// A stream found on the network.
pub struct Found {
    info: Info,
}

impl Found {
    /// Its name.
    pub fn name(&self) -> String {
        self.info.text(self.info.api.get_name)
    }

    /// Its type.
    pub fn kind(&self) -> String {
        self.info.text(self.info.api.get_type)
    }

    /// Its source id.
    pub fn source_id(&self) -> String {
        self.info.text(self.info.api.get_source_id)
    }

    /// Its channel count.
    pub fn channels(&self) -> i32 {
        self.info.channel_count()
    }

    /// Its nominal rate (Hz; 0 irregular).
    pub fn rate_hz(&self) -> f64 {
        self.info.nominal_srate()
    }

    /// Its channel format (none for an unknown code).
    pub fn format(&self) -> Option<Format> {
        Format::from_code(self.info.channel_format())
    }

    /// Opens an inlet on it and the stream, within `timeout_secs`.
    pub fn open(&self, timeout_secs: f64) -> Result<Inlet, LslError> {
        let raw = RawInlet::create(&self.info)?;
        let name = self.name();
        match raw.open(timeout_secs) {
            0 => {}
            LSL_TIMEOUT => {
                return Err(LslError::Stream(format!(
                    "the stream {name:?} did not open within {timeout_secs} s"
                )));
            }
            ec => {
                return Err(LslError::Lost(format!(
                    "the stream {name:?} could not be opened (liblsl error {ec})"
                )));
            }
        }
        Ok(Inlet {
            raw,
            channels: usize::try_from(self.channels()).unwrap_or(0),
            name,
        })
    }
}

/// A stream being read.
pub struct Inlet {
    raw: RawInlet,
    channels: usize,
    name: String,
}

impl Inlet {
    /// The next sample into `buffer` (as many values as the stream has
    /// channels), waiting up to `timeout_secs`: its timestamp (the
    /// sender's clock), or none if nothing came. A sender gone is
    /// [`LslError::Lost`].
    pub fn pull(&self, buffer: &mut [f64], timeout_secs: f64) -> Result<Option<f64>, LslError> {
        if buffer.len() != self.channels {
            return Err(LslError::Argument(format!(
                "{}: a buffer of {} for {} channels",
                self.name,
                buffer.len(),
                self.channels
            )));
        }
        let (stamp, ec) = self.raw.pull(buffer, timeout_secs);
        pulled(&self.name, stamp, ec)
    }

    /// The offset (s) to add to the sender's timestamps for the local
    /// clock, measured within `timeout_secs`.
    pub fn time_correction(&self, timeout_secs: f64) -> Result<f64, LslError> {
        match self.raw.time_correction(timeout_secs) {
            (t, 0) => Ok(t),
            (_, LSL_LOST) => Err(LslError::Lost(format!(
                "the stream {:?} was lost: its sender stopped",
                self.name
            ))),
            (_, ec) => Err(LslError::Stream(format!(
                "{}: no clock offset within {timeout_secs} s (liblsl error {ec})",
                self.name
            ))),
        }
    }

    /// Channels per sample.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The stream's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// What a pull of the stream `name` gave: a sample's timestamp (`stamp`,
/// liblsl's error code `ec` 0), nothing yet (0 without a timestamp, or a
/// timeout), a lost sender, or another error.
fn pulled(name: &str, stamp: f64, ec: i32) -> Result<Option<f64>, LslError> {
    match ec {
        0 if stamp != 0.0 => Ok(Some(stamp)),
        0 | LSL_TIMEOUT => Ok(None),
        LSL_LOST => Err(LslError::Lost(format!(
            "the stream {name:?} was lost: its sender stopped"
        ))),
        ec => Err(LslError::Stream(format!(
            "{name}: liblsl error {ec} while reading"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FORMATS: [Format; 7] = [
        Format::Float32,
        Format::Double64,
        Format::String,
        Format::Int32,
        Format::Int16,
        Format::Int8,
        Format::Int64,
    ];

    #[test]
    fn every_format_has_liblsls_code_and_name() {
        for (k, f) in FORMATS.into_iter().enumerate() {
            // lsl_channel_format_t: cft_float32 = 1 ... cft_int64 = 7.
            assert_eq!(f.code(), k as i32 + 1);
            assert_eq!(Format::from_code(f.code()), Some(f));
        }
        assert_eq!(Format::from_code(0), None, "cft_undefined");
        assert_eq!(Format::from_code(8), None);
        assert_eq!(Format::String.name(), "string");
        assert_eq!(Format::Double64.name(), "double64");
    }

    #[test]
    fn a_description_is_a_tree_of_leaves_and_nodes() {
        let e = Element::node("errp", vec![Element::leaf("speed", 2.5)]);
        assert_eq!(e.value, None);
        assert_eq!(e.children[0].name, "speed");
        assert_eq!(e.children[0].value.as_deref(), Some("2.5"));
        assert!(e.children[0].children.is_empty());
    }

    #[test]
    fn a_path_that_is_no_library_is_refused_naming_it() {
        let dir = std::env::temp_dir().join(format!("errp-lsl-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let missing = dir.join("missing.so");
        let e = Lsl::open(&missing).unwrap_err().to_string();
        assert!(
            e.contains("missing.so") && e.ends_with("no such file"),
            "{e}"
        );
        let e = Lsl::open(&dir).unwrap_err().to_string();
        assert!(e.ends_with("not a regular file"), "{e}");
        let text = dir.join("liblsl.so");
        std::fs::write(&text, "not a library").unwrap();
        let e = Lsl::open(&text).unwrap_err();
        assert!(matches!(e, LslError::Load { .. }), "{e}");
        assert!(matches!(
            Lsl::find(Some(&missing)),
            Err(LslError::Load { .. })
        ));
        // A name without a directory is a file here, not one the system's
        // loader would find elsewhere.
        let e = Lsl::open(Path::new("errp-no-such-liblsl.so"))
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("no such file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_nul_in_a_name_is_refused_before_liblsl_sees_it() {
        let e = ffi::c_string("a marker", "a\0b").unwrap_err();
        assert!(matches!(e, LslError::Argument(_)));
        assert_eq!(e.to_string(), "a marker holds a NUL character");
        assert!(ffi::c_string("a marker", "ab").is_ok());
    }

    #[test]
    fn a_pull_is_a_sample_nothing_yet_or_a_lost_sender() {
        assert_eq!(pulled("d", 12.5, 0).unwrap(), Some(12.5));
        assert_eq!(pulled("d", 0.0, 0).unwrap(), None);
        assert_eq!(pulled("d", 0.0, LSL_TIMEOUT).unwrap(), None);
        let e = pulled("d", 0.0, LSL_LOST).unwrap_err();
        assert!(matches!(e, LslError::Lost(_)), "{e}");
        assert_eq!(
            e.to_string(),
            "the stream \"d\" was lost: its sender stopped"
        );
        assert!(matches!(pulled("d", 0.0, -4), Err(LslError::Stream(_))));
    }
}
