//! `errp inspect FILE.rrd...`: what a recording holds, its runs recomputed
//! from its data tables, tidy CSV tables, and the paper's Fig. 5 / Fig. 4.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use errp_sim::inspect::{
    Comparison, CsvTable, Recording, RecordingHeadline, RecordingReport, Runs, csv_tables,
};
use errp_sim::{PendingFile, create_dirs};
use errp_sweep::{ArenaPlot, GridPlot, RunPath};

use crate::cli::{InspectArgs, check_extension};
use crate::out::{out, outln};

/// The kind of `--figure`, checked before any work: one recording, a
/// `.png` or `.svg` name that is not an output directory, and not a file
/// this program did not write.
fn check_figure(args: &InspectArgs) -> Result<Option<FigureKind>> {
    if args.figure.is_some() && args.files.len() != 1 {
        bail!("--figure draws one recording; give one file");
    }
    let figure_kind = match &args.figure {
        Some(f) => Some(match f.extension().and_then(|e| e.to_str()) {
            Some("png") => FigureKind::Png,
            Some("svg") => FigureKind::Svg,
            _ => bail!(
                "--figure {}: the file name must end in .png or .svg",
                f.display()
            ),
        }),
        None => None,
    };
    if let Some(figure) = &args.figure {
        let same = |dir: &Path| {
            std::path::absolute(dir)
                .ok()
                .is_some_and(|d| std::path::absolute(figure).ok().is_some_and(|f| f == d))
        };
        for (flag, dir) in [("--csv", &args.csv), ("--parquet", &args.parquet)] {
            if let Some(dir) = dir.as_deref().filter(|d| same(d)) {
                bail!(
                    "--figure {} is also the {flag} directory {}: give the figure another path",
                    figure.display(),
                    dir.display()
                );
            }
        }
    }
    if let (Some(path), Some(kind)) = (&args.figure, figure_kind) {
        let (magic, what): (&[u8], &str) = match kind {
            FigureKind::Png => (b"\x89PNG", "a PNG image"),
            FigureKind::Svg => (b"<svg", "an SVG drawing"),
        };
        crate::save::check_ours(path, magic, what, "--figure")?;
    }
    Ok(figure_kind)
}

pub(crate) fn inspect(args: &InspectArgs) -> Result<()> {
    if args.scenario || args.provenance {
        if args.files.len() != 1 {
            bail!("--scenario and --provenance print one recording's; give one file");
        }
        let rec = Recording::open(&args.files[0])?;
        if args.scenario {
            out!("{}", rec.provenance.scenario_text)?;
        } else {
            let json = serde_json::to_string_pretty(&rec.provenance)
                .context("writing the provenance as JSON")?;
            outln!("{json}")?;
        }
        return Ok(());
    }
    for f in &args.files {
        check_extension(f, "rrd", "FILE")?;
    }
    if args.replay && args.files.len() != 1 {
        bail!("--replay replays one recording's runs; give one file");
    }
    let figure_kind = check_figure(args)?;
    let started = crate::commands::sweep::wall_clock();
    let recs: Vec<Recording> = args
        .files
        .iter()
        .map(Recording::open)
        .collect::<Result<_, _>>()?;
    if args.run == 0 || args.run > recs[0].n_runs().max(1) {
        bail!(
            "--run {}: {} holds runs 1 to {}",
            args.run,
            args.files[0].display(),
            recs[0].n_runs()
        );
    }
    // The figure is drawn and written to its temporary (made before any
    // work, so an unwritable path fails first) before the tables, and
    // renamed into place after them: a failure leaves neither.
    let figure = match (&args.figure, figure_kind) {
        (Some(path), Some(kind)) => {
            let (pending, mut file) = PendingFile::create(path).context("--figure")?;
            let bytes = draw(&recs[0], args.run - 1, kind)?;
            std::io::Write::write_all(&mut file, &bytes)
                .and_then(|()| file.sync_all())
                .with_context(|| format!("--figure: cannot write {}", path.display()))?;
            Some(pending)
        }
        _ => None,
    };
    let mut outputs = Vec::new();
    if let Some(dir) = &args.csv {
        outputs.push((dir.as_path(), TableFormat::Csv));
    }
    if let Some(dir) = &args.parquet {
        outputs.push((dir.as_path(), TableFormat::Parquet));
    }
    write_tables(&outputs, &args.files, &recs)?;
    if let Some(pending) = figure {
        pending.commit().context("--figure")?;
    }
    if recs.len() == 1 {
        out!("{}", RecordingReport(&recs[0]))?;
        if args.replay {
            replay(&recs[0])?;
        }
    } else {
        for r in &recs {
            outln!("{}", RecordingHeadline(r))?;
        }
        outln!()?;
        out!("{}", Comparison(&recs))?;
    }
    for (dir, format) in &outputs {
        outln!("Wrote the tables to {} ({})", dir.display(), format.name())?;
    }
    if let Some(path) = &args.figure {
        outln!("Wrote {}", path.display())?;
    }
    crate::out::errln!(
        "read {} recording(s) in {:.2} s",
        recs.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[derive(Clone, Copy)]
enum FigureKind {
    Png,
    Svg,
}

/// A format of the tidy tables.
#[derive(Clone, Copy)]
enum TableFormat {
    Csv,
    Parquet,
}

impl TableFormat {
    fn name(self) -> &'static str {
        match self {
            TableFormat::Csv => "CSV",
            TableFormat::Parquet => "Parquet",
        }
    }

    fn flag(self) -> &'static str {
        match self {
            TableFormat::Csv => "--csv",
            TableFormat::Parquet => "--parquet",
        }
    }

    fn extension(self) -> &'static str {
        match self {
            TableFormat::Csv => "csv",
            TableFormat::Parquet => "parquet",
        }
    }

    /// True if `head` (the file's first bytes) and `tail` (its last 64 KiB)
    /// are those of table `t` as errp writes it: a CSV file with the same
    /// header, or a Parquet file whose metadata names an errp table.
    fn ours(self, t: &CsvTable, head: &[u8], tail: &[u8]) -> bool {
        match self {
            TableFormat::Csv => {
                let header: Vec<&str> = t.columns.iter().map(|(n, _)| *n).collect();
                head.starts_with((header.join(",") + "\n").as_bytes())
            }
            TableFormat::Parquet => {
                let key = errp_sim::inspect::PARQUET_TABLE_KEY.as_bytes();
                head.starts_with(b"PAR1")
                    && tail.ends_with(b"PAR1")
                    && tail.windows(key.len()).any(|w| w == key)
            }
        }
    }

    fn bytes(self, t: &CsvTable) -> Result<Vec<u8>> {
        match self {
            TableFormat::Csv => Ok(t.to_csv().into_bytes()),
            TableFormat::Parquet => t
                .to_parquet()
                .map_err(|e| anyhow::anyhow!("--parquet: cannot encode {}: {e}", t.name)),
        }
    }
}

/// The first 4 KiB and the last 64 KiB of the regular file `path`, if it
/// is one and can be read.
fn head_and_tail(path: &Path) -> Option<(Vec<u8>, Vec<u8>)> {
    use std::io::{Read, Seek, SeekFrom};
    let mut file = errp_sim::open_regular(path).ok()?;
    let len = file.metadata().ok()?.len();
    let mut head = vec![0u8; 4096];
    let n = file.read(&mut head).ok()?;
    head.truncate(n);
    let from = len.saturating_sub(64 * 1024);
    file.seek(SeekFrom::Start(from)).ok()?;
    let mut tail = Vec::new();
    file.take(64 * 1024).read_to_end(&mut tail).ok()?;
    Some((head, tail))
}

/// Writes every table of every recording into each directory of `outputs`
/// in its format (a subdirectory per file when several). Existing files
/// are replaced only if they are tables of ours; every file is written to
/// its temporary and all are renamed into place together, and the
/// directories made are removed on failure.
fn write_tables(
    outputs: &[(&Path, TableFormat)],
    files: &[PathBuf],
    recs: &[Recording],
) -> Result<()> {
    if outputs.is_empty() {
        return Ok(());
    }
    let mut plan: Vec<(PathBuf, TableFormat, &Path, CsvTable)> = Vec::new();
    for &(dir, format) in outputs {
        for (f, r) in files.iter().zip(recs) {
            let base = if recs.len() == 1 {
                dir.to_path_buf()
            } else {
                dir.join(f.file_stem().unwrap_or_default())
            };
            for t in csv_tables(r) {
                let name = format!("{}.{}", t.name, format.extension());
                plan.push((base.join(name), format, dir, t));
            }
        }
    }
    for (path, format, dir, t) in &plan {
        if let Some((head, tail)) = head_and_tail(path) {
            if !head.is_empty() && !format.ours(t, &head, &tail) {
                bail!(
                    "{} {}: {} exists and is not a table errp wrote; errp replaces only its \
                     own files: move it away or give another directory",
                    format.flag(),
                    dir.display(),
                    path.display()
                );
            }
        } else if path.exists() {
            bail!(
                "{} {}: {} exists and is not a regular file",
                format.flag(),
                dir.display(),
                path.display()
            );
        }
    }
    let mut made = Vec::new();
    let result = (|| -> Result<()> {
        let mut pending = Vec::with_capacity(plan.len());
        for (path, format, _, t) in &plan {
            if let Some(parent) = path.parent() {
                made.push(create_dirs(parent).context(format.flag())?);
            }
            let bytes = format.bytes(t)?;
            let (file_pending, mut file) = PendingFile::create(path).context(format.flag())?;
            std::io::Write::write_all(&mut file, &bytes)
                .and_then(|()| file.sync_all())
                .with_context(|| format!("{}: cannot write {}", format.flag(), path.display()))?;
            pending.push(file_pending);
        }
        for p in pending {
            p.commit().context("the tables")?;
        }
        Ok(())
    })();
    if result.is_err() {
        for d in made.iter().rev() {
            d.remove();
        }
    }
    result
}

/// Every e-puck run's path (8 points a second, as the viewer draws the
/// trajectory) and detections, in cm, from the recording's frames.
fn epuck_paths(rec: &Recording, results: &[errp_sim::epuck::EpuckEpisodeResult]) -> Vec<RunPath> {
    let frames = errp_sim::record::schema::FramesView::or_empty(&rec.tables);
    let (runs_col, xs, ys) = (frames.run, frames.x_cm, frames.y_cm);
    let mut paths: Vec<RunPath> = results
        .iter()
        .map(|r| RunPath {
            points: Vec::new(),
            detections: r
                .detections
                .iter()
                .map(|d| [100.0 * d[0], 100.0 * d[1]])
                .collect(),
        })
        .collect();
    for (i, &run) in runs_col.iter().enumerate() {
        // 8 points a second, as the viewer draws the trajectory.
        if let Some(p) = usize::try_from(run).ok().and_then(|k| paths.get_mut(k))
            && (i % 8 == 0 || p.points.is_empty())
        {
            p.points.push([xs[i], ys[i]]);
        }
    }
    paths
}

/// The figure of `rec` with run `highlight` (from 0) drawn in full.
fn draw(rec: &Recording, highlight: usize, kind: FigureKind) -> Result<Vec<u8>> {
    let runs_title = |n: usize| {
        if n == 1 {
            String::new()
        } else {
            format!(", run {} of {n}", highlight + 1)
        }
    };
    let bytes = match &rec.runs {
        Runs::Epuck { scenario, results } => {
            let paths = epuck_paths(rec, results);
            let layout = &scenario.layout;
            let plot = ArenaPlot {
                title: format!(
                    "{}{}: {} detections",
                    scenario.name,
                    runs_title(results.len()),
                    results[highlight].detected_errors
                ),
                size_cm: 100.0 * scenario.arena.size_m,
                obstacles: scenario
                    .arena
                    .obstacles
                    .iter()
                    .map(|o| {
                        o.outline()
                            .into_iter()
                            .map(|(x, y)| [100.0 * x, 100.0 * y])
                            .collect()
                    })
                    .collect(),
                cities: layout
                    .goals()
                    .iter()
                    .map(|g| (g.name.clone(), [100.0 * g.x_m, 100.0 * g.y_m]))
                    .collect(),
                goal: scenario.episode.goal,
                runs: paths,
                highlight,
            };
            match kind {
                FigureKind::Png => errp_sweep::arena_png(&plot)?,
                FigureKind::Svg => errp_sweep::arena_svg(&plot)?.into_bytes(),
            }
        }
        Runs::Grid { scenario, results } => {
            let grid = errp_robot::Grid::paper();
            let mut visits = vec![0.0; grid.n_cells()];
            for r in results {
                for (v, &c) in visits.iter_mut().zip(&r.visits) {
                    *v += f64::from(c);
                }
            }
            let most = visits.iter().copied().fold(0.0, f64::max).max(1.0);
            visits.iter_mut().for_each(|v| *v /= most);
            let xy = |c: errp_robot::Cell| [c.x as f64, c.y as f64];
            let runs: Vec<RunPath> = results
                .iter()
                .map(|r| RunPath {
                    points: std::iter::once(xy(r.start))
                        .chain(r.steps.iter().map(|s| xy(s.to)))
                        .collect(),
                    detections: r
                        .steps
                        .iter()
                        .filter(|s| s.decoded_error)
                        .map(|s| {
                            let (a, b) = (xy(s.from), xy(s.to));
                            [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
                        })
                        .collect(),
                })
                .collect();
            let h = &results[highlight];
            let plot = GridPlot {
                title: format!("{}: visits{}", scenario.name, runs_title(results.len())),
                size: (grid.width, grid.height),
                visits,
                runs,
                highlight,
                start: xy(h.start),
                goal: xy(h.goal),
            };
            match kind {
                FigureKind::Png => errp_sweep::grid_png(&plot)?,
                FigureKind::Svg => errp_sweep::grid_svg(&plot)?.into_bytes(),
            }
        }
    };
    Ok(bytes)
}

/// Runs a live session's runs again with the decisions it applied, prints
/// their table and checks it against the recorded one.
fn replay(rec: &Recording) -> Result<()> {
    let replay = rec.replay_live().context("--replay")?;
    outln!()?;
    outln!("Replayed offline, each run decided by the decisions it applied:")?;
    match rec.runs {
        Runs::Grid { .. } => outln!("{}", errp_sim::grid::GridEpisodeHeader)?,
        Runs::Epuck { .. } => outln!("{}", errp_sim::epuck::EpuckRunHeader)?,
    }
    for row in &replay.replayed {
        outln!("{row}")?;
    }
    if let Some(k) = replay.first_difference() {
        let none = String::from("(none)");
        bail!(
            "--replay: run {} differs from the recording:\n  recorded: {}\n  replayed: {}",
            k + 1,
            replay.recorded.get(k).unwrap_or(&none).trim(),
            replay.replayed.get(k).unwrap_or(&none).trim()
        );
    }
    outln!(
        "the same per-run table as recorded ({} runs)",
        replay.replayed.len()
    )?;
    Ok(())
}
