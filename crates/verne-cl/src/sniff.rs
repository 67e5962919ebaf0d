//! Which files are CL files (SPEC §2), so that the CLI never parses a CL file as CSV.

use super::lex::{collapse_upper, header_line, text_record_name, trim};

/// Record names that make a file a CL file when its first record has one of them (SPEC §2).
const SNIFF_NAMES: [&[u8]; 27] = [
    b"TOOL PATH",
    b"PARTNO",
    b"MACHIN",
    b"GOTO",
    b"FROM",
    b"UNITS",
    b"UNIT",
    b"MULTAX",
    b"CUTTER",
    b"LOADTL",
    b"TLDATA",
    b"MSYS",
    b"PPRINT",
    b"INSERT",
    b"SPINDL",
    b"FEDRAT",
    b"RAPID",
    b"COOLNT",
    b"LOAD",
    b"SELECT",
    b"CSYS",
    b"TRNTYP",
    b"CIRCLE",
    b"CYCLE",
    b"REMARK",
    b"TPRINT",
    b"TOOLNO",
];

/// How many leading bytes [`sniff`] needs to see: pass at least this many (or the whole file
/// when it is shorter).
pub const SNIFF_BYTES: usize = 8192;

/// Whether the file name has a CL extension (case-insensitive): `.cl`, `.cls`, `.clsf`,
/// `.apt`, `.aptsource`, `.ncl`, or `.ncl.<digits>` (Creo versions).
pub fn has_cl_extension(path_name: &str) -> bool {
    let base = path_name
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or(path_name)
        .to_ascii_lowercase();
    let mut parts = base.rsplit('.');
    let Some(last) = parts.next() else {
        return false;
    };
    if !base.contains('.') {
        return false;
    }
    const EXT: [&str; 6] = ["cl", "cls", "clsf", "apt", "aptsource", "ncl"];
    if EXT.contains(&last) {
        return true;
    }
    // name.ncl.8 (but not a bare ".8" file or "ncl.8" without a stem)
    !last.is_empty()
        && last.bytes().all(|b| b.is_ascii_digit())
        && parts.next() == Some("ncl")
        && parts.next().is_some()
}

/// Whether a file is a CL file, by its name (extension) or, failing that, by its first bytes
/// (SPEC §2): after blank lines and NX listing header lines, the first line starts with `$$`
/// or with a record name such as `TOOL PATH/`, `PARTNO`, `MACHIN/`, `GOTO/`, `UNITS/`.
/// G-code (`%`, `O1000`, `G0 …`, `N10 …`, `(…)`) and CSV are not CL files.
///
/// `first_bytes`: the start of the file, at least [`SNIFF_BYTES`] bytes when the file is that
/// long. A first line cut by the end of `first_bytes` is judged on what is there.
pub fn sniff(path_name: &str, first_bytes: &[u8]) -> bool {
    has_cl_extension(path_name) || sniff_content(first_bytes)
}

/// The content rule of [`sniff`] alone.
pub fn sniff_content(first_bytes: &[u8]) -> bool {
    let bytes = first_bytes
        .strip_prefix(&[0xEF, 0xBB, 0xBF][..])
        .unwrap_or(first_bytes);
    let mut lines = bytes.split(|&b| b == b'\n');
    while let Some(raw) = lines.next() {
        let s = trim(trim_cr(raw));
        if s.is_empty() || header_line(s).is_some() {
            continue;
        }
        if s.starts_with(b"$$") {
            return true;
        }
        // CATIA writes `PARTNO` without a slash (`PARTNO PART TO BE MACHINED`): a free-text
        // record name followed by its text counts too (SPEC §3.8).
        if text_record_name(s).is_some() {
            return true;
        }
        // the first record, its `$` continuations joined (SPEC §3.6), as far as it goes
        let mut content = Vec::with_capacity(64);
        let mut piece = s;
        loop {
            match piece.iter().position(|&b| b == b'$') {
                None => {
                    content.extend_from_slice(trim(piece));
                    break;
                }
                Some(k) => {
                    content.extend_from_slice(trim(&piece[..k]));
                    if piece.get(k + 1) == Some(&b'$') || content.contains(&b'/') {
                        break;
                    }
                    match lines.next() {
                        Some(next) => piece = trim(trim_cr(next)),
                        None => break,
                    }
                }
            }
        }
        let end = content
            .iter()
            .position(|&b| b == b'/')
            .unwrap_or(content.len());
        let mut name = Vec::with_capacity(16);
        collapse_upper(&content[..end], &mut name);
        return SNIFF_NAMES.contains(&name.as_slice());
    }
    false
}

fn trim_cr(s: &[u8]) -> &[u8] {
    let mut s = s;
    while let [rest @ .., b'\r'] = s {
        s = rest;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions() {
        for n in [
            "a.cl",
            "a.CLS",
            "dir/a.clsf",
            "a.apt",
            "C:\\x\\a.aptsource",
            "a.NCL",
            "part.ncl.1",
            "part.ncl.12",
            "x.y.cls",
        ] {
            assert!(has_cl_extension(n), "{n}");
        }
        for n in [
            "a.txt", "a.csv", "cl", "a.cl.bak", "a.ncl.", "a.ncl.x", ".8", "ncl.8", "a.nc",
            "a.cl/b",
        ] {
            assert!(!has_cl_extension(n), "{n}");
        }
    }

    #[test]
    fn content() {
        let yes: [&[u8]; 12] = [
            b"TOOL PA$ x\n  $\n TH/OP\n",
            b"GO$\nTO/1,$\n2,3\n",
            b"GOTO/0,0,50\n",
            b"\n\nPARTNO/X\n",
            b"$$ comment\nG0 X1\n",
            b"  tool path / OP,TOOL,T\n",
            b"=====\nInformation listing created by : u\nDate : 1\n\nTOOL PATH/X\n",
            b"PARTNO PART TO BE MACHINED\r\n",
            b"\xEF\xBB\xBFMACHIN/VERNE\n",
            b"RAPID\n",
            b"units / mm\n",
            b"GOTO / 1, 2, 3",
        ];
        for y in yes {
            assert!(sniff_content(y), "{}", String::from_utf8_lossy(y));
            assert!(sniff("file.txt", y));
        }
        let no: [&[u8]; 9] = [
            b"%\nO1000\nG0 X0\n",
            b"O1000 (NOT CL)\n",
            b"G0 X0 Y0\n",
            b"N10 G1 X1\n",
            b"(comment)\nGOTO/1,2,3\n",
            b"x,y,z,i,j,k\n1,2,3,0,0,1\n",
            b"",
            b"\n\n",
            b"GOTOX/1,2,3\n",
        ];
        for n in no {
            assert!(!sniff_content(n), "{}", String::from_utf8_lossy(n));
            assert!(sniff("part.cls", n), "the extension decides");
        }
    }
}
