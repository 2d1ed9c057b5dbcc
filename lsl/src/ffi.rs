//! liblsl's C API (`lsl_c.h`, liblsl 1.14 and later), loaded at run time:
//! the functions the testbed calls, copied out of the library once, and the
//! library kept loaded as long as one of them may be called.

#![allow(
    unsafe_code,
    reason = "the calls into liblsl: the one module of the workspace that allows unsafe code, \
              each block with its SAFETY note"
)]
#![warn(clippy::undocumented_unsafe_blocks)]

use std::ffi::{CStr, CString, c_char, c_double, c_void};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use libloading::Library;

use crate::LslError;

/// A liblsl object (streaminfo, XML node, outlet, inlet).
pub(crate) type Handle = *mut c_void;

/// The functions of liblsl the testbed calls.
pub(crate) struct Api {
    pub library_version: unsafe extern "C" fn() -> i32,
    pub local_clock: unsafe extern "C" fn() -> c_double,
    pub create_streaminfo: unsafe extern "C" fn(
        *const c_char,
        *const c_char,
        i32,
        c_double,
        i32,
        *const c_char,
    ) -> Handle,
    pub destroy_streaminfo: unsafe extern "C" fn(Handle),
    pub get_desc: unsafe extern "C" fn(Handle) -> Handle,
    pub append_child: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    pub append_child_value: unsafe extern "C" fn(Handle, *const c_char, *const c_char) -> Handle,
    pub get_name: unsafe extern "C" fn(Handle) -> *const c_char,
    pub get_type: unsafe extern "C" fn(Handle) -> *const c_char,
    pub get_source_id: unsafe extern "C" fn(Handle) -> *const c_char,
    pub get_channel_count: unsafe extern "C" fn(Handle) -> i32,
    pub get_nominal_srate: unsafe extern "C" fn(Handle) -> c_double,
    pub get_channel_format: unsafe extern "C" fn(Handle) -> i32,
    pub create_outlet: unsafe extern "C" fn(Handle, i32, i32) -> Handle,
    pub destroy_outlet: unsafe extern "C" fn(Handle),
    pub push_sample_ftp: unsafe extern "C" fn(Handle, *const f32, c_double, i32) -> i32,
    pub push_sample_strtp: unsafe extern "C" fn(Handle, *const *const c_char, c_double, i32) -> i32,
    pub have_consumers: unsafe extern "C" fn(Handle) -> i32,
    pub wait_for_consumers: unsafe extern "C" fn(Handle, c_double) -> i32,
    pub resolve_byprop:
        unsafe extern "C" fn(*mut Handle, u32, *const c_char, *const c_char, i32, c_double) -> i32,
    pub create_inlet: unsafe extern "C" fn(Handle, i32, i32, i32) -> Handle,
    pub destroy_inlet: unsafe extern "C" fn(Handle),
    pub open_stream: unsafe extern "C" fn(Handle, c_double, *mut i32),
    pub pull_sample_d:
        unsafe extern "C" fn(Handle, *mut c_double, i32, c_double, *mut i32) -> c_double,
    pub time_correction: unsafe extern "C" fn(Handle, c_double, *mut i32) -> c_double,
    /// `lsl_set_config_content` (liblsl 1.16 and later).
    pub set_config_content: Option<unsafe extern "C" fn(*const c_char)>,
    /// Keeps the functions above valid.
    _library: Library,
    pub path: PathBuf,
}

impl Api {
    /// Loads liblsl from `path` (a file, or a name the system's loader
    /// searches for) and looks up every function.
    pub(crate) fn load(path: &Path) -> Result<Arc<Self>, LslError> {
        let fail = |why: String| LslError::Load {
            path: path.to_path_buf(),
            why,
        };
        // SAFETY: loading a shared library runs its initialisers; liblsl's
        // only start its clock and read its configuration file.
        let library = unsafe { Library::new(path) }.map_err(|e| fail(e.to_string()))?;
        macro_rules! symbol {
            ($name:literal) => {{
                // SAFETY: the type is the function's in lsl_c.h (checked
                // against pylsl's ctypes declarations); the pointer is used
                // only while `_library` is loaded.
                let f = unsafe { library.get(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| fail(format!("no function {}: {e}", $name)))?;
                *f
            }};
        }
        let api = Self {
            library_version: symbol!("lsl_library_version"),
            local_clock: symbol!("lsl_local_clock"),
            create_streaminfo: symbol!("lsl_create_streaminfo"),
            destroy_streaminfo: symbol!("lsl_destroy_streaminfo"),
            get_desc: symbol!("lsl_get_desc"),
            append_child: symbol!("lsl_append_child"),
            append_child_value: symbol!("lsl_append_child_value"),
            get_name: symbol!("lsl_get_name"),
            get_type: symbol!("lsl_get_type"),
            get_source_id: symbol!("lsl_get_source_id"),
            get_channel_count: symbol!("lsl_get_channel_count"),
            get_nominal_srate: symbol!("lsl_get_nominal_srate"),
            get_channel_format: symbol!("lsl_get_channel_format"),
            create_outlet: symbol!("lsl_create_outlet"),
            destroy_outlet: symbol!("lsl_destroy_outlet"),
            push_sample_ftp: symbol!("lsl_push_sample_ftp"),
            push_sample_strtp: symbol!("lsl_push_sample_strtp"),
            have_consumers: symbol!("lsl_have_consumers"),
            wait_for_consumers: symbol!("lsl_wait_for_consumers"),
            resolve_byprop: symbol!("lsl_resolve_byprop"),
            create_inlet: symbol!("lsl_create_inlet"),
            destroy_inlet: symbol!("lsl_destroy_inlet"),
            open_stream: symbol!("lsl_open_stream"),
            pull_sample_d: symbol!("lsl_pull_sample_d"),
            time_correction: symbol!("lsl_time_correction"),
            // SAFETY: as for `symbol!`; an older liblsl lacks it.
            set_config_content: unsafe { library.get(b"lsl_set_config_content\0") }
                .ok()
                .map(|f| *f),
            _library: library,
            path: path.to_path_buf(),
        };
        Ok(Arc::new(api))
    }

    /// Sets liblsl's configuration (the text of an `lsl_api.cfg`) before
    /// its first use; false when this liblsl cannot.
    pub(crate) fn configure(&self, text: &str) -> bool {
        let (Some(f), Ok(c)) = (self.set_config_content, CString::new(text)) else {
            return false;
        };
        // SAFETY: the string outlives the call, which copies it.
        unsafe { f(c.as_ptr()) };
        true
    }

    pub(crate) fn version(&self) -> i32 {
        // SAFETY: no arguments; a pure query.
        unsafe { (self.library_version)() }
    }

    pub(crate) fn clock(&self) -> f64 {
        // SAFETY: no arguments; reads a steady clock.
        unsafe { (self.local_clock)() }
    }
}

/// A C string of `s`, or an error naming `what` if it holds a NUL.
pub(crate) fn c_string(what: &str, s: &str) -> Result<CString, LslError> {
    CString::new(s).map_err(|_| LslError::Argument(format!("{what} holds a NUL character")))
}

/// A stream description made here and destroyed when dropped.
pub(crate) struct Info {
    pub api: Arc<Api>,
    pub ptr: Handle,
}

impl Info {
    /// Creates a description: `format` is liblsl's channel format code.
    pub(crate) fn create(
        api: &Arc<Api>,
        name: &str,
        kind: &str,
        channels: u32,
        rate_hz: f64,
        format: i32,
        source_id: &str,
    ) -> Result<Self, LslError> {
        let (n, k, s) = (
            c_string("the stream name", name)?,
            c_string("the stream type", kind)?,
            c_string("the source id", source_id)?,
        );
        let count = i32::try_from(channels)
            .map_err(|_| LslError::Argument(format!("{channels} channels")))?;
        // SAFETY: the strings outlive the call, which copies them.
        let ptr = unsafe {
            (api.create_streaminfo)(n.as_ptr(), k.as_ptr(), count, rate_hz, format, s.as_ptr())
        };
        if ptr.is_null() {
            return Err(LslError::Argument(format!(
                "liblsl refused the stream {name:?} ({channels} channels at {rate_hz} Hz)"
            )));
        }
        Ok(Self {
            api: api.clone(),
            ptr,
        })
    }

    /// The description's root element (`<desc>`).
    pub(crate) fn desc(&self) -> Handle {
        // SAFETY: `ptr` is a live streaminfo.
        unsafe { (self.api.get_desc)(self.ptr) }
    }

    /// Appends `<name>value</name>` (or an empty `<name/>`) to `parent`, a
    /// node of this description, and returns the new node.
    pub(crate) fn append(
        &self,
        parent: Handle,
        name: &str,
        value: Option<&str>,
    ) -> Result<Handle, LslError> {
        let n = c_string("an XML element's name", name)?;
        let node = match value {
            Some(v) => {
                let v = c_string("an XML element's value", v)?;
                // SAFETY: `parent` belongs to this live description; the
                // strings outlive the call, which copies them.
                unsafe { (self.api.append_child_value)(parent, n.as_ptr(), v.as_ptr()) }
            }
            // SAFETY: as above.
            None => unsafe { (self.api.append_child)(parent, n.as_ptr()) },
        };
        Ok(node)
    }

    pub(crate) fn text(&self, f: unsafe extern "C" fn(Handle) -> *const c_char) -> String {
        // SAFETY: `ptr` is a live streaminfo; the string it returns lives
        // as long as it does and is copied at once.
        unsafe {
            let s = f(self.ptr);
            if s.is_null() {
                String::new()
            } else {
                CStr::from_ptr(s).to_string_lossy().into_owned()
            }
        }
    }

    pub(crate) fn channel_count(&self) -> i32 {
        // SAFETY: `ptr` is a live streaminfo.
        unsafe { (self.api.get_channel_count)(self.ptr) }
    }

    pub(crate) fn nominal_srate(&self) -> f64 {
        // SAFETY: `ptr` is a live streaminfo.
        unsafe { (self.api.get_nominal_srate)(self.ptr) }
    }

    pub(crate) fn channel_format(&self) -> i32 {
        // SAFETY: `ptr` is a live streaminfo.
        unsafe { (self.api.get_channel_format)(self.ptr) }
    }
}

impl Drop for Info {
    fn drop(&mut self) {
        // SAFETY: `ptr` was made by liblsl and is destroyed once, here.
        unsafe { (self.api.destroy_streaminfo)(self.ptr) }
    }
}

/// Resolves the streams whose `prop` is `value` within `timeout_secs` (at
/// most 64).
pub(crate) fn resolve(
    api: &Arc<Api>,
    prop: &str,
    value: &str,
    timeout_secs: f64,
) -> Result<Vec<Info>, LslError> {
    let (p, v) = (
        c_string("the property", prop)?,
        c_string("the value", value)?,
    );
    let mut found: [Handle; 64] = [std::ptr::null_mut(); 64];
    // SAFETY: the buffer holds 64 handles, as the call is told; the
    // strings outlive it.
    let n = unsafe {
        (api.resolve_byprop)(
            found.as_mut_ptr(),
            64,
            p.as_ptr(),
            v.as_ptr(),
            1,
            timeout_secs,
        )
    };
    if n < 0 {
        return Err(LslError::Stream(format!(
            "resolving streams with {prop}={value} failed (liblsl error {n})"
        )));
    }
    Ok(found[..n.min(64) as usize]
        .iter()
        .map(|&ptr| Info {
            api: api.clone(),
            ptr,
        })
        .collect())
}

/// An outlet, destroyed when dropped.
pub(crate) struct RawOutlet {
    pub api: Arc<Api>,
    pub ptr: Handle,
}

impl RawOutlet {
    pub(crate) fn create(info: &Info) -> Result<Self, LslError> {
        // SAFETY: `info` is live; liblsl copies it. Chunks of any size, 360
        // s buffered.
        let ptr = unsafe { (info.api.create_outlet)(info.ptr, 0, 360) };
        if ptr.is_null() {
            return Err(LslError::Stream(format!(
                "liblsl could not open an outlet for {:?}",
                info.text(info.api.get_name)
            )));
        }
        Ok(Self {
            api: info.api.clone(),
            ptr,
        })
    }

    /// Pushes one sample of `values` (exactly the stream's channels: the
    /// caller checks).
    pub(crate) fn push_f32(&self, values: &[f32], stamp: f64) -> i32 {
        // SAFETY: the outlet is live and `values` holds its channel count.
        unsafe { (self.api.push_sample_ftp)(self.ptr, values.as_ptr(), stamp, 1) }
    }

    /// Pushes one string sample (a one-channel string stream).
    pub(crate) fn push_str(&self, text: &CStr, stamp: f64) -> i32 {
        let one = [text.as_ptr()];
        // SAFETY: the outlet is live with one string channel; the string
        // outlives the call, which copies it.
        unsafe { (self.api.push_sample_strtp)(self.ptr, one.as_ptr(), stamp, 1) }
    }

    pub(crate) fn have_consumers(&self) -> bool {
        // SAFETY: the outlet is live.
        unsafe { (self.api.have_consumers)(self.ptr) != 0 }
    }

    pub(crate) fn wait_for_consumers(&self, timeout_secs: f64) -> bool {
        // SAFETY: the outlet is live.
        unsafe { (self.api.wait_for_consumers)(self.ptr, timeout_secs) != 0 }
    }
}

// SAFETY: liblsl's outlets are thread-safe (lsl_c.h: "all functions of
// an outlet may be called from any thread"); the handle is owned here.
unsafe impl Send for RawOutlet {}

impl Drop for RawOutlet {
    fn drop(&mut self) {
        // SAFETY: made by liblsl, destroyed once, here.
        unsafe { (self.api.destroy_outlet)(self.ptr) }
    }
}

/// An inlet, destroyed when dropped.
pub(crate) struct RawInlet {
    pub api: Arc<Api>,
    pub ptr: Handle,
}

/// liblsl's error codes.
pub(crate) const LSL_TIMEOUT: i32 = -1;
pub(crate) const LSL_LOST: i32 = -2;

impl RawInlet {
    /// An inlet on `info` that does not recover a lost stream (a decoder
    /// that goes away is an error, not a wait).
    pub(crate) fn create(info: &Info) -> Result<Self, LslError> {
        // SAFETY: `info` is live; liblsl copies it. 360 s buffered, chunks
        // as sent, no recovery.
        let ptr = unsafe { (info.api.create_inlet)(info.ptr, 360, 0, 0) };
        if ptr.is_null() {
            return Err(LslError::Stream("liblsl could not open an inlet".into()));
        }
        Ok(Self {
            api: info.api.clone(),
            ptr,
        })
    }

    /// Opens the stream; the error code.
    pub(crate) fn open(&self, timeout_secs: f64) -> i32 {
        let mut ec = 0;
        // SAFETY: the inlet is live; `ec` is a valid out-pointer.
        unsafe { (self.api.open_stream)(self.ptr, timeout_secs, &mut ec) };
        ec
    }

    /// Pulls one sample into `buffer` (the stream's channel count: the
    /// caller checks): its timestamp (0 when none came) and the error code.
    pub(crate) fn pull(&self, buffer: &mut [f64], timeout_secs: f64) -> (f64, i32) {
        let mut ec = 0;
        let n = i32::try_from(buffer.len()).unwrap_or(i32::MAX);
        // SAFETY: the inlet is live; the buffer holds `n` values.
        let stamp = unsafe {
            (self.api.pull_sample_d)(self.ptr, buffer.as_mut_ptr(), n, timeout_secs, &mut ec)
        };
        (stamp, ec)
    }

    /// The sender's clock offset (add it to a sample's timestamp for the
    /// local clock) and the error code.
    pub(crate) fn time_correction(&self, timeout_secs: f64) -> (f64, i32) {
        let mut ec = 0;
        // SAFETY: the inlet is live; `ec` is a valid out-pointer.
        let t = unsafe { (self.api.time_correction)(self.ptr, timeout_secs, &mut ec) };
        (t, ec)
    }
}

// SAFETY: an inlet may be used from another thread than the one that
// made it (not from two at once: `RawInlet` is not `Sync`).
unsafe impl Send for RawInlet {}

impl Drop for RawInlet {
    fn drop(&mut self) {
        // SAFETY: made by liblsl, destroyed once, here.
        unsafe { (self.api.destroy_inlet)(self.ptr) }
    }
}
