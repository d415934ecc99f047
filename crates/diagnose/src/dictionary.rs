//! The generic dictionary: every group of generic terms the campaign
//! supports ([`crate::terms::Frame::generic_groups`]), the ball-screw
//! period scan, the worn-segment (step) scan, and the linear screen that
//! ranks them at the current fit.
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
//! **Step scan.** The edges `a < b` of a leg's step (the leg longer by `h`
//! while its command is inside `[a, b]`) on a grid of `step_cells + 1`
//! cuts equally spaced over the leg's stroke in the campaign (its first
//! and last command included: an edge there is a single step at the other
//! edge): every pair but the whole stroke (which a leg offset absorbs), so
//! `K (K + 1) / 2 - 1` pairs for `K` cells, each counted in the
//! multiplicity. A pair with fewer than [`MIN_STEP_POSES`] poses inside
//! or outside is not scored (a step carried by a few poses is a gross
//! error, for the outlier screen). The best pair is refined within one
//! cell of each edge over every distinct segment of the poses (the score
//! changes only where an edge crosses a pose's command: the edges are put
//! midway between neighbouring commands), one edge at a time until
//! neither moves. Each edge's standard deviation is the half-width of its
//! profile-likelihood interval (the edge positions whose score is within
//! `s2` of the best, the other edge fixed); an edge at the end of the
//! stroke has none (the campaign cannot place it). On a leg that a leg
//! polynomial of the model covers, a step is screened by what it explains
//! beyond the polynomial's next order (its quartic part): a step that only
//! mops up what the polynomial leaves of a curved leg is not a worn
//! segment.
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
use crate::terms::{Frame, GenericTerm, Scope, Term};

/// The fewest poses a scanned step may hold inside its segment, and leave
/// outside it.
pub(crate) const MIN_STEP_POSES: usize = 3;

/// Rounds of the step refinement (one edge, then the other) at most.
const STEP_ROUNDS: usize = 10;

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
    /// Standard deviation of each edge of a step, mm (`None` for an edge
    /// at the end of the campaign's stroke).
    pub(crate) edges_sd_mm: Option<[Option<f64>; 2]>,
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
        let s = self.lin.score_generic(term, self.frame, self.data);
        (s.explained, s.rank)
    }

    /// What a step `term` of score `explained` and rank `rank` explains
    /// beyond the next order of the smooth leg terms of the model on its
    /// leg (the quartic part of a leg polynomial): a step that only mops up
    /// what a polynomial leaves of a curved leg is not a worn segment.
    /// `None` when nothing is left.
    fn beyond_smooth(
        &self,
        term: &GenericTerm,
        explained: f64,
        rank: usize,
        model_terms: &[Term],
    ) -> Option<(f64, usize)> {
        let legs = term.legs();
        let smooth: Vec<(usize, Vec<f64>)> = model_terms
            .iter()
            .filter_map(|t| match t {
                Term::Generic(g) if g.family == GenericFamily::LegPolynomial => {
                    g.refinement(self.frame, self.data)
                }
                _ => None,
            })
            .flatten()
            .filter(|(direction, _)| legs.contains(direction))
            .collect();
        if smooth.is_empty() {
            return Some((explained, rank));
        }
        let alone = self.lin.score_columns(&smooth);
        let mut both = smooth;
        both.extend(self.lin.generic_columns(term, self.frame, self.data));
        let with = self.lin.score_columns(&both);
        let rank = with.rank.saturating_sub(alone.rank);
        (rank > 0).then(|| ((with.explained - alone.explained).max(0.0), rank))
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
    /// Cells of the step scan's grid over each leg's stroke (0: no scan).
    step_cells: usize,
}

impl Dictionary {
    /// The dictionary of the campaign in `frame` (empty when disabled).
    pub(crate) fn new(frame: &Frame, options: &DictionaryOptions) -> Dictionary {
        if !options.enabled {
            return Dictionary {
                groups: Vec::new(),
                frequencies: Vec::new(),
                step: 0.0,
                step_cells: 0,
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
        let step_cells = options.step_cells;
        let groups = frame
            .generic_groups()
            .into_iter()
            .filter(|g| g.family != GenericFamily::LegPeriodic || !frequencies.is_empty())
            .filter(|g| g.family != GenericFamily::LegStep || step_cells > 0)
            .collect();
        Dictionary {
            groups,
            frequencies,
            step,
            step_cells,
        }
    }

    /// Pairs of edges of one leg's step scan: every pair of the grid's
    /// cuts but the whole stroke.
    fn step_pairs(&self) -> usize {
        let k = self.step_cells;
        (k * (k + 1) / 2).saturating_sub(1)
    }

    /// Tests of one group: the scan's grid points for a scanned family.
    fn tests(&self, family: GenericFamily) -> usize {
        match family {
            GenericFamily::LegPeriodic => self.frequencies.len(),
            GenericFamily::LegStep => self.step_pairs(),
            _ => 1,
        }
    }

    /// Number of tests the dictionary makes (every scan period and every
    /// pair of a step's edges counts).
    pub(crate) fn multiplicity(&self) -> usize {
        self.groups.iter().map(|g| self.tests(g.family)).sum()
    }

    /// The alternatives of a scanned family for the penalised gain: every
    /// grid point of its scan over all its groups (`None` for a family
    /// without a scan).
    pub(crate) fn scan_alternatives(&self, family: GenericFamily) -> Option<usize> {
        matches!(family, GenericFamily::LegPeriodic | GenericFamily::LegStep).then(|| {
            self.groups
                .iter()
                .filter(|g| g.family == family)
                .map(|g| self.tests(g.family))
                .sum()
        })
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
                        edges_sd_mm: None,
                    });
                }
                continue;
            }
            if g.family == GenericFamily::LegStep {
                if let Some((explained, rank, term, edges_sd_mm)) = self.step_scan(at, g)
                    && let Some((explained, rank)) =
                        at.beyond_smooth(&term, explained, rank, model_terms)
                {
                    out.push(Scored {
                        term,
                        explained,
                        rank,
                        p_adjusted: test(explained, rank),
                        period_sd_mm: None,
                        edges_sd_mm: Some(edges_sd_mm),
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
                edges_sd_mm: None,
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

    /// The best step of the scan on `group`'s leg, refined: (score, rank,
    /// term with its edges, sd of each edge).
    fn step_scan(
        &self,
        at: &At<'_>,
        group: &GenericTerm,
    ) -> Option<(f64, usize, GenericTerm, [Option<f64>; 2])> {
        let Scope::Leg(leg) = group.scope else {
            return None;
        };
        let leg = usize::from(leg);
        let [lo, hi] = at.frame.leg_range_mm[leg];
        let cells = self.step_cells;
        if hi <= lo || cells == 0 {
            return None;
        }
        let commands: Vec<[f64; 3]> = at.data.poses.iter().map(|p| p.commands_mm).collect();
        let n = commands.len();
        let counts_ok = |inside: usize| inside >= MIN_STEP_POSES && n - inside >= MIN_STEP_POSES;
        // The grid.
        let grid: Vec<f64> = (0..=cells)
            .map(|k| {
                if k == cells {
                    hi
                } else {
                    lo + (hi - lo) * k as f64 / cells as f64
                }
            })
            .collect();
        let prefix = at.lin.step_prefix(&commands, leg, &grid);
        let mut best: Option<(usize, usize, f64)> = None;
        for u in 0..cells {
            for v in u + 1..=cells {
                if (u, v) == (0, cells) {
                    continue;
                }
                let (s, k, inside) = at.lin.step_score(&prefix, u, v);
                if k > 0 && counts_ok(inside) && best.is_none_or(|b| s > b.2) {
                    best = Some((u, v, s));
                }
            }
        }
        let (u, v, _) = best?;
        // The candidate edges within one cell of each: midway between
        // neighbouring commands, and the end of the stroke when the window
        // reaches it; each with the gap of commands it stands for.
        let mut sorted: Vec<f64> = commands.iter().map(|q| q[leg]).collect();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        let window = |k: usize| (grid[k.saturating_sub(1)], grid[(k + 1).min(cells)]);
        let candidates = |(from, to): (f64, f64)| -> Vec<(f64, [f64; 2])> {
            let mut out: Vec<(f64, [f64; 2])> = Vec::new();
            if from <= lo {
                out.push((lo, [f64::NEG_INFINITY, lo]));
            }
            out.extend(
                sorted
                    .windows(2)
                    .map(|w| (0.5 * (w[0] + w[1]), [w[0], w[1]]))
                    .filter(|(m, _)| (from..=to).contains(m)),
            );
            if to >= hi {
                out.push((hi, [hi, f64::INFINITY]));
            }
            out
        };
        let (lower, upper) = (candidates(window(u)), candidates(window(v)));
        let mut cuts: Vec<f64> = lower.iter().chain(&upper).map(|c| c.0).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let index = |x: f64| cuts.partition_point(|c| *c < x);
        let prefix = at.lin.step_prefix(&commands, leg, &cuts);
        let score = |a: usize, b: usize| -> Option<f64> {
            let (s, k, inside) = at.lin.step_score(&prefix, a, b);
            (a < b && k > 0 && counts_ok(inside)).then_some(s)
        };
        // Start from the candidates nearest the grid's edges.
        let nearest = |list: &[(f64, [f64; 2])], x: f64| {
            list.iter()
                .min_by(|p, q| (p.0 - x).abs().total_cmp(&(q.0 - x).abs()))
                .map(|c| index(c.0))
        };
        let (mut a, mut b) = (nearest(&lower, grid[u])?, nearest(&upper, grid[v])?);
        let mut s_best = score(a, b).unwrap_or(f64::NEG_INFINITY);
        for _ in 0..STEP_ROUNDS {
            let before = (a, b);
            for (list, lower_edge) in [(&lower, true), (&upper, false)] {
                for c in list.iter() {
                    let i = index(c.0);
                    let (x, y) = if lower_edge { (i, b) } else { (a, i) };
                    if let Some(s) = score(x, y)
                        && s > s_best
                    {
                        s_best = s;
                        (a, b) = (x, y);
                    }
                }
            }
            if (a, b) == before {
                break;
            }
        }
        let term = GenericTerm {
            edges_mm: Some([cuts[a], cuts[b]]),
            ..*group
        };
        let (s, k) = at.score(&term);
        if k == 0 {
            return None;
        }
        // Each edge's profile-likelihood interval: the candidates within
        // s2 of the best, the other edge fixed.
        let s2 = at.scale(s, k);
        let interval = |list: &[(f64, [f64; 2])], lower_edge: bool| -> Option<f64> {
            let admitted: Vec<[f64; 2]> = list
                .iter()
                .filter(|c| {
                    let i = index(c.0);
                    let (x, y) = if lower_edge { (i, b) } else { (a, i) };
                    score(x, y).is_some_and(|v| v >= s_best - s2)
                })
                .map(|c| c.1)
                .collect();
            let from = admitted.iter().map(|g| g[0]).fold(f64::INFINITY, f64::min);
            let to = admitted
                .iter()
                .map(|g| g[1])
                .fold(f64::NEG_INFINITY, f64::max);
            let half = 0.5 * (to - from);
            half.is_finite().then_some(half)
        };
        let sd = [interval(&lower, true), interval(&upper, false)];
        Some((s, k, term, sd))
    }
}
