//! One module per subcommand.

pub(crate) mod calibrate;
pub(crate) mod fit;
#[cfg(feature = "rerun")]
pub(crate) mod inspect;
pub(crate) mod realism;
pub(crate) mod run;
pub(crate) mod stream;
pub(crate) mod sweep;
pub(crate) mod table1;

/// The simulated users of `errp table1` and `errp fit grid`: the
/// `[realism]` table of the scenario file at `path` (the ideal user if it
/// has none), or the shipped scenarios' user, [`errp_bci::Realism::published`].
pub(crate) fn user_realism(path: Option<&std::path::Path>) -> anyhow::Result<errp_bci::Realism> {
    Ok(match path {
        Some(path) => load(path)?.realism().clone(),
        None => errp_bci::Realism::published(),
    })
}

/// The scenario file at `path`, as it is written: every command loads its
/// scenarios as an [`errp_sim::ScenarioInput`].
pub(crate) fn load(path: &std::path::Path) -> anyhow::Result<errp_sim::AnyScenario> {
    let input = errp_sim::ScenarioInput::new(errp_sim::ScenarioSource::File(path.to_path_buf()));
    Ok(input.load(&errp_sim::Names::CLI)?.scenario)
}

/// The command line as it was given, for a result's provenance: an
/// argument that is not UTF-8 (a file name, say) is kept with U+FFFD in
/// place of its bad bytes, never a panic.
pub(crate) fn command_line() -> Vec<String> {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}
