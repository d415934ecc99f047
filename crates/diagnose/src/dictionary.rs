//! The generic dictionary: every group of generic terms the campaign
//! supports ([`crate::terms::Frame::generic_groups`]), the ball-screw
//! period scan, and the linear screen that ranks them at the current fit.
//!
//! **Period scan.** Periods from `period_range_mm` (default 4 to 50 mm:
//! standard screw leads; above about a fifth of the stroke a sinusoid looks
//! like a polynomial), on a grid uniform in frequency with step
//! `1 / (oversampling L)`, `L` the largest leg stroke of the campaign. Every
//! grid period counts in the multiplicity (Bonferroni over every period
//! tried: with the textbook "independent frequencies" `L (f_max - f_min)`
//! the scan raised false alarms on clean data). The best grid period is
//! refined by golden-section search of the score within one grid step;
//! its standard deviation follows from the curvature of the score,
//! `sd(f) = sqrt(2 s2 / -S''(f))`.
//!
//! **Screen.** Each group's score `S` (the linearised drop of chi-square,
//! [`crate::linear`]) is tested against chi-square with its rank as degrees
//! of freedom, after dividing by the residual variance the model with the
//! group would leave (never below the stated noise, `s2 >= 1`), and the
//! p-value is multiplied by the dictionary's multiplicity.

use tricept_data::Dataset;
use tricept_model::effects::GenericFamily;

use crate::evidence::Reference;
use crate::linear::Linearisation;
use crate::options::DictionaryOptions;
use crate::terms::{Frame, GenericTerm, Term};

/// A group of the dictionary scored at a fit.
#[derive(Debug, Clone)]
pub(crate) struct Scored {
    /// The group (with its refined period for `leg-periodic`).
    pub(crate) term: GenericTerm,
    /// Linearised drop of chi-square.
    pub(crate) explained: f64,
    /// Its degrees of freedom.
    pub(crate) rank: usize,
    /// p-value times the multiplicity (at most 1).
    pub(crate) p_adjusted: f64,
    /// Standard deviation of the period, mm.
    pub(crate) period_sd_mm: Option<f64>,
}

/// A fit the dictionary is screened at: its linearisation, the campaign
/// frame and poses, the test reference, and the fit's chi-square.
pub(crate) struct At<'a> {
    pub(crate) lin: &'a Linearisation,
    pub(crate) frame: &'a Frame,
    pub(crate) data: &'a Dataset,
    pub(crate) reference: &'a Reference,
    pub(crate) chi_square: f64,
    pub(crate) dof: usize,
}

impl At<'_> {
    /// Score and rank of a term's columns.
    fn score(&self, term: &GenericTerm) -> (f64, usize) {
        let s = self
            .lin
            .score_columns(&self.lin.generic_columns(term, self.frame, self.data));
        (s.explained, s.rank)
    }

    /// The residual variance factor a term of score `explained` and rank
    /// `rank` would leave.
    fn scale(&self, explained: f64, rank: usize) -> f64 {
        self.reference
            .scale(self.chi_square - explained, self.dof.saturating_sub(rank))
    }
}

/// The dictionary of one campaign.
#[derive(Debug, Clone)]
pub(crate) struct Dictionary {
    /// Groups without a period, and `leg-periodic` (once) when scanned.
    groups: Vec<GenericTerm>,
    /// Scan frequencies, 1/mm: `f_min + k step`.
    frequencies: Vec<f64>,
    /// Grid step, 1/mm.
    step: f64,
}

impl Dictionary {
    /// The dictionary of the campaign in `frame` (empty when disabled).
    pub(crate) fn new(frame: &Frame, options: &DictionaryOptions) -> Dictionary {
        if !options.enabled {
            return Dictionary {
                groups: Vec::new(),
                frequencies: Vec::new(),
                step: 0.0,
            };
        }
        let stroke = frame
            .leg_range_mm
            .iter()
            .map(|[lo, hi]| hi - lo)
            .fold(0.0, f64::max);
        let (p_min, p_max) = options.period_range_mm;
        let mut frequencies = Vec::new();
        let step = 1.0 / (options.oversampling.max(1.0) * stroke.max(1e-9));
        // A period needs at least two cycles over the stroke to be told from
        // a polynomial.
        if stroke > 2.0 * p_min && p_max > p_min && p_min > 0.0 {
            let (f_min, f_max) = ((1.0 / p_max).max(2.0 / stroke), 1.0 / p_min);
            frequencies = (0..)
                .map(|k| f_min + f64::from(k) * step)
                .take_while(|&f| f <= f_max)
                .collect();
        }
        let groups = frame
            .generic_groups()
            .into_iter()
            .filter(|g| g.family != GenericFamily::LegPeriodic || !frequencies.is_empty())
            .collect();
        Dictionary {
            groups,
            frequencies,
            step,
        }
    }

    /// Number of tests the dictionary makes (every scan period counts).
    pub(crate) fn multiplicity(&self) -> usize {
        self.groups
            .iter()
            .map(|g| {
                if g.family == GenericFamily::LegPeriodic {
                    self.frequencies.len()
                } else {
                    1
                }
            })
            .sum()
    }

    /// Number of scan periods.
    pub(crate) fn scan_len(&self) -> usize {
        self.frequencies.len()
    }

    /// Whether the dictionary is empty.
    pub(crate) fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Scores every group not made redundant by `model_terms`, best first
    /// (smallest adjusted p-value, then largest score).
    pub(crate) fn screen(&self, at: &At<'_>, model_terms: &[Term]) -> Vec<Scored> {
        let m = self.multiplicity().max(1) as f64;
        let test = |explained: f64, rank: usize| -> f64 {
            let s2 = at.scale(explained, rank);
            (at.reference.p_value(explained / s2, rank) * m).min(1.0)
        };
        let admitted_frequencies: Vec<f64> = model_terms
            .iter()
            .filter_map(|t| match t {
                Term::Generic(g) => g.period_mm.map(|p| 1.0 / p),
                Term::Catalogue(_) => None,
            })
            .collect();
        let mut out = Vec::new();
        for g in &self.groups {
            if model_terms.iter().any(|t| t.overlaps(&Term::Generic(*g))) {
                continue;
            }
            if g.family == GenericFamily::LegPeriodic {
                if let Some((explained, rank, term, period_sd_mm)) =
                    self.scan(at, g, &admitted_frequencies)
                {
                    out.push(Scored {
                        term,
                        explained,
                        rank,
                        p_adjusted: test(explained, rank),
                        period_sd_mm,
                    });
                }
                continue;
            }
            let (explained, rank) = at.score(g);
            if rank == 0 {
                continue;
            }
            out.push(Scored {
                term: *g,
                explained,
                rank,
                p_adjusted: test(explained, rank),
                period_sd_mm: None,
            });
        }
        out.sort_by(|a, b| {
            a.p_adjusted
                .total_cmp(&b.p_adjusted)
                .then(b.explained.total_cmp(&a.explained))
        });
        out
    }

    /// The best period of the scan, refined: (score, rank, term with its
    /// period, sd of the period).
    fn scan(
        &self,
        at: &At<'_>,
        group: &GenericTerm,
        admitted: &[f64],
    ) -> Option<(f64, usize, GenericTerm, Option<f64>)> {
        let with = |f: f64| GenericTerm {
            period_mm: Some(1.0 / f),
            ..*group
        };
        let near_admitted = |f: f64| admitted.iter().any(|a| (f - a).abs() <= 2.0 * self.step);
        let commands: Vec<[f64; 3]> = at.data.poses.iter().map(|p| p.commands_mm).collect();
        let legs = group.legs();
        let score = |f: f64| at.lin.periodic_score(&commands, &legs, f);
        let f0 = self.frequencies.first().copied()?;
        let scores = at
            .lin
            .periodic_scan(&commands, &legs, f0, self.step, self.frequencies.len());
        let mut best: Option<(f64, f64)> = None;
        for (&f, &(s, k)) in self.frequencies.iter().zip(&scores) {
            if near_admitted(f) {
                continue;
            }
            if k > 0 && best.is_none_or(|b| s > b.1) {
                best = Some((f, s));
            }
        }
        let (f0, _) = best?;
        // Golden-section search of the score within one grid step.
        let (mut a, mut b) = (f0 - self.step, f0 + self.step);
        let ratio = 0.5 * (5f64.sqrt() - 1.0);
        let mut x1 = b - ratio * (b - a);
        let mut x2 = a + ratio * (b - a);
        let (mut s1, mut s2) = (score(x1).0, score(x2).0);
        for _ in 0..25 {
            if s1 > s2 {
                b = x2;
                x2 = x1;
                s2 = s1;
                x1 = b - ratio * (b - a);
                s1 = score(x1).0;
            } else {
                a = x1;
                x1 = x2;
                s1 = s2;
                x2 = a + ratio * (b - a);
                s2 = score(x2).0;
            }
        }
        let f = 0.5 * (a + b);
        let (s, k) = score(f);
        // Curvature by central differences (a tenth of a grid step).
        let h = 0.1 * self.step;
        let curvature = (score(f + h).0 - 2.0 * s + score(f - h).0) / (h * h);
        let sd_f = (curvature < 0.0).then(|| (2.0 * at.scale(s, k) / -curvature).sqrt());
        Some((s, k, with(f), sd_f.map(|sd| sd / (f * f))))
    }
}
