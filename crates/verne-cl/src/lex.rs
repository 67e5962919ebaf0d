//! Physical lines to logical records (SPEC §3), streaming, with reused buffers.
//!
//! Every piece of input is looked at a bounded number of times: a record continued over
//! many lines and a very long line are read in linear time. A physical line and a logical
//! record are bounded by `max_record_bytes`.

use std::io::{self, BufRead};

use super::error::{ClError, ClErrorKind, Warning, WarningKind};
use super::number::{self, Num};
use super::types::{Units, latin1_short};

/// Records whose argument is free text, never continued (SPEC §3.8).
const TEXT_RECORDS: [&[u8]; 5] = [b"PARTNO", b"PPRINT", b"INSERT", b"REMARK", b"TPRINT"];

/// Keys of NX information-listing header lines (SPEC §3.9), upper case.
const HEADER_KEYS: [&[u8]; 5] = [
    b"INFORMATION LISTING CREATED BY",
    b"DATE",
    b"CURRENT WORK PART",
    b"NODE NAME",
    b"INFORMATION UNITS",
];

/// Record names that make a comment continuation worth a warning when a continued comment
/// takes a line starting with them.
const RECORD_LOOKALIKES: [&[u8]; 16] = [
    b"GOTO",
    b"FROM",
    b"GODLTA",
    b"CIRCLE",
    b"CYCLE",
    b"RAPID",
    b"FEDRAT",
    b"LOADTL",
    b"LOAD",
    b"MSYS",
    b"CSYS",
    b"UNITS",
    b"UNIT",
    b"FINI",
    b"END-OF-PATH",
    b"TOOL PATH",
];

/// Index of the first `needle` in `hay`, eight bytes at a time.
#[inline]
pub(super) fn find_byte(hay: &[u8], needle: u8) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    let rep = LO.wrapping_mul(needle as u64);
    let mut chunks = hay.chunks_exact(8);
    let mut base = 0;
    for c in chunks.by_ref() {
        let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]) ^ rep;
        // the lowest flagged byte is exactly the first zero byte of `w`
        let t = w.wrapping_sub(LO) & !w & HI;
        if t != 0 {
            return Some(base + (t.trailing_zeros() / 8) as usize);
        }
        base += 8;
    }
    chunks
        .remainder()
        .iter()
        .position(|&b| b == needle)
        .map(|i| base + i)
}

/// Index of the first `a` or `b` in `hay`, eight bytes at a time.
#[inline]
pub(super) fn find_byte2(hay: &[u8], a: u8, b: u8) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    let ra = LO.wrapping_mul(a as u64);
    let rb = LO.wrapping_mul(b as u64);
    let mut chunks = hay.chunks_exact(8);
    let mut base = 0;
    for c in chunks.by_ref() {
        let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        let (x, y) = (w ^ ra, w ^ rb);
        // the lowest flagged byte of either mask is exactly the first match of either byte
        let t = (x.wrapping_sub(LO) & !x & HI) | (y.wrapping_sub(LO) & !y & HI);
        if t != 0 {
            return Some(base + (t.trailing_zeros() / 8) as usize);
        }
        base += 8;
    }
    chunks
        .remainder()
        .iter()
        .position(|&c| c == a || c == b)
        .map(|i| base + i)
}

/// Most fields the one-pass number path handles (CSYS has 12).
const MAX_FAST_FIELDS: usize = 12;

/// Blank characters around fields and at line ends (SPEC §3.2).
pub(super) fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | 0x0b | 0x0c)
}

/// `(start, end)` of `s` without leading and trailing blanks.
pub(super) fn trim_range(s: &[u8]) -> (usize, usize) {
    let mut a = 0;
    let mut b = s.len();
    while a < b && is_blank(s[a]) {
        a += 1;
    }
    while b > a && is_blank(s[b - 1]) {
        b -= 1;
    }
    (a, b)
}

pub(super) fn trim(s: &[u8]) -> &[u8] {
    let (a, b) = trim_range(s);
    &s[a..b]
}

/// An NX listing header line (SPEC §3.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Header<'a> {
    /// A line of `=` or a `Key : value` line that carries nothing for the reader.
    Plain,
    /// `Information Units : value` (the value, trimmed; may be empty).
    Units(&'a [u8]),
}

/// Whether the trimmed, non-empty line `s` is a listing header line.
pub(super) fn header_line(s: &[u8]) -> Option<Header<'_>> {
    match s.first() {
        Some(b'=') => return s.iter().all(|&b| b == b'=').then_some(Header::Plain),
        Some(c) if c.is_ascii_alphabetic() => {}
        _ => return None,
    }
    // the key is letters and spaces up to the colon (blanks before it)
    let colon = s
        .iter()
        .position(|&b| !(b.is_ascii_alphabetic() || is_blank(b)))
        .filter(|&i| s[i] == b':')?;
    let key = trim(&s[..colon]);
    if key.is_empty()
        || !key[0].is_ascii_alphabetic()
        || !key.iter().all(|&b| b.is_ascii_alphabetic() || b == b' ')
    {
        return None;
    }
    let k = HEADER_KEYS
        .iter()
        .position(|h| h.eq_ignore_ascii_case(key))?;
    if k == 4 {
        let v = trim(&s[colon + 1..]);
        let end = v.iter().position(|&b| is_blank(b)).unwrap_or(v.len());
        Some(Header::Units(&v[..end]))
    } else {
        Some(Header::Plain)
    }
}

/// The units of an `Information Units` value.
fn listing_units(v: &[u8]) -> Option<Units> {
    let up = v.to_ascii_uppercase();
    match up.as_slice() {
        b"IN" | b"INCH" | b"INCHES" => Some(Units::Inch),
        b"MM" | b"MILLIMETER" | b"MILLIMETERS" | b"MILLIMETRE" | b"MILLIMETRES" | b"METRIC" => {
            Some(Units::Mm)
        }
        _ => None,
    }
}

/// The line count of an NX listing's last line, `Tool Path Listing has N lines.` (SPEC §3.9):
/// the words case-insensitive, any run of blanks between them, `line` or `lines`, the final
/// `.` optional. `None` for any other line.
pub(super) fn listing_trailer(s: &[u8]) -> Option<u64> {
    let mut words = s.split(|&b| is_blank(b)).filter(|w| !w.is_empty());
    for w in [&b"TOOL"[..], b"PATH", b"LISTING", b"HAS"] {
        if !words.next()?.eq_ignore_ascii_case(w) {
            return None;
        }
    }
    let n = words.next()?;
    if n.is_empty() || !n.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let last = words.next()?;
    let last = last.strip_suffix(b".").unwrap_or(last);
    if words.next().is_some()
        || !(last.eq_ignore_ascii_case(b"LINES") || last.eq_ignore_ascii_case(b"LINE"))
    {
        return None;
    }
    Some(n.iter().fold(0u64, |a, &d| {
        a.saturating_mul(10).saturating_add(u64::from(d - b'0'))
    }))
}

/// Length of the name of a free-text record at the start of `s` (SPEC §3.8): a run of letters
/// that is one of `PARTNO`, `PPRINT`, `INSERT`, `REMARK`, `TPRINT`, not followed by a letter,
/// digit or `_`.
pub(super) fn text_record_name(s: &[u8]) -> Option<usize> {
    let n = s.iter().take_while(|b| b.is_ascii_alphabetic()).count();
    if n != 6 {
        return None;
    }
    if s.get(n)
        .is_some_and(|&c| c.is_ascii_alphanumeric() || c == b'_')
    {
        return None;
    }
    TEXT_RECORDS
        .iter()
        .any(|t| t.eq_ignore_ascii_case(&s[..n]))
        .then_some(n)
}

/// Writes the record name `raw` into `out`: blanks collapsed to one space, upper case.
pub(super) fn collapse_upper(raw: &[u8], out: &mut Vec<u8>) {
    out.clear();
    if raw
        .iter()
        .all(|b| b.is_ascii_alphanumeric() || *b == b'_' || *b == b'-')
    {
        out.extend_from_slice(raw);
        out.make_ascii_uppercase();
        return;
    }
    let mut blank = false;
    for &b in trim(raw) {
        if is_blank(b) {
            blank = true;
            continue;
        }
        if blank {
            out.push(b' ');
            blank = false;
        }
        out.push(b.to_ascii_uppercase());
    }
}

/// Whether an upper-case name is acceptable to the lexer: letters, digits, `_`, `-`, or
/// `TOOL PATH`; or a name with a comma (an APT geometric statement, refused by the reader).
fn valid_name(name: &[u8]) -> bool {
    if !name.is_empty()
        && name
            .iter()
            .all(|&b| b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
    {
        return true;
    }
    let word = |w: &[u8]| {
        !w.is_empty()
            && w.iter()
                .all(|&b| b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
    };
    name == b"TOOL PATH" || name.split(|&b| b == b',').all(|w| word(trim(w)))
}

/// What the lexer found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Item {
    /// A listing header line, with its units if it is `Information Units`.
    Header(Option<Units>),
    /// The last line of an NX listing, `Tool Path Listing has N lines.`: the lines after it
    /// are skipped up to the next listing header line (SPEC §3.9).
    ListingEnd,
    /// A comment; its text (continuations joined with a blank) is in `content`.
    Comment,
    /// A free-text record; its name is in `name`.
    Text,
    /// A line of numbers without a record name (Creo, SPEC §3.10); fields in `fields`.
    Point,
    /// A record: `name` and `fields`.
    Record,
}

/// Streaming lexer over a `BufRead`.
pub(super) struct Lexer<R> {
    input: R,
    max: usize,
    /// The current physical line, without its line end (and without a UTF-8 BOM on line 1).
    line: Vec<u8>,
    /// Column of `line[0]` minus one (3 after a BOM).
    line_col0: u64,
    /// Physical lines read.
    pub(super) line_no: u64,
    eof: bool,
    /// Record content (pieces joined) or comment text.
    pub(super) content: Vec<u8>,
    /// Upper-case record name (records and free-text records).
    pub(super) name: Vec<u8>,
    /// Field ranges in `content`.
    pub(super) fields: Vec<(usize, usize)>,
    /// Values of the fields when all of them are plain numbers (the fast path), for the
    /// first `nums_len` fields (0 otherwise).
    nums: [f64; MAX_FAST_FIELDS],
    nums_len: usize,
    /// First line of the current item.
    pub(super) rec_line: u64,
    /// Column of `content[0]`.
    rec_col: u64,
    /// `content[..first_piece_end]` is on the record's first line.
    first_piece_end: usize,
    /// The record has no continuation.
    one_piece: bool,
    /// Warnings found while lexing, taken by the reader.
    pub(super) warnings: Vec<Warning>,
    /// Line of the last NX listing's last line, while the lines after it are skipped.
    listing_end: Option<u64>,
    /// The lines skipped after that last line have had their warning.
    after_end_warned: bool,
    /// The line count that last line states.
    pub(super) listing_lines: u64,
}

impl<R: BufRead> Lexer<R> {
    pub(super) fn new(input: R, max_record_bytes: usize) -> Lexer<R> {
        Lexer {
            input,
            max: max_record_bytes,
            line: Vec::with_capacity(256),
            line_col0: 0,
            line_no: 0,
            eof: false,
            content: Vec::with_capacity(256),
            name: Vec::with_capacity(32),
            fields: Vec::with_capacity(16),
            nums: [0.0; MAX_FAST_FIELDS],
            nums_len: 0,
            rec_line: 0,
            rec_col: 1,
            first_piece_end: 0,
            one_piece: true,
            warnings: Vec::new(),
            listing_end: None,
            after_end_warned: false,
            listing_lines: 0,
        }
    }

    /// Gives the input back.
    pub(super) fn into_inner(self) -> R {
        self.input
    }

    fn too_long(&self, line: u64) -> ClError {
        ClError::at(line, ClErrorKind::RecordTooLong { limit: self.max })
    }

    /// Reads the next physical line into `self.line`; false at the end of the input.
    fn read_line(&mut self) -> Result<bool, ClError> {
        self.line.clear();
        if self.eof {
            return Ok(false);
        }
        let mut got = false;
        // position in `line` of the first carriage return, if any
        let mut cr: Option<usize> = None;
        loop {
            let (used, done) = {
                let buf = match self.input.fill_buf() {
                    Ok(b) => b,
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                    Err(e) => {
                        return Err(ClError::at(
                            self.line_no + 1,
                            ClErrorKind::Io(e.to_string()),
                        ));
                    }
                };
                if buf.is_empty() {
                    self.eof = true;
                    break;
                }
                got = true;
                let mut from = 0;
                let newline = loop {
                    match find_byte2(&buf[from..], b'\n', b'\r') {
                        Some(k) if buf[from + k] == b'\r' => {
                            cr.get_or_insert(self.line.len() + from + k);
                            from += k + 1;
                        }
                        Some(k) => break Some(from + k),
                        None => break None,
                    }
                };
                match newline {
                    Some(i) => {
                        if self.line.len() + i > self.max {
                            return Err(self.too_long(self.line_no + 1));
                        }
                        self.line.extend_from_slice(&buf[..i]);
                        (i + 1, true)
                    }
                    None => {
                        if self.line.len() + buf.len() > self.max {
                            return Err(self.too_long(self.line_no + 1));
                        }
                        self.line.extend_from_slice(buf);
                        (buf.len(), false)
                    }
                }
            };
            self.input.consume(used);
            if done {
                break;
            }
        }
        if !got {
            return Ok(false);
        }
        self.line_no += 1;
        self.line_col0 = 0;
        if self.line_no == 1 && self.line.starts_with(&[0xEF, 0xBB, 0xBF]) {
            self.line.drain(..3);
            self.line_col0 = 3;
        }
        if let Some(i) = cr {
            while self.line.last() == Some(&b'\r') {
                self.line.pop();
            }
            let i = i.saturating_sub(self.line_col0 as usize);
            if i < self.line.len() {
                // a CR inside the line (the first CR is not part of the line end)
                return Err(ClError::new(
                    self.line_no,
                    Some(self.line_col0 + i as u64 + 1),
                    ClErrorKind::CarriageReturn,
                ));
            }
        }
        Ok(true)
    }

    /// The next item; `None` at the end of the input.
    pub(super) fn next_item(&mut self) -> Result<Option<Item>, ClError> {
        loop {
            if !self.read_line()? {
                return Ok(None);
            }
            let (a, b) = trim_range(&self.line);
            if a == b {
                continue;
            }
            self.rec_line = self.line_no;
            self.rec_col = self.line_col0 + a as u64 + 1;
            let s = &self.line[a..b];
            if let Some(end) = self.listing_end {
                // After a listing's last line only a new listing's header is read (SPEC §3.9).
                if header_line(s).is_none() {
                    if !self.after_end_warned && self.warnings.len() < 16 {
                        self.after_end_warned = true;
                        self.warnings.push(Warning {
                            line: self.line_no,
                            kind: WarningKind::AfterListingEnd { end_line: end },
                        });
                    }
                    continue;
                }
                self.listing_end = None;
            }
            if s.starts_with(b"GOTO/") {
                // the most frequent record: not a header, comment or free text; its name is
                // plain (checked again by `read_record`)
                if let Some(item) = self.read_record(a, b)? {
                    return Ok(Some(item));
                }
                continue;
            }
            if let Some(h) = header_line(s) {
                let units = match h {
                    Header::Plain => None,
                    Header::Units(v) => match listing_units(v) {
                        Some(u) => Some(u),
                        None => {
                            return Err(ClError::at(
                                self.line_no,
                                ClErrorKind::UnknownListingUnits {
                                    found: latin1_short(v, 40),
                                },
                            ));
                        }
                    },
                };
                return Ok(Some(Item::Header(units)));
            }
            if let Some(n) = listing_trailer(s) {
                self.listing_end = Some(self.line_no);
                self.after_end_warned = false;
                self.listing_lines = n;
                return Ok(Some(Item::ListingEnd));
            }
            if s.starts_with(b"$$") {
                self.read_comment(a, b)?;
                return Ok(Some(Item::Comment));
            }
            if let Some(n) = text_record_name(s) {
                self.name.clear();
                self.name
                    .extend(s[..n].iter().map(|c| c.to_ascii_uppercase()));
                return Ok(Some(Item::Text));
            }
            if let Some(item) = self.read_record(a, b)? {
                if item == Item::Record && !valid_name(&self.name) {
                    let end = find_byte(&self.content, b'/').unwrap_or(self.content.len());
                    return Err(ClError::new(
                        self.rec_line,
                        Some(self.rec_col),
                        ClErrorKind::BadRecordName {
                            found: latin1_short(trim(&self.content[..end]), 40),
                        },
                    ));
                }
                return Ok(Some(item));
            }
        }
    }

    /// A comment starting at `line[a..b]`, with the continuation of SPEC §3.7.
    fn read_comment(&mut self, a: usize, b: usize) -> Result<(), ClError> {
        self.content.clear();
        self.content.extend_from_slice(&self.line[a..b]);
        loop {
            let n = self.content.len();
            let continued = n >= 3 && self.content[n - 1] == b'$' && self.content[n - 2] != b'$';
            if !continued {
                return Ok(());
            }
            self.content.pop();
            while self.content.last().is_some_and(|&c| is_blank(c)) {
                self.content.pop();
            }
            self.content.push(b' ');
            if !self.read_line()? {
                return Err(ClError::at(
                    self.rec_line,
                    ClErrorKind::CommentContinuationAtEof,
                ));
            }
            let piece = trim(&self.line);
            if self.warnings.len() < 16 {
                if let Some(name) = lookalike(piece) {
                    self.warnings.push(Warning {
                        line: self.line_no,
                        kind: WarningKind::CommentTakesRecord { name },
                    });
                }
            }
            if self.content.len() + piece.len() > self.max {
                return Err(self.too_long(self.rec_line));
            }
            self.content.extend_from_slice(piece);
        }
    }

    /// Appends the trimmed `line[a..b]` to the record content.
    fn push_piece(&mut self, a: usize, b: usize) -> Result<(), ClError> {
        let (ta, tb) = trim_range(&self.line[a..b]);
        if ta == tb {
            return Ok(());
        }
        if self.content.len() + (tb - ta) > self.max {
            return Err(self.too_long(self.rec_line));
        }
        self.content.extend_from_slice(&self.line[a + ta..a + tb]);
        Ok(())
    }

    /// A record starting at `line[a..b]` (trimmed), with `$` continuation and `$$` trailing
    /// comments (SPEC §3.5, §3.6). `None` when its content is empty.
    fn read_record(&mut self, a: usize, b: usize) -> Result<Option<Item>, ClError> {
        self.fields.clear();
        self.one_piece = true;
        if a == 0 && find_byte(&self.line[..b], b'$').is_none() {
            // the usual case, one line without `$`: the line becomes the content, no copy
            std::mem::swap(&mut self.line, &mut self.content);
            self.content.truncate(b);
            self.first_piece_end = b;
            return Ok(self.classify_content());
        }
        self.content.clear();
        let (mut pa, mut pb) = (a, b);
        let mut first = true;
        loop {
            let dollar = find_byte(&self.line[pa..pb], b'$');
            let (end, go_on) = match dollar {
                None => (pb, false),
                Some(k) if self.line.get(pa + k + 1) == Some(&b'$') => (pa + k, false),
                Some(k) => (pa + k, true),
            };
            self.push_piece(pa, end)?;
            if first {
                self.first_piece_end = self.content.len();
                first = false;
            }
            if !go_on {
                break;
            }
            self.one_piece = false;
            if !self.read_line()? {
                return Err(ClError::at(self.rec_line, ClErrorKind::ContinuationAtEof));
            }
            (pa, pb) = trim_range(&self.line);
        }
        if self.content.is_empty() {
            return Ok(None);
        }
        Ok(self.classify_content())
    }

    /// Classifies the record content: a point line or a record with its name and fields.
    fn classify_content(&mut self) -> Option<Item> {
        let c0 = self.content[0];
        if c0.is_ascii_digit() || matches!(c0, b'+' | b'-' | b'.') {
            // one more point of a GOTO (SPEC §3.10): named GOTO in messages
            self.name.clear();
            self.name.extend_from_slice(b"GOTO");
            self.split(0);
            return Some(Item::Point);
        }
        let slash = if self.content.starts_with(b"GOTO/") {
            self.name.clear();
            self.name.extend_from_slice(b"GOTO");
            Some(4)
        } else {
            let slash = find_byte(&self.content, b'/');
            let name_end = slash.unwrap_or(self.content.len());
            collapse_upper(&self.content[..name_end], &mut self.name);
            slash
        };
        self.fields.clear();
        self.nums_len = 0;
        if let Some(s) = slash {
            self.split(s + 1);
        }
        Some(Item::Record)
    }

    /// Splits `content[from..]` into fields: in one pass with their values when they are
    /// all plain numbers, else by the general rule.
    fn split(&mut self, from: usize) {
        if !self.split_numbers(from) {
            self.split_fields(from);
        }
    }

    /// The one-pass path: fields that are all numbers of the fast form (SPEC §3.3), at most
    /// [`MAX_FAST_FIELDS`], with blanks around the commas. False (and nothing kept) otherwise.
    fn split_numbers(&mut self, from: usize) -> bool {
        self.fields.clear();
        self.nums_len = 0;
        let c = &self.content;
        let n = c.len();
        let mut i = from;
        let mut k = 0;
        loop {
            while i < n && is_blank(c[i]) {
                i += 1;
            }
            if k == MAX_FAST_FIELDS {
                break;
            }
            let Some((v, used)) = number::fast_prefix(&c[i..]) else {
                break;
            };
            self.nums[k] = v;
            self.fields.push((i, i + used));
            k += 1;
            i += used;
            while i < n && is_blank(c[i]) {
                i += 1;
            }
            if i == n {
                self.nums_len = k;
                return true;
            }
            if c[i] != b',' {
                break;
            }
            i += 1;
        }
        self.fields.clear();
        false
    }

    /// Splits `content[from..]` on `,` into trimmed field ranges; a lone empty field is no
    /// field (`RAPID/`).
    fn split_fields(&mut self, from: usize) {
        self.fields.clear();
        let c = &self.content;
        let n = c.len();
        // (start of the field's text, end of its last non-blank byte)
        let mut first = usize::MAX;
        let mut last = from;
        let mut start = from;
        for (i, &b) in c.iter().enumerate().skip(from) {
            if b == b',' {
                if first == usize::MAX {
                    self.fields.push((start, start));
                } else {
                    self.fields.push((first, last));
                }
                first = usize::MAX;
                start = i + 1;
            } else if !is_blank(b) {
                if first == usize::MAX {
                    first = i;
                }
                last = i + 1;
            }
        }
        if first == usize::MAX {
            self.fields.push((start.min(n), start.min(n)));
        } else {
            self.fields.push((first, last));
        }
        if self.fields.len() == 1 && self.fields[0].0 == self.fields[0].1 {
            self.fields.clear();
        }
    }
}

impl<R> Lexer<R> {
    /// The values of all fields when they are all plain numbers (the one-pass path).
    #[inline]
    pub(super) fn all_numbers(&self) -> Option<&[f64]> {
        (self.nums_len == self.fields.len()).then(|| &self.nums[..self.nums_len])
    }

    /// Number of fields of the current record.
    pub(super) fn nfields(&self) -> usize {
        self.fields.len()
    }

    /// Field `i` (trimmed) of the current record.
    pub(super) fn field(&self, i: usize) -> &[u8] {
        let (a, b) = self.fields[i];
        &self.content[a..b]
    }

    /// Field `i` read as a number.
    pub(super) fn num(&self, i: usize) -> Num {
        if i < self.nums_len {
            return Num::Value(self.nums[i]);
        }
        number::parse(self.field(i))
    }

    /// Whether field `i` is the word `w` (upper case), case-insensitively.
    pub(super) fn is_word(&self, i: usize, w: &[u8]) -> bool {
        i < self.fields.len() && self.field(i).eq_ignore_ascii_case(w)
    }

    /// Column of content offset `at`, if it is on the record's first line.
    pub(super) fn column_of(&self, at: usize) -> Option<u64> {
        let on_first = at < self.first_piece_end || (self.one_piece && at == self.first_piece_end);
        on_first.then_some(self.rec_col + at as u64)
    }

    /// The current record's name as text.
    pub(super) fn name_str(&self) -> String {
        latin1_short(&self.name, 40)
    }

    /// An error at the current record's line, column of its start.
    pub(super) fn err(&self, kind: ClErrorKind) -> ClError {
        ClError::new(self.rec_line, Some(self.rec_col), kind)
    }

    /// An error about field `i` of the current record.
    pub(super) fn err_field(&self, i: usize, kind: ClErrorKind) -> ClError {
        ClError::new(self.rec_line, self.field_column(i), kind)
    }

    /// The column where the current record starts.
    pub(super) fn record_column(&self) -> u64 {
        self.rec_col
    }

    /// The column of field `i` of the current record (of its end when it has fewer fields);
    /// `None` on a continuation line.
    pub(super) fn field_column(&self, i: usize) -> Option<u64> {
        let at = self.fields.get(i).map_or(self.content.len(), |f| f.0);
        self.column_of(at)
    }

    /// Reads fields `0..out.len()` as numbers (each must be a finite number).
    pub(super) fn numbers(&self, out: &mut [f64]) -> Result<(), ClError> {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.number(i)?;
        }
        Ok(())
    }

    /// Field `i` as a finite number, or the error naming it.
    pub(super) fn number(&self, i: usize) -> Result<f64, ClError> {
        if i < self.nums_len {
            return Ok(self.nums[i]);
        }
        match self.num(i) {
            Num::Value(v) => Ok(v),
            Num::OutOfRange => Err(self.err_field(
                i,
                ClErrorKind::NumberOutOfRange {
                    record: self.name_str(),
                },
            )),
            Num::NotNumber => Err(self.err_field(
                i,
                ClErrorKind::BadNumber {
                    record: self.name_str(),
                    field: i + 1,
                    found: latin1_short(self.field(i), 40),
                },
            )),
        }
    }
}

/// The record name a comment continuation line starts with, if it is one that matters.
fn lookalike(piece: &[u8]) -> Option<String> {
    let end = piece.iter().position(|&c| c == b'/').unwrap_or(piece.len());
    let mut name = Vec::new();
    collapse_upper(&piece[..end], &mut name);
    if (end < piece.len() || name == b"RAPID" || name == b"FINI")
        && RECORD_LOOKALIKES.contains(&name.as_slice())
    {
        Some(latin1_short(&name, 20))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn items(text: &str) -> Vec<(u64, Item, String, Vec<String>)> {
        let mut lx = Lexer::new(text.as_bytes(), 1 << 20);
        let mut out = Vec::new();
        while let Some(it) = lx.next_item().unwrap() {
            let name = match it {
                Item::Comment => String::from_utf8_lossy(&lx.content).into_owned(),
                _ => String::from_utf8_lossy(&lx.name).into_owned(),
            };
            let fields = match it {
                Item::Record | Item::Point => (0..lx.nfields())
                    .map(|i| String::from_utf8_lossy(lx.field(i)).into_owned())
                    .collect(),
                _ => Vec::new(),
            };
            out.push((lx.rec_line, it, name, fields));
        }
        out
    }

    fn err(text: &str) -> ClError {
        let mut lx = Lexer::new(text.as_bytes(), 64);
        loop {
            match lx.next_item() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("no error in {text:?}"),
                Err(e) => return e,
            }
        }
    }

    #[test]
    fn continuation_joins_pieces() {
        let it = items("GOTO / 1.0, $ rest ignored\n   $\n  2.0,$\n3.0\nRAPID\n");
        assert_eq!(it.len(), 2);
        assert_eq!(it[0].0, 1);
        assert_eq!(it[0].2, "GOTO");
        assert_eq!(it[0].3, vec!["1.0", "2.0", "3.0"]);
        assert_eq!(it[1].0, 5);
        assert_eq!(it[1].2, "RAPID");
        // a trailing comment ends the record and the line
        let it = items("GOTO/1,2,3 $$ note $ not a continuation\nFINI\n");
        assert_eq!(it[0].3, vec!["1", "2", "3"]);
        assert_eq!(it[1].2, "FINI");
        // a continuation line that is a comment ends the record
        let it = items("GOTO/1,2,$\n$$ comment\n3\n");
        assert_eq!(it[0].3, vec!["1", "2", ""]);
        assert_eq!(it[1].1, Item::Point);
    }

    #[test]
    fn continued_comment_blocks() {
        let it = items(
            "$$-> CSYS / 1, 0, 0, 0,  $\n            0, 1, 0, 0,  $\n   0, 0, 1, 0\nGOTO/1,2,3\n",
        );
        assert_eq!(it.len(), 2);
        assert_eq!(it[0].1, Item::Comment);
        assert_eq!(it[0].2, "$$-> CSYS / 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0");
        assert_eq!(it[1].0, 4);
        // `$$` at the end is not a continuation
        let it = items("$$ a $$\nGOTO/1,2,3\n$$\n$$$\nFINI\n");
        assert_eq!(it.len(), 5);
        // a continued comment that takes a GOTO line: a warning
        let mut lx = Lexer::new(&b"$$ cost in $\nGOTO/1,2,3\nFINI\n"[..], 1 << 20);
        assert_eq!(lx.next_item().unwrap(), Some(Item::Comment));
        assert_eq!(lx.warnings.len(), 1);
        assert_eq!(lx.warnings[0].line, 2);
        assert_eq!(err("$$ a $\n").line, 1);
        assert_eq!(err("$$ a $\n").kind, ClErrorKind::CommentContinuationAtEof);
    }

    #[test]
    fn text_records_and_headers() {
        let it = items(
            "======\nInformation listing created by :  x\nDate : 1\nPARTNO PART $ X\nPPRINT/ GOTO/1,2,3 $\nINSERTX/1\nInformation Units : in\n",
        );
        assert_eq!(it[0].1, Item::Header(None));
        assert_eq!(it[1].1, Item::Header(None));
        assert_eq!(it[2].1, Item::Header(None));
        assert_eq!((it[3].1, it[3].2.as_str()), (Item::Text, "PARTNO"));
        assert_eq!((it[4].1, it[4].2.as_str()), (Item::Text, "PPRINT"));
        assert_eq!((it[5].1, it[5].2.as_str()), (Item::Record, "INSERTX"));
        assert_eq!(it[6].1, Item::Header(Some(Units::Inch)));
        assert_eq!(
            err("Information Units : feet\n").kind,
            ClErrorKind::UnknownListingUnits {
                found: "feet".into()
            }
        );
    }

    #[test]
    fn names_fields_and_blanks() {
        let it = items("tool   path / OP , TOOL , T1\nRAPID/\nEND-OF-PATH\nLOADTL/1,,,\n");
        assert_eq!(it[0].2, "TOOL PATH");
        assert_eq!(it[0].3, vec!["OP", "TOOL", "T1"]);
        assert!(it[1].3.is_empty());
        assert_eq!(it[2].2, "END-OF-PATH");
        assert_eq!(it[3].3, vec!["1", "", "", ""]);
        let e = err("GOTO 1,2,3\n");
        assert_eq!((e.line, e.column), (1, Some(1)));
        assert!(matches!(e.kind, ClErrorKind::BadRecordName { .. }));
        let e = err("\n  %\n");
        assert_eq!((e.line, e.column), (2, Some(3)));
    }

    #[test]
    fn line_ends_and_limits() {
        let it = items("\u{feff}GOTO/1,2,3\r\nFINI\r\n");
        assert_eq!(it[0].2, "GOTO");
        let e = err("GOTO/1,2,3\rGOTO/4,5,6\n");
        assert_eq!(e.kind, ClErrorKind::CarriageReturn);
        assert_eq!(e.column, Some(11));
        let e = err("GOTO/1,2,3,$\n");
        assert_eq!((e.line, e.kind), (1, ClErrorKind::ContinuationAtEof));
        // the limit (64 bytes in `err`): a long line, a long record
        let long = format!("PPRINT/{}\n", "x".repeat(100));
        assert_eq!(err(&long).kind, ClErrorKind::RecordTooLong { limit: 64 });
        let cont = format!("RAPID\nGOTO/1,$\n{}", "0000000000$\n".repeat(10));
        let e = err(&cont);
        assert_eq!(
            (e.line, e.kind),
            (2, ClErrorKind::RecordTooLong { limit: 64 })
        );
    }

    #[test]
    fn columns() {
        let mut lx = Lexer::new(&b"  GOTO / 1.0, x, 3\n"[..], 1 << 20);
        lx.next_item().unwrap();
        let e = lx.number(1).unwrap_err();
        assert_eq!((e.line, e.column), (1, Some(15)));
        let mut lx = Lexer::new(&b"GOTO/1.0,$\n  x,3\n"[..], 1 << 20);
        lx.next_item().unwrap();
        let e = lx.number(1).unwrap_err();
        assert_eq!((e.line, e.column), (1, None));
    }
}
