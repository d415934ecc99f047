//! `outliers`: a few gross reading errors, screened row by row (never a
//! term of a model: the rows are set aside).

use super::spec::{Deployment, EffectSpec, Kind, Needs, PlotAxes, XAxis, YAxis};

pub(super) const SPEC: EffectSpec = EffectSpec {
    name: "outliers",
    physics: "a few gross reading errors",
    quoted_in: "count",
    parameters: &[],
    kind: Kind::Rows,
    needs: Needs::Nothing,
    deployment: Deployment::SetAside,
    fused: false,
    plausible: &[],
    description: "gross reading errors",
    plot: PlotAxes {
        x: XAxis::Line,
        y: YAxis::LargestResidualSigma,
    },
    realistic: |_| Vec::new(),
    aliases: &[],
};
