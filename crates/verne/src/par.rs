//! Data parallelism: with the `parallel` feature, rayon's parallel iterators; without it, the
//! same iterator chains (`par_iter`, `into_par_iter`, `with_min_len`, `flat_map_iter`,
//! `reduce(identity, op)`) run in order on the calling thread. The computations they carry are
//! independent per item and collected in order, so both give the same results.

#[cfg(feature = "parallel")]
pub(crate) use rayon::prelude::*;

#[cfg(not(feature = "parallel"))]
pub(crate) use sequential::*;

#[cfg(not(feature = "parallel"))]
mod sequential {
    /// An iterator run in order, with the methods of rayon's parallel iterators the crate uses.
    pub(crate) struct Seq<I>(I);

    /// `into_par_iter()` for anything iterable.
    pub(crate) trait IntoParallelIterator: IntoIterator + Sized {
        fn into_par_iter(self) -> Seq<Self::IntoIter> {
            Seq(self.into_iter())
        }
    }

    impl<T: IntoIterator> IntoParallelIterator for T {}

    /// `par_iter()` for slices (and through them vectors and arrays).
    pub(crate) trait ParallelSlice<T> {
        fn par_iter(&self) -> Seq<std::slice::Iter<'_, T>>;
    }

    impl<T> ParallelSlice<T> for [T] {
        fn par_iter(&self) -> Seq<std::slice::Iter<'_, T>> {
            Seq(self.iter())
        }
    }

    impl<I: Iterator> Seq<I> {
        pub(crate) fn map<R, F: FnMut(I::Item) -> R>(self, f: F) -> Seq<std::iter::Map<I, F>> {
            Seq(self.0.map(f))
        }

        pub(crate) fn enumerate(self) -> Seq<std::iter::Enumerate<I>> {
            Seq(self.0.enumerate())
        }

        pub(crate) fn with_min_len(self, _min: usize) -> Self {
            self
        }

        pub(crate) fn flat_map_iter<U: IntoIterator, F: FnMut(I::Item) -> U>(
            self,
            f: F,
        ) -> Seq<std::iter::FlatMap<I, U, F>> {
            Seq(self.0.flat_map(f))
        }

        pub(crate) fn reduce<ID, OP>(self, identity: ID, op: OP) -> I::Item
        where
            ID: Fn() -> I::Item,
            OP: Fn(I::Item, I::Item) -> I::Item,
        {
            self.0.fold(identity(), op)
        }

        pub(crate) fn collect<C: FromIterator<I::Item>>(self) -> C {
            self.0.collect()
        }
    }
}
