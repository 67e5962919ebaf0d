//! The fast paths give what the complete solvers give: `module_ik::working_fast` (the working
//! branch alone) against `module_ik::working(module_ik::solve(..))`, over a dense grid of the
//! reachable space, random points, and the neighbourhoods where it must hand over to the complete
//! solver (alpha = 0, y_p = 0, R1 cos(alpha) = r1, joint limits).

use nalgebra::Vector3;
use verne::machine::Machine;
use verne::module_ik::{self, IkBranch, IkBranches};

fn lin(lo: f64, hi: f64, n: usize, i: usize) -> f64 {
    lo + (hi - lo) * i as f64 / (n - 1) as f64
}

/// Deterministic points in [0, 1)^3.
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[derive(Default, Debug)]
struct Tally {
    points: usize,
    fast: usize,
    working: usize,
    worst_rad: f64,
    worst_mm: f64,
}

/// Compares the fast path with the complete solver at `p`; Err describes a disagreement.
fn agree(m: &Machine, p: &Vector3<f64>, t: &mut Tally) -> Result<(), String> {
    t.points += 1;
    let full = module_ik::solve(m, p);
    let expected: Option<&IkBranch> = module_ik::working(&full);
    t.working += expected.is_some() as usize;
    let fast = module_ik::working_fast(m, p);
    let mut via = IkBranches::new();
    module_ik::solve_working_into(m, p, &mut via);
    let via_working = module_ik::working(&via).copied();
    if via_working.is_some() != expected.is_some() {
        return Err(format!(
            "p={p:?}: solve_working_into {via_working:?} vs {expected:?}"
        ));
    }
    let Some(f) = fast else {
        return Ok(());
    };
    t.fast += 1;
    let Some(e) = expected else {
        return Err(format!(
            "p={p:?}: fast path found {f:?}, the complete solver no working branch"
        ));
    };
    if f.config != e.config || f.verdict != e.verdict {
        return Err(format!("p={p:?}: fast {f:?} vs {e:?}"));
    }
    let (da, dr) = ((f.alpha - e.alpha).abs(), (f.rho - e.rho).amax());
    t.worst_rad = t.worst_rad.max(da);
    t.worst_mm = t.worst_mm.max(dr);
    if da > 1e-12 || dr > 1e-9 {
        return Err(format!(
            "p={p:?}: fast {f:?} vs {e:?} (d alpha {da:e}, d rho {dr:e})"
        ));
    }
    Ok(())
}

fn check(points: impl Iterator<Item = Vector3<f64>>, m: &Machine) -> Tally {
    let mut t = Tally::default();
    let failures: Vec<String> = points.filter_map(|p| agree(m, &p, &mut t).err()).collect();
    eprintln!("{t:?}");
    assert!(
        failures.is_empty(),
        "{} disagreements, first: {:?}",
        failures.len(),
        &failures[..failures.len().min(5)]
    );
    t
}

#[test]
fn working_fast_matches_the_complete_solver_on_a_grid() {
    let m = Machine::default_verne();
    let n = 40;
    let grid = (0..n * n * n).map(|k| {
        let (i, j, l) = (k / (n * n), (k / n) % n, k % n);
        Vector3::new(
            lin(-650.0, 450.0, n, i),
            lin(-550.0, 550.0, n, j),
            lin(450.0, 1650.0, n, l),
        )
    });
    let t = check(grid, &m);
    // The fast path must carry the bulk of the reachable points, not hand everything over.
    assert!(t.working > n * n * n / 10, "{t:?}");
    assert!(t.fast * 100 >= t.working * 99, "{t:?}");
}

#[test]
fn working_fast_matches_the_complete_solver_on_random_points() {
    let m = Machine::default_verne();
    let mut r = Lcg(7);
    let pts: Vec<Vector3<f64>> = (0..50_000)
        .map(|_| {
            Vector3::new(
                -700.0 + 1200.0 * r.unit(),
                -600.0 + 1200.0 * r.unit(),
                400.0 + 1300.0 * r.unit(),
            )
        })
        .collect();
    check(pts.into_iter(), &m);
}

/// Points on and within 1e-12..1e-3 of the places where the fast path must hand over: y_p = 0
/// (alpha = 0 and the sign of eq. (14)), the joint limits of the working branch of a reachable
/// point, and R1 cos(alpha) = r1.
#[test]
fn working_fast_matches_the_complete_solver_near_hand_over_places() {
    let m = Machine::default_verne();
    let offsets = [
        0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6, 1e-5, -1e-5, 1e-3, -1e-3,
    ];
    let mut pts = Vec::new();
    for i in 0..25 {
        for k in 0..25 {
            let x = lin(-600.0, 400.0, 25, i);
            let z = lin(500.0, 1600.0, 25, k);
            pts.extend(offsets.iter().map(|&d| Vector3::new(x, d, z)));
        }
    }
    // Along rays from a reachable point: the working branch leaves the limits somewhere on each.
    let centre = Vector3::new(-250.0, 0.0, 1050.0);
    let mut r = Lcg(11);
    for _ in 0..400 {
        let dir = Vector3::new(r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5).normalize();
        let inside =
            |s: f64| module_ik::working(&module_ik::solve(&m, &(centre + dir * s))).is_some();
        let (mut a, mut b) = (0.0, 1500.0);
        if !inside(a) || inside(b) {
            continue;
        }
        for _ in 0..60 {
            let mid = 0.5 * (a + b);
            if inside(mid) { a = mid } else { b = mid }
        }
        pts.extend(offsets.iter().map(|&d| centre + dir * (a + d)));
    }
    check(pts.into_iter(), &m);
}
