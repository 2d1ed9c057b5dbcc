//! Reading EDF, EDF+, BDF and BDF+ files: the header, every signal in
//! physical units, and the EDF+ annotations (time-stamped annotation lists,
//! TALs).
//!
//! Written here rather than taken from a crate: none of the EDF crates we
//! found reads both EDF+ annotations and 24-bit BDF, and the format is
//! small (a 256-byte header, 256 bytes per signal, then data records). The
//! reader trusts nothing it reads: every field is parsed and checked, sizes
//! are bounded ([`MAX_EDF_SIGNALS`], [`MAX_EDF_SAMPLES`]) before anything
//! is allocated, and a file that ends inside a record, or has bytes after
//! its last one, is refused. Discontinuous files (EDF+D, BDF+D) are
//! refused: own EEG in the loop is one unbroken session.
//!
//! EDF+ keeps time in annotations: each data record's first TAL gives the
//! record's start, and every onset counts from the header's start time.
//! The first record may start later than that (edfio writes a sub-second
//! start time so; a file cut from a longer one starts later still), so the
//! onsets read here are moved to count from the first sample, as MNE and
//! pyEDFlib place them, and a record that does not follow the previous one
//! is refused.

use std::io::Read;

use crate::error::{BciError, Result};

/// The most signals a file may declare.
pub const MAX_EDF_SIGNALS: usize = 512;
/// The most samples a file may hold, over all its signals (2^27: 3.6 hours
/// of 40 channels at 256 Hz, 1 GiB as `f64`).
pub const MAX_EDF_SAMPLES: u64 = 1 << 27;
/// The most samples one signal may have in one data record.
const MAX_SAMPLES_PER_RECORD: usize = 1 << 20;
/// The most samples one data record may hold over all its signals (12 MiB
/// of BDF).
const MAX_RECORD_SAMPLES: usize = 1 << 22;
/// The largest physical minimum or maximum a signal may declare, in its own
/// unit (a million volts in µV; real EEG is under a volt in any unit).
const MAX_PHYSICAL: f64 = 1e12;
/// The most annotations a file may hold (one every 0.13 s over the 3.6
/// hours [`MAX_EDF_SAMPLES`] allows at 40 channels and 256 Hz).
pub const MAX_EDF_ANNOTATIONS: usize = 100_000;

/// Which variant of the format a file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdfFormat {
    /// EDF (16-bit samples), without annotations.
    Edf,
    /// EDF+C: continuous EDF with annotations.
    EdfPlus,
    /// BDF (BioSemi, 24-bit samples), without annotations.
    Bdf,
    /// BDF+C: continuous BDF with annotations.
    BdfPlus,
}

impl EdfFormat {
    /// The format's name.
    pub fn name(self) -> &'static str {
        match self {
            EdfFormat::Edf => "EDF",
            EdfFormat::EdfPlus => "EDF+C",
            EdfFormat::Bdf => "BDF",
            EdfFormat::BdfPlus => "BDF+C",
        }
    }

    fn bytes_per_sample(self) -> usize {
        match self {
            EdfFormat::Edf | EdfFormat::EdfPlus => 2,
            EdfFormat::Bdf | EdfFormat::BdfPlus => 3,
        }
    }
}

/// One ordinary signal of a file, in physical units.
#[derive(Debug, Clone, PartialEq)]
pub struct EdfSignal {
    /// Its label, trimmed (`FCz`, `EEG FCz`, `EOG LA`).
    pub label: String,
    /// Its physical dimension as written (`uV`, `mV`).
    pub unit: String,
    /// Its sampling rate (samples per record over the record's duration).
    pub sfreq_hz: f64,
    /// Its samples, in the file's physical unit.
    pub samples: Vec<f64>,
}

impl EdfSignal {
    /// The factor from the signal's unit to microvolts, if it is a voltage
    /// (`uV`, `µV`, `mV`, `V`, `nV`, any case).
    pub fn to_microvolts(&self) -> Option<f64> {
        match self.unit.trim().to_ascii_lowercase().as_str() {
            "uv" | "µv" | "μv" => Some(1.0),
            "mv" => Some(1e3),
            "v" => Some(1e6),
            "nv" => Some(1e-3),
            _ => None,
        }
    }
}

/// An annotation of an EDF+ or BDF+ file.
#[derive(Debug, Clone, PartialEq)]
pub struct EdfAnnotation {
    /// Its onset from the file's first sample, in seconds (the file's own
    /// onset, from the header's start time, less
    /// [`EdfFile::start_secs`]).
    pub onset_secs: f64,
    /// Its duration in seconds, if given.
    pub duration_secs: Option<f64>,
    /// Its text.
    pub text: String,
}

/// An EDF, EDF+C, BDF or BDF+C file read whole.
#[derive(Debug, Clone, PartialEq)]
pub struct EdfFile {
    /// The variant.
    pub format: EdfFormat,
    /// The ordinary signals, in the file's order.
    pub signals: Vec<EdfSignal>,
    /// The annotations, in the file's order (the time-keeping ones left
    /// out).
    pub annotations: Vec<EdfAnnotation>,
    /// The number of data records.
    pub records: usize,
    /// One data record's duration, in seconds.
    pub record_secs: f64,
    /// When the first data record starts, in seconds after the header's
    /// start time: its time-keeping TAL (EDF+ and BDF+), 0 without
    /// annotations.
    pub start_secs: f64,
}

/// One signal's header.
struct SignalHeader {
    label: String,
    unit: String,
    annotations: bool,
    samples_per_record: usize,
    /// Physical = digital * scale + offset.
    scale: f64,
    offset: f64,
}

/// An error about the file's content.
fn bad(what: impl Into<String>) -> BciError {
    BciError::Format(what.into())
}

/// Reads into `buf` until it is full or the file ends; the bytes read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(BciError::Io(e)),
        }
    }
    Ok(got)
}

/// Reads exactly `buf.len()` bytes; the end of the file first is `what`
/// truncated.
fn read_exact(r: &mut impl Read, buf: &mut [u8], what: &str) -> Result<()> {
    r.read_exact(buf).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => bad(format!("truncated: the file ends inside {what}")),
        _ => BciError::Io(e),
    })
}

/// A header field, trimmed. EDF asks for ASCII; other bytes are read as
/// Latin-1, as some writers put `µ` (0xB5) in units.
fn text(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|&b| char::from(b))
        .collect::<String>()
        .trim()
        .to_string()
}

fn number(bytes: &[u8], what: &str) -> Result<f64> {
    let t = text(bytes);
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(bad(format!("the header's {what} is {t:?}, not a number"))),
    }
}

fn whole(bytes: &[u8], what: &str) -> Result<i64> {
    let t = text(bytes);
    t.parse::<i64>()
        .map_err(|_| bad(format!("the header's {what} is {t:?}, not a whole number")))
}

/// The format from the version field and the reserved field.
fn format_of(version: &[u8], reserved: &str) -> Result<EdfFormat> {
    let bdf = version == b"\xffBIOSEMI";
    if !bdf && version != b"0       " {
        return Err(bad(
            "not an EDF or BDF file: its first 8 bytes are not \"0\" (EDF) or \
             0xFF \"BIOSEMI\" (BDF)"
                .to_string(),
        ));
    }
    match (bdf, reserved) {
        (_, r) if r.starts_with("EDF+D") || r.starts_with("BDF+D") => Err(bad(format!(
            "a discontinuous recording ({}): only continuous ones (EDF, EDF+C, BDF, BDF+C) \
             can be read",
            &r[..5]
        ))),
        (false, r) if r.starts_with("EDF+C") => Ok(EdfFormat::EdfPlus),
        (true, r) if r.starts_with("BDF+C") || r.starts_with("EDF+C") => Ok(EdfFormat::BdfPlus),
        (false, _) => Ok(EdfFormat::Edf),
        (true, _) => Ok(EdfFormat::Bdf),
    }
}

/// The signals' headers: `n` signals, fields laid out across signals.
fn signal_headers(bytes: &[u8], n: usize, format: EdfFormat) -> Result<Vec<SignalHeader>> {
    // (offset of the field block, width of one signal's field)
    let field = |block: usize, width: usize, i: usize| {
        let at = block * n + i * width;
        &bytes[at..at + width]
    };
    // Field blocks: label 16, transducer 80, unit 8, phys min 8, phys max 8,
    // dig min 8, dig max 8, prefiltering 80, samples 8, reserved 32.
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let label = text(field(0, 16, i));
        let unit = text(field(96, 8, i));
        let what = |f: &str| format!("{f} of signal {label:?}");
        let pmin = number(field(104, 8, i), &what("physical minimum"))?;
        let pmax = number(field(112, 8, i), &what("physical maximum"))?;
        let dmin = number(field(120, 8, i), &what("digital minimum"))?;
        let dmax = number(field(128, 8, i), &what("digital maximum"))?;
        let spr = whole(field(216, 8, i), &what("samples per record"))?;
        let plain = format == EdfFormat::Edf || format == EdfFormat::Bdf;
        if plain && is_annotation_label(&label) {
            return Err(bad(format!(
                "signal {} is labelled {label:?}, but the header's reserved field does not \
                 say {}: its annotations would be read as samples (a writer that left out \
                 the field; write the file again, e.g. with MNE's export_raw)",
                i + 1,
                if format == EdfFormat::Edf {
                    "EDF+C"
                } else {
                    "BDF+C"
                }
            )));
        }
        let annotations = !plain && is_annotation_label(&label);
        if !(1..=MAX_SAMPLES_PER_RECORD as i64).contains(&spr) {
            return Err(bad(format!(
                "{} is {spr}; accepted: 1 to {MAX_SAMPLES_PER_RECORD}",
                what("samples per record")
            )));
        }
        if !annotations && (dmax <= dmin || pmax == pmin) {
            return Err(bad(format!(
                "signal {label:?} has digital range [{dmin}, {dmax}] and physical range \
                 [{pmin}, {pmax}]; the digital maximum must exceed the minimum and the \
                 physical range must not be empty"
            )));
        }
        if !annotations && pmin.abs().max(pmax.abs()) > MAX_PHYSICAL {
            return Err(bad(format!(
                "signal {label:?} has physical range [{}, {}] {unit}; accepted: magnitudes \
                 up to {MAX_PHYSICAL:e} (a header that lies about its physical range)",
                errp_valid::shown(pmin),
                errp_valid::shown(pmax)
            )));
        }
        let scale = (pmax - pmin) / (dmax - dmin);
        out.push(SignalHeader {
            label,
            unit,
            annotations,
            samples_per_record: spr as usize,
            scale,
            offset: pmin - dmin * scale,
        });
    }
    Ok(out)
}

fn is_annotation_label(label: &str) -> bool {
    label == "EDF Annotations" || label == "BDF Annotations"
}

impl EdfFile {
    /// Reads a whole file from `r`, checking every field; `len` is the
    /// file's size in bytes if known (to refuse a truncated file before
    /// reading its records).
    pub fn read(mut r: impl Read, len: Option<u64>) -> Result<Self> {
        let mut head = [0u8; 256];
        let got = read_full(&mut r, &mut head)?;
        let format = format_of(&head[0..8], &text(&head[192..236]))?;
        if got < head.len() {
            return Err(bad("truncated: the file ends inside its 256-byte header"));
        }
        let header_bytes = whole(&head[184..192], "header size")?;
        let declared = whole(&head[236..244], "number of data records")?;
        let record_secs = number(&head[244..252], "duration of a data record")?;
        let n = whole(&head[252..256], "number of signals")?;
        if !(1..=MAX_EDF_SIGNALS as i64).contains(&n) {
            return Err(bad(format!(
                "the header's number of signals is {n}; accepted: 1 to {MAX_EDF_SIGNALS}"
            )));
        }
        let n = n as usize;
        if header_bytes != 256 * (n as i64 + 1) {
            return Err(bad(format!(
                "the header's size is {header_bytes} bytes; with {n} signals it must be {}",
                256 * (n + 1)
            )));
        }
        if !(0.001..=3600.0).contains(&record_secs) {
            return Err(bad(format!(
                "the duration of a data record is {} s; accepted: 0.001 to 3600",
                // As written (1e-300, not its 300 decimal digits).
                text(&head[244..252]).trim()
            )));
        }
        let mut sig_bytes = vec![0u8; 256 * n];
        read_exact(&mut r, &mut sig_bytes, "its signal headers")?;
        let headers = signal_headers(&sig_bytes, n, format)?;
        let bps = format.bytes_per_sample();
        let record_samples: usize = headers.iter().map(|h| h.samples_per_record).sum();
        if record_samples > MAX_RECORD_SAMPLES {
            return Err(bad(format!(
                "a data record of {record_samples} samples; accepted: at most \
                 {MAX_RECORD_SAMPLES}"
            )));
        }
        let record_bytes = record_samples * bps;
        let records = count_records(declared, len, header_bytes as u64, record_bytes as u64)?;
        if (records as u64).saturating_mul(record_samples as u64) > MAX_EDF_SAMPLES {
            return Err(bad(format!(
                "{records} records of {record_samples} samples: more than the {MAX_EDF_SAMPLES} \
                 samples a file may hold"
            )));
        }
        let mut file = EdfFile {
            format,
            signals: headers
                .iter()
                .filter(|h| !h.annotations)
                .map(|h| EdfSignal {
                    label: h.label.clone(),
                    unit: h.unit.clone(),
                    sfreq_hz: h.samples_per_record as f64 / record_secs,
                    samples: Vec::with_capacity(h.samples_per_record * records),
                })
                .collect(),
            annotations: Vec::new(),
            records,
            record_secs,
            start_secs: 0.0,
        };
        // A record's start may differ from where the previous one ends by
        // less than half a sample of the fastest signal: no sample moves.
        let fastest = headers
            .iter()
            .filter(|h| !h.annotations)
            .map(|h| h.samples_per_record)
            .max()
            .unwrap_or(1);
        let clock = Clock {
            record_secs,
            tolerance: 0.5 * record_secs / fastest as f64,
        };
        let mut buf = vec![0u8; record_bytes];
        for k in 0..records {
            read_exact(
                &mut r,
                &mut buf,
                &format!("data record {} of {records}", k + 1),
            )?;
            file.take_record(&buf, &headers, k, &clock)?;
        }
        let end = header_bytes as u64 + (records * record_bytes) as u64;
        ends_after_its_records(&mut r, len, end, records, record_bytes)?;
        let start = file.start_secs;
        for a in &mut file.annotations {
            a.onset_secs -= start;
        }
        Ok(file)
    }

    /// Decodes one data record into the signals and annotations.
    fn take_record(
        &mut self,
        buf: &[u8],
        headers: &[SignalHeader],
        k: usize,
        clock: &Clock,
    ) -> Result<()> {
        let bps = self.format.bytes_per_sample();
        let mut at = 0;
        let mut ordinary = 0;
        let mut keeps_time = true;
        for h in headers {
            let bytes = &buf[at..at + h.samples_per_record * bps];
            at += bytes.len();
            if h.annotations {
                // The first annotation signal keeps the time.
                self.take_tals(bytes, k, keeps_time.then_some(clock))?;
                keeps_time = false;
                continue;
            }
            let out = &mut self.signals[ordinary].samples;
            ordinary += 1;
            for s in bytes.chunks_exact(bps) {
                let d = if bps == 2 {
                    f64::from(i16::from_le_bytes([s[0], s[1]]))
                } else {
                    // 24-bit little-endian two's complement.
                    f64::from(i32::from_le_bytes([0, s[0], s[1], s[2]]) >> 8)
                };
                out.push(d * h.scale + h.offset);
            }
        }
        Ok(())
    }

    /// Parses the TALs of one record's annotation signal: `+onset[\x15
    /// duration]\x14text\x14...\x14\0`, padded with zeros. In the first
    /// annotation signal (`clock` given), the first TAL keeps time: its
    /// onset is the record's start and its first text is empty.
    fn take_tals(&mut self, bytes: &[u8], k: usize, clock: Option<&Clock>) -> Result<()> {
        let where_ = || format!("the annotations of data record {}", k + 1);
        let mut keeper = clock;
        for tal in bytes.split(|&b| b == 0).filter(|t| !t.is_empty()) {
            let mut parts = tal.split(|&b| b == 0x14);
            let stamp = parts.next().unwrap_or_default();
            let mut stamp = stamp.split(|&b| b == 0x15);
            let onset = tal_number(stamp.next().unwrap_or_default(), true)
                .ok_or_else(|| bad(format!("{}: a TAL without a valid onset", where_())))?;
            let duration =
                match stamp.next() {
                    None => None,
                    Some(d) => Some(tal_number(d, false).ok_or_else(|| {
                        bad(format!("{}: a TAL with an invalid duration", where_()))
                    })?),
                };
            if let Some(clock) = keeper.take() {
                if parts.next().is_none_or(|t| !t.is_empty()) {
                    return Err(bad(format!(
                        "{}: its first TAL is not a time-keeping one (an onset and an empty \
                         text, as EDF+ asks of every record)",
                        where_()
                    )));
                }
                self.keep_time(onset, k, clock)?;
            }
            for t in parts.filter(|t| !t.is_empty()) {
                let text = std::str::from_utf8(t)
                    .map_err(|_| bad(format!("{}: an annotation that is not UTF-8", where_())))?;
                if self.annotations.len() == MAX_EDF_ANNOTATIONS {
                    return Err(bad(format!(
                        "more than {MAX_EDF_ANNOTATIONS} annotations (at data record {} of \
                         {}): more than a file may hold",
                        k + 1,
                        self.records
                    )));
                }
                self.annotations.push(EdfAnnotation {
                    onset_secs: onset,
                    duration_secs: duration,
                    text: text.to_string(),
                });
            }
        }
        if keeper.is_some() {
            return Err(bad(format!(
                "{}: no time-keeping TAL (EDF+ starts every record's first annotation \
                 signal with one: the record's start)",
                where_()
            )));
        }
        Ok(())
    }

    /// Record `k`'s start, `onset` seconds after the header's start time:
    /// the first sets [`EdfFile::start_secs`], each later one must follow
    /// the one before.
    fn keep_time(&mut self, onset: f64, k: usize, clock: &Clock) -> Result<()> {
        if k == 0 {
            self.start_secs = onset;
            return Ok(());
        }
        let expected = self.start_secs + k as f64 * clock.record_secs;
        if (onset - expected).abs() > clock.tolerance {
            return Err(bad(format!(
                "data record {} starts at {} s, where the one before ends at {} s: the \
                 records of a continuous file (EDF+C, BDF+C) follow each other without gaps",
                k + 1,
                errp_valid::shown(onset),
                errp_valid::shown(expected)
            )));
        }
        Ok(())
    }

    /// The ordinary signal labelled `label`, matched as own EEG's
    /// channels are ([`OwnEeg`](crate::OwnEeg)): ignoring case and an
    /// `EEG ` or `EOG ` prefix; two signals that match are an error naming
    /// both.
    pub fn signal(&self, label: &str) -> Result<Option<&EdfSignal>> {
        let labels: Vec<&str> = self.signals.iter().map(|s| s.label.as_str()).collect();
        Ok(crate::montage::find_label(&labels, label)
            .map_err(bad)?
            .map(|i| &self.signals[i]))
    }

    /// The file's duration, in seconds.
    pub fn duration_secs(&self) -> f64 {
        self.records as f64 * self.record_secs
    }
}

/// The time-keeping rule of a file's records.
struct Clock {
    /// One record's duration, in seconds.
    record_secs: f64,
    /// How far a record's start may be from the previous record's end.
    tolerance: f64,
}

/// A TAL's onset (signed) or duration (unsigned), as EDF+ writes them.
fn tal_number(bytes: &[u8], signed: bool) -> Option<f64> {
    let t = std::str::from_utf8(bytes).ok()?;
    let body = if signed {
        t.strip_prefix('+')
            .or_else(|| t.strip_prefix('-').map(|_| t))?
    } else {
        t
    };
    if body.is_empty()
        || !body
            .bytes()
            .all(|b| b.is_ascii_digit() || b == b'.' || b == b'-')
    {
        return None;
    }
    body.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Refuses a file that goes on after its last data record (which ends at
/// byte `end`; the file has `len` bytes if known).
fn ends_after_its_records(
    r: &mut impl Read,
    len: Option<u64>,
    end: u64,
    records: usize,
    record_bytes: usize,
) -> Result<()> {
    let mut more = [0u8; 1];
    if read_full(r, &mut more)? == 0 {
        return Ok(());
    }
    let after = len.map_or_else(
        || "bytes".to_string(),
        |l| format!("{} bytes", l.saturating_sub(end)),
    );
    Err(bad(format!(
        "{after} after its {records} data records of {record_bytes} bytes: not a whole \
         record (a damaged or concatenated file, or a header that declares too few records)"
    )))
}

/// The number of data records: the header's, checked against the file's
/// size when known; or, when the header says -1 (unknown), what the size
/// holds.
fn count_records(declared: i64, len: Option<u64>, header: u64, record: u64) -> Result<usize> {
    let whole_in_file = len.map(|l| l.saturating_sub(header) / record.max(1));
    let records = match (declared, whole_in_file) {
        (-1, Some(n)) => n,
        (-1, None) => {
            return Err(bad(
                "the number of data records is -1 (unknown), and the file's size is not known",
            ));
        }
        (d, Some(n)) if d >= 0 && (d as u64) > n => {
            return Err(bad(format!(
                "truncated: the header declares {d} data records of {record} bytes, the file \
                 holds {n} whole ones"
            )));
        }
        (d, _) if d >= 0 => d as u64,
        (d, _) => {
            return Err(bad(format!(
                "the number of data records is {d}; accepted: a whole number from 0, or -1"
            )));
        }
    };
    usize::try_from(records).map_err(|_| bad(format!("{records} data records: too many")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edf::EdfWriter;
    use crate::erp::AssessmentKind;
    use crate::generator::{Assessment, EegBlock};
    use crate::montage::Montage;
    use std::io::Cursor;

    fn exported(seconds: usize) -> (Vec<u8>, EegBlock) {
        let m = Montage::standard();
        let mut w = EdfWriter::new(Cursor::new(Vec::new()), &m, 256.0).unwrap();
        let mut block = EegBlock::zeros(m.len(), 256 * seconds);
        for ch in 0..m.len() {
            for (t, v) in block.channel_mut(ch).iter_mut().enumerate() {
                *v = ((t * 7 + ch * 13) % 200) as f64 - 100.0 + 0.05 * ch as f64;
            }
        }
        let ev = [
            Assessment {
                onset_secs: 2.0,
                kind: AssessmentKind::Correct,
            },
            Assessment {
                onset_secs: 5.3125,
                kind: AssessmentKind::Error,
            },
        ];
        w.write(&block, &ev).unwrap();
        (w.finish().unwrap().into_inner(), block)
    }

    #[test]
    fn an_export_reads_back_to_its_samples_and_events() {
        let (bytes, block) = exported(8);
        let f = EdfFile::read(Cursor::new(&bytes), Some(bytes.len() as u64)).unwrap();
        let m = Montage::standard();
        assert_eq!(f.format, EdfFormat::EdfPlus);
        assert_eq!(
            (f.records, f.record_secs, f.signals.len()),
            (8, 1.0, m.len())
        );
        for (ch, s) in f.signals.iter().enumerate() {
            assert_eq!(s.label, m.channels()[ch].name);
            assert_eq!((s.sfreq_hz, s.to_microvolts()), (256.0, Some(1.0)));
            for (a, b) in s.samples.iter().zip(block.channel(ch)) {
                assert!((a - b).abs() <= 0.051, "{a} vs {b}: 0.1 uV steps");
            }
        }
        let texts: Vec<(f64, &str)> = f
            .annotations
            .iter()
            .map(|a| (a.onset_secs, a.text.as_str()))
            .collect();
        assert_eq!(texts, [(2.0, "correct"), (5.3125, "error")]);
        assert!(f.signal("EEG fcz").unwrap().is_some() && f.signal("Fcz").unwrap().is_some());
        assert!(f.signal("FCzz").unwrap().is_none());
        assert_eq!(f.start_secs, 0.0);
    }

    /// `bytes` (an export: 1 s records, the annotation signal last, 128
    /// bytes) with every TAL of record k moved by `by(k)` seconds, as a
    /// writer whose first record starts later than the header's start time
    /// writes them.
    fn moved(bytes: &[u8], by: impl Fn(usize) -> f64) -> Vec<u8> {
        let ns: usize = text(&bytes[252..256]).parse().unwrap();
        let (header, record) = (256 * (ns + 1), (ns - 1) * 512 + 128);
        let mut out = bytes.to_vec();
        for (k, start) in (header..out.len()).step_by(record).enumerate() {
            let tals = &mut out[start + record - 128..start + record];
            let mut new = Vec::new();
            for tal in tals.split(|&b| b == 0).filter(|t| !t.is_empty()) {
                let tal = std::str::from_utf8(tal).unwrap();
                let end = tal.find(['\x14', '\x15']).unwrap();
                let onset: f64 = tal[1..end].parse().unwrap();
                new.extend_from_slice(format!("+{}{}\0", onset + by(k), &tal[end..]).as_bytes());
            }
            new.resize(128, 0);
            tals.copy_from_slice(&new);
        }
        out
    }

    /// An EDF+ file of 1 s records: signal `Cz` (`spr` zero samples a
    /// record) and an annotation signal of `ann_bytes` bytes a record,
    /// `tals[k]` in record k; `reserved` the header's reserved field.
    fn edf_plus(spr: usize, tals: &[&[u8]], ann_bytes: usize, reserved: &str) -> Vec<u8> {
        let mut h = String::new();
        let f = |h: &mut String, v: &str, w: usize| h.push_str(&format!("{v:<w$}"));
        for (v, w) in [
            ("0", 8),
            ("", 160),
            ("01.01.00", 8),
            ("00.00.00", 8),
            ("768", 8),
        ] {
            f(&mut h, v, w);
        }
        f(&mut h, reserved, 44);
        f(&mut h, &tals.len().to_string(), 8);
        f(&mut h, "1", 8);
        f(&mut h, "2", 4);
        f(&mut h, "Cz", 16);
        f(&mut h, "EDF Annotations", 16);
        f(&mut h, "", 160);
        f(&mut h, "uV", 8);
        f(&mut h, "", 8);
        for v in [
            "-100", "-1", "100", "1", "-32768", "-32768", "32767", "32767",
        ] {
            f(&mut h, v, 8);
        }
        f(&mut h, "", 160);
        f(&mut h, &spr.to_string(), 8);
        f(&mut h, &(ann_bytes / 2).to_string(), 8);
        f(&mut h, "", 64);
        let mut b = h.into_bytes();
        assert_eq!(b.len(), 768);
        for tal in tals {
            b.extend(std::iter::repeat_n(0u8, 2 * spr));
            let mut t = tal.to_vec();
            t.resize(ann_bytes, 0);
            b.extend_from_slice(&t);
        }
        b
    }

    fn read(b: &[u8]) -> Result<EdfFile> {
        EdfFile::read(Cursor::new(b), Some(b.len() as u64))
    }

    #[test]
    fn onsets_count_from_the_first_sample_as_edf_plus_keeps_time() {
        // edfio writes a sub-second start time into the first record's
        // TAL; a file cut from a longer session starts later still.
        let (bytes, _) = exported(8);
        let original = read(&bytes).unwrap();
        for by in [0.5, 100.0] {
            let f = read(&moved(&bytes, |_| by)).unwrap();
            assert_eq!(f.start_secs, by);
            assert_eq!(f.annotations, original.annotations, "started at +{by} s");
            assert_eq!(f.signals, original.signals);
        }
        // A record that does not follow the one before: refused, naming it.
        let e = read(&moved(&bytes, |k| if k >= 3 { 0.5 } else { 0.0 }))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("data record 4 starts at 3.5 s, where the one before ends at 3 s"),
            "{e}"
        );
        // Less than half a sample off moves no sample.
        let f = read(&moved(&bytes, |k| if k >= 3 { 0.001 } else { 0.0 })).unwrap();
        assert_eq!(
            (f.start_secs, f.signals.len()),
            (0.0, original.signals.len())
        );
        // A record without its time-keeping TAL, or whose first TAL has text.
        let tk: &[u8] = b"+0\x14\x14\0";
        let e = read(&edf_plus(4, &[tk, b"+1\x14\x14\0", b""], 16, "EDF+C"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("data record 3: no time-keeping TAL"), "{e}");
        let e = read(&edf_plus(4, &[b"+0\x14e\x14\0"], 16, "EDF+C"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("data record 1: its first TAL is not a time-keeping"),
            "{e}"
        );
        let f = read(&edf_plus(
            4,
            &[tk, b"+1\x14\x14\0+1.5\x14e\x14\0"],
            32,
            "EDF+C",
        ))
        .unwrap();
        assert_eq!((f.annotations.len(), f.annotations[0].onset_secs), (1, 1.5));
    }

    #[test]
    fn annotations_in_a_plain_edf_and_too_many_are_refused() {
        let tk: &[u8] = b"+0\x14\x14\0";
        let e = read(&edf_plus(4, &[tk], 16, "")).unwrap_err().to_string();
        assert!(
            e.contains(
                "signal 2 is labelled \"EDF Annotations\", but the header's reserved \
                 field does not say EDF+C"
            ),
            "{e}"
        );
        let mut tals = tk.to_vec();
        for _ in 0..=MAX_EDF_ANNOTATIONS {
            tals.extend_from_slice(b"+0\x14a\x14\0");
        }
        let e = read(&edf_plus(1, &[&tals], (tals.len() + 2) & !1, "EDF+C"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 100000 annotations"), "{e}");
    }

    #[test]
    fn a_24_bit_bdf_is_read() {
        // One signal, 2 samples per 0.5 s record, 2 records; BDF+C with an
        // annotation signal of 6 "samples" (18 bytes).
        let mut h = String::new();
        let f = |h: &mut String, v: &str, w: usize| h.push_str(&format!("{v:<w$}"));
        f(&mut h, "XBIOSEMI", 8);
        f(&mut h, "", 160);
        f(&mut h, "01.01.00", 8);
        f(&mut h, "00.00.00", 8);
        f(&mut h, "768", 8);
        f(&mut h, "BDF+C", 44);
        f(&mut h, "2", 8);
        f(&mut h, "0.5", 8);
        f(&mut h, "2", 4);
        for (a, b) in [("Cz", "BDF Annotations"), ("", ""), ("mV", "")] {
            let w = if a == "Cz" {
                16
            } else if a.is_empty() {
                80
            } else {
                8
            };
            f(&mut h, a, w);
            f(&mut h, b, w);
        }
        // Physical = digital, in mV.
        for (a, b) in [("-8388608", "-1"), ("8388607", "1")] {
            f(&mut h, a, 8);
            f(&mut h, b, 8);
        }
        for (a, b) in [("-8388608", "-8388608"), ("8388607", "8388607")] {
            f(&mut h, a, 8);
            f(&mut h, b, 8);
        }
        f(&mut h, "", 160);
        f(&mut h, "2", 8);
        f(&mut h, "6", 8);
        f(&mut h, "", 64);
        let mut bytes = h.into_bytes();
        bytes[0] = 0xff;
        assert_eq!(bytes.len(), 768);
        for (k, samples) in [[1i32, -1], [-8388608, 8388607]].iter().enumerate() {
            for s in samples {
                bytes.extend_from_slice(&s.to_le_bytes()[..3]);
            }
            let mut tal = format!("+{}\x14\x14\0", k as f64 * 0.5).into_bytes();
            if k == 1 {
                tal.extend_from_slice(b"+0.6\x14e\x14\0");
            }
            tal.resize(18, 0);
            bytes.extend_from_slice(&tal);
        }
        let file = EdfFile::read(Cursor::new(&bytes), None).unwrap();
        assert_eq!(file.format, EdfFormat::BdfPlus);
        let s = &file.signals[0];
        assert_eq!((s.sfreq_hz, s.to_microvolts()), (4.0, Some(1e3)));
        let want = [1.0, -1.0, -8388608.0, 8388607.0];
        for (a, b) in s.samples.iter().zip(want) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        assert_eq!(file.annotations[0].text, "e");
    }

    #[test]
    fn flipped_bits_are_read_or_refused_never_a_panic() {
        use rand::{Rng, SeedableRng};
        let (bytes, _) = exported(2);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..3000 {
            let mut b = bytes.clone();
            // Mostly the headers, where the sizes are.
            let at = if rng.random_bool(0.8) {
                rng.random_range(0..256 * 42)
            } else {
                rng.random_range(0..b.len())
            };
            b[at] ^= 1 << rng.random_range(0..8);
            let len = rng.random_bool(0.5).then_some(b.len() as u64);
            let _ = EdfFile::read(Cursor::new(&b), len);
        }
    }

    #[test]
    fn damaged_files_are_refused_naming_what_is_wrong() {
        let (bytes, _) = exported(3);
        let read = |b: &[u8]| {
            EdfFile::read(Cursor::new(b), Some(b.len() as u64))
                .unwrap_err()
                .to_string()
        };
        let e = read(b"name,kind\nFp1,eeg\n");
        assert!(e.contains("not an EDF or BDF file"), "{e}");
        let e = read(&bytes[..bytes.len() - 10]);
        assert!(
            e.contains("truncated") && e.contains("3 data records"),
            "{e}"
        );
        let e = EdfFile::read(Cursor::new(&bytes[..bytes.len() - 10]), None).unwrap_err();
        assert!(e.to_string().contains("ends inside data record 3"), "{e}");
        let e = read(&bytes[..100]);
        assert!(e.contains("header"), "{e}");
        // A physical range no EEG has (Fp1's minimum and maximum).
        let mut b = bytes.clone();
        let n = 41;
        b[256 + 104 * n..256 + 104 * n + 8].copy_from_slice(b"-1e300  ");
        b[256 + 112 * n..256 + 112 * n + 8].copy_from_slice(b"1e300   ");
        let e = read(&b);
        assert!(
            e.contains("signal \"Fp1\" has physical range [-1e300, 1e300] uV; accepted"),
            "{e}"
        );
        // Bytes after the last record, whether or not the size is known.
        let mut b = bytes.clone();
        b.extend_from_slice(&[7; 1000]);
        let e = read(&b);
        assert!(e.contains("1000 bytes after its 3 data records"), "{e}");
        let e = EdfFile::read(Cursor::new(&b), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bytes after its 3 data records"), "{e}");
        let mut b = bytes.clone();
        b[236..244].copy_from_slice(b"-1      ");
        b.extend_from_slice(&[7; 10]);
        let e = read(&b);
        assert!(e.contains("10 bytes after its 3 data records"), "{e}");
        // A record duration shown as written, not as its 300 decimals.
        let mut b = bytes.clone();
        b[244..252].copy_from_slice(b"1e-300  ");
        let e = read(&b);
        assert!(
            e.contains("duration of a data record is 1e-300 s; accepted: 0.001 to 3600"),
            "{e}"
        );
        let mut b = bytes.clone();
        b[252..256].copy_from_slice(b"9999");
        let e = read(&b);
        assert!(e.contains("number of signals is 9999"), "{e}");
        let mut b = bytes.clone();
        b[192..197].copy_from_slice(b"EDF+D");
        assert!(read(&b).contains("discontinuous"));
        let mut b = bytes.clone();
        b[236..244].copy_from_slice(b"-1      ");
        let f = EdfFile::read(Cursor::new(&b), Some(b.len() as u64)).unwrap();
        assert_eq!(f.records, 3);
        // A huge samples-per-record field is refused before any allocation.
        let mut b = bytes;
        let n = 41;
        let spr_at = 256 + 216 * n;
        b[spr_at..spr_at + 8].copy_from_slice(b"99999999");
        let e = read(&b);
        assert!(e.contains("samples per record of signal \"Fp1\""), "{e}");
    }
}
