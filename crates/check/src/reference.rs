//! What a check is tested against: the calibrated machine, the covariance
//! of its calibration, the sensor offsets and temperature it was
//! calibrated at, from a calibrated machine file's `calibration` record.

use nalgebra::DMatrix;
use tricept_engine::model::GeometricModel;
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::ParameterSet;

use crate::error::CheckError;

/// The calibrated machine a check campaign is compared with.
///
/// # Example
/// ```
/// use nalgebra::DMatrix;
/// use tricept_check::Reference;
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// // A calibration known to 10 um in every parameter, at 20 °C.
/// let r = Reference::new(m, set, DMatrix::from_diagonal_element(15, 15, 1e-4), [0.0; 3], Some(20.0)).unwrap();
/// assert_eq!(r.parameter_set().len(), 15);
/// ```
#[derive(Debug, Clone)]
pub struct Reference {
    model: GeometricModel,
    covariance: DMatrix<f64>,
    offsets: [f64; 3],
    temperature_c: Option<f64>,
    name: String,
}

impl Reference {
    /// The calibrated `machine` with its parameter set, the covariance of
    /// the calibration (`k x k`, mm^2; zero rows and columns for held
    /// parameters), the sensor offsets it estimated (rad, rad, mm) and the
    /// mean structure temperature of its campaign (°C), when logged.
    pub fn new(
        machine: Machine,
        set: ParameterSet,
        covariance: DMatrix<f64>,
        offsets: [f64; 3],
        temperature_c: Option<f64>,
    ) -> Result<Reference, CheckError> {
        let k = set.len();
        if covariance.shape() != (k, k) || covariance.iter().any(|v| !v.is_finite()) {
            return Err(CheckError::Record(format!(
                "a {}x{} covariance with finite entries is needed for the {k} parameters of {}",
                covariance.nrows(),
                covariance.ncols(),
                set.label()
            )));
        }
        Ok(Reference {
            name: machine.name.clone(),
            model: GeometricModel::new(machine, set),
            covariance: 0.5 * (&covariance + covariance.transpose()),
            offsets,
            temperature_c,
        })
    }

    /// The reference of a calibrated machine file: its geometry, and from
    /// its `calibration` record the covariance (standard deviations and
    /// correlations), the sensor offsets, the temperature and the nominal
    /// machine whose rank rule the check keeps. A description without a
    /// record cannot be checked against (there is no prediction with an
    /// uncertainty).
    pub fn from_description(d: &MachineDescription) -> Result<Reference, CheckError> {
        let Some(c) = &d.calibration else {
            return Err(CheckError::Record(format!(
                "`{}` holds no `calibration` record: a check needs the calibration's estimates, their uncertainty and its sensor offsets (the machine file a calibration writes: identify's `write_machine`)",
                d.name
            )));
        };
        let label = c
            .parameter_set
            .strip_suffix(" + head")
            .unwrap_or(&c.parameter_set);
        let set = ParameterSet::by_label(label).map_err(|e| CheckError::Record(e.to_string()))?;
        let machine = d
            .build()
            .map_err(|e| CheckError::Record(format!("the machine: {e}")))?;
        let nominal = c
            .nominal
            .build()
            .map_err(|e| CheckError::Record(format!("`calibration.nominal`: {e}")))?;
        let sd: Vec<f64> = set
            .names()
            .iter()
            .map(|n| match c.std_dev_mm.get(n) {
                Some(serde_json::Value::Null) => Ok(0.0),
                Some(v) => v
                    .as_f64()
                    .filter(|s| s.is_finite() && *s >= 0.0)
                    .ok_or_else(|| {
                        CheckError::Record(format!("`std_dev_mm.{n}` is not a standard deviation"))
                    }),
                None => Err(CheckError::Record(format!("`std_dev_mm` has no `{n}`"))),
            })
            .collect::<Result<_, _>>()?;
        let k = set.len();
        let mut cov = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            k,
            sd.iter().map(|s| s * s),
        ));
        let corr = &c.correlations;
        let index: Vec<Option<usize>> = corr
            .names
            .iter()
            .map(|n| set.names().iter().position(|m| m == n))
            .collect();
        if corr.matrix.len() != corr.names.len()
            || corr.matrix.iter().any(|row| row.len() != corr.names.len())
        {
            return Err(CheckError::Record(
                "`correlations.matrix` is not square over `correlations.names`".into(),
            ));
        }
        for (a, ia) in index.iter().enumerate() {
            for (b, ib) in index.iter().enumerate() {
                if let (Some(i), Some(j)) = (ia, ib)
                    && i != j
                {
                    let rho = corr.matrix[a][b];
                    if !(rho.is_finite() && rho.abs() <= 1.0 + 1e-9) {
                        return Err(CheckError::Record(format!(
                            "`correlations.matrix[{a}][{b}]` = {rho} is not a correlation"
                        )));
                    }
                    cov[(*i, *j)] = rho * sd[*i] * sd[*j];
                }
            }
        }
        let o = &c.sensor_offsets;
        let mut r = Reference::new(
            machine,
            set,
            cov,
            [o.phi_rad, o.theta_rad, o.s_mm],
            c.temperature_c,
        )?;
        r.model = r.model.with_rank_reference(nominal);
        r.name = d.name.clone();
        Ok(r)
    }

    /// The model of the calibrated machine (increments on it, with the
    /// nominal machine's rank rule when the record names one).
    pub fn model(&self) -> &GeometricModel {
        &self.model
    }

    /// The calibrated machine.
    pub fn machine(&self) -> &Machine {
        self.model.nominal()
    }

    /// The parameter set of the calibration.
    pub fn parameter_set(&self) -> &ParameterSet {
        self.model.parameter_set()
    }

    /// Covariance of the calibration, mm^2.
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }

    /// The sensor offsets of the calibration (rad, rad, mm).
    pub fn offsets(&self) -> [f64; 3] {
        self.offsets
    }

    /// Mean structure temperature of the calibration campaign, °C.
    pub fn temperature_c(&self) -> Option<f64> {
        self.temperature_c
    }

    /// The directions of the parameter space the calibration determined,
    /// with their variances (mm^2): the eigenvectors of the covariance whose
    /// eigenvalue is positive (above 1e-12 of the largest). What a check
    /// allows the calibrated machine to be off by, direction by direction.
    pub fn prior_directions(&self) -> Vec<(f64, nalgebra::DVector<f64>)> {
        let k = self.covariance.nrows();
        let eigen = self.covariance.clone().symmetric_eigen();
        let largest = eigen.eigenvalues.iter().copied().fold(0.0, f64::max);
        (0..k)
            .filter(|&i| eigen.eigenvalues[i] > 0.0 && eigen.eigenvalues[i] > 1e-12 * largest)
            .map(|i| {
                (
                    eigen.eigenvalues[i],
                    eigen.eigenvectors.column(i).into_owned(),
                )
            })
            .collect()
    }

    /// The machine's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}
