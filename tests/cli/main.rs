//! End-to-end tests of the `errp` program, run as a user would, one binary:
//! the commands (`commands`) and what they leave behind when they are
//! interrupted, run twice at once or given damaged files (`reliability`).

mod commands;
mod edges;
mod hostile;
mod inspect;
mod realism;
mod recorded;
mod reliability;
mod scripts;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub(crate) fn errp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_errp"))
        .args(args)
        .output()
        .expect("errp runs")
}

pub(crate) fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("errp-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub(crate) fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `errp args`, which must refuse with exit code 2; its stderr.
#[track_caller]
pub(crate) fn refused(args: &[&str]) -> String {
    let o = errp(args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    stderr(&o)
}

pub(crate) fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
