//! The full count of the constructed poses on the solvers' degenerate sets (docs/reliability.md): the forward kinematics
//! of the module, its inverse kinematics and the machine's inverse kinematics on poses built on
//! the solvers' degenerate sets, on the default machine and ten random valid geometries.
//!
//!     cargo run --release --example hard_sets [starts per set and machine, default 120]

use std::time::Instant;

use verne::selftest::hard_sets::{
    HardSet, Sampler, Tally, check_fk, check_ik, check_machine_ik, random_geometries,
};
use verne::spec::Machine;

fn main() {
    let starts: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(120);
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(10, 2024));
    let t0 = Instant::now();
    let mut rows = Vec::new();
    let (mut fk, mut ik) = (Tally::default(), Tally::default());
    for set in HardSet::ALL {
        let (mut f, mut i) = (Tally::default(), Tally::default());
        for (k, m) in machines.iter().enumerate() {
            let mut rng = Sampler::new(1000 * k as u64 + set as u64 + 1);
            f.add(check_fk(m, set, starts, &mut rng));
            i.add(check_ik(m, set, starts / 2, &mut rng));
        }
        rows.push((format!("module FK, {}", set.name()), f.clone()));
        rows.push((format!("module IK, {}", set.name()), i.clone()));
        fk.add(f);
        ik.add(i);
    }
    let mut mk = Tally::default();
    for (k, m) in machines.iter().enumerate() {
        let mut rng = Sampler::new(77 + k as u64);
        mk.add(check_machine_ik(m, starts, &mut rng));
    }
    rows.push(("machine IK, Table II double root".into(), mk.clone()));
    println!(
        "{:<38} {:>8} {:>5} {:>9} {:>9} {:>9}",
        "construction, set", "poses", "lost", "factored", "extended", "unproved"
    );
    for (name, t) in &rows {
        println!(
            "{name:<38} {:>8} {:>5} {:>9} {:>9} {:>9}",
            t.poses, t.lost, t.factored, t.extended, t.unproved
        );
    }
    let mut all = fk.clone();
    all.add(ik.clone());
    all.add(mk.clone());
    let pct = |n: u64| 100.0 * n as f64 / all.poses.max(1) as f64;
    println!(
        "\nall: {} poses on {} machines, {} lost; {:.2} % proved by the factors, {:.2} % in \
         double-double, {:.4} % unproved ({:.0} s)",
        all.poses,
        machines.len(),
        all.lost,
        pct(all.factored),
        pct(all.extended),
        pct(all.unproved),
        t0.elapsed().as_secs_f64()
    );
    for e in all.examples.iter().take(10) {
        println!("  {e}");
    }
}
