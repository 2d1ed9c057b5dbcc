//! Damaged recordings: whatever the bytes say, `Recording::open` reads the
//! file or refuses it with an error naming it; it never aborts on a size
//! it was told, nor panics.

use errp_sim::grid::DecoderChoice;
use errp_sim::inspect::Recording;
use errp_sim::{
    Names, RunOptions, RunProvenance, ScenarioInput, ScenarioSource, TaskKind, run_scenario,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use re_protos::external::prost::Message as _;
use re_protos::log_msg::v1alpha1::ArrowMsg;

const NAMES: Names = Names::PYTHON;

/// The built-in grid scenario recorded (oracle decoder), as bytes.
fn recording(dir: &std::path::Path) -> Vec<u8> {
    let path = dir.join("good.rrd");
    let input = ScenarioInput {
        decoder: Some(DecoderChoice::Oracle),
        ..ScenarioInput::new(ScenarioSource::built_in(TaskKind::Grid))
    };
    let options = RunOptions {
        save: Some(&path),
        provenance: &RunProvenance::default(),
        names: &NAMES,
    };
    run_scenario(input.load(&NAMES).unwrap(), options, &()).unwrap();
    std::fs::read(&path).unwrap()
}

/// The messages of a one-stream file: (offset of the header, kind, length).
fn messages(bytes: &[u8]) -> Vec<(usize, u64, usize)> {
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    let mut at = 12;
    let mut out = Vec::new();
    loop {
        let (kind, len) = (word(at), word(at + 8) as usize);
        out.push((at, kind, len));
        at += 16 + len;
        if kind == 0 {
            return out;
        }
    }
}

/// Opens `bytes` as a recording; `Some(error)` if refused.
fn open(dir: &std::path::Path, bytes: &[u8]) -> Option<String> {
    let f = dir.join("x.rrd");
    std::fs::write(&f, bytes).unwrap();
    match Recording::open(&f) {
        Ok(_) => None,
        Err(e) => {
            let e = e.to_string();
            assert!(e.contains("x.rrd"), "{e}");
            Some(e)
        }
    }
}

#[test]
fn stated_sizes_are_checked_and_no_damage_aborts_or_panics() {
    let dir = std::env::temp_dir().join(format!("errp-damaged-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = recording(&dir);
    assert_eq!(open(&dir, &good), None);
    let msgs = messages(&good);
    assert_eq!(
        msgs.last().unwrap().0 + 16 + msgs.last().unwrap().2 + 32,
        good.len()
    );

    // Every message length made huge: the decoder would allocate it.
    for &(at, _, _) in &msgs {
        let mut b = good.clone();
        b[at + 15] = 0x40;
        let e = open(&dir, &b).expect("a huge length is refused");
        assert!(
            e.contains(&format!("message at byte {at} says it is")),
            "{e}"
        );
    }
    // A stream footer claiming 2^31 entries.
    let mut b = good.clone();
    *b.last_mut().unwrap() ^= 0x80;
    let e = open(&dir, &b).expect("a footer of many entries is refused");
    assert!(e.contains("stream footer"), "{e}");
    // Every Arrow message stating a huge uncompressed size.
    let mut arrow = 0;
    for &(at, kind, len) in &msgs {
        if kind != 2 {
            continue;
        }
        arrow += 1;
        let mut msg = ArrowMsg::decode(&good[at + 16..at + 16 + len]).unwrap();
        msg.uncompressed_size = 1 << 50;
        let payload = msg.encode_to_vec();
        let mut b = good[..at + 8].to_vec();
        b.extend((payload.len() as u64).to_le_bytes());
        b.extend(&payload);
        b.extend(&good[at + 16 + len..]);
        let e = open(&dir, &b).expect("a huge uncompressed size is refused");
        assert!(e.contains("more than they can"), "{e}");
    }
    assert!(arrow >= 5, "{arrow} Arrow messages");

    // Seeded single-bit flips anywhere: read or refused, and many refused.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut refused = 0;
    for _ in 0..600 {
        let mut b = good.clone();
        let at = rng.random_range(0..b.len());
        b[at] ^= 1 << rng.random_range(0..8);
        refused += usize::from(open(&dir, &b).is_some());
    }
    assert!(refused > 100, "{refused} of 600 flips refused");
    let _ = std::fs::remove_dir_all(&dir);
}
