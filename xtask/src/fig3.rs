//! Fig. 3 of the paper, "before compensation": the volumetric error `|dr|`
//! of the platform over the workspace's middle plane with the Table 2
//! errors, commanded by the nominal IK.
//!
//! `cargo xtask fig3-before` prints the figures for the default conventions
//! and for every combination of the conventions the paper leaves open
//! (joint placement order, U-joint axis order, plane height, grid), and says
//! which, if any, reproduces the paper's 1.179 / 0.573 / 0.693 mm.

use nalgebra::Vector3;
use tricept_kinematics::{AxisOrder, Machine, MachineDescription, Placement};
use tricept_model::{MapStats, ParameterSet, actual_machine, volumetric_errors};

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
    /// The project's defaults (the placement, x-first, z = 750 mm,
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
