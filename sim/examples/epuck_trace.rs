//! Prints the event log of one e-puck run, with the pose, target, p(error)
//! and the two most probable cities once a second.
//!
//! `cargo run -p errp_sim --example epuck_trace -- scenarios/mexico_to_pisa.toml [seed]`

use errp_sim::epuck::{EpuckObserver, WindowFrame, prepare_continuous_decoder, run_epuck_once};

struct Trace {
    names: Vec<String>,
    next_secs: f64,
}

impl EpuckObserver for Trace {
    fn on_window(&mut self, f: &WindowFrame) {
        if f.time_secs + 1e-9 < self.next_secs {
            return;
        }
        self.next_secs += 1.0;
        let mut order: Vec<usize> = (0..f.belief.len()).collect();
        order.sort_by(|&a, &b| f.belief[b].total_cmp(&f.belief[a]));
        println!(
            "{:7.2}  ({:5.1}, {:5.1}) cm {:6.1} deg  target {:<14} p(error) {:.2}  {} {:.3}, {} {:.3}",
            f.time_secs,
            100.0 * f.tracked.x_m,
            100.0 * f.tracked.y_m,
            f.tracked.heading_rad.to_degrees(),
            self.names[f.target],
            f.p_error,
            self.names[order[0]],
            f.belief[order[0]],
            self.names[order[1]],
            f.belief[order[1]],
        );
    }

    fn on_event(&mut self, time_secs: f64, text: &str, warn: bool) {
        println!("{time_secs:7.2}  {}{text}", if warn { "WARN " } else { "" });
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .map_or("scenarios/mexico_to_pisa.toml", String::as_str);
    let mut scenario =
        errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path.into()))?
            .into_epuck()
            .ok_or("not an e-puck scenario")?;
    if let Some(seed) = args.get(1) {
        scenario.seed = seed.parse()?;
    }
    let (decoder, _) = prepare_continuous_decoder(&scenario, |_| {})?;
    let mut trace = Trace {
        names: scenario
            .layout
            .names()
            .iter()
            .map(|s| s.to_string())
            .collect(),
        next_secs: 0.0,
    };
    let r = run_epuck_once(&scenario, &decoder, 0, &mut trace)?;
    println!("{r:#?}");
    Ok(())
}
