//! The door's names for the `nalgebra` types its signatures hold, so that
//! a signature reads `Vector3` or `DMatrix` rather than nalgebra's full
//! generic type. They are aliases: every `nalgebra` operation applies.

/// A point or a direction in the machine's base frame (mm for a point):
/// `nalgebra`'s 3-vector of `f64`.
///
/// # Example
/// ```
/// use tricept_ident::kinematics::Vector3;
/// let p = Vector3::new(3.0, 4.0, 0.0);
/// assert_eq!(p.norm(), 5.0);
/// ```
pub type Vector3 = nalgebra::Vector3<f64>;

/// A dense matrix of `f64` whose size is known at run time (a covariance
/// of the estimates, say): `nalgebra`'s `DMatrix<f64>`.
///
/// # Example
/// ```
/// use tricept_ident::calibrate::DMatrix;
/// let m = DMatrix::from_diagonal_element(2, 2, 4.0);
/// assert_eq!(m[(1, 1)].sqrt(), 2.0);
/// assert_eq!(m.nrows(), 2);
/// ```
pub type DMatrix = nalgebra::DMatrix<f64>;
