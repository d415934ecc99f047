//! The Fanuc writer's tests: its staircases against the exact correction.

use super::*;
use tricept_kinematics::description::LegTableDescription;

/// A lead error of `ppm` on a leg of stroke 640 to 1040 mm, the
/// reference at 800 mm.
fn lead(ppm: f64) -> LegCorrection {
    LegCorrection {
        leg: 0,
        lead_ppm: ppm,
        table: None,
        reference_mm: 800.0,
        lo_mm: 640.0,
        hi_mm: 1040.0,
    }
}

#[test]
fn a_lead_error_is_a_staircase_zero_at_the_reference_in_either_reading() {
    let leg = lead(50.0);
    let a = plan(&leg, 128, 0, 1.0, 127, 100);
    assert!(a.last_point - a.first_point < 128);
    for step_at in StepAt::BOTH {
        assert_eq!(a.output_mm(800.0, 1.0, step_at), 0.0);
        // 200 mm above the reference the axis is 10 um long: -10 um.
        assert!((a.output_mm(1000.0, 1.0, step_at) + 0.010).abs() < 0.0008);
        assert!((a.output_mm(700.0, 1.0, step_at) - 0.005).abs() < 0.0008);
    }
    // 50 ppm over two sections of ~3.15 mm (a level may cover either):
    // a level misses by half its range (0.16 um) plus half a detection
    // unit.
    assert!(
        a.format_error_um > 0.5 && a.format_error_um < 0.7,
        "{}",
        a.format_error_um
    );
}

#[test]
fn the_two_readings_are_one_interval_apart() {
    // Reaching a point outputs what entering its section did, one
    // interval later.
    let a = plan(&lead(300.0), 60, 0, 1.0, 127, 100);
    for j in 0..4000 {
        let q = 641.0 + 0.0997 * f64::from(j);
        let entering = a.output_mm(q, 1.0, StepAt::Entering);
        let reaching = a.output_mm(q + a.interval_mm, 1.0, StepAt::Reaching);
        if q + a.interval_mm < 1039.0 {
            assert!((entering - reaching).abs() < 1e-12, "{q}");
        }
    }
}

#[test]
fn the_magnification_grows_until_each_increment_fits_and_clipping_is_said() {
    // 5000 ppm over ~3.15 mm sections: 16 um a section, 7 at the most:
    // magnification 3.
    let a = plan(&lead(5000.0), 128, 0, 1.0, 7, 100);
    assert_eq!(a.magnification, 3);
    assert!(!a.clipped);
    assert!(a.increments.iter().all(|v| v.abs() <= 7));
    // 200 um a section cannot fit 1 x 100: clipped, and the error
    // says so.
    let b = plan(&lead(62_500.0), 128, 0, 1.0, 1, 100);
    assert!(b.clipped);
    assert_eq!(b.magnification, 100);
    assert!(b.format_error_um > 1000.0, "{}", b.format_error_um);
}

#[test]
fn a_section_holds_its_upper_end_and_not_its_lower() {
    // Section k runs from P_ref + (k - 1) h (excluded) to P_ref + k h.
    assert_eq!(section(10.0, 0.0, 2.0), 5);
    assert_eq!(section(10.5, 0.0, 2.0), 6);
    assert_eq!(section(8.5, 0.0, 2.0), 5);
    assert_eq!(section(0.0, 0.0, 2.0), 0);
    assert_eq!(section(-2.0, 0.0, 2.0), -1);
    assert_eq!(section(-2.5, 0.0, 2.0), -1);
    // 803.2 - 800 is 3.2000000000000455 in floating point: still the
    // end of section 2 of 1.6 mm.
    assert_eq!(section(803.2, 800.0, 1.6), 2);
}

#[test]
fn the_interval_is_the_smallest_whose_points_cover_the_stroke() {
    // 10 mm around the reference at 105 mm: n points put (n - 1) / 2
    // intervals on each side, so 12 points take 5 a side (one number
    // unused): 1 mm; 9 points take 4 a side: 1.25 mm.
    let leg = LegCorrection {
        leg: 0,
        lead_ppm: 0.0,
        table: None,
        reference_mm: 105.0,
        lo_mm: 100.0,
        hi_mm: 110.0,
    };
    let a = plan(&leg, 12, 0, 1.0, 127, 100);
    assert_eq!((a.interval_units, a.interval_mm), (1000, 1.0));
    assert_eq!(a.span_mm(), (100.0, 110.0));
    assert_eq!(plan(&leg, 12, 0, 0.1, 127, 100).interval_units, 10_000);
    let c = plan(&leg, 9, 0, 1.0, 127, 100);
    assert_eq!(c.interval_units, 1250);
    assert_eq!(c.last_point - c.first_point + 1, 9);
    // An off-centre reference: every number is used, the first point
    // at or below the stroke, the last at or above it, and one unit
    // less would need more points.
    for (reference_mm, points) in [(101.3, 7), (108.9, 20), (100.0, 3)] {
        let leg = LegCorrection {
            reference_mm,
            ..leg.clone()
        };
        let a = plan(&leg, points, 0, 1.0, 127, 100);
        let (lo, hi) = a.span_mm();
        assert!(lo <= 100.0 + 1e-9 && hi >= 110.0 - 1e-9, "{a:?}");
        assert!(a.last_point - a.first_point < points);
        let (k_lo, k_hi) = points_for(
            100.0,
            110.0,
            reference_mm,
            (a.interval_units - 1) as f64 * 1e-3,
        );
        assert!(
            (k_hi - k_lo + 1) as usize > points,
            "{reference_mm} {points}"
        );
    }
}

#[test]
fn clipping_on_either_side_of_the_reference_is_said() {
    // Three sections, the reference's the middle one; 1 um units, at
    // most 3 a point. Above the reference point k carries A_k -
    // A_(k-1); below, point k + 1 carries A_(k+1) - A_k.
    assert_eq!(
        increments_of(&[-0.002, 0.0, 0.002], -1, 0.001, 3),
        (vec![0, 2, 2], false)
    );
    assert_eq!(
        increments_of(&[0.0, 0.0, 0.010], -1, 0.001, 3),
        (vec![0, 0, 3], true)
    );
    assert_eq!(
        increments_of(&[-0.010, 0.0, 0.0], -1, 0.001, 3),
        (vec![0, 3, 0], true)
    );
}

/// The largest miss of `a`'s staircase of `leg` (in detection units of
/// `detection_unit_um`) in either reading: where the control leaves the
/// axis minus where the machine file asks for it, searched at setpoints
/// on a grid of 1 um over the span of the points and on either side of
/// every point.
fn largest_miss_um(a: &FanucAxis, leg: &LegCorrection, detection_unit_um: f64) -> f64 {
    let output = a.staircase(detection_unit_um);
    let miss = |p: f64| {
        StepAt::BOTH
            .map(|s| {
                let exact = crate::correction::settle(p, |x| leg.relative_mm(x) - a.shift_mm);
                (p + output.output_mm(p, s) - exact).abs() * 1e3
            })
            .into_iter()
            .fold(0.0, f64::max)
    };
    let (first, last) = a.span_mm();
    let steps = ((last - first) * 1e3).floor() as usize;
    let mut largest: f64 = 0.0;
    for j in 0..=steps {
        largest = largest.max(miss(first + j as f64 * 1e-3));
    }
    for k in 0..a.increments.len() {
        let point = first + a.interval_mm * k as f64;
        for p in [point - 1e-9, point, point + 1e-9] {
            if (first..=last).contains(&p) {
                largest = largest.max(miss(p));
            }
        }
    }
    largest
}

#[test]
fn the_format_error_is_the_staircase_s_largest_miss_in_either_reading() {
    // A lead error with the reference point off the grid of whole mm:
    // the format error is the largest difference between the staircase
    // (read back either way) and the exact correction, searched here on
    // a grid of 1 um and on either side of every point.
    let leg = LegCorrection {
        leg: 0,
        lead_ppm: 300.0,
        table: None,
        reference_mm: 800.37,
        lo_mm: 640.0,
        hi_mm: 1040.0,
    };
    let a = plan(&leg, 100, 0, 0.1, 127, 100);
    let largest = largest_miss_um(&a, &leg, 0.1);
    assert!(
        (a.format_error_um - largest).abs() < 2e-3,
        "{} um reported, {largest} um found",
        a.format_error_um
    );
    // A table rising 4 um/mm from 640 to 680 mm, flat above, the
    // reference near the bottom: the largest misses lie in the rise,
    // half of a level's range over its two sections (4 um/mm over 2
    // h) and up to half a unit (the magnification 2 keeps 16 um
    // within 127 units of 0.1).
    for rise_end_mm in [680.0, 681.7, 683.3] {
        let mut values = vec![160.0; 11];
        values[0] = 0.0;
        let leg = LegCorrection {
            lead_ppm: 0.0,
            table: Some(LegTableDescription::new(
                1,
                640.0,
                rise_end_mm - 640.0,
                values,
            )),
            reference_mm: 660.37,
            ..leg.clone()
        };
        let a = plan(&leg, 100, 0, 0.1, 127, 100);
        let largest = largest_miss_um(&a, &leg, 0.1);
        assert_eq!(a.magnification, 2);
        let slope = 160.0 / (rise_end_mm - 640.0);
        assert!(
            (largest - slope * a.interval_mm).abs() <= 0.1 + 1e-9,
            "{rise_end_mm}: {largest}"
        );
        assert!(
            (a.format_error_um - largest).abs() < 2e-3,
            "{rise_end_mm}: {} um reported, {largest} um found",
            a.format_error_um
        );
    }
}

#[test]
fn each_level_sits_at_the_middle_of_the_correction_s_range_knots_included() {
    // A deployed table zero but for a 10 um spike at one point, between
    // the samples a level's range is sought at (h/16 apart): the levels
    // covering it sit at the middle of 0 and 10 um, and the format
    // error is half the spike.
    // The interval depends on the stroke and the reference alone: the
    // spike is put at a table point halfway between two samples.
    let plain = LegCorrection {
        reference_mm: 800.37,
        ..lead(0.0)
    };
    let h = plan(&plain, 100, 0, 0.1, 127, 100).interval_mm;
    let spike = (12_000..12_200)
        .find(|k| {
            let sample = (640.0 + 0.02 * f64::from(*k) - 800.37) / (h / 16.0);
            (sample - sample.floor() - 0.5).abs() < 0.15
        })
        .unwrap();
    let values: Vec<f64> = (0..20_001)
        .map(|k| if k == spike { 10.0 } else { 0.0 })
        .collect();
    let leg = LegCorrection {
        leg: 0,
        lead_ppm: 0.0,
        table: Some(LegTableDescription::new(1, 640.0, 0.02, values)),
        reference_mm: 800.37,
        lo_mm: 640.0,
        hi_mm: 1040.0,
    };
    let spike_mm = 640.0 + 0.02 * f64::from(spike);
    let a = plan(&leg, 100, 0, 0.1, 127, 100);
    assert_eq!(a.interval_mm, h);
    assert!(
        (a.format_error_um - 5.0).abs() < 0.06,
        "{}",
        a.format_error_um
    );
    // Either reading outputs -5 um at the spike (the output is added to
    // the command; the leg is 10 um long there).
    for step_at in StepAt::BOTH {
        assert!((a.output_mm(spike_mm, 0.1, step_at) + 0.005).abs() < 0.06e-3);
    }
}

#[test]
fn a_hand_built_axis_outputs_its_values_summed_from_the_reference_outwards() {
    // Points 10 to 15, the reference 12 at 100 mm, 1 mm apart, in
    // units of 2 x 1 um. The module docs' reading: point n carries the
    // increment over the section from P_(n-1) to P_n, accumulated from
    // the reference outwards; entering: the level of point n over
    // (P_(n-1), P_n]; reaching: over [P_n, P_(n+1)). Worked by hand, the
    // levels: point 13: +4; 14: 4 + 1; 15: 5 + 2; 12: 0; 11: 0 - (-5)
    // (the reference point's own value); 10: 5 - 3; the first point's
    // value (7) never counts; beyond either end the end's level.
    let a = FanucAxis {
        reference_point: 12,
        first_point: 10,
        last_point: 15,
        magnification: 2,
        interval_units: 1000,
        interval_mm: 1.0,
        reference_mm: 100.0,
        increments: vec![7, 3, -5, 4, 1, 2],
        clipped: false,
        shift_mm: 0.0,
        format_error_um: 0.0,
    };
    let entering = [(90.0, 2), (97.5, 2), (98.5, 5), (99.5, 0), (100.5, 4)]
        .into_iter()
        .chain([(101.5, 5), (102.5, 7), (110.0, 7)]);
    let reaching = [(90.0, 2), (97.5, 2), (98.5, 2), (99.5, 5), (100.5, 0)]
        .into_iter()
        .chain([(101.5, 4), (102.5, 5), (103.5, 7), (110.0, 7)]);
    for (step_at, levels) in [
        (StepAt::Entering, entering.collect::<Vec<_>>()),
        (StepAt::Reaching, reaching.collect()),
    ] {
        for (q_mm, level) in levels {
            let expected_mm = f64::from(level) * 2.0 * 1e-3;
            let got = a.output_mm(q_mm, 1.0, step_at);
            assert!(
                (got - expected_mm).abs() < 1e-12,
                "{step_at:?} {q_mm} mm: {got} mm, not {expected_mm}"
            );
        }
    }
    // Entering: a section's upper end belongs to it; reaching: a point
    // takes its own level.
    assert!((a.output_mm(101.0, 1.0, StepAt::Entering) - 0.008).abs() < 1e-12);
    assert!((a.output_mm(98.0, 1.0, StepAt::Entering) - 0.004).abs() < 1e-12);
    assert!((a.output_mm(101.0, 1.0, StepAt::Reaching) - 0.008).abs() < 1e-12);
    assert!(a.output_mm(100.0, 1.0, StepAt::Reaching).abs() < 1e-12);
    assert_eq!(a.span_mm(), (98.0, 103.0));
}

#[test]
fn the_largest_point_count_is_planned_with_its_format_error() {
    // --max-points' largest value (100000) over a 400 mm stroke in
    // 1 um units: 4 um would take 100001 points, so 5 um. A 50 ppm
    // lead moves 0.5 nm over two sections: the staircase misses by
    // half a unit, 0.5 um, plus at most that.
    let leg = lead(50.0);
    let a = plan(&leg, 100_000, 0, 1.0, 127, 100);
    assert_eq!(a.interval_units, 5);
    assert_eq!(a.last_point - a.first_point + 1, 80_001);
    assert!(
        (0.5..0.51).contains(&a.format_error_um),
        "{}",
        a.format_error_um
    );
}
