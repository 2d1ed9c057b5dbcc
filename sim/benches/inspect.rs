//! Speed of reading recordings back: `Recording::open` on a 10-run
//! Mexico-to-Pisa recording made by `errp run --save` (decode every chunk,
//! check it, recompute every run from its tables), and the tidy tables
//! built from it, as CSV text and as Parquet. Per run = the median / 10.
//! Run with `cargo bench -p errp_sim --bench inspect`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use divan::{Bencher, black_box};
use errp_sim::epuck::{epuck_recording, prepare_continuous_decoder, record_epuck_runs};
use errp_sim::inspect::{Recording, csv_tables};
use errp_sim::record::data::Provenance;

fn main() {
    divan::main();
    if let Some(path) = FILE.get() {
        let _ = std::fs::remove_file(path);
    }
}

/// Runs in the recording.
const RUNS: usize = 10;

/// The recording, made once in the temporary directory and removed at the
/// end.
static FILE: OnceLock<PathBuf> = OnceLock::new();

fn recording() -> &'static Path {
    FILE.get_or_init(make_recording)
}

fn make_recording() -> PathBuf {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/mexico_to_pisa.toml"
    );
    let mut s =
        errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path.into()))
            .unwrap()
            .into_epuck()
            .unwrap();
    s.runs = RUNS;
    let (d, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let out = std::env::temp_dir().join(format!("errp-bench-inspect-{}.rrd", std::process::id()));
    let file = epuck_recording(&out).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let p = Provenance::new(errp_sim::TaskKind::Epuck, &s.name, text, s.seed);
    record_epuck_runs(&file, &s, &d, &p).unwrap();
    file.finish().unwrap();
    let mb = std::fs::metadata(&out).unwrap().len() as f64 / 1e6;
    eprintln!(
        "inspect bench: {RUNS} runs, {mb:.1} MB at {}",
        out.display()
    );
    out
}

/// Decode, check and recompute the runs of the 10-run recording.
#[divan::bench(sample_count = 10, sample_size = 1)]
fn open_ten_runs(bencher: Bencher) {
    let path = recording();
    bencher.bench_local(|| black_box(Recording::open(path).unwrap()));
}

/// Its tidy tables as CSV text (what `--csv` writes).
#[divan::bench(sample_count = 10, sample_size = 1)]
fn tables_as_csv(bencher: Bencher) {
    let rec = Recording::open(recording()).unwrap();
    bencher.bench_local(|| {
        black_box(
            csv_tables(&rec)
                .iter()
                .map(|t| t.to_csv().len())
                .sum::<usize>(),
        )
    });
}

/// Its tidy tables as Parquet (what `--parquet` writes).
#[divan::bench(sample_count = 10, sample_size = 1)]
fn tables_as_parquet(bencher: Bencher) {
    let rec = Recording::open(recording()).unwrap();
    bencher.bench_local(|| {
        black_box(
            csv_tables(&rec)
                .iter()
                .map(|t| t.to_parquet().unwrap().len())
                .sum::<usize>(),
        )
    });
}
