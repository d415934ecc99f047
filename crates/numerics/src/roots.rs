//! Where a monotone condition starts to hold: bracketing by doubling, then
//! bisection.
//!
//! Every threshold the project searches for has this shape: a quantile of
//! the chi-square distribution (the tail probability falls below a level),
//! the non-centrality at which a test reaches a power, the encoder grade at
//! which a Monte Carlo median reaches a target. [`threshold`] is the one
//! search all of them use:
//!
//! 1. if the condition already holds at `lower`, the answer is `lower`;
//! 2. otherwise `upper` is doubled (and `lower` moved up behind it) until
//!    the condition holds at `upper`, or `upper` passes `limit`: then the
//!    condition is never reached in range, which is an answer, not a loop
//!    without end;
//! 3. the bracket `[lower, upper]` is halved `iterations` times, at the
//!    arithmetic or the geometric mean ([`Spacing`]), and its midpoint is
//!    returned.
//!
//! The condition may fail (a Monte Carlo run that errors): the error is
//! returned as it is.

/// Where the midpoint of a bracket is taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spacing {
    /// Arithmetic mean: for quantities that may be zero.
    Linear,
    /// Geometric mean: for positive quantities spanning decades (encoder
    /// grades). Both ends of the bracket must be positive.
    Logarithmic,
}

impl Spacing {
    fn midpoint(self, a: f64, b: f64) -> f64 {
        match self {
            Spacing::Linear => 0.5 * (a + b),
            Spacing::Logarithmic => (a * b).sqrt(),
        }
    }
}

/// The outcome of [`threshold`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// The condition already holds at the lower end.
    AtLower(f64),
    /// The condition turns true at (about) this value.
    At(f64),
    /// The condition does not hold anywhere up to the limit.
    NotReached,
}

impl Threshold {
    /// The value where the condition holds first, if it does in range.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::roots::Threshold;
    /// assert_eq!(Threshold::At(2.0).value(), Some(2.0));
    /// assert_eq!(Threshold::AtLower(0.5).value(), Some(0.5));
    /// assert_eq!(Threshold::NotReached.value(), None);
    /// ```
    pub fn value(self) -> Option<f64> {
        match self {
            Threshold::AtLower(x) | Threshold::At(x) => Some(x),
            Threshold::NotReached => None,
        }
    }
}

/// The value where `holds` turns from false to true, for a condition that
/// is false below some threshold and true above it (see the module docs).
/// `upper` is the first trial upper end (doubled while the condition fails
/// there, up to `limit`); `iterations` bisection steps follow.
///
/// # Example
/// ```
/// use tricept_numerics::roots::{Spacing, Threshold, threshold};
/// // sqrt(2): the first x with x^2 >= 2.
/// let t = threshold(0.0, 1.0, 1e6, Spacing::Linear, 60, |x| Ok::<_, ()>(x * x >= 2.0));
/// assert!((t.unwrap().value().unwrap() - 2f64.sqrt()).abs() < 1e-12);
/// // A condition that never holds ends the search instead of looping.
/// let never = threshold(0.0, 1.0, 1e6, Spacing::Linear, 60, |_| Ok::<_, ()>(false));
/// assert_eq!(never, Ok(Threshold::NotReached));
/// ```
pub fn threshold<E>(
    lower: f64,
    upper: f64,
    limit: f64,
    spacing: Spacing,
    iterations: u32,
    mut holds: impl FnMut(f64) -> Result<bool, E>,
) -> Result<Threshold, E> {
    if holds(lower)? {
        return Ok(Threshold::AtLower(lower));
    }
    let (mut lo, mut hi) = (lower, upper);
    loop {
        // A non-finite or non-growing bracket cannot be expanded further.
        if !(hi.is_finite() && hi > lo && hi <= limit) {
            return Ok(Threshold::NotReached);
        }
        if holds(hi)? {
            break;
        }
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..iterations {
        let mid = spacing.midpoint(lo, hi);
        if holds(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Threshold::At(spacing.midpoint(lo, hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_by_doubling_and_bisects() {
        // The condition turns at 1000: found from an upper end of 1.
        let t = threshold(0.0, 1.0, 1e9, Spacing::Linear, 80, |x| {
            Ok::<_, ()>(x >= 1000.0)
        })
        .unwrap();
        assert!((t.value().unwrap() - 1000.0).abs() < 1e-9, "{t:?}");
        // Geometric midpoints keep the relative precision over decades.
        let t = threshold(0.01, 0.02, 1e4, Spacing::Logarithmic, 60, |x| {
            Ok::<_, ()>(x >= 3.7)
        })
        .unwrap();
        assert!((t.value().unwrap() / 3.7 - 1.0).abs() < 1e-12, "{t:?}");
    }

    #[test]
    fn ends_and_errors_are_reported() {
        assert_eq!(
            threshold(2.0, 4.0, 10.0, Spacing::Linear, 10, |_| Ok::<_, ()>(true)),
            Ok(Threshold::AtLower(2.0))
        );
        // Beyond the limit: not reached (and a bounded number of calls).
        let mut calls = 0;
        let t = threshold(0.0, 1.0, 1e3, Spacing::Linear, 10, |_| {
            calls += 1;
            Ok::<_, ()>(false)
        });
        assert_eq!(t, Ok(Threshold::NotReached));
        assert!(calls <= 12, "{calls}");
        // An error of the condition is passed through.
        assert_eq!(
            threshold(0.0, 1.0, 1e3, Spacing::Linear, 10, |x| if x > 0.5 {
                Err("failed")
            } else {
                Ok(false)
            }),
            Err("failed")
        );
    }
}
