//! Rerun recordings: an `.rrd` file with a default layout, written whole or
//! not at all.

use std::path::Path;

pub mod data;
pub mod paths;
pub mod schema;

pub use paths::eeg_channel;

use rerun::{RecordingStream, RecordingStreamBuilder, blueprint::Blueprint};

use crate::error::{Result, SimError};
use crate::output::PendingFile;

/// The simulation timeline of task recordings (s).
pub const SIM_TIME: &str = "sim_time";

/// The timeline of calibration recordings: time after the action (s), on
/// which grand averages are drawn.
pub const LATENCY_TIMELINE: &str = "latency";

/// The layout of a task recording: the scene above the event log on the
/// left, `panels` stacked on the right.
pub(crate) fn task_blueprint(
    scene: rerun::blueprint::Spatial2DView,
    panels: Vec<rerun::blueprint::ContainerLike>,
) -> Blueprint {
    use rerun::blueprint::{Horizontal, TextLogView, Vertical};
    let events = TextLogView::new("Events").with_origin(paths::LOG);
    opening_view(
        // The scene gets the wider column.
        Blueprint::new(
            Horizontal::new([
                Vertical::new([scene.into(), events.into()]).into(),
                Vertical::new(panels).into(),
            ])
            .with_column_shares([3.0, 2.0]),
        ),
        SIM_TIME,
    )
}

/// What a file shows when it opens: the views over the whole window (the
/// blueprint and selection panels folded away, one click to unfold) and the
/// time cursor on `timeline` at the latest data, so a run opens finished
/// (the whole trajectory, every detection), not as an empty scene at time 0.
pub(crate) fn opening_view(blueprint: Blueprint, timeline: &str) -> Blueprint {
    use rerun::blueprint::components::{PanelState, PlayState};
    use rerun::blueprint::{BlueprintPanel, SelectionPanel, TimePanel};
    blueprint
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(
            TimePanel::new()
                .with_state(PanelState::Collapsed)
                .with_timeline(timeline)
                .with_play_state(PlayState::Following),
        )
}

/// How long a recording's flush may go without its file growing before
/// the writer is taken to have stopped ([`RrdFile::finish`]).
pub const FLUSH_STEP: std::time::Duration = std::time::Duration::from_secs(3);

/// An `.rrd` file being recorded. Log to [`RrdFile::stream`]; call
/// [`RrdFile::finish`] to flush it and move it into place.
pub struct RrdFile {
    stream: RecordingStream,
    pending: PendingFile,
}

impl RrdFile {
    /// Starts a recording of application `app_id` at `path` with `blueprint`
    /// as its default layout. An unwritable path fails here, before any work.
    pub fn create(
        app_id: &'static str,
        path: impl AsRef<Path>,
        blueprint: Blueprint,
    ) -> Result<Self> {
        let (pending, file) = PendingFile::create_exclusive(path)?;
        drop(file);
        let stream = RecordingStreamBuilder::new(app_id)
            .with_default_blueprint(blueprint)
            .save(pending.temp_path())
            .map_err(|e| SimError::Record {
                path: pending.path().to_path_buf(),
                message: e.to_string(),
            })?;
        Ok(Self { stream, pending })
    }

    /// The stream to log to.
    pub fn stream(&self) -> &RecordingStream {
        &self.stream
    }

    /// The final path of the recording.
    pub fn path(&self) -> &Path {
        self.pending.path()
    }

    /// Flushes everything to disk and renames the file into place.
    ///
    /// When the SDK's file writer stops on an error (a full disk, a
    /// file-size limit), a flush can wait for it forever; the flush is
    /// therefore waited for in steps of [`FLUSH_STEP`], and a step in which
    /// the file did not grow is the writer's end: an error, and the
    /// temporary is removed. The stream, whose threads may still wait, is
    /// then left to the process's end rather than dropped (which would
    /// wait too).
    pub fn finish(self) -> Result<std::path::PathBuf> {
        let Self { stream, pending } = self;
        let path = pending.path().to_path_buf();
        let size = || std::fs::metadata(pending.temp_path()).map_or(0, |m| m.len());
        let mut last = size();
        loop {
            match stream.flush_with_timeout(FLUSH_STEP) {
                Ok(()) => break,
                Err(rerun::sink::SinkFlushError::Timeout) if size() != last => last = size(),
                Err(e) => {
                    std::mem::forget(stream);
                    let message = match e {
                        rerun::sink::SinkFlushError::Timeout => format!(
                            "the file writer stopped with the file at {last} bytes (a full disk \
                             or a file-size limit?)"
                        ),
                        other => other.to_string(),
                    };
                    return Err(recording_failed(&path, message));
                }
            }
        }
        stream.disconnect();
        // Dropping the stream ends the writer, which writes the file's end
        // then; an error there is only logged by the SDK, so the end is
        // checked on disk.
        drop(stream);
        if let Err(message) = check_stream_footer(pending.temp_path()) {
            return Err(recording_failed(&path, message));
        }
        pending.commit()
    }
}

/// Checks that the `.rrd` file at `path` ends with Rerun's stream footer
/// (32 bytes: the span of the footer message, its checksum, `RRF2FOOT` and
/// the count 1) and that the span ends where the footer begins: a file whose
/// last writes failed does not.
fn check_stream_footer(path: &Path) -> std::result::Result<(), String> {
    use std::io::{Read, Seek, SeekFrom};
    const FOOTER: u64 = 32;
    let mut file = crate::open_regular(path).map_err(|e| e.to_string())?;
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut tail = [0u8; FOOTER as usize];
    let read = len >= FOOTER
        && file.seek(SeekFrom::Start(len - FOOTER)).is_ok()
        && file.read_exact(&mut tail).is_ok();
    let word = |at: usize| u64::from_le_bytes(tail[at..at + 8].try_into().expect("8 bytes"));
    if read && &tail[20..28] == b"RRF2FOOT" && word(0).checked_add(word(8)) == Some(len - FOOTER) {
        Ok(())
    } else {
        Err(format!(
            "the recording's end was not written: the file stops at {len} bytes (a full disk or \
             a file-size limit?)"
        ))
    }
}

/// Styles the decoder's two series: p(error) in red under `decoder/p_error`
/// and the decision threshold, named `threshold_name`, in grey under
/// `decoder/threshold`.
pub(crate) fn log_decoder_series(
    rec: &rerun::RecordingStream,
    threshold_name: &str,
) -> std::result::Result<(), rerun::RecordingStreamError> {
    use rerun::{Color, SeriesLines};
    rec.log_static(
        paths::P_ERROR,
        &SeriesLines::new()
            .with_names(["p(error)"])
            .with_colors([Color::from_rgb(200, 40, 40)]),
    )?;
    rec.log_static(
        paths::THRESHOLD,
        &SeriesLines::new()
            .with_names([threshold_name])
            .with_colors([Color::from_rgb(120, 120, 120)]),
    )
}

/// Maps a Rerun SDK error to a [`SimError`] about `path`.
pub(crate) fn record_error(path: &Path) -> impl Fn(rerun::RecordingStreamError) -> SimError + '_ {
    move |e| recording_failed(path, e.to_string())
}

/// The error of a recording to `path` that failed with the SDK's
/// `message`. The SDK's file writer says that it stopped ("File-writer
/// thread shut down prematurely"), not why: a probe written beside the
/// file finds the usual cause (a full disk, a quota), which leads.
fn recording_failed(path: &Path, message: String) -> SimError {
    let message = match probe_space(path) {
        Err(e) => format!("{e} ({message})"),
        Ok(()) => message,
    };
    SimError::Record {
        path: path.to_path_buf(),
        message,
    }
}

/// Writes and syncs 1 MiB beside `path`, then removes it.
fn probe_space(path: &Path) -> std::io::Result<()> {
    use std::io::Write;
    let probe = path.with_file_name(".errp-space-probe");
    let (pending, mut file) = PendingFile::create(&probe).map_err(|e| match e {
        SimError::Output { source, .. } => source,
        other => std::io::Error::other(other.to_string()),
    })?;
    let result = file
        .write_all(&vec![0u8; 1 << 20])
        .and_then(|()| file.sync_all());
    drop(pending);
    result
}
