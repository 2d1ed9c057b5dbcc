//! EDF+ export of raw EEG with event annotations, readable by MNE-Python
//! (`mne.io.read_raw_edf`), EEGLAB and EDFbrowser.

use std::io::{Seek, SeekFrom, Write};

use crate::erp::AssessmentKind;
use crate::error::{BciError, Result};
use crate::generator::{Assessment, EegBlock};
use crate::montage::{ChannelKind, Montage};

/// Physical range of every signal (uV): 16-bit samples at 0.1 uV resolution.
const PHYS_MAX_UV: f64 = 3276.7;
/// Samples of the annotation signal per record (2 bytes each).
const ANNOTATION_SAMPLES: usize = 64;

/// Streams an EDF+C file, one data record per second.
///
/// Samples beyond +-3276.7 uV are clipped (the synthetic EEG stays far inside).
/// Each record carries its time-keeping annotation and the assessments whose
/// onsets fall in it, as `error` / `correct`.
pub struct EdfWriter<W: Write + Seek> {
    out: W,
    n_channels: usize,
    samples_per_record: usize,
    records: usize,
    pending: Vec<Vec<f64>>,
    pending_events: Vec<Assessment>,
}

impl<W: Write + Seek> EdfWriter<W> {
    /// Writes the header for `montage` at `sfreq_hz` (an integer rate).
    pub fn new(mut out: W, montage: &Montage, sfreq_hz: f64) -> Result<Self> {
        if sfreq_hz.fract() != 0.0 || sfreq_hz <= 0.0 {
            return Err(BciError::InvalidParameter {
                name: "sfreq_hz",
                value: sfreq_hz.to_string(),
                expected: "a whole number of Hz for 1 s EDF records".into(),
            });
        }
        let spr = sfreq_hz as usize;
        let ns = montage.len() + 1;
        let mut h = String::with_capacity(256 * (ns + 1));
        field(&mut h, "0", 8);
        field(&mut h, "X X X X", 80);
        field(&mut h, "Startdate 01-JAN-2000 X errp-testbed synthetic", 80);
        field(&mut h, "01.01.00", 8);
        field(&mut h, "00.00.00", 8);
        field(&mut h, &(256 * (ns + 1)).to_string(), 8);
        field(&mut h, "EDF+C", 44);
        field(&mut h, "-1", 8); // patched by finish()
        field(&mut h, "1", 8);
        field(&mut h, &ns.to_string(), 4);
        let chans = montage.channels();
        for c in chans {
            field(&mut h, &c.name, 16);
        }
        field(&mut h, "EDF Annotations", 16);
        for c in chans {
            let t = match c.kind {
                ChannelKind::Eeg => "synthetic EEG electrode",
                ChannelKind::Eog => "synthetic EOG electrode",
            };
            field(&mut h, t, 80);
        }
        field(&mut h, "", 80);
        for _ in chans {
            field(&mut h, "uV", 8);
        }
        field(&mut h, "", 8);
        for _ in chans {
            field(&mut h, &format!("{:.1}", -PHYS_MAX_UV), 8);
        }
        field(&mut h, "-1", 8);
        for _ in chans {
            field(&mut h, &format!("{PHYS_MAX_UV:.1}"), 8);
        }
        field(&mut h, "1", 8);
        for _ in chans {
            field(&mut h, "-32767", 8);
        }
        field(&mut h, "-32768", 8);
        for _ in 0..ns {
            field(&mut h, "32767", 8);
        }
        for _ in chans {
            field(&mut h, "none (raw synthetic)", 80);
        }
        field(&mut h, "", 80);
        for _ in chans {
            field(&mut h, &spr.to_string(), 8);
        }
        field(&mut h, &ANNOTATION_SAMPLES.to_string(), 8);
        for _ in 0..ns {
            field(&mut h, "", 32);
        }
        debug_assert_eq!(h.len(), 256 * (ns + 1));
        out.write_all(h.as_bytes())?;
        Ok(Self {
            out,
            n_channels: montage.len(),
            samples_per_record: spr,
            records: 0,
            pending: vec![Vec::new(); montage.len()],
            pending_events: Vec::new(),
        })
    }

    /// Appends raw samples `(n_channels, n)` and the assessments whose onsets
    /// fall in them.
    pub fn write(&mut self, block: &EegBlock, events: &[Assessment]) -> Result<()> {
        assert_eq!(block.n_channels, self.n_channels, "channel count");
        for ch in 0..self.n_channels {
            self.pending[ch].extend_from_slice(block.channel(ch));
        }
        self.pending_events.extend_from_slice(events);
        while self.pending[0].len() >= self.samples_per_record {
            self.flush_record()?;
        }
        Ok(())
    }

    fn flush_record(&mut self) -> Result<()> {
        let spr = self.samples_per_record;
        let mut bytes = Vec::with_capacity(2 * (spr * self.n_channels + ANNOTATION_SAMPLES));
        for ch in 0..self.n_channels {
            for &v in &self.pending[ch][..spr] {
                let d = (v / PHYS_MAX_UV * 32767.0).round().clamp(-32767.0, 32767.0) as i16;
                bytes.extend_from_slice(&d.to_le_bytes());
            }
            self.pending[ch].drain(..spr);
        }
        let start = self.records as f64;
        let end = start + 1.0;
        let mut tal = format!("+{start}\x14\x14\0").into_bytes();
        let (now, later): (Vec<Assessment>, Vec<Assessment>) =
            self.pending_events.iter().partition(|a| a.onset_secs < end);
        for a in &now {
            let label = match a.kind {
                AssessmentKind::Error => "error",
                AssessmentKind::Correct => "correct",
            };
            tal.extend_from_slice(format!("+{:.4}\x14{label}\x14\0", a.onset_secs).as_bytes());
        }
        self.pending_events = later;
        if tal.len() > 2 * ANNOTATION_SAMPLES {
            return Err(BciError::InvalidParameter {
                name: "events",
                value: now.len().to_string(),
                expected: "few enough events per second to fit one EDF record".into(),
            });
        }
        tal.resize(2 * ANNOTATION_SAMPLES, 0);
        bytes.extend_from_slice(&tal);
        self.out.write_all(&bytes)?;
        self.records += 1;
        Ok(())
    }

    /// Pads the last record with zeros, writes the record count and returns
    /// the writer.
    pub fn finish(mut self) -> Result<W> {
        if !self.pending[0].is_empty() {
            for p in &mut self.pending {
                p.resize(self.samples_per_record, 0.0);
            }
            self.flush_record()?;
        }
        self.out.seek(SeekFrom::Start(236))?;
        let mut count = String::new();
        field(&mut count, &self.records.to_string(), 8);
        self.out.write_all(count.as_bytes())?;
        self.out.flush()?;
        Ok(self.out)
    }
}

/// Appends `value` left-aligned and space-padded to `width` ASCII bytes.
fn field(h: &mut String, value: &str, width: usize) {
    let v: String = value.chars().filter(|c| c.is_ascii()).take(width).collect();
    h.push_str(&v);
    h.extend(std::iter::repeat_n(' ', width - v.len()));
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn header_records_and_annotations_are_well_formed() {
        let m = Montage::standard();
        let mut w = EdfWriter::new(Cursor::new(Vec::new()), &m, 256.0).unwrap();
        let mut block = EegBlock::zeros(m.len(), 640);
        block.channel_mut(0)[0] = 12.3;
        block.channel_mut(1)[0] = -5000.0;
        let ev = [Assessment {
            onset_secs: 1.25,
            kind: AssessmentKind::Error,
        }];
        w.write(&block, &ev).unwrap();
        let bytes = w.finish().unwrap().into_inner();
        let ns = m.len() + 1;
        let header_len = 256 * (ns + 1);
        let record_len = 2 * (256 * m.len() + ANNOTATION_SAMPLES);
        assert_eq!(
            bytes.len(),
            header_len + 3 * record_len,
            "2.5 s -> 3 records"
        );
        let text = |a: usize, b: usize| String::from_utf8_lossy(&bytes[a..b]).trim().to_string();
        assert_eq!(text(236, 244), "3");
        assert_eq!(text(192, 197), "EDF+C");
        assert_eq!(text(256, 272), "Fp1");
        // First sample of channel 0: 12.3 uV -> round(12.3 / 3276.7 * 32767) = 123.
        let s0 = i16::from_le_bytes([bytes[header_len], bytes[header_len + 1]]);
        assert_eq!(s0, 123);
        let s1 = i16::from_le_bytes([bytes[header_len + 512], bytes[header_len + 513]]);
        assert_eq!(s1, -32767, "clipped");
        let rec1 = header_len + record_len;
        let ann = String::from_utf8_lossy(
            &bytes[rec1 + record_len - 2 * ANNOTATION_SAMPLES..rec1 + record_len],
        );
        assert!(
            ann.starts_with("+1\x14\x14\0+1.2500\x14error\x14\0"),
            "{ann:?}"
        );
    }
}
