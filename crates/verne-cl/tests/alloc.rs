//! No allocation per row in the steady state: a counting global allocator around a read of a
//! long file that mixes the common records (GOTO with 3 and 6 values, RAPID, FEDRAT, SPINDL,
//! LOADTL of the same tool, CIRCLE, a Creo multi-point arc, a cycle, PAINT, comments, free
//! text, a continued record). After the first block, the count must not grow.
//!
//! (Only the test's own thread is counted: the harness's threads do not disturb it.)

use std::io::Cursor;

use verne_cl::{Options, Reader};

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::{Counting, allocations, count_this_thread};

#[global_allocator]
static A: Counting = Counting;

const BLOCK: &str = "\
$$ block
PAINT/COLOR,31
LOADTL/4
SPINDL/RPM,3000,CLW
RAPID
GOTO/10,0,20,0,0,1
FEDRAT/MMPM,500
GOTO/10,0,0
GOTO/10.5,0,0,0,0.6,0.8
GOTO/10.0,0,0,0,0,1
CIRCLE/0,0,0,0,0,1,10
GOTO/0,10,0
CIRCLE / 0,0,0, 0,0,1, $
        10
GOTO / -10, 0, 0
       0,-10,0
       7.0710678119, -7.0710678119, 0
PPRINT/ text $ not continued
CYCLE/DRILL,RAPTO,2,FEDTO,-5,RTRCTO,AUTO,MMPM,100
GOTO/20,20,0
GOTO/30,20,0
CYCLE/OFF
FEDRAT/0.1,MMPR
GOTO/0,-10,0
";

#[test]
fn no_allocation_per_row_in_the_steady_state() {
    count_this_thread();
    let mut text = String::from("UNITS/MM\n");
    for _ in 0..2000 {
        text.push_str(BLOCK);
    }
    text.push_str("FINI\n");
    let bytes = text.into_bytes();
    let mut reader = Reader::new(Cursor::new(&bytes[..]), Options::default()).unwrap();
    let mut rows = 0u64;
    let mut at_warm = 0;
    let mut warm_rows = 0;
    for r in reader.by_ref() {
        let r = r.unwrap();
        std::hint::black_box(r);
        rows += 1;
        if rows == 5_000 {
            at_warm = allocations();
            warm_rows = rows;
        }
    }
    let after = allocations();
    let s = reader.summary();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.tools.len(), 1);
    eprintln!(
        "{rows} rows; {} allocations after the first {warm_rows} rows",
        after - at_warm
    );
    assert!(rows > 100_000, "{rows}");
    // The counter sees this thread: setting up the reader allocated.
    assert!(at_warm > 0, "the counting allocator counted nothing");
    assert_eq!(after - at_warm, 0, "allocations in the steady state");
}
