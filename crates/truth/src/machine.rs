//! Machines and measurements the project did not generate: a true Tricept
//! written from the documented conventions alone (`docs/conventions.md`,
//! `docs/data-format.md`, the Table 1 machine of
//! `fixtures/machines/tricept-paper.json` read as plain JSON), never
//! through the project's kinematics, error model or simulator.
//!
//! - The module: base joints `B_i`, platform joints `A_i` (platform frame)
//!   and leg offsets, each coordinate the paper's frame conventions leave
//!   free off by N(0, 0.25 mm) (`docs/identifiability.md`: the four others
//!   are genuine errors the 15-parameter model assumes away; with them the
//!   internal data are not explained, chi2/dof about 7000); the x-first UP limb `R = Rx(phi) Ry(theta)`, `r = q4 R e_z`;
//!   leg `i` has length `|r + R A_i - B_i| = q_i + dq_i`; its forward
//!   kinematics by a Newton iteration of this file's own.
//! - The head: a general two-axis chain in the platform frame at zero
//!   angles: each axis a line (its direction tilted, its point shifted in
//!   all three coordinates, along the axis too), angle zeros (kinematic =
//!   command + zero), the tool tip off by 0.1-0.5 mm along the tool and a
//!   few hundredths of a mm across it, the tool direction tilted; the
//!   point `x` of the spindle goes to `p1 + Rot(k1, h1) (p2 + Rot(k2, h2)
//!   (x - p2) - p1)`. Sizes scale with the head table's
//!   (`TYPICAL_HEAD_ERRORS`: 0.3 mrad, 0.1 mm, 0.5 mrad, 0.3 mm, 0.05 mm),
//!   all by one factor ([`TrueMachine::random`]) or each kind by its own
//!   ([`HeadSizes`], [`TrueMachine::random_head`]).
//! - The sensors: offsets, noise of 0.8 arcsec and 0.5 um per reading,
//!   the mean of 3.
//! - A tracker at a random pose 1-3 m from the workspace (any rotation),
//!   10 um per coordinate; a ballbar, 1 um per reading.

use nalgebra::{Matrix3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

use crate::{ARCSEC_PER_RAD, normal, normal3, rot};

fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

fn vec3(v: &serde_json::Value) -> Vector3<f64> {
    Vector3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

/// The documented Table 1 machine, read as plain JSON.
fn table1() -> serde_json::Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/machines/tricept-paper.json"
    ))
    .unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A general two-axis head, platform frame at zero head angles.
#[derive(Debug, Clone)]
pub struct TrueHead {
    /// First (outer) axis direction, unit.
    pub k1: Vector3<f64>,
    /// A point of the first axis, mm.
    pub p1: Vector3<f64>,
    /// Second (inner) axis direction, unit.
    pub k2: Vector3<f64>,
    /// A point of the second axis, mm.
    pub p2: Vector3<f64>,
    /// The tool tip, mm.
    pub tip: Vector3<f64>,
    /// The tool direction, unit.
    pub direction: Vector3<f64>,
    /// Kinematic angle = command + zero, rad.
    pub zeros: [f64; 2],
}

impl TrueHead {
    /// Where spindle point `x` (platform frame at zero angles) goes at
    /// commanded angles `h`.
    pub fn point(&self, h: [f64; 2], x: &Vector3<f64>) -> Vector3<f64> {
        let (a, b) = (h[0] + self.zeros[0], h[1] + self.zeros[1]);
        let second = self.p2 + rot(&self.k2, b) * (x - self.p2);
        self.p1 + rot(&self.k1, a) * (second - self.p1)
    }

    /// The spindle's rotation at commanded angles `h`.
    pub fn rotation(&self, h: [f64; 2]) -> Matrix3<f64> {
        rot(&self.k1, h[0] + self.zeros[0]) * rot(&self.k2, h[1] + self.zeros[1])
    }
}

/// The sizes of a true head's errors by kind, in the head table's typical
/// sizes (`TYPICAL_HEAD_ERRORS`: axis tilts 0.3 mrad, axis points 0.1 mm,
/// angle zeros 0.5 mrad, the tool tip 0.1-0.5 mm along the tool and 0.05
/// mm across it, the tool's tilt 0.3 mrad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadSizes {
    /// The two axes' directions.
    pub axis_tilts: f64,
    /// The two axes' points.
    pub axis_points: f64,
    /// The two angle zeros.
    pub angle_zeros: f64,
    /// The tool tip along the tool.
    pub tool_length: f64,
    /// The tool tip across the tool.
    pub tool_across: f64,
    /// The tool's direction.
    pub tool_tilt: f64,
}

impl HeadSizes {
    /// Every kind `c` typical sizes.
    pub fn all(c: f64) -> HeadSizes {
        HeadSizes {
            axis_tilts: c,
            axis_points: c,
            angle_zeros: c,
            tool_length: c,
            tool_across: c,
            tool_tilt: c,
        }
    }
}

/// A true machine.
#[derive(Debug, Clone)]
pub struct TrueMachine {
    /// Base joints `B_i`, base frame, mm.
    pub base: [Vector3<f64>; 3],
    /// Platform joints `A_i`, platform frame, mm.
    pub platform: [Vector3<f64>; 3],
    /// True leg length minus command, mm.
    pub leg_offsets_mm: [f64; 3],
    /// The two-axis head.
    pub head: TrueHead,
    /// phi rad, theta rad, s mm.
    pub sensor_offsets: [f64; 3],
}

/// A unit vector perpendicular to unit `v`.
fn perpendicular(v: &Vector3<f64>) -> Vector3<f64> {
    let t = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (t - v * v.dot(&t)).normalize()
}

/// `v` (unit) tilted by N(0, sigma) along two directions across it.
fn tilted(v: &Vector3<f64>, sigma: f64, rng: &mut Pcg64Mcg) -> Vector3<f64> {
    let a = perpendicular(v);
    let b = v.cross(&a);
    let (x, y): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
    (v + a * sigma * x + b * sigma * y).normalize()
}

impl TrueMachine {
    /// The documented machine itself (no errors, no sensor offsets).
    pub fn documented() -> TrueMachine {
        let mut m = TrueMachine::random_sized(0.0, HeadSizes::all(0.0), 0);
        m.sensor_offsets = [0.0; 3];
        m.head.tip = vec3(&table1()["head"]["tool_tip_mm"]);
        m
    }

    /// A machine: module errors N(0, 0.25 mm); head errors `head_scale`
    /// times the head table's sizes; seeded.
    pub fn random(head_scale: f64, seed: u64) -> TrueMachine {
        TrueMachine::random_sized(0.25, HeadSizes::all(head_scale), seed)
    }

    /// A machine whose head's errors are of different sizes by kind
    /// (`sizes`, in the head table's typical sizes), as a real head's may
    /// be: module errors N(0, 0.25 mm); seeded. With every size `c` it is
    /// [`TrueMachine::random`]`(c, seed)`.
    pub fn random_head(sizes: HeadSizes, seed: u64) -> TrueMachine {
        TrueMachine::random_sized(0.25, sizes, seed)
    }

    fn random_sized(module_mm: f64, sizes: HeadSizes, seed: u64) -> TrueMachine {
        let d = table1();
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x1dea_0f00);
        let c = &d["placement"]["circular"];
        let (b, a) = (
            c["base_radius_mm"].as_f64().unwrap(),
            c["platform_radius_mm"].as_f64().unwrap(),
        );
        let angles: Vec<f64> = c["joint_angles_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap().to_radians())
            .collect();
        let joint = |r: f64, t: f64| Vector3::new(r * t.cos(), r * t.sin(), 0.0);
        // The paper's frame conventions (docs/identifiability.md): the base
        // plane through B1 and B2 (dzB1 = dzB2 = 0), B1B2 parallel to y
        // (dxB2 = dxB1), the platform plane through the A_i (dzA_i = 0); every
        // other coordinate and each leg is off by N(0, module_mm).
        let mut base: [Vector3<f64>; 3] = std::array::from_fn(|i| {
            let mut e = normal3(&mut rng, module_mm);
            if i < 2 {
                e.z = 0.0;
            }
            joint(b, angles[i]) + e
        });
        base[1].x = joint(b, angles[1]).x + (base[0].x - joint(b, angles[0]).x);
        let platform = std::array::from_fn(|i| {
            let mut e = normal3(&mut rng, module_mm);
            e.z = 0.0;
            joint(a, angles[i]) + e
        });
        let leg_offsets_mm = std::array::from_fn(|_| module_mm * normal(&mut rng));
        let h = &d["head"];
        let HeadSizes {
            axis_tilts: tilts,
            axis_points: points,
            angle_zeros: zeros,
            tool_length: length,
            tool_across: across_size,
            tool_tilt,
        } = sizes;
        let k1 = tilted(
            &vec3(&h["axis1_direction"]).normalize(),
            3e-4 * tilts,
            &mut rng,
        );
        let k2 = tilted(
            &vec3(&h["axis2_direction"]).normalize(),
            3e-4 * tilts,
            &mut rng,
        );
        let direction0 = vec3(&h["tool_direction"]).normalize();
        let direction = tilted(&direction0, 3e-4 * tool_tilt, &mut rng);
        let along =
            (0.1 + 0.4 * rng.random::<f64>()) * if rng.random::<bool>() { 1.0 } else { -1.0 };
        let across = perpendicular(&direction0);
        let (e1, e2): (f64, f64) = (
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
        );
        let tip = vec3(&h["tool_tip_mm"])
            + direction0 * along * length
            + across * 0.05 * across_size * e1
            + direction0.cross(&across) * 0.05 * across_size * e2;
        let head = TrueHead {
            k1,
            p1: vec3(&h["axis1_point_mm"]) + normal3(&mut rng, 0.1 * points),
            k2,
            p2: vec3(&h["axis2_point_mm"]) + normal3(&mut rng, 0.1 * points),
            tip,
            direction,
            zeros: std::array::from_fn(|_| 5e-4 * zeros * normal(&mut rng)),
        };
        TrueMachine {
            base,
            platform,
            leg_offsets_mm,
            head,
            sensor_offsets: [0.0123, -0.0187, -612.5],
        }
    }

    /// The UP limb's joints `(phi, theta, q4)` for leg commands `q` (mm):
    /// Newton on `|r + R A_i - B_i| = q_i + dq_i`, central differences,
    /// step halving; panics unless the lengths close to 1e-10 mm.
    pub fn forward(&self, q: &[f64; 3]) -> [f64; 3] {
        self.forward_lengths(&std::array::from_fn(|i| q[i] + self.leg_offsets_mm[i]))
    }

    /// The UP limb's joints `(phi, theta, q4)` for true leg lengths
    /// `lengths_mm` (`|r + R A_i - B_i|`, the leg offsets and any effect a
    /// test adds already in them); panics unless they close to 1e-10 mm.
    pub fn forward_lengths(&self, lengths_mm: &[f64; 3]) -> [f64; 3] {
        let residual = |x: &[f64; 3]| -> Vector3<f64> {
            let r_mat = rx(x[0]) * ry(x[1]);
            let r = r_mat * Vector3::new(0.0, 0.0, x[2]);
            Vector3::from_fn(|i, _| {
                (r + r_mat * self.platform[i] - self.base[i]).norm() - lengths_mm[i]
            })
        };
        let mut x = [
            0.0,
            0.0,
            (lengths_mm[0] + lengths_mm[1] + lengths_mm[2]) / 3.0,
        ];
        for _ in 0..100 {
            let f = residual(&x);
            if f.norm() < 1e-10 {
                return x;
            }
            let mut j = Matrix3::zeros();
            for c in 0..3 {
                let h = if c == 2 { 1e-6 } else { 1e-9 };
                let (mut up, mut down) = (x, x);
                up[c] += h;
                down[c] -= h;
                let d = (residual(&up) - residual(&down)) / (2.0 * h);
                j.set_column(c, &d);
            }
            let step = j.try_inverse().unwrap() * f;
            let mut t = 1.0;
            loop {
                let trial = [x[0] - t * step[0], x[1] - t * step[1], x[2] - t * step[2]];
                if residual(&trial).norm() < f.norm() || t < 1e-6 {
                    x = trial;
                    break;
                }
                t *= 0.5;
            }
        }
        panic!("the independent forward kinematics did not close at {lengths_mm:?}");
    }

    /// The platform's pose `(r, R)` for leg commands `q`.
    pub fn platform_pose(&self, q: &[f64; 3]) -> (Vector3<f64>, Matrix3<f64>) {
        self.platform_pose_at(&self.forward(q))
    }

    /// The platform's pose `(r, R)` at the UP limb's joints `(phi, theta,
    /// q4)` (from [`TrueMachine::forward_lengths`] when a leg effect is in
    /// the true lengths).
    pub fn platform_pose_at(&self, joints: &[f64; 3]) -> (Vector3<f64>, Matrix3<f64>) {
        let [phi, theta, q4] = *joints;
        let r_mat = rx(phi) * ry(theta);
        (r_mat * Vector3::new(0.0, 0.0, q4), r_mat)
    }

    /// The spindle point `offset_mm + extension_mm * tool direction` beyond
    /// the tool tip (spindle frame at zero head angles) in the base frame,
    /// at commands `q` and commanded head angles `h`.
    pub fn spindle_point(
        &self,
        q: &[f64; 3],
        h: [f64; 2],
        extension_mm: f64,
        offset_mm: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.spindle_point_at(&self.forward(q), h, extension_mm, offset_mm)
    }

    /// [`TrueMachine::spindle_point`] at the UP limb's joints `(phi, theta,
    /// q4)` instead of commands.
    pub fn spindle_point_at(
        &self,
        joints: &[f64; 3],
        h: [f64; 2],
        extension_mm: f64,
        offset_mm: &Vector3<f64>,
    ) -> Vector3<f64> {
        let (r, r_mat) = self.platform_pose_at(joints);
        let x = self.head.tip + self.head.direction * extension_mm + offset_mm;
        r + r_mat * self.head.point(h, &x)
    }

    /// The tool axis in the base frame.
    pub fn tool_axis(&self, q: &[f64; 3], h: [f64; 2]) -> Vector3<f64> {
        let (_, r_mat) = self.platform_pose(q);
        r_mat * self.head.rotation(h) * self.head.direction
    }

    /// Logged readings `[phi, theta, s]` at commands `q`: the joints plus
    /// the sensor offsets plus the mean of 3 readings' noise (0.8 arcsec,
    /// 0.5 um each).
    pub fn readings(&self, q: &[f64; 3], rng: &mut Pcg64Mcg) -> [f64; 3] {
        self.sensed(&self.forward(q), &SensorNoise::DOCUMENTED, rng)
    }

    /// Logged readings of joints `joints` (`[phi, theta, q4]`, rad, rad,
    /// mm): the joints plus the sensor offsets plus the mean of
    /// `noise.readings_per_pose` readings' noise.
    pub fn sensed(&self, joints: &[f64; 3], noise: &SensorNoise, rng: &mut Pcg64Mcg) -> [f64; 3] {
        let sigma = noise.sigma();
        let n = noise.readings_per_pose.max(1);
        std::array::from_fn(|c| {
            let mean: f64 = (0..n).map(|_| normal(rng)).sum::<f64>() / n as f64;
            joints[c] + self.sensor_offsets[c] + sigma[c] * mean
        })
    }

    /// The machine `kelvin` K warmer than at its calibration, every length
    /// of the structure grown by `ppm_per_k` (base and platform joints
    /// about the frames' origins, and the legs: the true length of leg `i`
    /// becomes `(q_i + dq_i) (1 + e)`, which a test applies through
    /// [`TrueMachine::warm_lengths`]).
    pub fn warmed(&self, ppm_per_k: f64, kelvin: f64) -> TrueMachine {
        let e = 1.0 + ppm_per_k * 1e-6 * kelvin;
        let mut m = self.clone();
        m.base = self.base.map(|b| b * e);
        m.platform = self.platform.map(|a| a * e);
        m
    }

    /// True leg lengths at commands `q` with leg `i` `kelvin[i]` K warmer
    /// (growth `ppm_per_k`): `(q_i + dq_i) (1 + ppm_per_k 1e-6 kelvin_i)`.
    pub fn warm_lengths(&self, q: &[f64; 3], ppm_per_k: f64, kelvin: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| {
            (q[i] + self.leg_offsets_mm[i]) * (1.0 + ppm_per_k * 1e-6 * kelvin[i])
        })
    }
}

/// The noise of the UP limb's sensors, as `docs/data-format.md` states it:
/// one reading's standard deviation and the number of readings averaged
/// per pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// One encoder reading, arcsec.
    pub angle_arcsec: f64,
    /// One scale reading, um.
    pub length_um: f64,
    /// Readings averaged per logged row.
    pub readings_per_pose: usize,
}

impl SensorNoise {
    /// The documented default: 0.8 arcsec, 0.5 um, the mean of 3.
    pub const DOCUMENTED: SensorNoise = SensorNoise {
        angle_arcsec: 0.8,
        length_um: 0.5,
        readings_per_pose: 3,
    };

    /// This noise times `factor` (a sensor noisier than stated).
    pub fn times(self, factor: f64) -> SensorNoise {
        SensorNoise {
            angle_arcsec: self.angle_arcsec * factor,
            length_um: self.length_um * factor,
            ..self
        }
    }

    /// One reading's standard deviation `[rad, rad, mm]`.
    pub fn sigma(&self) -> [f64; 3] {
        let rad = self.angle_arcsec / ARCSEC_PER_RAD;
        [rad, rad, self.length_um * 1e-3]
    }
}
