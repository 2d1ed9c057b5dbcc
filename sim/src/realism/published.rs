//! The published figures `errp realism` sets the simulated user beside,
//! each with its source. A statistic we measure but for which no published
//! figure was found says so (its source is `None`) rather than borrow one.

/// Where a published figure comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Source {
    /// Authors, year, venue.
    pub cite: &'static str,
    /// DOI, where it has one.
    pub doi: &'static str,
}

/// One published statistic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Published {
    /// The name of the measurement it is set beside.
    pub key: &'static str,
    /// What it is, in words.
    pub what: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// The published value (the middle of the range, or the one value).
    pub value: f64,
    /// The published range, where the sources give one.
    pub range: Option<(f64, f64)>,
    /// Where it comes from; `None`: no published figure was found, and the
    /// row shows our value alone.
    pub source: Option<Source>,
}

const CHAVARRIAGA_2010: &str = "Chavarriaga & Millan 2010, IEEE TNSRE 18:381 (75.8 %); \
                                Ferrez & Millan 2008, IEEE TBME 55:923 (79.2 %)";

/// Every row of `errp realism`, in order.
pub static PUBLISHED: &[Published] = &[
    Published {
        key: "aperiodic_exponent",
        what: "background: 1/f exponent at Cz, 2-40 Hz",
        unit: "",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "alpha_peak_hz",
        what: "background: alpha peak at Oz",
        unit: "Hz",
        value: 10.3,
        range: None,
        source: Some(Source {
            cite: "Haegens et al. 2014, NeuroImage 92:46 (mean over 51 people)",
            doi: "10.1016/j.neuroimage.2014.01.049",
        }),
    },
    Published {
        key: "amplitude_uv",
        what: "background: SD per channel, 1-40 Hz (median)",
        unit: "uV",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "kurtosis",
        what: "background: excess kurtosis, 1-40 Hz (mean)",
        unit: "",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "block_sd_spread",
        what: "background: spread of 10 s blocks' SD at Cz",
        unit: "%",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "errp_negative_ms",
        what: "ErrP at FCz: negative peak latency",
        unit: "ms",
        value: 250.0,
        range: None,
        source: Some(Source {
            cite: "Ferrez & Millan 2008, IEEE TBME 55:923, as Fidencio et al. 2024 simulate it",
            doi: "10.3389/fnhum.2024.1390714",
        }),
    },
    Published {
        key: "errp_negative_uv",
        what: "ErrP at FCz: negative peak",
        unit: "uV",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "errp_positive_ms",
        what: "ErrP at FCz: positive peak latency",
        unit: "ms",
        value: 320.0,
        range: None,
        source: Some(Source {
            cite: "Ferrez & Millan 2008, IEEE TBME 55:923, as Fidencio et al. 2024 simulate it",
            doi: "10.3389/fnhum.2024.1390714",
        }),
    },
    Published {
        key: "errp_positive_uv",
        what: "ErrP at FCz: positive peak",
        unit: "uV",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "latency_jitter_ms",
        what: "ErrP: single-trial latency SD",
        unit: "ms",
        value: 19.0,
        // SEREEGA's 20 % six-sigma deviation: an SD of 6.7 % of the
        // N250's and the P320's latencies.
        range: Some((16.7, 21.3)),
        source: Some(Source {
            cite: "Fidencio et al. 2024, Front. Hum. Neurosci. 18:1390714 (simulation)",
            doi: "10.3389/fnhum.2024.1390714",
        }),
    },
    Published {
        key: "blinks_per_min",
        what: "blinks per minute (the model's rate)",
        unit: "",
        value: 14.5,
        range: Some((8.0, 21.0)),
        source: Some(Source {
            cite: "Optom. Vis. Sci. 2001, 78:712 (primary gaze, 8.0-21.0 a minute)",
            doi: "10.1097/00006324-200110000-00011",
        }),
    },
    Published {
        key: "discrete_error_class",
        what: "discrete decoder: error class detected",
        unit: "%",
        value: 77.5,
        range: Some((75.8, 79.2)),
        source: Some(Source {
            cite: CHAVARRIAGA_2010,
            doi: "10.1109/TNSRE.2010.2053387",
        }),
    },
    Published {
        key: "discrete_correct_class",
        what: "discrete decoder: correct class detected",
        unit: "%",
        value: 73.35,
        range: Some((63.2, 83.5)),
        source: Some(Source {
            cite: "Chavarriaga & Millan 2010, IEEE TNSRE 18:381 (63.2 %); \
                   Ferrez & Millan 2008, IEEE TBME 55:923 (83.5 %)",
            doi: "10.1109/TNSRE.2010.2053387",
        }),
    },
    Published {
        key: "binary_channel_bits",
        what: "discrete decoder: information in its class rates",
        unit: "bits",
        value: 0.21,
        range: Some((0.11, 0.31)),
        source: Some(Source {
            cite: "the class rates above as a binary channel at equal priors: \
                   Chavarriaga & Millan 2010 (0.11), Ferrez & Millan 2008 (0.31)",
            doi: "10.1109/TNSRE.2010.2053387",
        }),
    },
    Published {
        key: "information_bits",
        what: "discrete decoder: information in p(error)",
        unit: "bits",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "calibration_minus_online",
        what: "grid: calibration (cross-validated) minus online",
        unit: "points",
        value: f64::NAN,
        range: None,
        source: None,
    },
    Published {
        key: "continuous_tpr",
        what: "e-puck detector: ErrPs detected (per trial)",
        unit: "%",
        value: 70.0,
        range: None,
        source: Some(Source {
            cite: "Lopes-Dias et al. 2019, Sci. Rep. 9:17596",
            doi: "10.1038/s41598-019-54109-x",
        }),
    },
    Published {
        key: "continuous_tnr",
        what: "e-puck detector: correct trials without a false alarm",
        unit: "%",
        value: 86.8,
        range: None,
        source: Some(Source {
            cite: "Lopes-Dias et al. 2019, Sci. Rep. 9:17596",
            doi: "10.1038/s41598-019-54109-x",
        }),
    },
];
