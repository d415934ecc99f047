//! Sinumerik: leadscrew (measuring system) error compensation, LEC.
//!
//! The compensation table is the part program `%_N_AX_EEC_INI`: per
//! machine axis `AX`, `$AA_ENC_COMP[0,N,AX]` (mm) at the interpolation
//! points `N = 0 ..`, `$AA_ENC_COMP_STEP[0,AX]` (mm), `_MIN` and `_MAX`
//! (mm, the positions of the first and the last point) and
//! `_IS_MODULO[0,AX] = 0`. The control interpolates linearly between the
//! points and modifies the axis' actual position value by the table: a
//! positive value moves the axis in the negative direction, so the value
//! is the axis' error (how much longer the leg is than its position
//! says). Enabled by MD32700 `ENC_COMP_ENABLE[0] = 1`; MD38000
//! `MM_ENC_COMP_MAX_POINTS[0]` reserves the points (200 on an 808D); a
//! change of it reformats the static user memory at the next run-up.
//!
//! Thermal growth goes into the position-dependent temperature
//! compensation, whose slope SD43910 `TEMP_COMP_SLOPE` is "the gradient of
//! the approximated error line" of the "actual-value offsets": the error,
//! with the same sign as the LEC table. A leg of command `q` growing
//! `alpha q (T - T_ref)` has the error line of slope `+alpha 1e-6 (T -
//! T_ref)` through position 0. Sources in docs/controllers.md.

use crate::linear::{self, LinearTable};
use crate::setup::{ControlFiles, Setup};

/// Decimals of the values written, mm (1e-6 mm).
pub const DECIMALS: usize = 6;

/// The Sinumerik files of `setup`: the table program, the machine data,
/// and the parameters to set.
pub(crate) fn files(setup: &Setup) -> ControlFiles {
    let resolution = 10f64.powi(-(DECIMALS as i32));
    let (tables, mut out) = linear::plan_axes(setup, resolution, "MD38000 MM_ENC_COMP_MAX_POINTS");
    let names = &setup.names;
    let alpha = setup.params.thermal_expansion_ppm_per_k;
    let reference_c = setup.params.reference_temperature_c;
    out.files
        .push(("AX_EEC_INI.SPF".to_string(), table_program(&tables, names)));
    out.files.push((
        "MACHINE_DATA.TXT".to_string(),
        machine_data(&tables, names, &setup.backlash_mm, alpha, reference_c),
    ));
    out.carries_thermal = true;
    for (i, ax) in names.iter().enumerate() {
        out.parameters.push(format!(
            "{ax}: MD32700 ENC_COMP_ENABLE[0] = 1; MD38000 MM_ENC_COMP_MAX_POINTS[0] >= {} (a change reformats the static user memory at the next run-up: back up first); MD32450 BACKLASH[0] = {:.6} mm",
            tables[i].values_mm.len(),
            setup.backlash_mm[i]
        ));
        if alpha != 0.0 {
            out.parameters.push(format!(
                "{ax}: MD32750 TEMP_COMP_TYPE = 2 (position dependent); SD43900 TEMP_COMP_ABS_VALUE = 0; SD43920 TEMP_COMP_REF_POSITION = 0 mm; SD43910 TEMP_COMP_SLOPE = {:.6e} * (T - {reference_c} degC), set by the PLC",
                alpha * 1e-6,
            ));
        }
    }
    out
}

/// The table program of every axis (`names` the machine axis names).
pub fn table_program(tables: &[LinearTable], names: &[String]) -> String {
    let mut s = String::from("%_N_AX_EEC_INI\nCHANDATA(1)\n");
    s.push_str("; tricept export: leadscrew error compensation of the Tricept legs, mm;\n");
    s.push_str("; a positive value moves the axis in the negative direction (the leg is longer)\n");
    for (t, ax) in tables.iter().zip(names) {
        for (n, v) in t.values_mm.iter().enumerate() {
            s.push_str(&format!("$AA_ENC_COMP[0,{n},{ax}]={v:.DECIMALS$}\n"));
        }
        s.push_str(&format!(
            "$AA_ENC_COMP_STEP[0,{ax}]={:.DECIMALS$}\n",
            t.step_mm
        ));
        s.push_str(&format!(
            "$AA_ENC_COMP_MIN[0,{ax}]={:.DECIMALS$}\n",
            t.start_mm
        ));
        s.push_str(&format!(
            "$AA_ENC_COMP_MAX[0,{ax}]={:.DECIMALS$}\n",
            t.end_mm()
        ));
        s.push_str(&format!("$AA_ENC_COMP_IS_MODULO[0,{ax}]=0\n"));
    }
    s.push_str("M17\n");
    s
}

/// The machine and setting data to set, one assignment a line
/// (`backlash_mm` per axis; `thermal_ppm_per_k`, `reference_c` of the
/// legs' expansion, 0 for none).
pub fn machine_data(
    tables: &[LinearTable],
    names: &[String],
    backlash_mm: &[f64; 3],
    thermal_ppm_per_k: f64,
    reference_c: f64,
) -> String {
    let mut s = String::from("; tricept export: machine and setting data of the Tricept legs\n");
    s.push_str("; MD38000 MM_ENC_COMP_MAX_POINTS: a change is formatted into the static user memory at the next run-up: back up the NC data first\n");
    for (i, (t, ax)) in tables.iter().zip(names).enumerate() {
        s.push_str(&format!("$MA_ENC_COMP_ENABLE[0,{ax}]=1\n"));
        s.push_str(&format!(
            "$MA_MM_ENC_COMP_MAX_POINTS[0,{ax}]={}\n",
            t.values_mm.len()
        ));
        s.push_str(&format!(
            "$MA_BACKLASH[0,{ax}]={:.DECIMALS$}\n",
            backlash_mm[i]
        ));
        if thermal_ppm_per_k != 0.0 {
            s.push_str(&format!("$MA_TEMP_COMP_TYPE[{ax}]=2\n"));
            s.push_str(&format!("$SA_TEMP_COMP_ABS_VALUE[{ax}]=0\n"));
            s.push_str(&format!("$SA_TEMP_COMP_REF_POSITION[{ax}]=0\n"));
            s.push_str(&format!(
                "; $SA_TEMP_COMP_SLOPE[{ax}] = {:.6e} * (T - {reference_c}), T the legs' temperature in degC, set by the PLC (the gradient of the error line: the leg grows with T)\n",
                thermal_ppm_per_k * 1e-6
            ));
        }
    }
    s
}
