//! Library invariants of the glider mechanisms (Wenger, Gosselin, Chablat 2001): the paper's
//! Tables 1 and 2, IK/FK round trips, an independent FK root count, singularities and
//! amplification factors.

use std::f64::consts::{FRAC_PI_4, PI, SQRT_2};

use nalgebra::{Matrix2, Point2, Vector2};
use verne::glider::*;

/// Agreement demanded between two computations of the same exact quantity (multiples of L).
const EXACT_TOL: f64 = 1e-9;
/// Table 1: L0 and delta-rho within 1 % of the printed values.
const TABLE1_LENGTH_REL: f64 = 0.01;
/// Table 1: S within 5 % of the printed value (the paper measured it with a CAD sketcher).
const TABLE1_S_REL: f64 = 0.05;
/// Table 2: lengths scale as 1 / sqrt(S), so they inherit half of S's difference, plus the
/// rounding of the printed two decimals.
const TABLE2_LENGTH_REL: f64 = 0.03;
/// Table 2: the envelope scales as 1 / S.
const TABLE2_ENVELOPE_REL: f64 = 0.05;

fn presets() -> Vec<GliderSpec> {
    PRESET_NAMES
        .iter()
        .map(|n| GliderSpec::preset(n).unwrap())
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

// ---------------------------------------------------------------- Table 1 and Table 2

#[test]
fn table1_reproduces_paper() {
    // Table 1, Wenger 2001: (mechanism, L0 / L, delta-rho / L, S / L^2).
    let paper = [
        ("biglide1", 1.946, 0.547, 0.107),
        ("biglide2", 0.458, 0.529, 0.249),
        ("orthoglide", 1.961, 1.109, 0.885),
    ];
    let rows = table1(&DesignOptions::default());
    assert_eq!(rows.len(), 3);
    for (row, (name, l0, dr, s)) in rows.iter().zip(paper) {
        assert_eq!(row.mechanism, name);
        assert_eq!(
            (row.l0_paper, row.delta_rho_paper, row.s_paper),
            (l0, dr, s)
        );
        assert!(rel(row.l0, l0) < TABLE1_LENGTH_REL, "{name} L0 {}", row.l0);
        assert!(
            rel(row.delta_rho, dr) < TABLE1_LENGTH_REL,
            "{name} dr {}",
            row.delta_rho
        );
        assert!(rel(row.s, s) < TABLE1_S_REL, "{name} S {}", row.s);
        assert!((row.s_rel_diff - (row.s - s) / s).abs() < EXACT_TOL);
        assert!(row.square <= row.s + EXACT_TOL);
    }
    // Section 3.3: the rectangle is an exact square for biglide1 and the orthoglide, far from
    // one for the biglide2.
    for row in &rows {
        let aspect = row.s_width.max(row.s_height) / row.s_width.min(row.s_height);
        if row.mechanism == "biglide2" {
            assert!(aspect > 2.0, "biglide2 aspect {aspect}");
        } else {
            assert!(aspect < 1.01, "{} aspect {aspect}", row.mechanism);
        }
    }
}

#[test]
fn table2_reproduces_paper() {
    // Table 2, Wenger 2001 (1 m^2 rectangle): (mechanism, L0, L, delta-rho, envelope).
    let paper = [
        ("biglide1", 5.95, 3.05, 1.67, 16.45),
        ("biglide2", 0.92, 2.00, 1.06, 8.50),
        ("orthoglide", 2.08, 1.06, 1.18, 3.91),
    ];
    // Section 3.3: biglide2 dimensioned for a 1 m^2 square.
    let square_b2 = (1.075, 2.348, 1.242);
    let rows = table1(&DesignOptions::default());
    let t2 = table2(&rows, 1.0);
    assert_eq!(t2.len(), 6);
    for (row, (name, l0, l, dr, env)) in t2[..3].iter().zip(paper) {
        assert_eq!(
            (row.mechanism.as_str(), row.target),
            (name, Target::Rectangle)
        );
        assert!(rel(row.l0, l0) < TABLE2_LENGTH_REL, "{name} L0 {}", row.l0);
        assert!(rel(row.l, l) < TABLE2_LENGTH_REL, "{name} L {}", row.l);
        assert!(
            rel(row.delta_rho, dr) < TABLE2_LENGTH_REL,
            "{name} dr {}",
            row.delta_rho
        );
        assert!(
            rel(row.envelope, env) < TABLE2_ENVELOPE_REL,
            "{name} env {}",
            row.envelope
        );
    }
    let sq = t2
        .iter()
        .find(|r| r.mechanism == "biglide2" && r.target == Target::Square)
        .unwrap();
    assert!(
        rel(sq.l0, square_b2.0) < TABLE2_LENGTH_REL,
        "square L0 {}",
        sq.l0
    );
    assert!(
        rel(sq.l, square_b2.1) < TABLE2_LENGTH_REL,
        "square L {}",
        sq.l
    );
    assert!(
        rel(sq.delta_rho, square_b2.2) < TABLE2_LENGTH_REL,
        "square dr {}",
        sq.delta_rho
    );
}

#[test]
fn table2_design_has_the_target_area() {
    // Independent of the scaling rule: rebuild the scaled orthoglide and biglide2 and measure.
    let rows = table1(&DesignOptions::default());
    for row in table2(&rows, 1.0)
        .iter()
        .filter(|r| r.target == Target::Rectangle)
    {
        let arch = Architecture::from_name(&row.mechanism).unwrap();
        let (a1, a2) = arch.alphas();
        let dims = Dimensions {
            l: row.l,
            l0: row.l0,
            delta_rho: row.delta_rho,
        };
        let spec = design_spec(arch.name(), a1, a2, dims);
        let t1 = rows.iter().find(|r| r.mechanism == row.mechanism).unwrap();
        let grid = sample_workspace(
            &spec,
            &WorkspaceOptions {
                frame_angle: t1.s_angle_deg.to_radians(),
                ..WorkspaceOptions::default()
            },
        );
        let rect = largest_rectangle(&grid).unwrap();
        // Coarser grid (801 nodes) than Table 1 (1201): a few grid steps of slack.
        assert!(
            (rect.area() - 1.0).abs() < 0.02,
            "{} {}",
            row.mechanism,
            rect.area()
        );
    }
}

/// Section 2.7 amplification from the paper's own form J^-1 = [(1/c1) e1^T; (1/c2) e2^T]
/// (e_i unit strut vectors, c_i = cos(theta_i - alpha_i)): lambda = 1 / singular values.
fn lambdas_section_2_7(
    e1: Vector2<f64>,
    e2: Vector2<f64>,
    u1: Vector2<f64>,
    u2: Vector2<f64>,
) -> (f64, f64) {
    let (c1, c2) = (e1.dot(&u1), e2.dot(&u2));
    let jinv = Matrix2::new(e1.x / c1, e1.y / c1, e2.x / c2, e2.y / c2);
    let sv = jinv.svd(false, false).singular_values;
    let (g_max, g_min) = (sv[0].max(sv[1]), sv[0].min(sv[1]));
    (1.0 / g_max, 1.0 / g_min)
}

/// P above CD (assembly +) for struts of length 1, by the perpendicular bisector.
fn apex(c: Point2<f64>, d: Point2<f64>) -> Point2<f64> {
    let v = d - c;
    let h = (1.0 - v.norm_squared() / 4.0).sqrt();
    nalgebra::center(&c, &d) + Vector2::new(-v.y, v.x).normalize() * h
}

#[test]
fn dimensions_match_closed_forms_for_any_bounds() {
    for (lo, hi) in [(1.0 / 3.0_f64, 3.0_f64), (0.5, 2.0), (0.25, 4.0)] {
        // biglide1, symmetric configuration with s = L0 / 2 (L = 1): lambda = {1/sqrt2,
        // s / (sqrt2 t)}, t = sqrt(1 - s^2). lambda = hi at CD = L0, lambda = lo at CD = L0 - 2 dr.
        let s = (2.0 * hi * hi / (1.0 + 2.0 * hi * hi)).sqrt();
        let s2 = (2.0 * lo * lo / (1.0 + 2.0 * lo * lo)).sqrt();
        let d = dimension(0.0, PI, 1.0, [lo, hi]).unwrap();
        assert!(
            (d.l0 - 2.0 * s).abs() < EXACT_TOL,
            "biglide1 L0 {} bounds {lo} {hi}",
            d.l0
        );
        assert!(
            (d.delta_rho - (s - s2)).abs() < EXACT_TOL,
            "biglide1 dr {}",
            d.delta_rho
        );

        // orthoglide: lambda = {(s + t) / (2 s), (s + t) / (2 t)}; the larger reaches hi at both
        // ends; D - C = (L0 - sqrt2 rho, 0).
        let k = 2.0 * hi - 1.0;
        let s = k / (1.0 + k * k).sqrt();
        let s2 = 1.0 / (1.0 + k * k).sqrt();
        let d = dimension(FRAC_PI_4, 3.0 * FRAC_PI_4, 1.0, [lo, hi]).unwrap();
        assert!((d.l0 - 2.0 * s).abs() < EXACT_TOL, "orthoglide L0 {}", d.l0);
        assert!(
            (d.delta_rho - SQRT_2 * (s - s2)).abs() < EXACT_TOL,
            "orthoglide dr"
        );

        // biglide2: C, D level gives lambda_max = t / (sqrt2 s) = hi. Then delta-rho solves
        // lambda_min = lo at C = (0, 0), D = (L0, dr), by bisection on the section 2.7 formula.
        let s = 1.0 / (1.0 + 2.0 * hi * hi).sqrt();
        let l0 = 2.0 * s;
        let u = Vector2::new(0.0, 1.0);
        let lam_min = |dr: f64| {
            let (c, dd) = (Point2::new(0.0, 0.0), Point2::new(l0, dr));
            let p = apex(c, dd);
            lambdas_section_2_7(p - c, p - dd, u, u).0
        };
        let (mut good, mut bad) = (0.0, 1.5);
        for _ in 0..100 {
            let mid = 0.5 * (good + bad);
            if lam_min(mid) >= lo {
                good = mid
            } else {
                bad = mid
            }
        }
        let d = dimension(PI / 2.0, PI / 2.0, 1.0, [lo, hi]).unwrap();
        assert!((d.l0 - l0).abs() < EXACT_TOL, "biglide2 L0 {}", d.l0);
        assert!(
            (d.delta_rho - good).abs() < 1e-7,
            "biglide2 dr {} vs {good}",
            d.delta_rho
        );
    }
    // Scaling: every length is proportional to L.
    let d1 = dimension(0.0, PI, 1.0, PAPER_LAMBDA_BOUNDS).unwrap();
    let d3 = dimension(0.0, PI, 3.0, PAPER_LAMBDA_BOUNDS).unwrap();
    assert!((d3.l0 - 3.0 * d1.l0).abs() < 3.0 * EXACT_TOL);
    assert!((d3.delta_rho - 3.0 * d1.delta_rho).abs() < 3.0 * EXACT_TOL);
}

#[test]
fn presets_are_the_section_3_2_designs() {
    for arch in Architecture::ALL {
        let preset = GliderSpec::preset(arch.name()).unwrap();
        let design = architecture_spec(arch, 1.0, PAPER_LAMBDA_BOUNDS).unwrap();
        assert_eq!(preset.name, design.name);
        assert!((preset.alpha1 - design.alpha1).abs() < EXACT_TOL);
        assert!((preset.alpha2 - design.alpha2).abs() < EXACT_TOL);
        assert!((preset.l0 - design.l0).abs() < EXACT_TOL, "{}", arch.name());
        for k in 0..2 {
            assert!((preset.rho1_range[k] - design.rho1_range[k]).abs() < EXACT_TOL);
            assert!((preset.rho2_range[k] - design.rho2_range[k]).abs() < EXACT_TOL);
        }
    }
    assert!(GliderSpec::preset("triglide").is_none());
}

// ---------------------------------------------------------------- kinematics

#[test]
fn ik_then_fk_round_trip_every_mode() {
    for spec in presets() {
        let mut seen = std::collections::BTreeMap::new();
        for i in 0..=40 {
            for j in 0..=40 {
                let p = Point2::new(
                    -1.0 + (spec.l0 + 2.0) * i as f64 / 40.0,
                    -1.5 + 3.5 * j as f64 / 40.0,
                );
                for sol in inverse_kinematics(&spec, p) {
                    *seen.entry(sol.mode.to_string()).or_insert(0) += 1;
                    // The root satisfies both strut equations.
                    let (c, d) = spec.sliders(sol.rho);
                    assert!(((p - c).norm() - spec.l1).abs() < EXACT_TOL);
                    assert!(((p - d).norm() - spec.l2).abs() < EXACT_TOL);
                    assert_eq!(sol.mode, working_mode_of(&spec, p, sol.rho));
                    // FK of the joints gives P back, with the same labels.
                    let fk = forward_kinematics(&spec, sol.rho);
                    if let ForwardKinematics::StructuralSingularity { centre, radius } = fk {
                        // biglide1 in modes +- and -+: both sliders on one line, so C = D
                        // (Fig. 5); P is on the circle of possible positions.
                        assert_eq!(spec.name, "biglide1");
                        assert!(sol.mode.strut1 != sol.mode.strut2);
                        assert!(((p - centre).norm() - radius).abs() < EXACT_TOL);
                        *seen.entry("structural".to_string()).or_insert(0) += 1;
                        continue;
                    }
                    let hit = fk.solutions().iter().find(|s| (s.p - p).norm() < 1e-8);
                    let hit = hit.unwrap_or_else(|| panic!("{} {p} {}", spec.name, sol.mode));
                    assert_eq!(hit.assembly, sol.assembly);
                    assert_eq!(hit.mode, sol.mode);
                    // The single-mode solvers agree.
                    if sol.mode.strut1 != Branch::Double && sol.mode.strut2 != Branch::Double {
                        let rho = inverse_kinematics_in_mode(&spec, p, sol.mode).unwrap();
                        assert!((rho - sol.rho).norm() < EXACT_TOL);
                    }
                }
            }
        }
        for mode in WorkingMode::ALL {
            assert!(
                seen.get(&mode.to_string()).copied().unwrap_or(0) > 100,
                "{} {mode}",
                spec.name
            );
        }
    }
}

#[test]
fn fk_then_ik_round_trip_both_assembly_modes() {
    for spec in presets() {
        let mut assemblies = [0usize; 2];
        for i in 0..=30 {
            for j in 0..=30 {
                let rho = Vector2::new(-1.0 + 3.0 * i as f64 / 30.0, -1.0 + 3.0 * j as f64 / 30.0);
                for s in forward_kinematics(&spec, rho).solutions() {
                    match s.assembly {
                        Branch::Plus => assemblies[0] += 1,
                        Branch::Minus => assemblies[1] += 1,
                        Branch::Double => {}
                    }
                    assert_eq!(s.assembly, assembly_of(&spec, s.p, rho));
                    let back = inverse_kinematics(&spec, s.p);
                    let hit = back.iter().find(|b| b.mode == s.mode);
                    let hit = hit.unwrap_or_else(|| panic!("{} {rho} {}", spec.name, s.mode));
                    assert!(
                        (hit.rho - rho).norm() < 1e-8,
                        "{} {rho} {}",
                        spec.name,
                        hit.rho
                    );
                }
            }
        }
        assert!(
            assemblies[0] > 100 && assemblies[1] > 100,
            "{} {assemblies:?}",
            spec.name
        );
    }
}

/// Independent FK: P = C + l1 (cos t, sin t); roots of |P - D|^2 - l2^2 by a dense scan of t
/// and bisection of each sign change.
fn fk_by_scan(spec: &GliderSpec, rho: Vector2<f64>) -> Vec<Point2<f64>> {
    const SAMPLES: usize = 20_000;
    let (c, d) = spec.sliders(rho);
    let at = |t: f64| c + Vector2::new(t.cos(), t.sin()) * spec.l1;
    let f = |t: f64| (at(t) - d).norm_squared() - spec.l2 * spec.l2;
    let mut roots = Vec::new();
    let step = 2.0 * PI / SAMPLES as f64;
    for k in 0..SAMPLES {
        let (mut a, mut b) = (k as f64 * step, (k + 1) as f64 * step);
        let (fa, fb) = (f(a), f(b));
        if fa == 0.0 {
            roots.push(at(a));
            continue;
        }
        if fa * fb > 0.0 {
            continue;
        }
        for _ in 0..80 {
            let m = 0.5 * (a + b);
            if f(a) * f(m) <= 0.0 { b = m } else { a = m }
        }
        roots.push(at(0.5 * (a + b)));
    }
    roots
}

#[test]
fn fk_solution_count_agrees_with_dense_scan() {
    let mut counts = [0usize; 3];
    for spec in presets() {
        for i in 0..=24 {
            for j in 0..=24 {
                let rho = Vector2::new(-2.0 + 5.0 * i as f64 / 24.0, -2.0 + 5.0 * j as f64 / 24.0);
                let (c, d) = spec.sliders(rho);
                // Away from tangency, where a finite scan cannot tell 0, 1 and 2 roots apart.
                if ((d - c).norm() - (spec.l1 + spec.l2)).abs() < 1e-3 {
                    continue;
                }
                let scan = fk_by_scan(&spec, rho);
                let fk = forward_kinematics(&spec, rho);
                let sols = fk.solutions();
                assert_eq!(sols.len(), scan.len(), "{} {rho}", spec.name);
                counts[sols.len()] += 1;
                for p in scan {
                    assert!(
                        sols.iter().any(|s| (s.p - p).norm() < 1e-9),
                        "{} {rho}",
                        spec.name
                    );
                }
            }
        }
    }
    assert!(counts[0] > 50 && counts[2] > 50, "{counts:?}");
}

#[test]
fn fk_structural_and_tangent_cases() {
    // biglide1 with C = D: rho1 + rho2 = L0 (structural singularity, section 2.4, Fig. 5).
    let spec = GliderSpec::preset("biglide1").unwrap();
    let half = 0.5 * spec.l0;
    match forward_kinematics(&spec, Vector2::new(half, half)) {
        ForwardKinematics::StructuralSingularity { centre, radius } => {
            assert!((centre - Point2::new(half, 0.0)).norm() < EXACT_TOL);
            assert_eq!(radius, spec.l1);
        }
        other => panic!("expected a structural singularity, got {other:?}"),
    }
    // |CD| = 2L exactly: one double root, on CD, at a parallel singularity.
    let r = 0.5 * (spec.l0 - 2.0);
    let fk = forward_kinematics(&spec, Vector2::new(r, r));
    assert_eq!(fk.solutions().len(), 1);
    assert_eq!(fk.solutions()[0].assembly, Branch::Double);
    // |CD| slightly above 2L: no solution, and no error.
    let fk = forward_kinematics(&spec, Vector2::new(r - 1e-6, r));
    assert!(fk.solutions().is_empty());
}

// ---------------------------------------------------------------- singularities

#[test]
fn parallel_singularity_when_c_d_p_aligned() {
    for spec in presets() {
        for rho1 in [-0.5, 0.0, 0.3, 0.8] {
            // D on guide 2 at distance l1 + l2 from C: then P, the midpoint, is on CD.
            let c = spec.a() + spec.u1() * rho1;
            let (b, u2) = (spec.b(), spec.u2());
            let w = b - c;
            let reach = spec.l1 + spec.l2;
            let (bq, cq) = (w.dot(&u2), w.norm_squared() - reach * reach);
            let disc = bq * bq - cq;
            if disc < 0.0 {
                continue;
            }
            for rho2 in [-bq + disc.sqrt(), -bq - disc.sqrt()] {
                let rho = Vector2::new(rho1, rho2);
                let (c, d) = spec.sliders(rho);
                let p = c + (d - c) * (spec.l1 / reach);
                assert!(((d - c).norm() - reach).abs() < EXACT_TOL);
                assert!(
                    det_a(&spec, p, rho).abs() < EXACT_TOL,
                    "{} {rho}",
                    spec.name
                );
                assert!(is_parallel_singular(&spec, p, rho), "{} {rho}", spec.name);
                assert!(amplification(&spec, p, rho).is_none());
                // Moving P off the line by 1e-3 L leaves the singularity.
                let n = Vector2::new(-(d - c).y, (d - c).x).normalize() * 1e-3;
                assert!(!is_parallel_singular(&spec, p + n, rho));
            }
        }
    }
}

#[test]
fn serial_singularity_when_strut_orthogonal_to_guide() {
    for spec in presets() {
        for rho1 in [0.0, 0.2, 0.5] {
            // Strut 1 orthogonal to guide 1.
            let c = spec.a() + spec.u1() * rho1;
            let u1 = spec.u1();
            let p = c + Vector2::new(-u1.y, u1.x) * spec.l1;
            for sol in inverse_kinematics(&spec, p) {
                assert_eq!(sol.mode.strut1, Branch::Double, "{} {p}", spec.name);
                assert!((sol.rho.x - rho1).abs() < 1e-6);
                assert!(det_b(&spec, p, sol.rho).abs() < 1e-6, "{} {p}", spec.name);
                assert!(is_serial_singular(&spec, p, sol.rho));
                if let Some(a) = amplification(&spec, p, sol.rho) {
                    assert!(a.lambda_min < 1e-6, "{} {a:?}", spec.name);
                }
            }
        }
    }
    // Regular configurations: the centre of each preset's joint box.
    for spec in presets() {
        let rho = Vector2::new(0.5 * spec.rho1_range[1], 0.5 * spec.rho2_range[1]);
        let p = forward_kinematics_in_mode(&spec, rho, Branch::Plus).unwrap();
        assert!(!is_serial_singular(&spec, p, rho));
        assert!(!is_parallel_singular(&spec, p, rho));
        assert!(det_a(&spec, p, rho).abs() > 0.1 && det_b(&spec, p, rho).abs() > 0.1);
    }
}

// ---------------------------------------------------------------- amplification factors

#[test]
fn amplification_matches_finite_differences_and_section_2_7() {
    const H: f64 = 1e-6;
    for spec in presets() {
        for i in 0..=6 {
            for j in 0..=6 {
                let rho = Vector2::new(
                    spec.rho1_range[1] * i as f64 / 6.0,
                    spec.rho2_range[1] * j as f64 / 6.0,
                );
                let p = forward_kinematics_in_mode(&spec, rho, Branch::Plus).unwrap();
                let a = amplification(&spec, p, rho).unwrap();
                // J = dP / drho by central differences of the FK.
                let fk =
                    |r: Vector2<f64>| forward_kinematics_in_mode(&spec, r, Branch::Plus).unwrap();
                let dx =
                    (fk(rho + Vector2::new(H, 0.0)) - fk(rho - Vector2::new(H, 0.0))) / (2.0 * H);
                let dy =
                    (fk(rho + Vector2::new(0.0, H)) - fk(rho - Vector2::new(0.0, H))) / (2.0 * H);
                let j_fd = Matrix2::from_columns(&[dx, dy]);
                let sv = j_fd.svd(false, false).singular_values;
                assert!(
                    (a.lambda_max - sv[0].max(sv[1])).abs() < 1e-6,
                    "{} {rho}",
                    spec.name
                );
                assert!(
                    (a.lambda_min - sv[0].min(sv[1])).abs() < 1e-6,
                    "{} {rho}",
                    spec.name
                );
                let (c, d) = spec.sliders(rho);
                let (lmin, lmax) =
                    lambdas_section_2_7((p - c) / spec.l1, (p - d) / spec.l2, spec.u1(), spec.u2());
                assert!(
                    (a.lambda_min - lmin).abs() < EXACT_TOL
                        && (a.lambda_max - lmax).abs() < EXACT_TOL
                );
                // Section 3.2: the whole joint box of the design satisfies eq. (4).
                assert!(a.within(1.0 / 3.0, 3.0), "{} {rho} {a:?}", spec.name);
            }
        }
    }
}

#[test]
fn amplification_extremes_of_the_designs() {
    // Orthoglide isotropic configuration: struts along their guides, P where the guides meet.
    let spec = GliderSpec::preset("orthoglide").unwrap();
    let p = Point2::new(0.5 * spec.l0, 0.5 * spec.l0);
    let rho = inverse_kinematics_in_mode(&spec, p, WorkingMode::parse("++").unwrap()).unwrap();
    let a = amplification(&spec, p, rho).unwrap();
    assert!((a.lambda_min - 1.0).abs() < EXACT_TOL && (a.lambda_max - 1.0).abs() < EXACT_TOL);
    // The bounds are active where section 3.2 puts them.
    let at = |name: &str, rho: Vector2<f64>| {
        let s = GliderSpec::preset(name).unwrap();
        let p = forward_kinematics_in_mode(&s, rho, Branch::Plus).unwrap();
        amplification(&s, p, rho).unwrap()
    };
    let b1 = GliderSpec::preset("biglide1").unwrap().rho1_range[1];
    assert!((at("biglide1", Vector2::zeros()).lambda_max - 3.0).abs() < 1e-9);
    assert!((at("biglide1", Vector2::new(b1, b1)).lambda_min - 1.0 / 3.0).abs() < 1e-9);
    let b2 = GliderSpec::preset("biglide2").unwrap().rho1_range[1];
    assert!((at("biglide2", Vector2::new(0.2, 0.2)).lambda_max - 3.0).abs() < 1e-9);
    assert!((at("biglide2", Vector2::new(0.0, b2)).lambda_min - 1.0 / 3.0).abs() < 1e-9);
    let o = spec.rho1_range[1];
    assert!((at("orthoglide", Vector2::zeros()).lambda_max - 3.0).abs() < 1e-9);
    assert!((at("orthoglide", Vector2::new(o, o)).lambda_max - 3.0).abs() < 1e-9);
}

// ---------------------------------------------------------------- workspace

#[test]
fn workspace_is_identical_whatever_the_thread_count() {
    let spec = GliderSpec::preset("orthoglide").unwrap();
    let opts = WorkspaceOptions {
        nodes: 301,
        frame_angle: 0.3,
        ..WorkspaceOptions::default()
    };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let g = sample_workspace(&spec, &opts);
            let r = largest_rectangle(&g);
            (g, r)
        })
    };
    let (g1, r1) = run(1);
    let (g4, r4) = run(4);
    assert_eq!(g1, g4);
    assert_eq!(r1, r4);
}

#[test]
fn largest_rectangle_lies_in_the_workspace() {
    for (name, angle) in [
        ("biglide1", FRAC_PI_4),
        ("biglide2", 0.0),
        ("orthoglide", FRAC_PI_4),
    ] {
        let spec = GliderSpec::preset(name).unwrap();
        let opts = WorkspaceOptions {
            nodes: 401,
            frame_angle: angle,
            ..WorkspaceOptions::default()
        };
        let grid = sample_workspace(&spec, &opts);
        let rect = largest_rectangle(&grid).unwrap();
        let square = largest_square(&grid).unwrap();
        assert!(square.area() <= rect.area());
        assert!(rect.area() <= grid.region_area());
        assert!((square.width - square.height).abs() < EXACT_TOL);
        // Every point of a lattice on the rectangle, shrunk by one grid step, is reachable in
        // mode ++ within the joint ranges and satisfies eq. (4).
        let shrunk = Rectangle {
            width: rect.width - 2.0 * grid.step,
            height: rect.height - 2.0 * grid.step,
            ..rect
        };
        let [c0, c1, _, c3] = shrunk.corners();
        for i in 0..=20 {
            for j in 0..=20 {
                let p = c0 + (c1 - c0) * (i as f64 / 20.0) + (c3 - c0) * (j as f64 / 20.0);
                let rho = inverse_kinematics_in_mode(&spec, p, WorkingMode::parse("++").unwrap())
                    .unwrap_or_else(|| panic!("{name} {p} unreachable"));
                assert!(spec.within_limits(rho), "{name} {p} {rho}");
                let a = amplification(&spec, p, rho).unwrap();
                assert!(a.within(1.0 / 3.0, 3.0), "{name} {p} {a:?}");
            }
        }
    }
}

/// The presets and machines that are not: an orthoglide with unequal struts and shifted
/// strokes, a biglide whose guides are not parallel, an orthoglide designed for other bounds.
fn workspace_machines() -> Vec<GliderSpec> {
    let mut specs = presets();
    let mut o = GliderSpec::preset("orthoglide").unwrap();
    o.name = "orthoglide, l2 = 0.8 l1".into();
    o.l2 = 0.8 * o.l1;
    o.rho2_range = [o.rho2_range[0] - 0.1, o.rho2_range[1] - 0.25];
    let mut b = GliderSpec::preset("biglide2").unwrap();
    b.name = "biglide2, guides at 90 and 80 deg".into();
    b.alpha2 = 80f64.to_radians();
    specs.extend([o, b]);
    // `verne design --bounds 1/2,2`'s orthoglide.
    specs.extend(architecture_spec(Architecture::Orthoglide, 1.0, [0.5, 2.0]));
    specs
}

/// The adaptive grid classifies every node as the uniform grid does, so the region, its area
/// and the largest rectangle and square are the same, on machines other than the presets, in
/// both assembly modes and three working modes, with and without the amplification bounds, the
/// grid turned or not, and a grid too coarse for adaptive sampling by default; it classifies
/// fewer nodes.
#[test]
fn adaptive_workspace_equals_the_uniform_grid() {
    let mut cases = 0;
    for spec in workspace_machines() {
        for (mode, assembly, bounds, angle, nodes) in [
            // `verne workspace`'s default grid, and `verne design`'s (both orientations).
            ("++", Branch::Plus, Some(PAPER_LAMBDA_BOUNDS), 0.0, 801),
            ("++", Branch::Plus, Some(PAPER_LAMBDA_BOUNDS), 0.0, 1201),
            (
                "++",
                Branch::Plus,
                Some(PAPER_LAMBDA_BOUNDS),
                FRAC_PI_4,
                1201,
            ),
            ("++", Branch::Plus, None, 0.3, 601),
            ("++", Branch::Minus, None, 0.0, 601),
            ("+-", Branch::Plus, Some([0.5, 2.0]), 0.0, 401),
            (
                "-+",
                Branch::Minus,
                Some(PAPER_LAMBDA_BOUNDS),
                FRAC_PI_4,
                257,
            ),
        ] {
            let opts = |sampling| WorkspaceOptions {
                mode: WorkingMode::parse(mode).unwrap(),
                assembly,
                lambda_bounds: bounds,
                nodes,
                frame_angle: angle,
                seed: None,
                sampling,
            };
            let what = format!(
                "{} {mode} {assembly:?} {bounds:?} {angle} {nodes}",
                spec.name
            );
            let uniform = sample_workspace(&spec, &opts(Sampling::Uniform));
            let adaptive = sample_workspace(&spec, &opts(Sampling::Adaptive));
            let differ: Vec<_> = (0..uniform.class.len())
                .filter(|&k| uniform.class[k] != adaptive.class[k])
                .map(|k| {
                    (
                        k % uniform.nx,
                        k / uniform.nx,
                        uniform.class[k],
                        adaptive.class[k],
                    )
                })
                .collect();
            assert!(
                differ.is_empty(),
                "{what}: {} nodes differ, {:?}",
                differ.len(),
                &differ[..differ.len().min(8)]
            );
            assert!(uniform.region == adaptive.region, "{what}");
            assert_eq!(uniform.seed, adaptive.seed, "{what}");
            assert_eq!(uniform.region_estimate, adaptive.region_estimate, "{what}");
            assert_eq!(largest_rectangle(&uniform), largest_rectangle(&adaptive));
            assert_eq!(largest_square(&uniform), largest_square(&adaptive));
            assert_eq!(uniform.coarse_step, None);
            assert_eq!(adaptive.coarse_step, Some(8.0 * adaptive.step));
            assert_eq!(
                uniform.classified,
                uniform.nx * uniform.ny + uniform.region_estimate.boundary_cells
            );
            if uniform.class.contains(&NodeClass::Admissible) {
                cases += 1;
                assert!(
                    adaptive.classified < uniform.classified / 2,
                    "{what}: {} of {}",
                    adaptive.classified,
                    uniform.classified
                );
            }
            // Auto is uniform below 513 nodes and adaptive from there.
            let auto = sample_workspace(&spec, &opts(Sampling::Auto));
            assert_eq!(auto.coarse_step.is_some(), nodes >= 513, "{what}");
            assert_eq!(auto.class, uniform.class, "{what}");
        }
    }
    assert!(cases >= 20, "{cases} cases with a workspace");
}

/// Random machines near the presets (guides turned up to 17 deg, struts 0.7-1.3 l1 apart,
/// the base length and the strokes changed), with and without eq. (4), the grid turned or not:
/// every node of the adaptive grid as the uniform grid's. (300 such machines, 37 million
/// nodes, all equal when this was written: docs/gliders.md.)
#[test]
fn adaptive_workspace_equals_the_uniform_grid_on_random_machines() {
    let mut unit = {
        let mut s = 99u64;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    };
    let mut compared = 0;
    for _ in 0..60 {
        let mut g = GliderSpec::preset(PRESET_NAMES[(unit() * 3.0) as usize]).unwrap();
        g.alpha1 += (unit() - 0.5) * 0.6;
        g.alpha2 += (unit() - 0.5) * 0.6;
        g.l2 = g.l1 * (0.7 + 0.6 * unit());
        g.l0 *= 0.7 + 0.6 * unit();
        let w = g.rho1_range[1] - g.rho1_range[0];
        g.rho1_range[1] = g.rho1_range[0] + w * (0.5 + unit());
        g.rho2_range[0] -= w * 0.3 * unit();
        if !g.validate().is_empty() {
            continue;
        }
        let bounds = (unit() < 0.5).then_some(PAPER_LAMBDA_BOUNDS);
        let angle = if unit() < 0.5 { 0.0 } else { FRAC_PI_4 };
        let opts = |sampling| WorkspaceOptions {
            lambda_bounds: bounds,
            nodes: 401,
            frame_angle: angle,
            sampling,
            ..WorkspaceOptions::default()
        };
        let uniform = sample_workspace(&g, &opts(Sampling::Uniform));
        let adaptive = sample_workspace(&g, &opts(Sampling::Adaptive));
        let differ = (0..uniform.class.len())
            .filter(|&k| uniform.class[k] != adaptive.class[k])
            .count();
        assert_eq!(differ, 0, "{g:?} {bounds:?} {angle}");
        assert!(
            uniform.region == adaptive.region,
            "{g:?} {bounds:?} {angle}"
        );
        compared += 1;
    }
    assert!(compared >= 50, "{compared} machines");
}

/// The cost of the adaptive grid grows with the boundary: about 2x a halving of the step (the
/// uniform grid's 4x), from 401 to 3201 nodes.
#[test]
fn adaptive_cost_grows_with_the_boundary() {
    let spec = GliderSpec::preset("orthoglide").unwrap();
    let cost = |nodes| {
        sample_workspace(
            &spec,
            &WorkspaceOptions {
                nodes,
                sampling: Sampling::Adaptive,
                ..WorkspaceOptions::default()
            },
        )
        .classified as f64
    };
    let costs = [401, 801, 1601, 3201].map(cost);
    for w in costs.windows(2) {
        let ratio = w[1] / w[0];
        assert!((1.6..2.6).contains(&ratio), "{costs:?}");
    }
}

/// The region's area lies in its bracket, whose width shrinks with the step; the sampled
/// estimates of a coarse and a fine grid agree within their half-widths, and the fine grid's
/// node count within the coarse grid's bracket.
#[test]
fn region_area_bracket_and_sampled_estimate() {
    for spec in workspace_machines() {
        let run = |nodes| {
            sample_workspace(
                &spec,
                &WorkspaceOptions {
                    nodes,
                    ..WorkspaceOptions::default()
                },
            )
        };
        let (coarse, fine) = (run(201), run(1601));
        let name = &spec.name;
        for g in [&coarse, &fine] {
            let e = g.region_estimate;
            assert!(
                e.lo > 0.0 && e.lo <= g.region_area() && g.region_area() <= e.hi,
                "{name} {e:?} {} {}",
                g.region_area(),
                g.nx
            );
            assert!(e.lo <= e.sampled && e.sampled <= e.hi, "{name} {e:?}");
            assert!(
                e.half_width > 0.0 && e.half_width <= e.hi - e.lo,
                "{name} {e:?}"
            );
            let cell = g.step * g.step;
            assert!(((e.hi - e.lo) / cell - e.boundary_cells as f64).abs() < 1e-6);
        }
        let (c, f) = (coarse.region_estimate, fine.region_estimate);
        assert!(f.hi - f.lo < 0.25 * (c.hi - c.lo), "{name} {c:?} {f:?}");
        assert!(c.lo <= f.sampled && f.sampled <= c.hi, "{name} {c:?} {f:?}");
        assert!(
            (c.sampled - f.sampled).abs() <= c.half_width + f.half_width,
            "{name} {c:?} {f:?}"
        );
    }
}

#[test]
fn empty_workspace_is_empty_not_an_error() {
    // Joint box entirely beyond reach: C and D more than 2L apart.
    let mut spec = GliderSpec::preset("biglide1").unwrap();
    spec.rho1_range = [-5.0, -4.0];
    let grid = sample_workspace(&spec, &WorkspaceOptions::default());
    assert_eq!(grid.region_area(), 0.0);
    assert!(largest_rectangle(&grid).is_none());
}

// ---------------------------------------------------------------- spec files

#[test]
fn spec_toml_round_trip_and_errors() {
    for spec in presets() {
        let text = spec.to_toml_string();
        let back = GliderSpec::from_toml_str(&text, "round trip").unwrap();
        assert_eq!(back.name, spec.name);
        assert!((back.alpha2 - spec.alpha2).abs() < EXACT_TOL && back.l0 == spec.l0);
        assert!(spec.validate().is_empty());
    }
    let bad = r#"
kind = "verne"
name = ""
alpha1_deg = 0.0
alpha2_deg = 180.0
l1 = -1.0
l2 = 1.0
l0 = 0.0
rho1_range = [1.0, 0.0]
rho2_range = [0.0, 0.5]
"#;
    let err = GliderSpec::from_toml_str(bad, "bad.toml").unwrap_err();
    let keys: Vec<&str> = err.problems.iter().map(|p| p.key.as_str()).collect();
    assert_eq!(keys, ["kind", "name", "l1", "l0", "rho1_range"]);
    let msg = err.to_string();
    assert!(msg.contains("bad.toml: 5 problems"), "{msg}");
    assert!(
        msg.contains("rho1_range: is [1, 0]: minimum 1 > maximum 0"),
        "{msg}"
    );
    let err =
        GliderSpec::from_toml_str("kind = \"glider\"\nl0 = 1.0\nspeed = 3\n", "x").unwrap_err();
    assert_eq!(err.problems.len(), 1);
    assert!(
        err.problems[0].message.contains("speed") || err.problems[0].message.contains("missing")
    );
    // Every problem carries the line of its key: the lines of `bad` counted by hand.
    let lines: Vec<Option<usize>> = GliderSpec::from_toml_str(bad, "bad.toml")
        .unwrap_err()
        .problems
        .iter()
        .map(|p| p.line)
        .collect();
    assert_eq!(lines, [Some(2), Some(3), Some(6), Some(8), Some(9)]);
    assert!(msg.contains("bad.toml:9: rho1_range"), "{msg}");
}

/// A range is two numbers, [min, max]: a list of any other length is refused with the line of
/// its key (three numbers were read as the first two).
#[test]
fn a_range_of_other_than_two_numbers_is_refused_at_its_line() {
    let good = GliderSpec::preset("biglide1").unwrap().to_toml_string();
    for (key, list, count) in [
        ("rho1_range", "[0.0, 0.3, 0.5]", 3),
        ("rho2_range", "[0.0, 0.1, 0.2, 0.5]", 4),
        ("rho1_range", "[0.5]", 1),
        ("rho2_range", "[]", 0),
    ] {
        let text: String = good
            .lines()
            .map(|l| {
                if l.starts_with(key) {
                    format!("{key} = {list}\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect();
        let line = text.lines().position(|l| l.starts_with(key)).unwrap() + 1;
        let err = GliderSpec::from_toml_str(&text, "g.toml").unwrap_err();
        assert_eq!(err.problems.len(), 1, "{key} = {list}: {err}");
        let p = &err.problems[0];
        assert_eq!((p.key.as_str(), p.line), (key, Some(line)), "{err}");
        assert!(p.message.contains(&format!("has {count} number")), "{err}");
        assert!(
            err.to_string().contains(&format!("g.toml:{line}: {key}")),
            "{err}"
        );
    }
    // A syntax error has its line too.
    let err = GliderSpec::from_toml_str("kind = \"glider\"\nl0 = = 1\n", "s.toml").unwrap_err();
    assert_eq!(err.problems[0].line, Some(2), "{err}");
}

/// Table 1 in mm stays finite up to the largest strut length allowed, for the reason its
/// documentation gives: in multiples of L, L0 < 2, delta-rho <= 4 and S below the square of
/// side L0 + 2 delta-rho + 2; and it overflows beyond (the strut length the value refused).
#[test]
fn table_1_in_mm_is_finite_up_to_the_largest_strut_length() {
    let rows = table1(&DesignOptions {
        nodes: 201,
        ..DesignOptions::default()
    });
    assert_eq!(rows.len(), 3);
    let l = verne::glider::MAX_STRUT_LENGTH_MM;
    for r in &rows {
        assert!(r.l0 < 2.0 && r.delta_rho <= 4.0, "{}", r.mechanism);
        assert!(
            r.s < (r.l0 + 2.0 * r.delta_rho + 2.0).powi(2),
            "{}",
            r.mechanism
        );
        for v in [r.l0 * l, r.delta_rho * l, r.s * l * l] {
            assert!(v.is_finite(), "{}: {v}", r.mechanism);
        }
        assert!((r.s * 1e200 * 1e200).is_infinite(), "{}", r.mechanism);
    }
}
