//! What proves that a solver's list of solutions is complete ([`Certificate`]), and the list
//! that carries it ([`Certified`]).

use arrayvec::ArrayVec;

/// What proves that the solutions returned are all the real ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Hash)]
#[non_exhaustive]
pub enum Certificate {
    /// Every real root of the eliminated equation isolated in double precision, each proved
    /// simple, with bounds on the rounding of the equation's coefficients and of its evaluation;
    /// every other angle proved not a root; each root gave its solution.
    #[default]
    Double,
    /// As [`Certificate::Double`], except on intervals where the equation has two roots closer
    /// than its rounding: there each of its two factors was proved to have one simple root, by
    /// interval arithmetic (forward kinematics: next to a zero of condition (21) of IFToMM 2007,
    /// where two assembly modes share nearly the same alpha; machine inverse kinematics: where
    /// the two signs of rho1 - zp meet, sin(alpha) = 0).
    Factored,
    /// Some interval needed the half-angle polynomial in double-double precision.
    Extended,
    /// Some interval could be decided by none of the methods: the solutions returned are what
    /// was found, not proved complete (status `uncertified`).
    Unproved,
}

impl Certificate {
    /// True unless [`Certificate::Unproved`].
    pub fn proved(self) -> bool {
        self != Certificate::Unproved
    }

    /// Its name in reports: `double`, `factored`, `extended`, `unproved`.
    pub fn code(self) -> &'static str {
        match self {
            Certificate::Double => "double",
            Certificate::Factored => "factored",
            Certificate::Extended => "extended",
            Certificate::Unproved => "unproved",
        }
    }
}

impl From<crate::math::certify::Resolution> for Certificate {
    fn from(r: crate::math::certify::Resolution) -> Certificate {
        use crate::math::certify::Resolution;
        match r {
            Resolution::Factored => Certificate::Factored,
            Resolution::Extended => Certificate::Extended,
            Resolution::Unproved => Certificate::Unproved,
        }
    }
}

/// A list of solutions with the certificate that says why there are no others. Dereferences to
/// the list.
#[derive(Debug, Clone, PartialEq)]
pub struct Certified<T, const N: usize> {
    items: ArrayVec<T, N>,
    /// How completeness was proved, or that it was not.
    pub certificate: Certificate,
}

impl<T, const N: usize> Default for Certified<T, N> {
    fn default() -> Self {
        Certified {
            items: ArrayVec::new(),
            certificate: Certificate::default(),
        }
    }
}

impl<T, const N: usize> Certified<T, N> {
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties the list and resets the certificate.
    pub fn reset(&mut self) {
        self.items.clear();
        self.certificate = Certificate::default();
    }

    /// Marks every item's verdict [`crate::parallel_module::branches::Reason::Uncertified`] when the list is not
    /// proved complete (no branch of such a row is the machine's without a word).
    pub fn mark_unproved(
        &mut self,
        verdict: impl Fn(&mut T) -> &mut crate::parallel_module::branches::Verdict,
    ) {
        if !self.certificate.proved() {
            for item in self.items.iter_mut() {
                verdict(item).add(crate::parallel_module::branches::Reason::Uncertified);
            }
        }
    }

    /// Lowers the certificate to `c` if that is weaker.
    pub fn weaken(&mut self, c: Certificate) {
        self.certificate = self.certificate.max(c);
    }
}

impl<T, const N: usize> std::ops::Deref for Certified<T, N> {
    type Target = ArrayVec<T, N>;
    fn deref(&self) -> &Self::Target {
        &self.items
    }
}

impl<T, const N: usize> std::ops::DerefMut for Certified<T, N> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.items
    }
}

impl<T, const N: usize> IntoIterator for Certified<T, N> {
    type Item = T;
    type IntoIter = arrayvec::IntoIter<T, N>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter()
    }
}

impl<'a, T, const N: usize> IntoIterator for &'a Certified<T, N> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
    }
}
