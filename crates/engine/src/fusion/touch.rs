//! Touch-offs: a probe in the spindle triggers on a reference sphere or
//! plane; the record holds the leg commands and head angles latched at the
//! trigger. One row per touch, along the surface normal.
//!
//! - Sphere `f`: `|x - c_f| - r = R_f`, with the stylus centre `x` (the
//!   tool tip), the sphere's centre `c_f` (3 nuisance, mm; started from a
//!   linear sphere fit, at least four touches not in one plane), its
//!   radius `R_f` known and the effective stylus radius `r` (1 nuisance,
//!   shared by every touch, with the prior of the features file;
//!   pre-travel is lumped into it).
//! - Plane `f`: `n_f . x - d_f = 0`, with the normal `n_f` (2 nuisance: a
//!   tilt re-based after every step; started from the best-fit plane, at
//!   least three touches not on one line, oriented out of the material,
//!   against the tool) and `d_f` (1 nuisance, mm: the plane's offset plus
//!   the stylus radius, which it absorbs: plane rows carry no information
//!   on `r`).
//!
//! A plane sees only errors along its normal, a sphere only over its own
//! diameter; both locate the part the way the machine itself will, which is
//! what makes a rigid translation of the machine irrelevant to the part.

use nalgebra::Vector3;
use tricept_data::{
    external::Feature, external::Features, external::TouchData, external::TouchReading,
};

use crate::error::IdentError;
use crate::fusion::source::{
    Nuisance, PointRows, Readings, RecordList, Sink, Source, SourceKind, SourceRows, Start,
    project_rows, sphere_centre,
};

/// How to read a touch-off file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchOptions {
    /// Standard deviation of a touch along the normal for rows without
    /// `sigma_um`, um.
    pub sigma_um: f64,
}

impl Default for TouchOptions {
    /// 1.5 um (a kinematic touch-trigger probe's repeatability).
    fn default() -> Self {
        TouchOptions { sigma_um: 1.5 }
    }
}

/// A feature in use, with the first column of its nuisance.
#[derive(Debug, Clone, Copy)]
struct Used {
    feature: Feature,
    column: usize,
}

#[derive(Debug, Clone)]
struct Touch {
    touches: Readings<TouchReading>,
    stylus_mm: f64,
    stylus_sigma_mm: f64,
    used: Vec<Used>,
    feature_of: Vec<usize>,
}

impl Source {
    /// Touch-offs on the features of `features`. Refused: a touch of a
    /// feature the file does not declare; a sphere with fewer than four
    /// touches, a plane with fewer than three.
    ///
    /// # Example
    /// ```
    /// use tricept_engine::fusion::{Source, TouchOptions};
    /// let features = tricept_data::external::Features::from_json(
    ///     r#"{"stylus": {"radius_mm": 1, "radius_sigma_um": 2}, "features": [{"id": 1, "kind": "plane"}]}"#,
    ///     "f.json",
    /// )
    /// .unwrap();
    /// let csv = "q1,q2,q3,h1,h2,feature\n800,800,800,0,0.3,4\n";
    /// let data = tricept_data::external::read_external_from(csv.as_bytes(), "t.csv").unwrap();
    /// let e = Source::touch(&data, &features, &TouchOptions::default()).unwrap_err();
    /// assert_eq!(
    ///     e.to_string(),
    ///     "t.csv: line 2: column `feature`: feature 4 is not in the features file"
    /// );
    /// ```
    pub fn touch(
        data: &TouchData,
        features: &Features,
        options: &TouchOptions,
    ) -> Result<Source, IdentError> {
        let touches = Readings::new(data, options.sigma_um);
        let mut used: Vec<Used> = Vec::new();
        let mut feature_of = Vec::with_capacity(data.records.len());
        let mut column = 1;
        for t in &data.records {
            let k = match used.iter().position(|u| u.feature.id() == t.feature) {
                Some(k) => k,
                None => {
                    let feature = *features.get(t.feature).ok_or_else(|| IdentError::Source {
                        file: data.source.clone(),
                        line: Some(t.line),
                        message: format!(
                            "column `feature`: feature {} is not in the features file",
                            t.feature
                        ),
                    })?;
                    used.push(Used { feature, column });
                    column += 3;
                    used.len() - 1
                }
            };
            feature_of.push(k);
        }
        for (k, u) in used.iter().enumerate() {
            let n = feature_of.iter().filter(|&&f| f == k).count();
            let (needed, what) = match u.feature {
                Feature::Sphere { .. } => (4, "sphere"),
                Feature::Plane { .. } => (3, "plane"),
            };
            if n < needed {
                return Err(touches.degenerate(
                    |j| feature_of[j] == k,
                    |lines| {
                        format!(
                            "{what} {} has {n} touches ({lines}); it needs at least {needed}",
                            u.feature.id()
                        )
                    },
                ));
            }
        }
        Ok(Source::new(Box::new(Touch {
            touches,
            stylus_mm: features.stylus.radius_mm,
            stylus_sigma_mm: 1e-3 * features.stylus.radius_sigma_um,
            used,
            feature_of,
        })))
    }
}

/// Two unit vectors completing `n` (unit) to an orthonormal frame.
fn plane_basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let trial = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let a = (trial - n * n.dot(&trial)).normalize();
    (a, n.cross(&a))
}

impl SourceRows for Touch {
    fn kind(&self) -> SourceKind {
        SourceKind::Touch
    }

    fn record_list(&self) -> &dyn RecordList {
        &self.touches
    }

    fn nuisance_names(&self) -> Vec<String> {
        let mut names = vec!["stylus_radius_mm".to_string()];
        for u in &self.used {
            let id = u.feature.id();
            let parts: [&str; 3] = match u.feature {
                Feature::Sphere { .. } => ["centre_x_mm", "centre_y_mm", "centre_z_mm"],
                Feature::Plane { .. } => ["tilt_a_rad", "tilt_b_rad", "offset_mm"],
            };
            names.extend(parts.iter().map(|p| format!("f{id}.{p}")));
        }
        names
    }

    fn rows_each(&self) -> usize {
        1
    }

    fn prior_rows(&self) -> usize {
        1
    }

    fn min_redundancy(&self) -> f64 {
        4.0 * self.used.len() as f64
    }

    fn judged_nuisance(&self, values: &[f64]) -> Vec<(&'static str, usize, f64)> {
        vec![(
            "touch.stylus_radius_change_mm",
            0,
            values[0] - self.stylus_mm,
        )]
    }

    fn start(&self) -> Nuisance {
        let mut nu = Nuisance {
            values: vec![0.0; 1 + 3 * self.used.len()],
            rotations: Vec::new(),
            normals: vec![Vector3::zeros(); self.used.len()],
        };
        nu.values[0] = self.stylus_mm;
        nu
    }

    // The stylus centre is the tool tip: the default effector.
    fn fit_start(&self, start: Start<'_>) -> Result<Nuisance, IdentError> {
        let (mut nu, active, direction) = (start.nu, start.active, start.tool_direction);
        let n_touches = self.touches.records.len();
        let tips: Vec<Vector3<f64>> = start.points.iter().map(|x| x.position_mm).collect();
        let axes: Vec<Vector3<f64>> = start
            .points
            .iter()
            .map(|x| x.rotation * direction)
            .collect();
        for (k, u) in self.used.iter().enumerate() {
            let on_feature = |j: usize| self.feature_of[j] == k && active[j];
            let x: Vec<Vector3<f64>> = (0..n_touches)
                .filter(|&j| on_feature(j))
                .map(|j| tips[j])
                .collect();
            let degenerate = |shape: &str| {
                self.touches.degenerate(on_feature, |lines| {
                    format!(
                        "the touches of feature {} ({lines}) lie {shape}: it cannot be located",
                        u.feature.id()
                    )
                })
            };
            match u.feature {
                Feature::Sphere { radius_mm, .. } => {
                    let radii = vec![radius_mm + self.stylus_mm; x.len()];
                    let c = sphere_centre(&x, &radii).ok_or_else(|| degenerate("in one plane"))?;
                    nu.values[u.column..u.column + 3].copy_from_slice(c.as_slice());
                }
                Feature::Plane { .. } => {
                    let mean = x.iter().sum::<Vector3<f64>>() / x.len() as f64;
                    let scatter: nalgebra::Matrix3<f64> =
                        x.iter().map(|p| (p - mean) * (p - mean).transpose()).sum();
                    let eig = scatter.symmetric_eigen();
                    let order = {
                        let mut o = [0, 1, 2];
                        o.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
                        o
                    };
                    let (middle, largest) = (eig.eigenvalues[order[1]], eig.eigenvalues[order[2]]);
                    if middle.is_nan() || middle <= 1e-8 * largest {
                        return Err(degenerate("on one line"));
                    }
                    // The normal points out of the material, towards the
                    // probe: against the tool axes that touched it.
                    let mut n: Vector3<f64> = eig.eigenvectors.column(order[0]).into();
                    let mean_axis: Vector3<f64> = (0..n_touches)
                        .filter(|&j| on_feature(j))
                        .map(|j| axes[j])
                        .sum();
                    if n.dot(&mean_axis) > 0.0 {
                        n = -n;
                    }
                    nu.normals[k] = n;
                    nu.values[u.column + 2] = n.dot(&mean);
                }
            }
        }
        Ok(nu)
    }

    fn point_rows(&self, rows: PointRows<'_>, sink: &mut Sink) {
        let (j, x, k, nu) = (rows.record, rows.point, rows.k, rows.nu);
        let (jac, dnu, theta) = (rows.jac, rows.dnu, rows.theta);
        let x = x.position_mm;
        let f = self.feature_of[j];
        let u = &self.used[f];
        let col = u.column;
        let residual = match u.feature {
            Feature::Sphere { radius_mm, .. } => {
                let c = Vector3::new(nu.values[col], nu.values[col + 1], nu.values[col + 2]);
                let d = x - c;
                let rho = d.norm();
                let dir = d / rho;
                for m in 0..3 {
                    dnu[col + m] = -dir[m];
                }
                dnu[0] = -1.0;
                project_rows(&dir, jac, k, theta);
                radius_mm - (rho - nu.values[0])
            }
            Feature::Plane { .. } => {
                let n = nu.normals[f];
                let (a, b) = plane_basis(&n);
                dnu[col] = a.dot(&x);
                dnu[col + 1] = b.dot(&x);
                dnu[col + 2] = -1.0;
                project_rows(&n, jac, k, theta);
                -(n.dot(&x) - nu.values[col + 2])
            }
        };
        sink.data(j, 1.0 / self.touches.sigma_mm[j], dnu, theta, residual);
    }

    fn priors(&self, nu: &Nuisance, sink: &mut Sink) {
        sink.prior(0, self.stylus_sigma_mm, self.stylus_mm - nu.values[0]);
    }

    fn retract(&self, nu: &mut Nuisance, step: &[f64]) {
        nu.add(step);
        for (k, u) in self.used.iter().enumerate() {
            if let Feature::Plane { .. } = u.feature {
                let n = nu.normals[k];
                let (a, b) = plane_basis(&n);
                nu.normals[k] =
                    (n + a * nu.values[u.column] + b * nu.values[u.column + 1]).normalize();
                nu.values[u.column] = 0.0;
                nu.values[u.column + 1] = 0.0;
            }
        }
    }

    fn report_extra(&self, nu: &Nuisance) -> serde_json::Value {
        let normals: serde_json::Map<String, serde_json::Value> = self
            .used
            .iter()
            .zip(&nu.normals)
            .filter(|(u, _)| matches!(u.feature, Feature::Plane { .. }))
            .map(|(u, n)| {
                (
                    format!("f{}", u.feature.id()),
                    serde_json::json!([n.x, n.y, n.z]),
                )
            })
            .collect();
        serde_json::json!({ "plane_normals": normals })
    }

    fn nuisance_hint(&self) -> &'static str {
        "touch each sphere from directions spread over its surface, and each plane at points spread over it"
    }
}
