//! errp_lsl against a real liblsl: the one in pylsl's wheel (or
//! `ERRP_LIBLSL`), when this machine has one. CI's LSL step runs these with
//! `ERRP_LIBLSL` set; where no liblsl is found they say so and pass.
//!
//! Each stream is named for this process, and the session is isolated
//! (`LSLAPICFG` in CI), so that another program's streams are never found.

use errp_lsl::{Element, Format, Lsl, StreamSpec};

/// liblsl, if this machine has one; with `ERRP_LIBLSL` set (as in CI),
/// the one it names, or the test fails.
fn lsl() -> Option<Lsl> {
    match Lsl::find(None) {
        Ok(l) => Some(l),
        Err(e) if std::env::var_os("ERRP_LIBLSL").is_some() => {
            panic!("ERRP_LIBLSL is set but liblsl does not load: {e}")
        }
        Err(e) => {
            eprintln!("skipped: {e}");
            None
        }
    }
}

fn spec(name: &str, channels: u32, format: Format) -> StreamSpec {
    StreamSpec {
        name: name.into(),
        kind: "Test".into(),
        channels,
        rate_hz: 0.0,
        format,
        source_id: format!("{name}-source"),
        desc: vec![Element::node(
            "errp",
            vec![Element::leaf("contract", 1), Element::leaf("speed", 2.5)],
        )],
    }
}

#[test]
fn an_outlet_is_found_and_read_with_its_shape_values_and_stamps() {
    let Some(lsl) = lsl() else { return };
    assert!(lsl.version() >= errp_lsl::MIN_VERSION);
    let t0 = lsl.clock();
    assert!(lsl.clock() >= t0, "the clock runs forward");
    let name = format!("errp-lsl-test-{}", std::process::id());
    let outlet = lsl.outlet(&spec(&name, 2, Format::Double64)).unwrap();
    assert_eq!(outlet.name(), name);
    assert!(!outlet.wait_for_consumers(0.05), "nobody reads it yet");
    let found = lsl
        .resolve("source_id", &format!("{name}-source"), 5.0)
        .unwrap();
    assert_eq!(found.len(), 1, "one stream of that source");
    let f = &found[0];
    assert_eq!(f.name(), name);
    assert_eq!(f.kind(), "Test");
    assert_eq!(f.source_id(), format!("{name}-source"));
    assert_eq!(
        (f.channels(), f.rate_hz(), f.format()),
        (2, 0.0, Some(Format::Double64))
    );
    let inlet = f.open(5.0).unwrap();
    assert_eq!(inlet.channels(), 2);
    assert!(outlet.wait_for_consumers(5.0), "the inlet reads it");
    let mut buf = [0.0; 2];
    assert_eq!(inlet.pull(&mut buf, 0.0).unwrap(), None, "nothing sent yet");
    // Values go out as float32 and come back as doubles: exact for these.
    let stamp = lsl.clock();
    for k in 0..3 {
        outlet
            .push(&[k as f32, 0.25], stamp + f64::from(k))
            .unwrap();
    }
    for k in 0..3 {
        let got = inlet.pull(&mut buf, 5.0).unwrap();
        assert_eq!(got, Some(stamp + f64::from(k)));
        assert_eq!(buf, [f64::from(k), 0.25]);
    }
    // The wrong shape of sample is refused before liblsl sees it.
    assert!(outlet.push(&[1.0], stamp).is_err());
    assert!(outlet.push_text("x", stamp).is_err());
    assert!(inlet.pull(&mut [0.0; 3], 0.0).is_err());
}

#[test]
fn a_text_stream_carries_its_strings_and_nothing_else_is_found() {
    let Some(lsl) = lsl() else { return };
    let name = format!("errp-lsl-text-{}", std::process::id());
    let outlet = lsl.outlet(&spec(&name, 1, Format::String)).unwrap();
    outlet
        .push_text("{\"event\":\"end\"}", lsl.clock())
        .unwrap();
    assert!(
        outlet.push(&[1.0], lsl.clock()).is_err(),
        "numbers on a text stream"
    );
    assert!(outlet.push_text("a\0b", lsl.clock()).is_err(), "a NUL");
    let none = lsl
        .resolve("name", &format!("{name}-nobody-publishes-this"), 0.2)
        .unwrap();
    assert!(none.is_empty());
}

#[test]
fn a_truncated_copy_of_liblsl_is_refused_not_mapped() {
    let Some(lsl) = lsl() else { return };
    // (The system's copy is loaded by name: nothing to cut.)
    let Ok(bytes) = std::fs::read(lsl.path()) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("errp-lsl-cut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cut = dir.join("liblsl.so");
    for keep in [bytes.len() / 2, bytes.len() * 9 / 10] {
        std::fs::write(&cut, &bytes[..keep]).unwrap();
        let e = Lsl::open(&cut).unwrap_err().to_string();
        assert!(e.contains("truncated: the file has"), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
