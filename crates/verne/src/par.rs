//! Data parallelism: with the `parallel` feature, rayon's parallel iterators; without it, the
//! same iterator chains (`par_iter`, `into_par_iter`, `with_min_len`, `flat_map_iter`,
//! `par_chunks`, `par_chunks_mut`, `zip`, `for_each`, `filter`, `copied`, `count`, `fold(identity, op)`, `reduce(identity, op)`,
//! `par_sort_unstable`) and `join` run in order on the calling thread. The computations they carry are
//! independent per item and collected in order, so both give the same results.

#[cfg(feature = "parallel")]
pub(crate) use rayon::join;
#[cfg(feature = "parallel")]
pub(crate) use rayon::prelude::*;

#[cfg(not(feature = "parallel"))]
pub(crate) use sequential::*;

#[cfg(not(feature = "parallel"))]
mod sequential {
    /// `join(a, b)`: `a` then `b`.
    pub(crate) fn join<A: FnOnce() -> RA, B: FnOnce() -> RB, RA, RB>(a: A, b: B) -> (RA, RB) {
        (a(), b())
    }

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
        fn par_chunks(&self, size: usize) -> Seq<std::slice::Chunks<'_, T>>;
    }

    impl<T> ParallelSlice<T> for [T] {
        fn par_iter(&self) -> Seq<std::slice::Iter<'_, T>> {
            Seq(self.iter())
        }

        fn par_chunks(&self, size: usize) -> Seq<std::slice::Chunks<'_, T>> {
            Seq(self.chunks(size))
        }
    }

    /// `par_sort_unstable()` for slices.
    pub(crate) trait ParallelSliceMut<T> {
        fn par_sort_unstable(&mut self)
        where
            T: Ord;
        fn par_chunks_mut(&mut self, size: usize) -> Seq<std::slice::ChunksMut<'_, T>>;
    }

    impl<T> ParallelSliceMut<T> for [T] {
        fn par_sort_unstable(&mut self)
        where
            T: Ord,
        {
            self.sort_unstable()
        }

        fn par_chunks_mut(&mut self, size: usize) -> Seq<std::slice::ChunksMut<'_, T>> {
            Seq(self.chunks_mut(size))
        }
    }

    impl<I: Iterator> IntoIterator for Seq<I> {
        type Item = I::Item;
        type IntoIter = I;
        fn into_iter(self) -> I {
            self.0
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

        pub(crate) fn filter<P: FnMut(&I::Item) -> bool>(
            self,
            p: P,
        ) -> Seq<std::iter::Filter<I, P>> {
            Seq(self.0.filter(p))
        }

        pub(crate) fn copied<'a, T: 'a + Copy>(self) -> Seq<std::iter::Copied<I>>
        where
            I: Iterator<Item = &'a T>,
        {
            Seq(self.0.copied())
        }

        pub(crate) fn zip<J: IntoIterator>(self, other: J) -> Seq<std::iter::Zip<I, J::IntoIter>> {
            Seq(self.0.zip(other))
        }

        pub(crate) fn for_each<F: FnMut(I::Item)>(self, f: F) {
            self.0.for_each(f)
        }

        pub(crate) fn count(self) -> usize {
            self.0.count()
        }

        /// One accumulator for the whole sequence (rayon makes one per piece of work).
        pub(crate) fn fold<T, ID, F>(self, identity: ID, f: F) -> Seq<std::iter::Once<T>>
        where
            ID: Fn() -> T,
            F: FnMut(T, I::Item) -> T,
        {
            Seq(std::iter::once(self.0.fold(identity(), f)))
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
