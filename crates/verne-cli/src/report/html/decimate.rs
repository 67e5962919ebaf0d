//! Series of any length in bounded memory, for plots: rows go into buckets of consecutive rows,
//! each keeping, per series, its smallest and largest value and where they were; when the
//! buckets are full, neighbours merge and the width doubles. Drawn as two points per bucket
//! (its extremes in the order they came), a bucket no wider than a pixel draws what every row
//! would: no spike, and so no finding, is hidden by the decimation.

/// Most buckets kept: merged to half when exceeded, so a long run ends with between half and
/// all of them (1024 to 2048: at least one per pixel of a plot).
pub const MAX_BUCKETS: usize = 2048;

/// The extremes of one series over one bucket: (value, row) of the smallest and the largest.
#[derive(Debug, Clone, Copy)]
struct Extremes {
    min: f64,
    min_at: u64,
    max: f64,
    max_at: u64,
}

impl Extremes {
    const EMPTY: Extremes = Extremes {
        min: f64::INFINITY,
        min_at: 0,
        max: f64::NEG_INFINITY,
        max_at: 0,
    };

    fn add(&mut self, v: f64, at: u64) {
        if v.is_nan() {
            return;
        }
        if v < self.min {
            self.min = v;
            self.min_at = at;
        }
        if v > self.max {
            self.max = v;
            self.max_at = at;
        }
    }

    fn merge(&mut self, o: &Extremes) {
        if o.min < self.min {
            self.min = o.min;
            self.min_at = o.min_at;
        }
        if o.max > self.max {
            self.max = o.max;
            self.max_at = o.max_at;
        }
    }

    /// The two extremes in the order they came (NaN for a bucket without a value).
    fn in_order(&self) -> (f64, f64) {
        if self.min > self.max {
            (f64::NAN, f64::NAN)
        } else if self.min_at <= self.max_at {
            (self.min, self.max)
        } else {
            (self.max, self.min)
        }
    }
}

/// One bucket: its first and last row, their x values (several kinds of x: a time column, the
/// summed segment times), the extremes of each series and the marks of the rows in it.
#[derive(Debug, Clone)]
struct Bucket<const N: usize, const X: usize> {
    first: u64,
    last: u64,
    x_first: [f64; X],
    x_last: [f64; X],
    series: [Extremes; N],
    marks: u32,
}

/// `N` series and `X` kinds of x over rows 0, 1, 2, ... pushed in order.
#[derive(Debug, Clone)]
pub struct Decimator<const N: usize, const X: usize> {
    buckets: Vec<Bucket<N, X>>,
    width: u64,
    rows: u64,
}

/// The points to draw: x of each kind, the row, each series, and the marks of each point.
#[derive(Debug, Clone, PartialEq)]
pub struct Points<const X: usize> {
    /// Rows per bucket (1: every row is a point).
    pub width: u64,
    pub row: Vec<u64>,
    pub x: [Vec<f64>; X],
    pub series: Vec<Vec<f64>>,
    pub marks: Vec<u32>,
}

impl<const N: usize, const X: usize> Default for Decimator<N, X> {
    fn default() -> Self {
        Decimator {
            buckets: Vec::new(),
            width: 1,
            rows: 0,
        }
    }
}

impl<const N: usize, const X: usize> Decimator<N, X> {
    /// Rows pushed.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Rows per bucket now.
    pub fn width(&self) -> u64 {
        self.width
    }

    /// The next row (the `rows()`-th, from 0), its x of each kind and its values (NaN: none).
    pub fn push(&mut self, x: [f64; X], values: &[f64; N]) {
        let row = self.rows;
        self.rows += 1;
        if (row / self.width) as usize >= MAX_BUCKETS {
            self.halve();
        }
        let k = (row / self.width) as usize;
        if k == self.buckets.len() {
            self.buckets.push(Bucket {
                first: row,
                last: row,
                x_first: x,
                x_last: x,
                series: [Extremes::EMPTY; N],
                marks: 0,
            });
        }
        let b = self.buckets.last_mut().expect("a bucket");
        b.last = row;
        b.x_last = x;
        for (e, v) in b.series.iter_mut().zip(values) {
            e.add(*v, row);
        }
    }

    /// Marks row `row` (already pushed) with `bits`.
    pub fn mark(&mut self, row: u64, bits: u32) {
        if let Some(b) = self.buckets.get_mut((row / self.width) as usize) {
            b.marks |= bits;
        }
    }

    fn halve(&mut self) {
        let old = std::mem::take(&mut self.buckets);
        let mut it = old.into_iter();
        while let Some(mut a) = it.next() {
            if let Some(b) = it.next() {
                a.last = b.last;
                a.x_last = b.x_last;
                for (e, o) in a.series.iter_mut().zip(&b.series) {
                    e.merge(o);
                }
                a.marks |= b.marks;
            }
            self.buckets.push(a);
        }
        self.width *= 2;
    }

    /// The points: one per row while every bucket is one row, else two per bucket, at its first
    /// and last row, holding its extremes in the order they came.
    pub fn points(&self) -> Points<X> {
        let per = if self.width == 1 { 1 } else { 2 };
        let n = self.buckets.len() * per;
        let mut p = Points {
            width: self.width,
            row: Vec::with_capacity(n),
            x: std::array::from_fn(|_| Vec::with_capacity(n)),
            series: vec![Vec::with_capacity(n); N],
            marks: Vec::with_capacity(n),
        };
        for b in &self.buckets {
            let ends = if per == 1 {
                &[(b.first, &b.x_first)][..]
            } else {
                &[(b.first, &b.x_first), (b.last, &b.x_last)][..]
            };
            for (k, (row, x)) in ends.iter().enumerate() {
                p.row.push(*row);
                for (xs, v) in p.x.iter_mut().zip(x.iter()) {
                    xs.push(*v);
                }
                for (s, e) in p.series.iter_mut().zip(&b.series) {
                    let (a, z) = e.in_order();
                    s.push(if per == 1 {
                        if e.min > e.max { f64::NAN } else { e.min }
                    } else if k == 0 {
                        a
                    } else {
                        z
                    });
                }
                p.marks.push(b.marks);
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Up to MAX_BUCKETS rows, every row is a point with its own value.
    #[test]
    fn short_series_are_kept_whole() {
        let mut d = Decimator::<2, 1>::default();
        for k in 0..MAX_BUCKETS {
            let v = k as f64;
            d.push([v * 0.5], &[v, if k % 3 == 0 { f64::NAN } else { -v }]);
        }
        let p = d.points();
        assert_eq!(p.width, 1);
        assert_eq!(p.row.len(), MAX_BUCKETS);
        for k in 0..MAX_BUCKETS {
            assert_eq!(p.row[k], k as u64);
            assert_eq!(p.x[0][k], k as f64 * 0.5);
            assert_eq!(p.series[0][k], k as f64);
            assert_eq!(p.series[1][k].is_nan(), k % 3 == 0);
        }
    }

    /// A million rows of noise with one spike up and one down, each a single row: the points
    /// are at most 2 x MAX_BUCKETS, and both spikes are among them at their exact values, in
    /// the bucket of their row; every bucket's values are the extremes of its rows.
    #[test]
    fn a_single_row_spike_survives_any_length() {
        let n = 1_000_000u64;
        let noise = |k: u64| ((k * 2_654_435_761) % 1000) as f64 / 1000.0;
        let (up, down) = (777_777u64, 123_457u64);
        let mut d = Decimator::<1, 1>::default();
        for k in 0..n {
            let v = if k == up {
                50.0
            } else if k == down {
                -40.0
            } else {
                noise(k)
            };
            d.push([k as f64], &[v]);
        }
        d.mark(up, 4);
        let p = d.points();
        assert!(
            p.row.len() <= 2 * MAX_BUCKETS && p.row.len() >= MAX_BUCKETS,
            "{}",
            p.row.len()
        );
        assert!(p.width > 1 && p.width.is_power_of_two());
        let s = &p.series[0];
        let at = |v: f64| s.iter().position(|x| *x == v).expect("kept");
        for (row, v) in [(up, 50.0), (down, -40.0)] {
            let i = at(v);
            // The bucket holding it spans its row.
            let (first, last) = if i % 2 == 0 {
                (p.row[i], p.row[i + 1])
            } else {
                (p.row[i - 1], p.row[i])
            };
            assert!(first <= row && row <= last, "{row} in {first}..{last}");
        }
        assert_eq!(p.marks[at(50.0)], 4);
        assert_eq!(p.marks.iter().filter(|m| **m != 0).count(), 2);
        // Every other bucket's extremes are of the noise.
        for (k, v) in s.iter().enumerate() {
            if *v != 50.0 && *v != -40.0 {
                assert!((0.0..1.0).contains(v), "{k}: {v}");
            }
        }
    }

    /// Within a bucket the two extremes come in the order of their rows.
    #[test]
    fn extremes_keep_their_order() {
        let mut d = Decimator::<1, 1>::default();
        // 2 x MAX_BUCKETS rows: one halving, each bucket two rows, drawn exactly as they came
        // (one row more would halve again).
        let rows = 2 * MAX_BUCKETS as u64;
        for k in 0..rows {
            d.push([k as f64], &[if k % 2 == 0 { 1.0 } else { -1.0 }]);
        }
        let p = d.points();
        assert_eq!(p.width, 2);
        for (k, v) in p.series[0].iter().enumerate() {
            let row = p.row[k];
            assert_eq!(
                *v,
                if row % 2 == 0 { 1.0 } else { -1.0 },
                "point {k} row {row}"
            );
        }
    }
}
