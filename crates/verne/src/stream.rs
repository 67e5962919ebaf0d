//! The row engine every streaming command runs on (`verne ik`, `fk`, `modes --csv`, the
//! machine commands, and [`crate::verify`]): rows go through in batches, and three batches are
//! in flight. While one batch is read (in input order, on one thread), the one before is
//! processed (its rows solved in parallel, then finished in input order) and the one before
//! that is written. Memory is bounded by three batches, whatever the length of the input.

use crate::par::join;

/// Runs `read`, `process` and `write` over batches until `read` finds no more rows.
///
/// - `read(batch)` refills a batch from the input and returns whether it holds any row.
/// - `process(batch)` solves a batch that was read; it sees the batches in input order, so
///   it may carry state from one batch to the next (branch continuity, the previous row).
/// - `write(batch)` writes a processed batch; it too sees them in input order.
///
/// The three stages of consecutive batches run side by side. A stage's error ends the run:
/// of the errors of one step, the write's is returned first, then the process's, then the
/// read's (the order of the rows they concern). The batches are reused from step to step.
pub fn run_batches<B, E, R, P, W>(batches: [B; 3], read: R, process: P, write: W) -> Result<(), E>
where
    B: Send,
    E: Send,
    R: FnMut(&mut B) -> Result<bool, E> + Send,
    P: FnMut(&mut B) -> Result<(), E> + Send,
    W: FnMut(&mut B) -> Result<(), E> + Send,
{
    // The loop runs on one of rayon's workers (`rayon::scope` moves it there from the calling
    // thread, which then waits once for the whole run): its joins hand work to the other worker
    // directly, instead of waking the calling thread and a worker at every batch.
    #[cfg(feature = "parallel")]
    return rayon::scope(move |_| three_in_flight(batches, read, process, write));
    #[cfg(not(feature = "parallel"))]
    three_in_flight(batches, read, process, write)
}

/// The loop of [`run_batches`].
fn three_in_flight<B, E, R, P, W>(
    batches: [B; 3],
    mut read: R,
    mut process: P,
    mut write: W,
) -> Result<(), E>
where
    B: Send,
    E: Send,
    R: FnMut(&mut B) -> Result<bool, E> + Send,
    P: FnMut(&mut B) -> Result<(), E> + Send,
    W: FnMut(&mut B) -> Result<(), E> + Send,
{
    let [mut reading, mut processing, mut writing] = batches;
    let mut more = read(&mut reading)?;
    // Whether `writing` holds a processed batch not yet written.
    let mut to_write = false;
    while more {
        std::mem::swap(&mut reading, &mut processing);
        let (read_result, (written, processed)) = join(
            || read(&mut reading),
            || {
                join(
                    || {
                        if to_write {
                            write(&mut writing)
                        } else {
                            Ok(())
                        }
                    },
                    || process(&mut processing),
                )
            },
        );
        written?;
        processed?;
        more = read_result?;
        std::mem::swap(&mut processing, &mut writing);
        to_write = true;
    }
    if to_write {
        write(&mut writing)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A batch of the test: the numbers read, and their squares once processed.
    #[derive(Default)]
    struct Batch {
        read: Vec<u64>,
        squared: Vec<u64>,
    }

    /// Streams 0..n in batches of `size`; returns what was written, in order.
    fn stream(n: u64, size: usize, fail: Option<(&str, u64)>) -> Result<Vec<u64>, String> {
        let mut next = 0u64;
        let mut written = Vec::new();
        let mut carried = 0u64;
        let fails =
            |stage: &str, b: &Batch| fail.is_some_and(|(s, at)| s == stage && b.read.contains(&at));
        run_batches(
            Default::default(),
            |b: &mut Batch| {
                b.read.clear();
                while b.read.len() < size && next < n {
                    b.read.push(next);
                    next += 1;
                }
                if fails("read", b) {
                    return Err(format!("read {:?}", b.read));
                }
                Ok(!b.read.is_empty())
            },
            |b: &mut Batch| {
                // State carried across batches: the batches come in order.
                for &v in &b.read {
                    assert_eq!(v, carried, "batches processed out of order");
                    carried += 1;
                }
                b.squared = b.read.iter().map(|v| v * v).collect();
                if fails("process", b) {
                    return Err(format!("process {:?}", b.read));
                }
                Ok(())
            },
            |b: &mut Batch| {
                if fails("write", b) {
                    return Err(format!("write {:?}", b.read));
                }
                written.extend_from_slice(&b.squared);
                Ok(())
            },
        )?;
        Ok(written)
    }

    #[test]
    fn every_row_is_written_once_in_order() {
        for (n, size) in [(0, 3), (1, 3), (3, 3), (4, 3), (10, 3), (100, 7), (9, 1)] {
            let out = stream(n, size, None).unwrap();
            let expected: Vec<u64> = (0..n).map(|v| v * v).collect();
            assert_eq!(out, expected, "n = {n}, batches of {size}");
        }
    }

    #[test]
    fn an_error_stops_the_run_at_its_batch() {
        // Batches of 3: [0,1,2] [3,4,5] [6,7,8] [9].
        assert_eq!(
            stream(10, 3, Some(("read", 4))).unwrap_err(),
            "read [3, 4, 5]"
        );
        assert_eq!(
            stream(10, 3, Some(("process", 7))).unwrap_err(),
            "process [6, 7, 8]"
        );
        assert_eq!(stream(10, 3, Some(("write", 9))).unwrap_err(), "write [9]");
        // A later batch's read error waits for the earlier batch's process error.
        assert_eq!(
            stream(10, 3, Some(("process", 0))).unwrap_err(),
            "process [0, 1, 2]"
        );
    }
}
