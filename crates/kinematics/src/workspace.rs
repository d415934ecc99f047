//! The cylindrical workspace of the platform point O' and pose sampling in it.
//!
//! Table 1 of the paper: a cylinder of radius `R = 400` and height `h = 200`
//! whose near face is `H = 650` mm from the base plane, so O' ranges over
//! `x^2 + y^2 <= R^2`, `650 <= z <= 850` mm and the "middle plane" of Fig. 3
//! is `z = 750` mm. Random sampling is seeded (PCG-64 MCG) and reproducible.
//! [`PoseSet`] names a set of poses the way the command line does
//! (`grid`, `random:100,3`, ...).

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::description::WorkspaceDescription;

/// The workspace cylinder, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Workspace {
    /// Radius, mm.
    pub radius_mm: f64,
    /// Lowest z (nearest the base), mm.
    pub z_min_mm: f64,
    /// Highest z, mm.
    pub z_max_mm: f64,
}

impl Workspace {
    /// Builds from the description (`z_min = H`, `z_max = H + h`).
    pub fn from_description(d: &WorkspaceDescription) -> Workspace {
        Workspace {
            radius_mm: d.radius_mm,
            z_min_mm: d.distance_mm,
            z_max_mm: d.distance_mm + d.height_mm,
        }
    }

    /// z of the middle plane, mm.
    pub fn mid_plane_z_mm(&self) -> f64 {
        0.5 * (self.z_min_mm + self.z_max_mm)
    }

    /// Whether `p` lies in the cylinder (with a tolerance of 1e-9 mm).
    pub fn contains(&self, p: &Vector3<f64>) -> bool {
        let tol = 1e-9;
        p.x.hypot(p.y) <= self.radius_mm + tol
            && p.z >= self.z_min_mm - tol
            && p.z <= self.z_max_mm + tol
    }

    /// Polar grid: at each of `levels` equally spaced heights (one level:
    /// the middle plane), the axis point plus `rings` rings of `per_ring`
    /// points at radii `R k / rings`.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::Machine;
// The project's default identification pose set: 3 x (1 + 3 x 8) = 75 poses.
let poses = Machine::paper().workspace.polar_grid(3, 8, 3);
assert_eq!(poses.len(), 75);
```
"#
    )]
    pub fn polar_grid(&self, rings: usize, per_ring: usize, levels: usize) -> Vec<Vector3<f64>> {
        let mut out = Vec::with_capacity(levels * (1 + rings * per_ring));
        for z in self.levels(levels) {
            out.push(Vector3::new(0.0, 0.0, z));
            for k in 1..=rings {
                let radius = self.radius_mm * k as f64 / rings as f64;
                for j in 0..per_ring {
                    let a = std::f64::consts::TAU * j as f64 / per_ring as f64;
                    out.push(Vector3::new(radius * a.cos(), radius * a.sin(), z));
                }
            }
        }
        out
    }

    /// Heights of `levels` equally spaced planes from `z_min` to `z_max`
    /// (one level: the middle plane).
    pub fn levels(&self, levels: usize) -> Vec<f64> {
        match levels {
            0 => Vec::new(),
            1 => vec![self.mid_plane_z_mm()],
            n => (0..n)
                .map(|k| {
                    self.z_min_mm + (self.z_max_mm - self.z_min_mm) * k as f64 / (n - 1) as f64
                })
                .collect(),
        }
    }

    /// Square grid of spacing `spacing_mm` over the disc `x^2 + y^2 <= R^2` at
    /// height `z_mm`, centred on the axis (the axis point is always included).
    pub fn disc_grid(&self, z_mm: f64, spacing_mm: f64) -> Vec<Vector3<f64>> {
        let n = (self.radius_mm / spacing_mm).floor() as i64;
        let mut out = Vec::new();
        for i in -n..=n {
            for j in -n..=n {
                let (x, y) = (i as f64 * spacing_mm, j as f64 * spacing_mm);
                if x.hypot(y) <= self.radius_mm + 1e-9 {
                    out.push(Vector3::new(x, y, z_mm));
                }
            }
        }
        out
    }

    /// Square grid of `n x n` points spanning `[-R, R]^2` at height `z_mm`
    /// (the square circumscribing the workspace disc).
    pub fn square_grid(&self, z_mm: f64, n: usize) -> Vec<Vector3<f64>> {
        let step = if n > 1 {
            2.0 * self.radius_mm / (n - 1) as f64
        } else {
            0.0
        };
        let start = if n > 1 { -self.radius_mm } else { 0.0 };
        let mut out = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                out.push(Vector3::new(
                    start + i as f64 * step,
                    start + j as f64 * step,
                    z_mm,
                ));
            }
        }
        out
    }

    /// `n` points uniformly distributed in the cylinder's volume, reproducible
    /// from `seed`.
    pub fn random_poses(&self, n: usize, seed: u64) -> Vec<Vector3<f64>> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                // Uniform in the disc: radius ~ R sqrt(U).
                let rad = self.radius_mm * rng.random::<f64>().sqrt();
                let a = std::f64::consts::TAU * rng.random::<f64>();
                let z = self.z_min_mm + (self.z_max_mm - self.z_min_mm) * rng.random::<f64>();
                Vector3::new(rad * a.cos(), rad * a.sin(), z)
            })
            .collect()
    }
}

/// A pose set as the command line names it (`--poses`).
///
/// | spec | poses |
/// |---|---|
/// | `grid` | the default polar grid, 3 levels x (axis + 3 rings x 8) = 75 |
/// | `grid:R,P,L` | polar grid with `R` rings of `P` points on `L` levels |
/// | `random:N` or `random:N,SEED` | `N` points uniform in the workspace |
/// | `disc:S` or `disc:S,Z` | square lattice of spacing `S` mm on the plane `z = Z` (default: middle plane) |
/// | any other text | a CSV file with columns `x,y,z` (mm), read by the caller |
///
/// # Example
/// ```
/// use tricept_kinematics::{Machine, workspace::PoseSet};
/// let ws = Machine::paper().workspace;
/// let grid: PoseSet = "grid".parse().unwrap();
/// assert_eq!(grid.generate(&ws).unwrap().len(), 75);
/// let small: PoseSet = "grid:2,6,1".parse().unwrap();
/// assert_eq!(small.generate(&ws).unwrap().len(), 13);
/// assert_eq!("random:40,7".parse::<PoseSet>().unwrap().generate(&ws).unwrap().len(), 40);
/// assert!("grid:2,x,1".parse::<PoseSet>().unwrap_err().to_string().contains("grid:"));
/// // A file name: generated by nobody, read by the caller.
/// assert!("poses.csv".parse::<PoseSet>().unwrap().generate(&ws).is_none());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum PoseSet {
    /// Polar grid ([`Workspace::polar_grid`]).
    Grid {
        /// Rings per level.
        rings: usize,
        /// Points per ring.
        per_ring: usize,
        /// Levels.
        levels: usize,
    },
    /// Uniform random points ([`Workspace::random_poses`]).
    Random {
        /// Number of points.
        n: usize,
        /// Seed.
        seed: u64,
    },
    /// Square lattice on a plane ([`Workspace::disc_grid`]).
    Disc {
        /// Lattice spacing, mm (at least 1).
        spacing_mm: f64,
        /// Height of the plane, mm (default: the middle plane).
        z_mm: Option<f64>,
    },
    /// A CSV file of target points (`x,y,z`, mm).
    File(std::path::PathBuf),
}

/// The most points a generated pose set may have (`grid:` and `random:`),
/// checked before anything is allocated.
pub const MAX_POSES: usize = 1_000_000;

/// A pose-set spec that cannot be parsed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("pose set `{spec}`: {reason}")]
pub struct PoseSetError {
    /// The spec as given.
    pub spec: String,
    /// What is wrong with it.
    pub reason: String,
}

impl std::str::FromStr for PoseSet {
    type Err = PoseSetError;

    fn from_str(spec: &str) -> Result<PoseSet, PoseSetError> {
        let bad = |reason: String| PoseSetError {
            spec: spec.to_string(),
            reason,
        };
        let numbers = |rest: &str, what: &str| -> Result<Vec<f64>, PoseSetError> {
            rest.split(',')
                .map(|t| {
                    t.trim()
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite() && *v >= 0.0)
                        .ok_or_else(|| bad(format!("`{t}` is not a non-negative number ({what})")))
                })
                .collect()
        };
        let count = |v: f64, what: &str| -> Result<usize, PoseSetError> {
            if v.fract() == 0.0 && (1.0..=1e7).contains(&v) {
                Ok(v as usize)
            } else {
                Err(bad(format!("{what} must be a whole number >= 1")))
            }
        };
        if spec == "grid" {
            return Ok(PoseSet::Grid {
                rings: 3,
                per_ring: 8,
                levels: 3,
            });
        }
        if let Some(rest) = spec.strip_prefix("grid:") {
            let v = numbers(rest, "grid:RINGS,PER_RING,LEVELS")?;
            let [rings, per_ring, levels] = v.as_slice() else {
                return Err(bad("expected grid:RINGS,PER_RING,LEVELS".into()));
            };
            let (rings, per_ring, levels) = (
                count(*rings, "RINGS")?,
                count(*per_ring, "PER_RING")?,
                count(*levels, "LEVELS")?,
            );
            let points = rings
                .saturating_mul(per_ring)
                .saturating_add(1)
                .saturating_mul(levels);
            if points > MAX_POSES {
                return Err(bad(format!(
                    "{points} points; a generated pose set has at most {MAX_POSES}"
                )));
            }
            return Ok(PoseSet::Grid {
                rings,
                per_ring,
                levels,
            });
        }
        if let Some(rest) = spec.strip_prefix("random:") {
            let v = numbers(rest, "random:N[,SEED]")?;
            if v.first().is_some_and(|&n| n > MAX_POSES as f64) {
                return Err(bad(format!(
                    "{} points; a generated pose set has at most {MAX_POSES}",
                    v[0]
                )));
            }
            return match v.as_slice() {
                [n] => Ok(PoseSet::Random {
                    n: count(*n, "N")?,
                    seed: 0,
                }),
                [n, seed] => Ok(PoseSet::Random {
                    n: count(*n, "N")?,
                    seed: *seed as u64,
                }),
                _ => Err(bad("expected random:N or random:N,SEED".into())),
            };
        }
        if let Some(rest) = spec.strip_prefix("disc:") {
            let v = numbers(rest, "disc:SPACING[,Z]")?;
            let (spacing_mm, z_mm) = match v.as_slice() {
                [s] => (*s, None),
                [s, z] => (*s, Some(*z)),
                _ => return Err(bad("expected disc:SPACING or disc:SPACING,Z".into())),
            };
            if spacing_mm < 1.0 {
                return Err(bad("spacing must be at least 1 mm".into()));
            }
            return Ok(PoseSet::Disc { spacing_mm, z_mm });
        }
        Ok(PoseSet::File(spec.into()))
    }
}

impl PoseSet {
    /// The points of a generated set in `workspace`, mm; `None` for
    /// [`PoseSet::File`], whose points the caller reads
    /// (`tricept_data::targets::read_targets`).
    pub fn generate(&self, workspace: &Workspace) -> Option<Vec<Vector3<f64>>> {
        match self {
            PoseSet::Grid {
                rings,
                per_ring,
                levels,
            } => Some(workspace.polar_grid(*rings, *per_ring, *levels)),
            PoseSet::Random { n, seed } => Some(workspace.random_poses(*n, *seed)),
            PoseSet::Disc { spacing_mm, z_mm } => Some(workspace.disc_grid(
                z_mm.unwrap_or_else(|| workspace.mid_plane_z_mm()),
                *spacing_mm,
            )),
            PoseSet::File(_) => None,
        }
    }
}

/// Every point of the lattice of spacing `spacing_mm` in the box from
/// `min_mm` to `max_mm` (corners included), x slowest and z fastest: for
/// sweeps that go beyond the workspace cylinder.
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// let l = tricept_kinematics::workspace::box_lattice(
///     Vector3::new(-100.0, -100.0, 600.0),
///     Vector3::new(100.0, 100.0, 700.0),
///     50.0,
/// );
/// assert_eq!(l.len(), 5 * 5 * 3);
/// assert_eq!(l[1], Vector3::new(-100.0, -100.0, 650.0));
/// ```
pub fn box_lattice(
    min_mm: Vector3<f64>,
    max_mm: Vector3<f64>,
    spacing_mm: f64,
) -> Vec<Vector3<f64>> {
    let steps: [usize; 3] =
        std::array::from_fn(|a| ((max_mm[a] - min_mm[a]) / spacing_mm + 1e-9).floor() as usize);
    let mut out = Vec::with_capacity((steps[0] + 1) * (steps[1] + 1) * (steps[2] + 1));
    for i in 0..=steps[0] {
        for j in 0..=steps[1] {
            for k in 0..=steps[2] {
                let offset = Vector3::new(i as f64, j as f64, k as f64) * spacing_mm;
                out.push(min_mm + offset);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> Workspace {
        Workspace {
            radius_mm: 400.0,
            z_min_mm: 650.0,
            z_max_mm: 850.0,
        }
    }

    #[test]
    fn grids_stay_inside_and_have_the_expected_size() {
        let w = paper();
        let g = w.polar_grid(3, 8, 3);
        assert_eq!(g.len(), 75);
        assert!(g.iter().all(|p| w.contains(p)));
        let d = w.disc_grid(750.0, 100.0);
        // |i|,|j| <= 4 with i^2 + j^2 <= 16: 49 lattice points.
        assert_eq!(d.len(), 49);
        assert!(d.iter().all(|p| w.contains(p)));
        assert_eq!(w.levels(1), vec![750.0]);
        assert_eq!(w.square_grid(750.0, 3).len(), 9);
    }

    #[test]
    fn random_poses_are_reproducible_and_inside() {
        let w = paper();
        let a = w.random_poses(500, 7);
        let b = w.random_poses(500, 7);
        assert_eq!(a, b);
        assert_ne!(a, w.random_poses(500, 8));
        assert!(a.iter().all(|p| w.contains(p)));
        // Uniform in area: about a quarter of the points within R/2.
        let inner = a.iter().filter(|p| p.x.hypot(p.y) < 200.0).count();
        assert!((90..160).contains(&inner), "{inner}");
    }
}
