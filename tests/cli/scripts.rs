//! The scripts in `scripts/`: each answers `--help` with its usage and
//! exit code 0, and changes nothing (no build, no figure, no file).

use std::path::Path;
use std::process::Command;

/// Every file of `scripts/` and `scripts/slurm/` (not `__pycache__`).
fn scripts(root: &Path) -> Vec<std::path::PathBuf> {
    let mut all = Vec::new();
    for dir in ["scripts", "scripts/slurm"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                all.push(p);
            }
        }
    }
    all.sort();
    all
}

/// Names and modification times of the files under `dir`
/// (`__pycache__` aside).
fn snapshot(dir: &Path, out: &mut Vec<(String, Option<std::time::SystemTime>)>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if ["target", ".git", "__pycache__"].contains(&name.as_str()) {
            continue;
        }
        let p = e.path();
        if p.is_dir() {
            snapshot(&p, out);
        } else {
            out.push((
                p.display().to_string(),
                e.metadata().ok().and_then(|m| m.modified().ok()),
            ));
        }
    }
}

#[test]
fn every_script_answers_help_at_once_and_changes_nothing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let list = scripts(root);
    assert!(list.len() >= 20, "{list:?}");
    // What a script at work would change: its own directory, the figures
    // and the lock file (other tests may write beside them meanwhile).
    let watched = || {
        let mut v = Vec::new();
        snapshot(&root.join("scripts"), &mut v);
        snapshot(&root.join("docs"), &mut v);
        v.push((
            "Cargo.lock".into(),
            std::fs::metadata(root.join("Cargo.lock"))
                .ok()
                .and_then(|m| m.modified().ok()),
        ));
        v
    };
    let before = watched();
    for script in &list {
        let interpreter = match script.extension().and_then(|e| e.to_str()) {
            Some("py") => "python3",
            _ => "bash",
        };
        let o = Command::new(interpreter)
            .arg(script)
            .arg("--help")
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .output()
            .expect("the interpreter runs");
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}: {}",
            script.display(),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            out.lines().count() >= 2,
            "{}: no usage on stdout: {out}",
            script.display()
        );
    }
    assert_eq!(before, watched(), "a script's --help changed files");
}
