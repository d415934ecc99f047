//! [`identify_fused`]: the fused identification as a user calls it. The
//! gross-error screen ([`crate::fusion::ScreenOptions`], `screen.rs`)
//! decides which records enter the fit (`estimate.rs`); an implausible or
//! unexplained fit is handed to the likely-cause search (`causes.rs`).

use crate::error::IdentError;
use crate::fusion::causes::likely_causes;
use crate::fusion::estimate::fit_masked;
use crate::fusion::model::FusedModel;
use crate::fusion::options::FusionOptions;
use crate::fusion::result::Fusion;
use crate::fusion::screen::screened_fit;
use crate::fusion::source::Source;

/// Fits the parameters of `model` and every source's nuisance to all
/// sources at once (see the module docs): the gross-error screen of
/// `options.screen` decides which records enter the fit, the fit is judged
/// (redundancy, adequacy, plausibility) and an implausible or unexplained
/// one is searched for its likely cause.
///
/// # Example
/// ```
/// use tricept_engine::fusion::{FusedModel, FusionOptions, Source, identify_fused};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// // The internal data alone, head in the model: the head is invisible.
/// let model = FusedModel::new(m.clone(), set, &[], true).unwrap();
/// let fit = identify_fused(&model, &[Source::internal(&data, m.sensors.logged_sigma())],
///     &FusionOptions::for_machine(&m)).unwrap();
/// assert_eq!(fit.report.union.rank, 14);
/// assert!(fit.report.union.fixed.contains(&"tool_length_mm".to_string()));
/// assert!(fit.sources[0].checkable && fit.rejected.is_empty());
/// ```
pub fn identify_fused(
    model: &FusedModel,
    sources: &[Source],
    options: &FusionOptions,
) -> Result<Fusion, IdentError> {
    if sources.is_empty() {
        return Err(IdentError::Invalid("no data source".into()));
    }
    for (s, a) in sources.iter().enumerate() {
        if sources[..s].iter().any(|b| b.label() == a.label()) {
            return Err(IdentError::Invalid(format!(
                "two sources are labelled `{}`: label them apart (Source::with_label)",
                a.label()
            )));
        }
    }
    let (active, mut fit) = match &options.screen {
        Some(screen) => screened_fit(model, sources, options, screen)?,
        None => {
            let active: Vec<Vec<bool>> = sources.iter().map(|s| vec![true; s.records()]).collect();
            let fit = fit_masked(model, sources, &active, options)?;
            (active, fit)
        }
    };
    if options.likely_causes && fit.needs_causes() {
        let causes = likely_causes(model, sources, &active, options, &fit);
        fit.add_causes(causes);
    }
    Ok(fit)
}
