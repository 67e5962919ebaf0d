//! The arithmetic a formula can be written once for and then evaluated in several ways: in
//! double precision (`f64`), with rigorous bounds ([`crate::math::interval::Iv`]), in double-double
//! with an error bound ([`crate::math::dd::Tracked`]), or as the magnitude bound of its rounding error
//! ([`Mag`]).

use std::ops::{Add, Mul, Neg, Sub};

/// A ring with constants from `f64`: what the elimination formulas of the solvers need.
pub trait Scalar:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self> + From<f64>
{
}

impl<T> Scalar for T where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<Output = T> + Neg<Output = T> + From<f64>
{
}

/// The magnitude of an expression: the value it would have with every input replaced by its
/// absolute value and every subtraction by an addition. If the expression takes at most n
/// rounded operations on any path from an input, its computed value differs from the exact one
/// by at most about n * 2^-53 times this (Higham, *Accuracy and Stability of Numerical
/// Algorithms*, 2nd ed., section 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Mag(pub f64);

impl From<f64> for Mag {
    fn from(x: f64) -> Mag {
        Mag(x.abs())
    }
}

impl Add for Mag {
    type Output = Mag;
    #[inline]
    fn add(self, o: Mag) -> Mag {
        Mag(self.0 + o.0)
    }
}

impl Sub for Mag {
    type Output = Mag;
    /// A difference's magnitude is the sum of the magnitudes (that is the point).
    #[allow(clippy::suspicious_arithmetic_impl)]
    #[inline]
    fn sub(self, o: Mag) -> Mag {
        Mag(self.0 + o.0)
    }
}

impl Mul for Mag {
    type Output = Mag;
    #[inline]
    fn mul(self, o: Mag) -> Mag {
        Mag(self.0 * o.0)
    }
}

impl Neg for Mag {
    type Output = Mag;
    #[inline]
    fn neg(self) -> Mag {
        self
    }
}
