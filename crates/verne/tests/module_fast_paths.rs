//! The fast paths give what the complete solvers give: `ik::working_fast` (the working
//! branch alone) and `ik::solve_working_each` (four points side by side) against
//! `ik::working(ik::solve(..))`, over a dense grid of the reachable space, random
//! points, and the neighbourhoods where they must hand over to the complete solver (alpha = 0,
//! y_p = 0, R1 cos(alpha) = r1, joint limits); the FK tracker against `fk::solve`.

use nalgebra::Vector3;
use verne::parallel_module::ik::{self, IkBranch, IkBranches};
use verne::spec::Machine;

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

/// `n` deterministic points in a box around the reachable space.
fn random_points(seed: u64, n: usize) -> Vec<Vector3<f64>> {
    let mut r = Lcg(seed);
    (0..n)
        .map(|_| {
            Vector3::new(
                -700.0 + 1200.0 * r.unit(),
                -600.0 + 1200.0 * r.unit(),
                400.0 + 1300.0 * r.unit(),
            )
        })
        .collect()
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
    let full = ik::solve(m, p);
    let expected: Option<&IkBranch> = ik::working(&full);
    t.working += expected.is_some() as usize;
    let fast = ik::working_fast(m, p);
    let mut via = IkBranches::new();
    ik::solve_working_into(m, p, &mut via);
    let via_working = ik::working(&via).copied();
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
    check(random_points(7, 50_000).into_iter(), &m);
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
        let inside = |s: f64| ik::working(&ik::solve(&m, &(centre + dir * s))).is_some();
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

// ------------------------------------------------------------ FK: the working mode tracked

use verne::parallel_module::equations::Sliders;
use verne::parallel_module::fk::{self, FkModes};
use verne::parallel_module::track::FkTracker;

/// `fk::solve` (the AVX2 build where the processor has it) gives the modes of its
/// baseline x86-64 build bit for bit: the joints of every IK branch of random points, random
/// slider triples (a fifth with rho2 = rho3, where Det = 0 on a plane), cells not finite.
#[test]
fn fk_solve_builds_agree() {
    let m = Machine::default_verne();
    let mut rows: Vec<Sliders> = Vec::new();
    for p in random_points(29, 3000) {
        rows.extend(ik::solve(&m, &p).iter().map(|b| b.rho));
    }
    let mut r = Lcg(31);
    for k in 0..5000 {
        let (r1, r2) = (600.0 + 800.0 * r.unit(), 600.0 + 800.0 * r.unit());
        let r3 = if k % 5 == 0 {
            r2
        } else {
            600.0 + 800.0 * r.unit()
        };
        rows.push(Sliders::new(r1, r2, r3));
    }
    rows.extend([f64::NAN, f64::INFINITY, 1e300].map(|v| Sliders::new(1000.0, v, 1000.0)));
    let bits = |modes: &FkModes| -> Vec<_> {
        modes
            .iter()
            .map(|md| {
                let pose = [md.pose.alpha, md.pose.p.x, md.pose.p.y, md.pose.p.z];
                (
                    pose.map(f64::to_bits),
                    md.config,
                    format!("{:?}", md.verdict),
                )
            })
            .collect()
    };
    let mut modes = 0;
    for rho in &rows {
        let got = fk::solve(&m, rho);
        assert_eq!(
            bits(&got),
            bits(&fk::solve_baseline(&m, rho)),
            "rho={rho:?}"
        );
        modes += got.len();
    }
    assert!(modes > rows.len(), "{modes} modes on {} rows", rows.len());
}

/// Compares the tracked working mode with the complete solver's on every row of a path;
/// returns (rows with a working mode, rows answered by tracking).
fn tracked_agrees(m: &Machine, path: &[Sliders]) -> (usize, u64, u64) {
    let mut tracker = FkTracker::new(m);
    let mut modes = FkModes::new();
    let mut present = 0;
    for rho in path {
        tracker.working_into(rho, &mut modes);
        let t = &fk::working(&modes).copied();
        let full = fk::solve(m, rho);
        let e = fk::working(&full);
        assert_eq!(
            t.is_some(),
            e.is_some(),
            "rho={rho:?}: tracked {t:?} vs {e:?}"
        );
        if let (Some(t), Some(e)) = (t, e) {
            present += 1;
            let (da, dp) = (
                (t.pose.alpha - e.pose.alpha).abs(),
                (t.pose.p - e.pose.p).amax(),
            );
            assert!(
                da < 1e-11 && dp < 1e-9 && t.config == e.config && t.verdict == e.verdict,
                "rho={rho:?}: tracked {t:?} vs {e:?} (d alpha {da:e}, d p {dp:e})"
            );
        }
    }
    // Every row is answered once, by tracking or by the complete solution.
    assert_eq!(tracker.tracked + tracker.solved, path.len() as u64);
    (present, tracker.tracked, tracker.chord_steps)
}

/// Joints of the working branch along a helix of P (the path of the benchmarks).
fn helix_joints(m: &Machine, rows: usize) -> Vec<Sliders> {
    (0..rows)
        .filter_map(|k| {
            let t = k as f64 / rows as f64;
            let a = t * std::f64::consts::TAU;
            let p = Vector3::new(
                -250.0 + 120.0 * a.cos(),
                120.0 * a.sin(),
                1000.0 + 300.0 * t,
            );
            ik::working(&ik::solve(m, &p)).map(|b| b.rho)
        })
        .collect()
}

#[test]
fn tracked_fk_matches_the_complete_solver_along_a_helix() {
    let m = Machine::default_verne();
    let path = helix_joints(&m, 4096);
    let (present, tracked, steps) = tracked_agrees(&m, &path);
    assert_eq!(present, path.len());
    // Only the first row needs the complete solution.
    assert_eq!(tracked as usize, path.len() - 1);
    // The predictor (the pose extrapolated from the last two rows) leaves about three chord
    // steps a row: two to converge, one below rounding.
    assert!(
        steps <= 3 * tracked + tracked / 10,
        "{steps} chord steps for {tracked} rows"
    );
}

/// Along rays in joint space through the place where the working mode ends (it meets another
/// mode at a parallel singularity, or leaves a limit), forwards and back at 0.05 mm per row.
#[test]
fn tracked_fk_matches_the_complete_solver_through_branch_switches() {
    let m = Machine::default_verne();
    let starts = helix_joints(&m, 64);
    let mut r = Lcg(3);
    let (mut crossings, mut meeting, mut rows_present, mut tracked) = (0, 0, 0, 0);
    for start in starts {
        for _ in 0..6 {
            let dir = Vector3::new(r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5).normalize();
            let has = |s: f64| fk::working(&fk::solve(&m, &(start + dir * s))).is_some();
            let (mut a, mut b) = (0.0, 2000.0);
            if has(b) {
                continue;
            }
            for _ in 0..50 {
                let mid = 0.5 * (a + b);
                if has(mid) { a = mid } else { b = mid }
            }
            crossings += 1;
            // Is it a branch switch: does another mode come within 0.01 rad at the last row?
            let last = fk::solve(&m, &(start + dir * a));
            let w = fk::working(&last).map(|w| w.pose.alpha).unwrap_or(f64::NAN);
            meeting += last
                .iter()
                .any(|md| md.pose.alpha != w && (md.pose.alpha - w).abs() < 0.01)
                as usize;
            let forward: Vec<Sliders> = (0..=400)
                .map(|k| start + dir * (a - 10.0 + 0.05 * k as f64))
                .collect();
            let back: Vec<Sliders> = forward.iter().rev().copied().collect();
            for path in [forward, back] {
                let (present, t, _) = tracked_agrees(&m, &path);
                rows_present += present;
                tracked += t as usize;
            }
        }
    }
    eprintln!(
        "{crossings} crossings, {meeting} where two modes meet; {tracked} of {rows_present} rows with a working mode tracked"
    );
    assert!(
        crossings > 100 && meeting > 20,
        "{crossings} crossings, {meeting} meeting"
    );
    assert!(
        tracked * 10 > rows_present * 9,
        "{tracked} of {rows_present}"
    );
}

// ------------------------------------------------- IK: the working branch, points side by side

/// Compares the working branch of every point of `path`, solved LANES at a time
/// (`ik::solve_working_each`, as `verne ik` does), with the complete solver's; returns
/// (points with a working branch, points `ik::working_lanes` answered alone).
fn lanes_agree(m: &Machine, path: &[Vector3<f64>]) -> (usize, usize) {
    let mut got = vec![IkBranches::new(); path.len()];
    ik::solve_working_each(m, path.iter().copied().zip(got.iter_mut()));
    let mut present = 0;
    for (p, got) in path.iter().zip(&got) {
        let t = ik::working(got).copied();
        let full = ik::solve(m, p);
        let e = ik::working(&full);
        assert_eq!(t.is_some(), e.is_some(), "p={p:?}: lanes {t:?} vs {e:?}");
        if let (Some(t), Some(e)) = (t, e) {
            present += 1;
            let (da, dr) = ((t.alpha - e.alpha).abs(), (t.rho - e.rho).amax());
            assert!(
                da < 1e-12 && dr < 1e-9 && t.config == e.config && t.verdict == e.verdict,
                "p={p:?}: lanes {t:?} vs {e:?} (d alpha {da:e}, d rho {dr:e})"
            );
        }
    }
    let by_lanes = path
        .chunks_exact(ik::LANES)
        .map(|c| {
            let c: &[Vector3<f64>; ik::LANES] = c.try_into().unwrap();
            ik::working_lanes(m, c).iter().flatten().count()
        })
        .sum();
    (present, by_lanes)
}

fn helix_points(rows: usize) -> Vec<Vector3<f64>> {
    (0..rows)
        .map(|k| {
            let t = k as f64 / rows as f64;
            let a = t * std::f64::consts::TAU;
            Vector3::new(
                -250.0 + 120.0 * a.cos(),
                120.0 * a.sin(),
                1000.0 + 300.0 * t,
            )
        })
        .collect()
}

/// The bits of a branch, so that -0.0 and 0.0 (or two NaNs) are told apart.
fn branch_bits(b: &ik::IkBranch) -> ([u64; 4], [i8; 3], String) {
    let bits = [b.alpha, b.rho.x, b.rho.y, b.rho.z].map(f64::to_bits);
    (bits, b.config, format!("{:?}", b.verdict))
}

/// `ik::solve_each` (four points side by side, as `verne ik --all`) gives exactly the
/// lists `ik::solve` gives, branch for branch and bit for bit, whatever the grouping;
/// and so does its baseline x86-64 build (`solve_each` runs the AVX2 build where the processor
/// has AVX2).
#[test]
fn solve_each_gives_solves_lists() {
    let m = Machine::default_verne();
    let mut pts = helix_points(1024);
    pts.extend(random_points(17, 20_000));
    // y_p = 0 (alpha = 0 roots, both signs of eq. (11)) and near it.
    pts.extend(
        (0..400).map(|k| Vector3::new(-250.0, [0.0, 1e-9, -1e-7, 1e-4][k % 4], 1000.0 + k as f64)),
    );
    // Cells a CSV may hold: not finite, or far out.
    for v in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300, -0.0] {
        pts.extend([
            Vector3::new(v, 0.0, 1000.0),
            Vector3::new(-250.0, v, 1000.0),
            Vector3::new(-250.0, 10.0, v),
        ]);
    }
    for skip in [0, 1, 3] {
        let mut got = vec![IkBranches::new(); pts.len() - skip];
        ik::solve_each(&m, pts[skip..].iter().copied().zip(got.iter_mut()));
        let mut baseline = vec![IkBranches::new(); pts.len() - skip];
        ik::solve_each_baseline(&m, pts[skip..].iter().copied().zip(baseline.iter_mut()));
        for ((p, got), baseline) in pts[skip..].iter().zip(&got).zip(&baseline) {
            let expected = ik::solve(&m, p);
            for list in [got, baseline] {
                let bits: Vec<_> = list.iter().map(branch_bits).collect();
                let expected: Vec<_> = expected.iter().map(branch_bits).collect();
                assert_eq!(bits, expected, "p={p:?}");
            }
        }
    }
}

/// Every reason a branch can be refused for comes out of `ik::solve_each` as out of
/// `ik::solve`, bit for bit, on points with four leg-I postures (their labels come four
/// side by side in the AVX2 build, `module_ik_x4`): on the default machine and on one with
/// strokes 100-200 mm narrower at each end, each slider its own, and a rod-tilt limit beyond
/// 90 degrees (the other form of the tilt test).
#[test]
fn solve_each_labels_four_postures_as_solve_does() {
    use verne::parallel_module::branches::Reason;
    let mut other = Machine::default_verne();
    for (j, (lo, hi)) in [(150.0, 150.0), (100.0, 200.0), (200.0, 100.0)]
        .into_iter()
        .enumerate()
    {
        other.limits.rho_min[j] += lo;
        other.limits.rho_max[j] -= hi;
    }
    other.limits.cos_rod_tilt_max = 100f64.to_radians().cos();
    for (name, m) in [("default", Machine::default_verne()), ("other", other)] {
        let mut pts = helix_points(1024);
        pts.extend(random_points(31, 30_000));
        let mut got = vec![IkBranches::new(); pts.len()];
        ik::solve_each(&m, pts.iter().copied().zip(got.iter_mut()));
        let mut seen = std::collections::BTreeSet::new();
        let mut four = 0;
        for (p, got) in pts.iter().zip(&got) {
            let expected = ik::solve(&m, p);
            let bits = |list: &IkBranches| list.iter().map(branch_bits).collect::<Vec<_>>();
            assert_eq!(bits(got), bits(&expected), "{name}: p={p:?}");
            if got.len() == 16 {
                four += 1;
                seen.extend(
                    got.iter()
                        .flat_map(|b| b.verdict.reasons())
                        .map(|r| r.code()),
                );
            }
        }
        assert!(four > 3_000, "{name}: {four} points with sixteen branches");
        for r in Reason::ALL
            .into_iter()
            .filter(|r| !matches!(r, Reason::Theta1Range | Reason::Uncertified))
        {
            assert!(
                seen.contains(r.code()),
                "{name}: no branch with {}",
                r.code()
            );
        }
    }
}

/// `ik::solve_working_each` (as `verne ik`) gives the lists of its baseline x86-64 build
/// bit for bit (it runs the AVX2 build where the processor has AVX2).
#[test]
fn solve_working_each_builds_agree() {
    let m = Machine::default_verne();
    let mut pts = helix_points(1024);
    pts.extend(random_points(23, 20_000));
    pts.extend([f64::NAN, f64::INFINITY, 1e300].map(|v| Vector3::new(-250.0, v, 1000.0)));
    let mut got = vec![IkBranches::new(); pts.len()];
    ik::solve_working_each(&m, pts.iter().copied().zip(got.iter_mut()));
    let mut baseline = vec![IkBranches::new(); pts.len()];
    ik::solve_working_each_baseline(&m, pts.iter().copied().zip(baseline.iter_mut()));
    let mut working = 0;
    for ((p, got), baseline) in pts.iter().zip(&got).zip(&baseline) {
        let bits = |list: &IkBranches| list.iter().map(branch_bits).collect::<Vec<_>>();
        assert_eq!(bits(got), bits(baseline), "p={p:?}");
        working += usize::from(ik::working(got).is_some());
    }
    assert!(working > 2000, "{working} points with a working branch");
}

#[test]
fn lanes_match_the_complete_solver_along_a_helix() {
    let m = Machine::default_verne();
    let path = helix_points(4096);
    let (present, by_lanes) = lanes_agree(&m, &path);
    assert_eq!(present, path.len());
    // The helix crosses y_p = 0 twice (alpha = 0: handed over within the margin); every other
    // point is answered in one step from the estimate.
    assert!(by_lanes >= path.len() - 8, "{by_lanes} of {}", path.len());
}

/// Points all over and around the reachable space, the feasible ones among them answered by
/// the lanes almost always.
#[test]
fn lanes_match_the_complete_solver_on_scattered_points() {
    let m = Machine::default_verne();
    let pts = random_points(5, 20_000);
    let (present, by_lanes) = lanes_agree(&m, &pts);
    eprintln!("{present} with a working branch, {by_lanes} by the lanes");
    assert!(present > 1000);
    assert!(by_lanes * 100 > present * 95, "{by_lanes} of {present}");
}

/// Along rays through the places where the working branch ends (a joint or rod limit, two
/// roots of (9) meeting, rods of leg I crossing) and across y_p = 0 (alpha through 0, where the
/// two postures of a root meet), forwards and back at 0.05 mm per row.
#[test]
fn lanes_match_the_complete_solver_through_hand_over_places() {
    let m = Machine::default_verne();
    let starts = helix_points(64);
    let mut r = Lcg(13);
    let (mut crossings, mut rows_present, mut by_lanes) = (0, 0, 0);
    let has = |p: Vector3<f64>| ik::working(&ik::solve(&m, &p)).is_some();
    let mut rays = Vec::new();
    for start in &starts {
        for _ in 0..6 {
            let dir = Vector3::new(r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5).normalize();
            let (mut a, mut b) = (0.0, 2000.0);
            if !has(*start) || has(start + dir * b) {
                continue;
            }
            for _ in 0..50 {
                let mid = 0.5 * (a + b);
                if has(start + dir * mid) {
                    a = mid
                } else {
                    b = mid
                }
            }
            crossings += 1;
            rays.push((start + dir * (a - 10.0), dir));
        }
        // Across y_p = 0 along y.
        rays.push((Vector3::new(start.x, -10.0, start.z), Vector3::y()));
    }
    for (from, dir) in rays {
        let forward: Vec<Vector3<f64>> =
            (0..=400).map(|k| from + dir * (0.05 * k as f64)).collect();
        let back: Vec<Vector3<f64>> = forward.iter().rev().copied().collect();
        for path in [forward, back] {
            let (present, t) = lanes_agree(&m, &path);
            rows_present += present;
            by_lanes += t;
        }
    }
    eprintln!(
        "{crossings} crossings; {by_lanes} of {rows_present} rows with a working branch by the lanes"
    );
    assert!(crossings > 200, "{crossings} crossings");
    assert!(
        by_lanes * 10 > rows_present * 9,
        "{by_lanes} of {rows_present}"
    );
}

/// The tracker answers a row only within its certified radius (CERTIFIED_FRACTION of the
/// isolation radius 2 / (beta L)), not wherever its chord iteration converges: moving the three
/// sliders together moves the platform straight along z, where the Jacobian does not change, so
/// the iteration converges at once whatever the jump; a 5 mm jump is certified, a 9 mm one is
/// not and goes to the complete solution (the radius is about 7 mm here).
#[test]
fn the_tracker_answers_only_within_its_certified_radius() {
    let m = Machine::default_verne();
    let rho0 = Sliders::new(368.354796, 84.956547, 179.032689);
    for (jump, certified) in [(5.0, true), (9.0, false)] {
        let mut t = FkTracker::new(&m);
        let mut out = FkModes::default();
        t.working_into(&rho0, &mut out);
        let steps_before = t.chord_steps;
        let rho = rho0 + Sliders::new(jump, jump, jump);
        t.working_into(&rho, &mut out);
        assert!(
            t.chord_steps - steps_before <= 4,
            "the iteration converges in a few steps (of 8 allowed)"
        );
        assert_eq!(
            (t.tracked, t.solved),
            if certified { (1, 1) } else { (0, 2) },
            "{jump} mm"
        );
        let w = fk::working(&out).unwrap();
        let all = fk::solve(&m, &rho);
        let e = fk::working(&all).unwrap();
        assert!((w.pose.p - e.pose.p).amax() < 1e-9 && (w.pose.alpha - e.pose.alpha).abs() < 1e-12);
    }
}

/// The tracker's certified radius is the one its module documentation derives, to half a
/// percent: with beta the Frobenius norm of J(q*)^-1 in the scaled pose (alpha's row times the
/// platform radius R) and L = 4 (3 + max L_i / R), a row may move the pose by CERTIFIED_FRACTION
/// (1/4) of 2 / (beta L). Moving the three sliders together by d moves the platform by d along
/// z and leaves the rod vectors, so J and the radius, as they are; a jump of 0.995 of the radius
/// is tracked, one of 1.005 is sent to the complete solution.
#[test]
fn the_trackers_certified_radius_is_the_documented_one() {
    use verne::parallel_module::equations::jacobian_pose;
    let m = Machine::default_verne();
    let g = &m.module;
    let radius = g.r_big1.max(g.r_big2);
    let lipschitz = 4.0 * (3.0 + g.l1.max(g.l2).max(g.l3) / radius);
    for rho0 in [
        Sliders::new(368.354796, 84.956547, 179.032689),
        Sliders::new(300.0, 120.0, 150.0),
        Sliders::new(420.0, 60.0, 240.0),
    ] {
        let start = *fk::working(&fk::solve(&m, &rho0)).expect("a working mode");
        let inv = jacobian_pose(g, &start.pose, &rho0).try_inverse().unwrap();
        let beta = (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .map(|(i, j)| (inv[(i, j)] * if i == 3 { radius } else { 1.0 }).powi(2))
            .sum::<f64>()
            .sqrt();
        let certified = 0.25 * 2.0 / (beta * lipschitz);
        assert!(certified > 1.0, "{certified} mm at {rho0:?}");
        for (fraction, tracked) in [(0.995, true), (1.005, false)] {
            let jump = fraction * certified;
            let mut t = FkTracker::new(&m);
            let mut out = FkModes::default();
            t.working_into(&rho0, &mut out);
            let rho = rho0 + Sliders::new(jump, jump, jump);
            t.working_into(&rho, &mut out);
            assert_eq!(
                (t.tracked, t.solved),
                if tracked { (1, 1) } else { (0, 2) },
                "a jump of {jump} mm ({fraction} of the radius {certified}) at {rho0:?}"
            );
            let w = fk::working(&out).unwrap();
            assert!((w.pose.p.z - start.pose.p.z - jump).abs() < 1e-9);
            assert!((w.pose.p.xy() - start.pose.p.xy()).amax() < 1e-9);
            assert!((w.pose.alpha - start.pose.alpha).abs() < 1e-12);
        }
    }
}
