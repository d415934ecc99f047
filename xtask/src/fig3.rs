//! Fig. 3 of the paper, "before compensation": the volumetric error `|dr|`
//! of the platform over the workspace's middle plane with the Table 2
//! errors, commanded by the nominal IK.
//!
//! `cargo xtask fig3-before` prints the figures for the default conventions
//! and for every combination of the conventions the paper leaves open
//! (joint placement order, U-joint axis order, plane height, grid), and says
//! which, if any, reproduces the paper's 1.179 / 0.573 / 0.693 mm.

use nalgebra::Vector3;
use tricept_kinematics::{
    Machine, MachineDescription, description::AxisOrder, description::Placement,
};
use tricept_model::{
    ParameterSet, actual::actual_machine, volumetric::MapStats, volumetric::volumetric_errors,
};
use tricept_numerics::stats::quantile;

/// The paper's before-compensation figures (max, min, mean), mm.
pub const PAPER_BEFORE_MM: [f64; 3] = [1.179, 0.573, 0.693];

/// One way of reading the paper's conventions.
#[derive(Debug, Clone)]
pub struct Conventions {
    /// Joint angles a_1, a_2, a_3 on the circles, degrees.
    pub joint_angles_deg: [f64; 3],
    /// U-joint axis order.
    pub axis_order: AxisOrder,
    /// Height of the plane, mm.
    pub plane_z_mm: f64,
    /// Grid over the plane.
    pub grid: Grid,
}

/// Grids over the plane.
#[derive(Debug, Clone, Copy)]
pub enum Grid {
    /// Square lattice of this spacing clipped to the workspace disc, mm.
    Disc(f64),
    /// n x n lattice over the square [-R, R]^2 circumscribing the disc.
    Square(usize),
}

impl Grid {
    fn label(&self) -> String {
        match self {
            Grid::Disc(s) => format!("disc, {s} mm lattice"),
            Grid::Square(n) => format!("square [-R,R]^2, {n}x{n}"),
        }
    }

    fn points(&self, m: &Machine, z: f64) -> Vec<Vector3<f64>> {
        match self {
            Grid::Disc(s) => m.workspace.disc_grid(z, *s),
            Grid::Square(n) => m.workspace.square_grid(z, *n),
        }
    }
}

impl Conventions {
    /// The project's defaults (the documented placement, x-first, z = 750 mm,
    /// 10 mm lattice over the disc).
    pub fn default_for(m: &Machine) -> Conventions {
        Conventions {
            joint_angles_deg: [120.0, 240.0, 0.0],
            axis_order: AxisOrder::XFirst,
            plane_z_mm: m.workspace.mid_plane_z_mm(),
            grid: Grid::Disc(10.0),
        }
    }

    /// Whether this placement satisfies the paper's frame convention
    /// (B1B2 parallel to y, which the 15-parameter set relies on).
    pub fn placement_follows_paper_frames(&self) -> bool {
        let [a1, a2, _] = self.joint_angles_deg.map(f64::to_radians);
        (a1.cos() - a2.cos()).abs() < 1e-9
    }
}

/// Builds the nominal machine for these conventions from the paper's description.
pub fn machine_for(c: &Conventions) -> Machine {
    let mut d = MachineDescription::paper();
    if let Placement::Circular(circ) = &mut d.placement {
        circ.joint_angles_deg = c.joint_angles_deg;
    }
    d.up_limb.axis_order = c.axis_order;
    // The paper gives no joint limits; the corners of the square grid tilt
    // the UP limb beyond the project's default 40 degrees.
    d.limits.max_tilt_deg = 60.0;
    match d.build() {
        Ok(m) => m,
        Err(e) => unreachable!("paper machine with permuted joints is valid: {e}"),
    }
}

/// The before-compensation statistics for one reading of the conventions.
pub fn before_stats(c: &Conventions) -> Result<MapStats, String> {
    before_stats_with_leg_sign(c, 1.0)
}

/// As [`before_stats`], with the Table 2 leg errors `dq_i` multiplied by `sign`.
fn before_stats_with_leg_sign(c: &Conventions, sign: f64) -> Result<MapStats, String> {
    let nominal = machine_for(c);
    let set = ParameterSet::paper15();
    let mut errors = set.to_errors(&set.table2());
    errors.dq_mm = errors.dq_mm.map(|q| sign * q);
    let actual = actual_machine(&nominal, &errors);
    let targets = c.grid.points(&nominal, c.plane_z_mm);
    volumetric_errors(&nominal, &actual, &targets)
        .map(|m| m.stats())
        .map_err(|e| e.to_string())
}

/// Largest relative deviation of (max, min, mean) from the paper's figures.
pub fn deviation_from_paper(s: &MapStats) -> f64 {
    let ours = [s.max_mm, s.min_mm, s.mean_mm];
    ours.iter()
        .zip(PAPER_BEFORE_MM)
        .map(|(a, b)| ((a - b) / b).abs())
        .fold(0.0, f64::max)
}

fn row(c: &Conventions, s: &MapStats) -> String {
    format!(
        "| {:?} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.1} % |",
        c.joint_angles_deg.map(|a| a as i32),
        if c.placement_follows_paper_frames() {
            "yes"
        } else {
            "no"
        },
        c.axis_order,
        c.plane_z_mm,
        c.grid.label(),
        s.max_mm,
        s.min_mm,
        s.mean_mm,
        100.0 * deviation_from_paper(s)
    )
}

/// Runs the investigation and prints it as Markdown.
pub fn run(all: bool) -> Result<(), String> {
    let base = Machine::paper();
    let default = Conventions::default_for(&base);
    let header = "| joint angles a1,a2,a3 (deg) | B1B2 parallel to y | U-joint axes | plane z (mm) | grid | max (mm) | min (mm) | mean (mm) | worst deviation |\n|---|---|---|---|---|---|---|---|---|";
    println!(
        "Paper (Fig. 3a): max {:.3} / min {:.3} / mean {:.3} mm\n",
        PAPER_BEFORE_MM[0], PAPER_BEFORE_MM[1], PAPER_BEFORE_MM[2]
    );
    println!("Default conventions:\n\n{header}");
    let s = before_stats(&default)?;
    println!("{}", row(&default, &s));

    let placements = [
        [120.0, 240.0, 0.0],
        [240.0, 120.0, 0.0],
        [60.0, 300.0, 180.0],
        [300.0, 60.0, 180.0],
        [0.0, 120.0, 240.0],
        [90.0, 210.0, 330.0],
    ];
    let orders = [AxisOrder::XFirst, AxisOrder::YFirst];
    let heights = [
        base.workspace.z_min_mm,
        base.workspace.mid_plane_z_mm(),
        base.workspace.z_max_mm,
    ];
    let grids = [Grid::Disc(10.0), Grid::Disc(50.0), Grid::Square(41)];

    let mut results = Vec::new();
    for angles in placements {
        for order in orders {
            for z in heights {
                for grid in grids {
                    let c = Conventions {
                        joint_angles_deg: angles,
                        axis_order: order,
                        plane_z_mm: z,
                        grid,
                    };
                    let s = before_stats(&c)?;
                    results.push((c, s));
                }
            }
        }
    }
    println!("\nOne convention changed at a time from the default:\n\n{header}");
    for (c, s) in &results {
        let changed = [
            c.joint_angles_deg != default.joint_angles_deg,
            c.axis_order != default.axis_order,
            c.plane_z_mm != default.plane_z_mm,
            !matches!(c.grid, Grid::Disc(s) if s == 10.0),
        ]
        .iter()
        .filter(|b| **b)
        .count();
        if changed == 1 {
            println!("{}", row(c, s));
        }
    }
    results.sort_by(|a, b| deviation_from_paper(&a.1).total_cmp(&deviation_from_paper(&b.1)));
    println!(
        "\nClosest of all {} combinations (placements x axis orders x heights x grids):\n\n{header}",
        results.len()
    );
    for (c, s) in results.iter().take(if all { results.len() } else { 5 }) {
        println!("{}", row(c, s));
    }
    // Not a convention the paper leaves open (eq. 2 fixes actual length =
    // command + dq), shown only because it is the one change that moves the
    // mean onto the paper's: it does not fix the max.
    let mut flipped = default.clone();
    flipped.grid = Grid::Disc(10.0);
    let s = before_stats_with_leg_sign(&flipped, -1.0)?;
    println!(
        "\nFor reference only, leg errors with the sign eq. 2 rules out (actual = command - dq), default conventions: max {:.3} / min {:.3} / mean {:.3} mm ({:.1} % worst deviation).",
        s.max_mm,
        s.min_mm,
        s.mean_mm,
        100.0 * deviation_from_paper(&s)
    );
    let best = deviation_from_paper(&results[0].1);
    println!(
        "\nVerdict: {}",
        if best < 0.02 {
            "a combination reproduces all three figures within 2 %.".to_string()
        } else {
            format!(
                "no combination reproduces the paper; the closest misses one of the three figures by {:.1} %.",
                100.0 * best
            )
        }
    );
    Ok(())
}

/// The paper's after-compensation figures (max, min, mean), mm.
pub const PAPER_AFTER_MM: [f64; 3] = [0.278, 0.171, 0.203];

/// Statistics of one seed: before, after, after without translation.
#[derive(Debug, Clone, Copy)]
struct SeedResult {
    before: MapStats,
    after: MapStats,
    residual: MapStats,
    translation_z_mm: f64,
}

fn one_seed(
    nominal: &Machine,
    plant: &tricept_plant::Plant,
    targets: &[Vector3<f64>],
    plane: &[Vector3<f64>],
    seed: u64,
) -> Result<(SeedResult, tricept_engine::compensate::Compensation), String> {
    let campaign = tricept_plant::Campaign::from_targets(nominal, targets.to_vec(), seed);
    let data = plant.simulate(&campaign).map_err(|e| e.to_string())?;
    let model =
        tricept_engine::model::GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let id = tricept_engine::identify(
        &model,
        &data,
        &tricept_engine::IdentifyOptions::for_machine(nominal),
    )
    .map_err(|e| e.to_string())?;
    let identified = model.machine_at(&id.estimate);
    let c = tricept_engine::compensate::compensation(
        nominal,
        &identified,
        &plant.actual_machine(),
        plane,
    )
    .map_err(|e| e.to_string())?;
    let residual = c.after.without_mean_translation().stats();
    Ok((
        SeedResult {
            before: c.before.stats(),
            after: c.after.stats(),
            residual,
            translation_z_mm: c.after.mean_translation_mm().z,
        },
        c,
    ))
}

fn quantiles(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    let q = |p: f64| quantile(&v, p);
    (q(0.05), q(0.5), q(0.95))
}

/// Fig. 3 before and after compensation: identification with the paper's
/// noise on the default pose set, compensation, statistics over `seeds`
/// noise draws, and the maps of seed 1 as SVG.
pub fn run_compensation(
    seeds: u64,
    out_dir: &std::path::Path,
    spacing_mm: f64,
) -> Result<(), String> {
    use rayon::prelude::*;
    let nominal = Machine::paper();
    let set = ParameterSet::paper15();
    let plant = tricept_plant::Plant::geometric(nominal.clone(), set.to_errors(&set.table2()));
    let targets = nominal.workspace.polar_grid(3, 8, 3);
    let plane = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), spacing_mm);
    let results: Vec<SeedResult> = (1..=seeds)
        .into_par_iter()
        .map(|seed| one_seed(&nominal, &plant, &targets, &plane, seed).map(|r| r.0))
        .collect::<Result<_, _>>()?;
    println!(
        "Fig. 3 on the default machine: Table 2 errors, noise 0.8 arcsec / 0.5 um, mean of 3, \
         pose set `grid` (75 poses), middle plane z = {} mm on a {spacing_mm} mm lattice ({} points), {seeds} noise seeds.\n",
        nominal.workspace.mid_plane_z_mm(),
        plane.len()
    );
    println!(
        "| map | statistic | paper (mm) | ours: median [5 %, 95 %] over seeds (mm) |\n|---|---|---|---|"
    );
    type Row = (&'static str, fn(&SeedResult) -> MapStats, Option<[f64; 3]>);
    let rows: [Row; 3] = [
        ("before", |r| r.before, Some(PAPER_BEFORE_MM)),
        ("after", |r| r.after, Some(PAPER_AFTER_MM)),
        ("after, rigid translation removed", |r| r.residual, None),
    ];
    for (name, get, paper) in rows {
        for (k, stat) in ["max", "min", "mean"].iter().enumerate() {
            let values: Vec<f64> = results
                .iter()
                .map(|r| {
                    let s = get(r);
                    [s.max_mm, s.min_mm, s.mean_mm][k]
                })
                .collect();
            let (lo, med, hi) = quantiles(values);
            let paper = paper.map_or("-".to_string(), |p| format!("{:.3}", p[k]));
            println!("| {name} | {stat} | {paper} | {med:.4} [{lo:.4}, {hi:.4}] |");
        }
    }
    let zs: Vec<f64> = results.iter().map(|r| r.translation_z_mm).collect();
    let n = zs.len() as f64;
    let mean = zs.iter().sum::<f64>() / n;
    let sd = (zs.iter().map(|z| (z - mean) * (z - mean)).sum::<f64>() / (n - 1.0)).sqrt();
    let (lo, med, hi) = quantiles(zs);
    println!(
        "\nRigid translation along z after compensation: median {med:.4} mm [{lo:.4}, {hi:.4}], standard deviation {sd:.4} mm over seeds;"
    );
    println!(
        "predicted from the identification covariance (first order, seed 1): {:.4} mm, of which the weak common-leg-length combination alone gives {:.4} mm.",
        predicted_translation_sd(&nominal, &plant, &targets, &plane, false)?,
        predicted_translation_sd(&nominal, &plant, &targets, &plane, true)?
    );

    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let (_, c) = one_seed(&nominal, &plant, &targets, &plane, 1)?;
    let residual = c.after.without_mean_translation();
    for (file, map, what) in [
        ("fig3-before.svg", &c.before, "Error before compensation"),
        (
            "fig3-after.svg",
            &c.after,
            "Error after compensation (seed 1)",
        ),
        (
            "fig3-after-no-translation.svg",
            &residual,
            "After compensation, rigid shift removed",
        ),
    ] {
        let z = tricept_ident::advanced::plot::plane_z(map.targets_mm.iter().map(|p| p.z));
        let title = format!("{what} |dr| (mm), {z}");
        let cells: Vec<tricept_ident::advanced::plot::Cell> = map
            .targets_mm
            .iter()
            .zip(map.magnitudes_mm())
            .map(|(p, v)| tricept_ident::advanced::plot::Cell {
                x: p.x,
                y: p.y,
                value: v,
            })
            .collect();
        let path = out_dir.join(file);
        tricept_ident::advanced::plot::heat_map(
            &path,
            &title,
            &cells,
            spacing_mm,
            "|dr| (mm)",
            None,
        )
        .map_err(|e| e.to_string())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Standard deviation of the mean z error over `plane` after compensation,
/// propagated to first order from the identification covariance of seed 1:
/// `t_z = c^T (p_hat - p)` with `c` the plane-averaged z row of the platform
/// position Jacobian. With `weak_only`, only the covariance along the
/// weakest singular direction is kept.
fn predicted_translation_sd(
    nominal: &Machine,
    plant: &tricept_plant::Plant,
    targets: &[Vector3<f64>],
    plane: &[Vector3<f64>],
    weak_only: bool,
) -> Result<f64, String> {
    let set = ParameterSet::paper15();
    let k = set.len();
    let campaign = tricept_plant::Campaign::from_targets(nominal, targets.to_vec(), 1);
    let data = plant.simulate(&campaign).map_err(|e| e.to_string())?;
    let model = tricept_engine::model::GeometricModel::new(nominal.clone(), set.clone());
    let id = tricept_engine::identify(
        &model,
        &data,
        &tricept_engine::IdentifyOptions::for_machine(nominal),
    )
    .map_err(|e| e.to_string())?;
    let mut c = vec![0.0; k];
    let mut z_row = vec![0.0; k];
    for r in plane {
        let up = nominal.inverse(r).map_err(|e| e.to_string())?.up;
        let jp = tricept_model::jacobian::position_error_jacobian(&nominal.legs_at(&up))
            .map_err(|e| e.to_string())?;
        set.project(1, |_, f| jp[(2, f)], &mut z_row);
        for (cj, zj) in c.iter_mut().zip(&z_row) {
            *cj += zj / plane.len() as f64;
        }
    }
    let cov = |a: usize, b: usize| id.covariance[(a, b)];
    let var = if weak_only {
        // Project c on the weakest identifiable direction (in parameter units).
        let v = id
            .design()
            .direction(id.design().rank() - 1)
            .ok_or("no identifiable direction")?;
        let vv: f64 = (0..k)
            .map(|a| (0..k).map(|b| v[a] * v[b] * cov(a, b)).sum::<f64>())
            .sum();
        // Component of the functional along v, using the covariance metric.
        let cv: f64 = (0..k)
            .map(|a| (0..k).map(|b| c[a] * v[b] * cov(a, b)).sum::<f64>())
            .sum();
        cv * cv / vv
    } else {
        (0..k)
            .map(|a| (0..k).map(|b| c[a] * c[b] * cov(a, b)).sum::<f64>())
            .sum()
    };
    Ok(var.max(0.0).sqrt())
}
