//! Parsers of command-line values (`--pose 1,2,3`, bounds, pairs): plain strings to numbers,
//! with a message saying what was expected. Kept in the library so that they are fuzzed.

/// Parses `a,b,c` into three finite numbers.
pub fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers like 1,2,3, found {} value{}",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" }
        ));
    }
    let mut out = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        match p.parse::<f64>() {
            Ok(v) if v.is_finite() => out[k] = v,
            Ok(_) => return Err(format!("value {} `{p}` is not a finite number", k + 1)),
            Err(_) => return Err(format!("value {} `{p}` is not a number", k + 1)),
        }
    }
    Ok(out)
}

/// Parses a design sweep `KEY=FROM..TO:N` (N >= 1 values, from FROM to TO inclusive; N = 1
/// gives FROM alone).
pub fn parse_sweep(s: &str) -> Result<(String, f64, f64, usize), String> {
    let usage = "expected KEY=FROM..TO:N, e.g. module.L1=800..900:11";
    let (key, range) = s.split_once('=').ok_or(usage)?;
    let (span, n) = range.rsplit_once(':').ok_or(usage)?;
    let (from, to) = span.split_once("..").ok_or(usage)?;
    let num = |t: &str| -> Result<f64, String> {
        match t.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("`{t}` is not a number; {usage}")),
        }
    };
    let n: usize = n
        .trim()
        .parse()
        .ok()
        .filter(|n| (1..=1000).contains(n))
        .ok_or_else(|| format!("`{n}`: N must be a whole number from 1 to 1000; {usage}"))?;
    let key = key.trim();
    if key.is_empty() {
        return Err(format!("no key: {usage}"));
    }
    Ok((key.to_string(), num(from)?, num(to)?, n))
}

/// The points of a sweep of one or two keys (`--sweep` given once or twice): each key's N
/// values from FROM to TO, evenly spaced and rounded to 13 significant digits (so that
/// 1.8..2.1:4 gives 1.9, not 1.9000000000000001), the second key fastest.
pub fn sweep_points(sweeps: &[(String, f64, f64, usize)]) -> Vec<Vec<f64>> {
    let values = |(_, from, to, n): &(String, f64, f64, usize)| -> Vec<f64> {
        (0..*n)
            .map(|k| {
                let v = if *n == 1 {
                    *from
                } else {
                    from + (to - from) * k as f64 / (*n - 1) as f64
                };
                format!("{v:.12e}").parse().unwrap_or(v)
            })
            .collect()
    };
    let mut points: Vec<Vec<f64>> = vec![Vec::new()];
    for sweep in sweeps {
        points = points
            .into_iter()
            .flat_map(|p| {
                values(sweep)
                    .into_iter()
                    .map(move |v| [p.clone(), vec![v]].concat())
            })
            .collect();
    }
    points
}

/// Parses a point of either mechanism: `X,Y,Z` (the VERNE machine) or `X,Y` (a planar glider;
/// the third value is then NaN, which the VERNE commands refuse with [`spatial`]).
pub fn parse_point(s: &str) -> Result<[f64; 3], String> {
    if s.split(',').count() == 2 {
        let two = parse_numbers::<2>(s, "numbers")?;
        return Ok([two[0], two[1], f64::NAN]);
    }
    parse_triple(s)
}

/// The points given for the VERNE machine: three values each.
pub fn spatial(points: &[[f64; 3]], flag: &str, names: &str) -> Result<(), String> {
    match points.iter().find(|p| p[2].is_nan()) {
        Some(p) => Err(format!(
            "{flag} {},{}: the VERNE machine needs {names} (two values are a glider's planar point: -m biglide1|biglide2|orthoglide or a glider file)",
            p[0], p[1]
        )),
        None => Ok(()),
    }
}

pub fn parse_numbers<const N: usize>(s: &str, what: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(format!(
            "expected {N} comma-separated numbers ({what}), found {}",
            parts.len()
        ));
    }
    let mut out = [0.0; N];
    for (k, p) in parts.iter().enumerate() {
        match p.parse::<f64>() {
            Ok(v) if v.is_finite() => out[k] = v,
            _ => return Err(format!("value {} `{p}` is not a finite number", k + 1)),
        }
    }
    Ok(out)
}

/// Parses `XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX`.
pub fn parse_bounds(s: &str) -> Result<[f64; 6], String> {
    let b = parse_numbers::<6>(s, "XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX")?;
    for (d, name) in ["x", "y", "z"].iter().enumerate() {
        if b[2 * d] > b[2 * d + 1] {
            return Err(format!(
                "{name}: min {} is above max {}",
                b[2 * d],
                b[2 * d + 1]
            ));
        }
    }
    Ok(b)
}

/// Parses `LO,HI`.
pub fn parse_pair(s: &str) -> Result<[f64; 2], String> {
    let p = parse_numbers::<2>(s, "LO,HI")?;
    if !(0.0 <= p[0] && p[0] <= p[1]) {
        return Err(format!("need 0 <= LO <= HI, got {},{}", p[0], p[1]));
    }
    Ok(p)
}

/// Parses `z=VALUE` (or x=, y=) into (axis, value).
pub fn parse_slice(s: &str) -> Result<(usize, f64), String> {
    let (axis, value) = s
        .split_once('=')
        .ok_or_else(|| format!("expected AXIS=VALUE like z=1100, got `{s}`"))?;
    let axis = match axis.trim() {
        "x" | "X" => 0,
        "y" | "Y" => 1,
        "z" | "Z" => 2,
        other => return Err(format!("axis `{other}`: expected x, y or z")),
    };
    match value.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok((axis, v)),
        _ => Err(format!("`{value}` is not a finite number")),
    }
}

/// Parses a number or a fraction `a/b`.
pub fn parse_ratio(s: &str) -> Result<f64, String> {
    let s = s.trim();
    let v = match s.split_once('/') {
        Some((a, b)) => match (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
            (Ok(a), Ok(b)) => a / b,
            _ => return Err(format!("`{s}` is not a number or a fraction like 1/3")),
        },
        None => s
            .parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number or a fraction like 1/3"))?,
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("`{s}` is not a finite number"))
    }
}

/// Parses a finite number > 0.
pub fn parse_positive(s: &str) -> Result<f64, String> {
    let v = parse_ratio(s)?;
    let shown = verne::error::shown(s.trim().as_bytes());
    let digits = s.trim().chars().any(|c| ('1'..='9').contains(&c));
    match v {
        v if v >= f64::MIN_POSITIVE => Ok(v),
        v if v >= 0.0 && digits => Err(format!(
            "`{shown}` is too small to be used (below {:e}, it rounds to 0 or loses its digits): expected a number > 0",
            f64::MIN_POSITIVE
        )),
        _ => Err(format!("`{shown}` is not > 0")),
    }
}

/// Parses the strut length L (mm) of `verne design --l`: a finite number > 0, and at most
/// `verne::glider::MAX_STRUT_LENGTH_MM`, beyond which Table 1 in mm (S in mm^2) overflows.
pub fn parse_strut_length(s: &str) -> Result<f64, String> {
    let max = verne::glider::MAX_STRUT_LENGTH_MM;
    match parse_positive(s)? {
        l if l <= max => Ok(l),
        l => Err(format!(
            "{l:e} mm is beyond {max:e} mm: S in mm^2 (S per L^2 times L^2) would overflow"
        )),
    }
}

/// Parses `LO,HI` with 0 < LO < HI (numbers or fractions).
pub fn parse_lambda_bounds(s: &str) -> Result<[f64; 2], String> {
    let Some((lo, hi)) = s.split_once(',') else {
        return Err("expected two comma-separated bounds like 1/3,3".into());
    };
    let (lo, hi) = (parse_ratio(lo)?, parse_ratio(hi)?);
    if !(lo > 0.0 && lo < hi) {
        return Err(format!("expected 0 < LO < HI, found LO = {lo}, HI = {hi}"));
    }
    Ok([lo, hi])
}

/// Parses a tool pose `X,Y,Z,I,J,K` (tip in mm, axis) for `verne ik --tool`.
pub fn parse_tool_pose(s: &str) -> Result<[f64; 6], String> {
    parse_numbers::<6>(s, "X,Y,Z,I,J,K")
}

/// Parses machine joints `RHO1,RHO2,RHO3,THETA1,THETA2` for `verne fk --machine-joints`.
pub fn parse_machine_joints(s: &str) -> Result<[f64; 5], String> {
    parse_numbers::<5>(s, "RHO1,RHO2,RHO3,THETA1,THETA2")
}

/// Parses a `verne verify` threshold `NAME=VALUE` (names and checks in `verify::THRESHOLDS`;
/// fractions like `1/3` allowed).
pub fn parse_threshold(s: &str) -> Result<(String, f64), String> {
    let Some((name, value)) = s.split_once('=') else {
        return Err(format!(
            "expected NAME=VALUE like tip_error_mm=0.01, found `{}`",
            verne::error::shown(s.as_bytes())
        ));
    };
    let name = name.trim();
    let value = parse_ratio(value)?;
    verne::verify::check_threshold_value(name, value)?;
    Ok((name.to_string(), value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triples_parse_or_explain() {
        assert_eq!(parse_triple("1, -2.5,3e2"), Ok([1.0, -2.5, 300.0]));
        assert!(parse_triple("1,2").unwrap_err().contains("three"));
        assert!(parse_triple("1,x,3").unwrap_err().contains("value 2"));
        assert!(parse_triple("1,inf,3").unwrap_err().contains("finite"));
    }

    #[test]
    fn strut_lengths_that_overflow_table_1_are_refused() {
        assert_eq!(parse_strut_length("1000"), Ok(1000.0));
        assert_eq!(parse_strut_length("1e150"), Ok(1e150));
        for bad in ["1e200", "1.0000001e150", "1e308"] {
            let e = parse_strut_length(bad).unwrap_err();
            assert!(e.contains("overflow"), "{bad}: {e}");
        }
        assert!(parse_strut_length("0").unwrap_err().contains("not > 0"));
        assert!(parse_strut_length("inf").unwrap_err().contains("finite"));
    }

    #[test]
    fn thresholds_parse_or_explain() {
        assert_eq!(
            parse_threshold("tip_error_mm=0.01"),
            Ok(("tip_error_mm".to_string(), 0.01))
        );
        assert_eq!(parse_threshold("lambda_min = 1/4").unwrap().1, 0.25);
        assert!(
            parse_threshold("tip_error_mm")
                .unwrap_err()
                .contains("NAME=VALUE")
        );
        assert!(parse_threshold("nope=1").unwrap_err().contains("unknown"));
        assert!(
            parse_threshold("chord_error_mm=-1")
                .unwrap_err()
                .contains("positive")
        );
    }
}
