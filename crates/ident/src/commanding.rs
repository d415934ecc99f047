//! The machine a program commands: [`Machine`], the one type of the door
//! whose kinematics apply everything a machine file carries. Its inverse
//! and forward kinematics are the exact geometry (joints, leg offsets,
//! U-joint and guide-rail errors) plus the static leg effects a diagnosis
//! deploys (ball-screw lead, gravity compliance, per-leg compensation
//! tables): the same numbers as `tricept ik`, `fk` and `tool-ik` with
//! `--machine`, and the Python binding.
//!
//! The geometric machine alone (whose own kinematics ignore the leg
//! effects) is [`Machine::geometry`], for code that fits or simulates;
//! commanding a machine through it would be wrong by the leg effects
//! (tens of um for a deployed lead), so the door offers no shorter way.

use std::path::Path;

use tricept_kinematics::MachineDescription;
use tricept_kinematics::description::LegEffectsDescription;
use tricept_kinematics::{
    fk::FkSolution, head::HeadBranch, head::ToolIkSolution, machine::IkSolution,
};
use tricept_model::ExtendedMachine;

use crate::error::Error;
use crate::inputs::{LoadedMachine, SensorNoise, description_error, load_machine};
use crate::linalg::Vector3;

/// The geometric machine: joints, leg offsets, UP limb, head, sensors and
/// the leg effects it carries, whose **own** kinematics ignore those leg
/// effects. Reached through [`Machine::geometry`]; command a machine
/// through [`Machine`].
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{GeometricMachine, Machine};
/// let machine = Machine::paper();
/// let geometry: &GeometricMachine = machine.geometry();
/// assert_eq!(geometry, &GeometricMachine::paper());
/// ```
#[doc(inline)]
pub use tricept_kinematics::Machine as GeometricMachine;

/// A machine to command: inverse and forward kinematics with every effect
/// its file carries applied (the geometry and the static leg effects a
/// diagnosis deployed). Load one from a machine file ([`Machine::load`]),
/// take the calibrated one from a calibration
/// ([`crate::calibrate::Calibration::identified`]) or a diagnosis'
/// deployment (`Machine::from(&deployed)`,
/// [`crate::diagnosis::DiagnoseResult::deploy`]), or start from the
/// paper's Table 1 machine ([`Machine::paper`]).
///
/// # Example
/// ```
/// use tricept_ident::kinematics::{Machine, Vector3};
/// let m = Machine::paper();
/// let ik = m.inverse(&Vector3::new(0.0, 0.0, 750.0))?;
/// assert!((ik.legs_mm[0] - 773.3).abs() < 0.1);
/// // Forward kinematics undoes it.
/// let fk = m.forward(&ik.legs_mm)?;
/// assert!((fk.position_mm - Vector3::new(0.0, 0.0, 750.0)).norm() < 1e-8);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    extended: ExtendedMachine,
}

impl Machine {
    /// The paper's Table 1 machine (no errors, no leg effects).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// assert!(!Machine::paper().has_leg_effects());
    /// ```
    pub fn paper() -> Machine {
        Machine::from_geometry(GeometricMachine::paper())
    }

    /// The machine of a machine file (nominal or calibrated, deployed
    /// effects included), loaded as every workflow loads it: a calibrated
    /// file edited after its calibration is refused, an error naming the
    /// file.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/machines/tricept-paper.json");
    /// let m = Machine::load(file)?;
    /// assert_eq!(m, Machine::paper());
    /// let e = Machine::load("no/such/machine.json").unwrap_err();
    /// assert!(e.to_string().contains("no/such/machine.json"), "{e}");
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn load(path: impl AsRef<Path>) -> Result<Machine, Error> {
        Ok(load_machine(Some(path.as_ref()), &SensorNoise::default())?.commanding())
    }

    /// The machine a description describes (validated), with its leg
    /// effects; `source` names it in errors.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::{Machine, MachineDescription};
    /// let mut d = MachineDescription::paper();
    /// d.leg_effects.lead_ppm = [50.0, 0.0, 0.0];
    /// let m = Machine::from_description(&d, "my machine")?;
    /// assert!(m.has_leg_effects());
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn from_description(
        description: &MachineDescription,
        source: &str,
    ) -> Result<Machine, Error> {
        description
            .build()
            .map(Machine::from_geometry)
            .map_err(|e| description_error(source, e))
    }

    /// The machine whose geometry and leg effects are `geometry`'s.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::{GeometricMachine, Machine};
    /// let m = Machine::from_geometry(GeometricMachine::paper());
    /// assert_eq!(m, Machine::paper());
    /// ```
    pub fn from_geometry(geometry: GeometricMachine) -> Machine {
        Machine {
            extended: ExtendedMachine::new(geometry),
        }
    }

    /// Inverse kinematics: the leg commands (mm) and UP joints that put
    /// the platform point O' at `point_mm`, leg effects applied. A point
    /// out of reach is an input error.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::{Machine, Vector3};
    /// let ik = Machine::paper().inverse(&Vector3::new(100.0, -50.0, 760.0))?;
    /// assert!(ik.legs_mm.iter().all(|q| (700.0..900.0).contains(q)));
    /// assert!(Machine::paper().inverse(&Vector3::new(0.0, 0.0, 5000.0)).is_err());
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn inverse(&self, point_mm: &Vector3) -> Result<IkSolution, Error> {
        self.extended
            .inverse(point_mm)
            .map_err(|e| Error::with_context("ik", e))
    }

    /// Forward kinematics: the platform point and UP joints reached with
    /// the leg commands `legs_mm`, leg effects applied.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// let fk = Machine::paper().forward(&[800.0; 3])?;
    /// assert!(fk.position_mm.z > 700.0);
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn forward(&self, legs_mm: &[f64; 3]) -> Result<FkSolution, Error> {
        self.extended
            .forward(legs_mm)
            .map_err(|e| Error::with_context("fk", e))
    }

    /// Tool inverse kinematics: the leg commands and head angles that put
    /// the tool tip at `tip_mm` with its axis along `axis` (the head's
    /// default branch), leg effects applied.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::{Machine, Vector3};
    /// let s = Machine::paper().tool_inverse(&Vector3::new(0.0, 0.0, 900.0), &Vector3::z())?;
    /// assert!(!s.head_singular || s.head_rad[0].is_finite());
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn tool_inverse(&self, tip_mm: &Vector3, axis: &Vector3) -> Result<ToolIkSolution, Error> {
        self.extended
            .tool_inverse(tip_mm, axis, HeadBranch::default())
            .map_err(|e| Error::with_context("tool-ik", e))
    }

    /// Whether the machine carries any static leg effect (a lead, a
    /// compliance, a compensation table).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// assert!(!Machine::paper().has_leg_effects());
    /// ```
    pub fn has_leg_effects(&self) -> bool {
        self.extended.has_leg_effects()
    }

    /// The static leg effects applied (as the machine file writes them).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// assert_eq!(Machine::paper().leg_effects().lead_ppm, [0.0; 3]);
    /// ```
    pub fn leg_effects(&self) -> &LegEffectsDescription {
        &self.geometry().leg_effects
    }

    /// The geometric machine underneath, whose own kinematics ignore the
    /// leg effects: for fitting and simulating, not for commanding.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// assert_eq!(Machine::paper().geometry().leg_offsets_mm, [0.0; 3]);
    /// ```
    pub fn geometry(&self) -> &GeometricMachine {
        self.extended.machine()
    }

    /// The machine as a description (what a machine file holds, without a
    /// calibration record).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::{Machine, MachineDescription};
    /// assert_eq!(Machine::paper().to_description().leg_effects, MachineDescription::paper().leg_effects);
    /// ```
    pub fn to_description(&self) -> MachineDescription {
        self.geometry().to_description()
    }

    /// The same machine as the batch kinematics take it
    /// ([`crate::kinematics::run`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::kinematics::Machine;
    /// assert!(!Machine::paper().extended().has_leg_effects());
    /// ```
    pub fn extended(&self) -> &ExtendedMachine {
        &self.extended
    }
}

/// The machine a diagnosis deployed, its leg effects applied.
impl From<&tricept_diagnose::Deployed> for Machine {
    fn from(deployed: &tricept_diagnose::Deployed) -> Machine {
        Machine::from_geometry(deployed.geometry.clone())
    }
}

impl LoadedMachine {
    /// The machine to command, every effect of its file applied.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::MachineInput;
    /// use tricept_ident::kinematics::Machine;
    /// assert_eq!(MachineInput::default().load()?.commanding(), Machine::paper());
    /// # Ok::<(), tricept_ident::Error>(())
    /// ```
    pub fn commanding(&self) -> Machine {
        Machine::from_geometry(self.machine().clone())
    }
}
