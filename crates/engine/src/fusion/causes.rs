//! Why a fused fit is implausible, or does not explain an external source:
//! each usual mistake is undone in turn and the data fitted again, as
//! [`crate::suspects::likely_causes`] does for the UP limb's data; a mistake whose
//! undoing makes the fit converge, explain the source and leave every
//! estimate plausible is named, with the fit it gives.
//!
//! The mistakes tried, for each tracker whose target is stated
//! (`--tracker-target tip` or `X,Y,Z`):
//! - **the offset's sign**: a non-zero offset refitted with its sign
//!   flipped;
//! - **the target mode**: the target refitted as free (its offset then
//!   comes out of the data; the tool tip is then not calibrated, but a
//!   target that is not where it is stated, or a tool that is not the
//!   internal data's, shows as a plausible fit with the offset it finds);
//!
//! and for every external source:
//! - **another machine or tool**: the source fitted alone (module and head
//!   free, no internal data). A source that is checkable, explained and
//!   plausible on its own but not with the internal data describes another
//!   machine than they do (another machine's or tool's file, a tracker moved
//!   without a new `setup`, another thermal state).
//!
//! Each trial is a plain fit of the records the screen kept (no screen, no
//! further search).

use crate::fusion::estimate::fit_masked;
use crate::fusion::model::FusedModel;
use crate::fusion::options::FusionOptions;
use crate::fusion::result::{Fusion, FusionCause};
use crate::fusion::source::{Source, SourceKind, TrackerTarget};

/// Whether source `s` of the trial fit `f` is explained, checkable and the
/// fit converged and plausible.
fn passes(f: &Fusion, s: usize) -> bool {
    f.converged
        && f.implausible.is_empty()
        && f.sources
            .get(s)
            .is_some_and(|x| x.checkable && x.explained())
}

/// The likely causes (see the module docs), most specific first.
pub(crate) fn likely_causes(
    model: &FusedModel,
    sources: &[Source],
    active: &[Vec<bool>],
    options: &FusionOptions,
    fit: &Fusion,
) -> Vec<FusionCause> {
    let mut trial_options = options.clone();
    trial_options.screen = None;
    trial_options.likely_causes = false;
    let refit = |trial: &[Source], masks: &[Vec<bool>]| -> Option<Fusion> {
        fit_masked(model, trial, masks, &trial_options).ok()
    };
    let mut found = Vec::new();
    for (s, source) in sources.iter().enumerate() {
        if source.kind() == SourceKind::Internal {
            continue;
        }
        let file = source.file();
        if let Some(TrackerTarget::Known {
            offset_mm,
            sigma_um,
        }) = source.tracker_target()
        {
            let with = |target: TrackerTarget| -> Option<Fusion> {
                let mut trial: Vec<Source> = Vec::with_capacity(sources.len());
                for (i, x) in sources.iter().enumerate() {
                    trial.push(if i == s {
                        x.with_tracker_target(target)?
                    } else {
                        x.clone()
                    });
                }
                refit(&trial, active)
            };
            if offset_mm.iter().any(|v| *v != 0.0) {
                let flipped = offset_mm.map(|v| -v);
                if let Some(f) = with(TrackerTarget::Known {
                    offset_mm: flipped,
                    sigma_um,
                })
                .filter(|f| passes(f, s))
                {
                    found.push(FusionCause {
                        source: source.label().to_string(),
                        mistake: "target-sign",
                        description: format!(
                            "{file}: the target offset's sign is wrong: stated {}, the data fit with the tracker target (tracker_target) {} (chi2/dof {:.2}, every estimate plausible)",
                            triple(&offset_mm),
                            triple(&flipped),
                            f.sources[s].reduced_chi_square
                        ),
                        chi2_per_dof: f.sources[s].reduced_chi_square,
                    });
                }
            }
            if let Some(f) = with(TrackerTarget::Free).filter(|f| passes(f, s)) {
                let o = &f.sources[s].nuisance;
                let offset = [o[0], o[1], o[2]];
                let size = offset.iter().map(|v| v * v).sum::<f64>().sqrt();
                found.push(FusionCause {
                    source: source.label().to_string(),
                    mistake: "target-mode",
                    description: format!(
                        "{file}: the tracker target is not where tracker_target says (stated {}), or the tool is not the internal data's: with the target free the data put it at ({:.3}, {:.3}, {:.3}) mm from the nominal tool tip ({size:.3} mm; spindle frame at zero head angles) and every estimate is plausible (chi2/dof {:.2}); measure the target's offset from the tip and state it as tracker_target X,Y,Z",
                        triple(&offset_mm),
                        offset[0],
                        offset[1],
                        offset[2],
                        f.sources[s].reduced_chi_square
                    ),
                    chi2_per_dof: f.sources[s].reduced_chi_square,
                });
            }
        }
        let alone = [source.clone()];
        if let Some(f) = refit(&alone, &active[s..=s]).filter(|f| passes(f, 0)) {
            let original = &fit.sources[s];
            if !(original.explained() && fit.implausible.is_empty()) {
                found.push(FusionCause {
                    source: source.label().to_string(),
                    mistake: "another-machine",
                    description: format!(
                        "{file} alone fits a machine (chi2/dof {:.2}, every estimate plausible) but not together with the internal data: they describe different machines (a file of another machine or tool, a tracker moved without a new `setup`, or another thermal state)",
                        f.sources[0].reduced_chi_square
                    ),
                    chi2_per_dof: f.sources[0].reduced_chi_square,
                });
            }
        }
    }
    found
}

/// `X,Y,Z` as `--tracker-target` takes it.
fn triple(v: &[f64; 3]) -> String {
    format!("{},{},{}", v[0] + 0.0, v[1] + 0.0, v[2] + 0.0)
}
