//! Snapshot tests of what users read: a text is compared with the file
//! `sim/tests/snapshots/NAME.txt`; `UPDATE_SNAPSHOTS=1` writes it instead,
//! for a change of format that is meant (review the diff before
//! committing).

use std::path::PathBuf;

/// Asserts that `text` is the snapshot `name`, or writes it when
/// `UPDATE_SNAPSHOTS=1`.
#[track_caller]
pub(crate) fn assert_snapshot(name: &str, text: &str) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{name}.txt"));
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().expect("a snapshot has a folder"))
            .expect("the snapshot folder can be created");
        std::fs::write(&path, text).expect("the snapshot can be written");
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run with UPDATE_SNAPSHOTS=1 to write it)",
            path.display()
        )
    });
    if text != expected {
        let first = text
            .lines()
            .zip(expected.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| text.lines().count().min(expected.lines().count()));
        panic!(
            "{} differs from the snapshot at line {}:\n  got:      {:?}\n  expected: {:?}\n\
             (UPDATE_SNAPSHOTS=1 rewrites it if the change is meant)\n--- got ---\n{text}",
            path.display(),
            first + 1,
            text.lines().nth(first).unwrap_or(""),
            expected.lines().nth(first).unwrap_or("")
        );
    }
}
