//! Tables as text for a person (aligned columns) or as plain CSV, for the commands that print a
//! few rows (`verne modes -m GLIDER`, `verne design`).

/// Header and rows as CSV text (the cells need no quoting: numbers and codes).
pub fn csv_text(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut t = header.join(",");
    t.push('\n');
    for r in rows {
        t.push_str(&r.join(","));
        t.push('\n');
    }
    t
}

/// A table for a person: columns separated by two spaces, right-aligned except the columns
/// listed in `left`.
pub fn aligned(header: &[&str], rows: &[Vec<String>], left: &[usize]) -> String {
    let widths: Vec<usize> = (0..header.len())
        .map(|k| {
            rows.iter()
                .map(|r| r[k].chars().count())
                .chain([header[k].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[&str]| {
        let s = cells
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(k, (c, &w))| {
                if left.contains(&k) {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect::<Vec<_>>()
            .join("  ");
        format!("{}\n", s.trim_end())
    };
    let mut t = line(header);
    for r in rows {
        t.push_str(&line(&r.iter().map(String::as_str).collect::<Vec<_>>()));
    }
    t
}
