//! The e-puck recorder as an observer of runs, and the runs of a scenario recorded one after another.

#[allow(clippy::wildcard_imports, unused_imports)]
use super::*;

impl EpuckRunsObserver for EpuckRecorder {
    fn start_run(&mut self, k: usize, seed: u64) {
        let title = format!("run {}: {}", k + 1, self.run_title);
        self.next_run(&title, seed);
    }
}

impl EpuckObserver for EpuckRecorder {
    fn on_start(&mut self, start: &EpisodeStart) {
        self.tables.start = Some(*start);
    }

    fn on_errp(&mut self, time_secs: f64, onset_secs: f64, phase: usize) {
        let t = &mut self.tables;
        t.e_t.push(time_secs);
        t.e_onset.push(onset_secs);
        t.e_phase.push(phase as i64);
    }

    fn on_end(&mut self, time_secs: f64, committed: Option<usize>) {
        self.tables.end = Some((time_secs, committed));
    }

    fn on_physics(&mut self, f: &PhysicsFrame) {
        self.steps += 1;
        self.last_secs = f.time_secs;
        let t = &mut self.tables;
        t.f_t.push(f.time_secs);
        t.f_xy.push([f.pose.x_m, f.pose.y_m]);
        t.f_heading.push(f.pose.heading_rad.to_degrees());
        t.f_tracked.push([f.tracked.x_m, f.tracked.y_m]);
        t.f_phase.push(f.phase as i64);
        t.f_target.push(f.target as i64);
        if self.steps % TRAJECTORY_EVERY != 1 && self.steps > 1 {
            return;
        }
        self.at(f.time_secs);
        let p = f.pose;
        self.trajectory.push(cm(p.x_m, p.y_m));
        let r = self.rec.log(
            paths::ARENA_TRAJECTORY,
            &LineStrips2D::new([self.trajectory.clone()])
                .with_colors([Color::from_rgb(40, 90, 200)])
                .with_radii([0.6]),
        );
        self.keep(r);
        let r = self.rec.log(
            paths::ARENA_ROBOT,
            &Points2D::new([cm(p.x_m, p.y_m)])
                .with_radii([3.7])
                .with_colors([Color::from_rgb(30, 30, 30)]),
        );
        self.keep(r);
        let (s, c) = p.heading_rad.sin_cos();
        let r = self.rec.log(
            paths::ARENA_HEADING,
            &Arrows2D::from_vectors([[(8.0 * c) as f32, (8.0 * s) as f32]])
                .with_origins([cm(p.x_m, p.y_m)])
                .with_colors([Color::from_rgb(230, 120, 20)]),
        );
        self.keep(r);
    }

    fn on_window(&mut self, f: &WindowFrame) {
        let t = &mut self.tables;
        t.w_t.push(f.time_secs);
        t.w_p.push(f.p_error);
        t.w_evidence.push(f.evidence);
        t.w_detected.push(f.detected);
        t.w_step.push(f.step as i64);
        t.w_target.push(f.target as i64);
        let goals = self.layout.goals().len();
        // No belief (an agent drives): NaN in the table, the cities grey.
        if f.belief.len() == goals {
            t.w_belief.extend_from_slice(&f.belief);
        } else {
            t.w_belief.extend(std::iter::repeat_n(f64::NAN, goals));
        }
        self.at(f.time_secs);
        let colours: Vec<Color> = if f.belief.len() == goals {
            f.belief.iter().map(|&p| belief_colour(p)).collect()
        } else {
            vec![belief_colour(0.0); goals]
        };
        let r = self.rec.log(
            paths::ARENA_GOALS,
            &Points2D::new(self.layout.goals().iter().map(|g| cm(g.x_m, g.y_m)))
                .with_radii([5.0])
                .with_colors(colours),
        );
        self.keep(r);
        // The city the robot heads for: an orange ring.
        let t = &self.layout.goals()[f.target];
        let ring: Vec<[f32; 2]> = (0..=32)
            .map(|k| {
                let a = k as f64 / 32.0 * std::f64::consts::TAU;
                cm(t.x_m + 0.075 * a.cos(), t.y_m + 0.075 * a.sin())
            })
            .collect();
        let r = self.rec.log(
            paths::ARENA_TARGET,
            &LineStrips2D::new([ring])
                .with_colors([Color::from_rgb(230, 120, 20)])
                .with_radii([0.7]),
        );
        self.keep(r);
        for (i, &p) in f.belief.iter().enumerate() {
            let path = paths::belief_city(&self.layout.goals()[i].name);
            let r = self.rec.log(path, &Scalars::single(p));
            self.keep(r);
        }
        let r = self.rec.log(paths::P_ERROR, &Scalars::single(f.p_error));
        self.keep(r);
        // What the detector compared with T_e (the smoothed p(error)).
        let r = self.rec.log(paths::EVIDENCE, &Scalars::single(f.evidence));
        self.keep(r);
        let r = self.rec.log(paths::THRESHOLD, &Scalars::single(self.t_e));
        self.keep(r);
        if f.detected {
            self.detections.push(cm(f.tracked.x_m, f.tracked.y_m));
            let r = self.rec.log(
                paths::ARENA_DETECTIONS,
                &Points2D::new(self.detections.clone())
                    .with_radii([2.5])
                    .with_colors([Color::from_rgb(220, 30, 30)]),
            );
            self.keep(r);
        }
        // The EEG of the last 62.5 ms, sample by sample.
        let n = f.fcz_cz[0].len();
        let fs = n as f64 / crate::epuck::plant::WINDOW_STEP_SECS;
        for (name, samples) in ["FCz", "Cz"].iter().zip(&f.fcz_cz) {
            let path = eeg_channel(name);
            for (k, v) in samples.iter().enumerate() {
                self.at(f.time_secs - (n - 1 - k) as f64 / fs);
                let r = self.rec.log(path.as_str(), &Scalars::single(*v));
                self.keep(r);
            }
        }
    }

    fn on_event(&mut self, time_secs: f64, text: &str, warn: bool) {
        let t = &mut self.tables;
        t.v_t.push(time_secs);
        t.v_warn.push(warn);
        t.v_text.push(text.to_string());
        self.at(time_secs);
        let r = self.rec.log(
            paths::LOG,
            &TextLog::new(text).with_level(if warn { "WARN" } else { "INFO" }),
        );
        self.keep(r);
    }
}

/// The runs of `scenario` one after another, each recorded into `file` as
/// `errp run --save` records them, with `provenance` (its `runs` set here).
pub fn record_epuck_runs(
    file: &RrdFile,
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    provenance: &Provenance,
) -> Result<Vec<EpuckEpisodeResult>> {
    record_epuck_runs_with(
        file,
        scenario,
        decoder,
        provenance,
        scenario.runs,
        None,
        &|_| {},
    )
}

/// [`record_epuck_runs`] of `runs` runs, with `window_decoder` (a decoder
/// of the caller's own, as in [`crate::epuck::run_epuck_episode_with`]) in
/// place of the calibrated SVM when given; `on_run(k)` is called after run
/// `k` (from 0) is recorded.
pub fn record_epuck_runs_with(
    file: &RrdFile,
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    provenance: &Provenance,
    runs: usize,
    window_decoder: Option<WindowDecoder<'_>>,
    on_run: &(dyn Fn(usize) + Sync),
) -> Result<Vec<EpuckEpisodeResult>> {
    provenance.write(file, runs)?;
    let t_e = decoder.detector_t_e(&scenario.params, window_decoder.is_some());
    let mut recorder = EpuckRecorder::new(file, &scenario.arena, &scenario.layout, t_e)?;
    recorder.run_title = format!(
        "the user wants {} ({})",
        scenario.layout.goals()[scenario.episode.goal].name,
        scenario.decoder_text()
    );
    let out = run_epuck_runs(
        scenario,
        decoder,
        runs,
        window_decoder,
        &mut recorder,
        on_run,
    )?;
    recorder.finish()?;
    Ok(out)
}
