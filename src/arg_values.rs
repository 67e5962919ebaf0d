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
}
