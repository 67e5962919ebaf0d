//! One line of G-code as words: the lexer. Comments `( )` and `;`, block delete `/`, `%`
//! markers, spaces anywhere (RS274/NGC ignores them, even inside numbers), letters in either
//! case. What the reader does not evaluate (parameters `#`, expressions `[ ]`, o-word control)
//! is refused here with its column, never skipped.

use super::error::GcodeError;

/// Most words in one block.
pub const MAX_WORDS: usize = 48;

/// One word: a letter and its number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Word {
    /// Upper-case letter.
    pub letter: u8,
    /// Its number.
    pub value: f64,
    /// 1-based column of the letter.
    pub column: u32,
}

/// One line, lexed.
#[derive(Debug, Clone)]
pub struct Block {
    /// `/` at the start of the line.
    pub deleted: bool,
    /// The line is a `%` marker.
    pub percent: bool,
    /// The `N` word (the first one; more than one is an error).
    pub n: Option<u64>,
    /// The block's first comment `( )`, trimmed (a post's note on the block).
    pub comment: Option<super::types::Note>,
    words: [Word; MAX_WORDS],
    len: usize,
}

impl Block {
    pub fn new() -> Block {
        Block {
            deleted: false,
            percent: false,
            n: None,
            comment: None,
            words: [Word {
                letter: 0,
                value: 0.0,
                column: 0,
            }; MAX_WORDS],
            len: 0,
        }
    }

    /// The words other than `N`, in line order.
    pub fn words(&self) -> &[Word] {
        &self.words[..self.len]
    }

    /// Lexes `text` (one line without its end) into `self`.
    pub fn lex(&mut self, text: &[u8], line: u64) -> Result<(), GcodeError> {
        self.deleted = false;
        self.percent = false;
        self.n = None;
        self.comment = None;
        self.len = 0;
        let err = |i: usize, m: String| Err(GcodeError::new(line, Some(i as u64 + 1), m));
        let mut i = skip_blank(text, 0);
        if i < text.len() && text[i] == b'/' {
            self.deleted = true;
            i += 1;
        }
        if i < text.len() && text[i] == b'%' {
            let rest = skip_blank(text, i + 1);
            if rest == text.len() || text[rest] == b'(' || text[rest] == b';' {
                self.percent = true;
                return Ok(());
            }
            return err(
                i,
                "`%` must be alone on its line (the program's start or end marker)".into(),
            );
        }
        let mut program_number = false;
        while i < text.len() {
            let c = text[i];
            match c {
                b' ' | b'\t' | b'\r' | b'\x0c' => i += 1,
                b'(' => {
                    let Some(end) = text[i + 1..].iter().position(|&b| b == b')') else {
                        return err(i, "comment `(` not closed on its line".into());
                    };
                    let inside = &text[i + 1..i + 1 + end];
                    if inside.contains(&b'(') {
                        return err(i, "a comment may not contain `(` (nested comment)".into());
                    }
                    if self.comment.is_none() {
                        let text = String::from_utf8_lossy(inside.trim_ascii());
                        self.comment = Some(super::types::Note::new(&text));
                    }
                    i += end + 2;
                }
                b';' => break,
                b'#' => return err(i, PARAMETERS.into()),
                b'[' => return err(i, EXPRESSIONS.into()),
                b'O' | b'o' => {
                    // A Fanuc program number (`O1234` alone) names the program; o-word control
                    // (`o100 sub`, `o100 call`, `if`, `while`, ...) is refused.
                    let (value, next) = number(text, i + 1, line)?;
                    let rest = skip_blank(text, next);
                    let only_comment =
                        rest == text.len() || text[rest] == b'(' || text[rest] == b';';
                    if self.len == 0 && self.n.is_none() && only_comment && value >= 0.0 {
                        program_number = true;
                        i = next;
                        continue;
                    }
                    return err(
                        i,
                        "o-word control (sub, call, if, while, repeat, ...) is not evaluated by verne: expand the program first".into(),
                    );
                }
                _ if c.is_ascii_alphabetic() => {
                    let letter = c.to_ascii_uppercase();
                    if !b"ABCDFGHIJKLMNPQRSTUVWXYZ".contains(&letter) {
                        return err(
                            i,
                            format!(
                                "unknown word `{}`: RS274/NGC words are A B C D F G H I J K L M N P Q R S T U V W X Y Z",
                                c as char
                            ),
                        );
                    }
                    if program_number {
                        return err(
                            i,
                            "a program number `O...` must be alone on its line".into(),
                        );
                    }
                    let (value, next) = number(text, i + 1, line)?;
                    if letter == b'N' {
                        if self.n.is_some() || self.len > 0 {
                            return err(i, "`N` must be the first word of the block, once".into());
                        }
                        if value < 0.0 || value.fract() != 0.0 || value > 1e15 {
                            return err(
                                i,
                                format!("expected a line number (N0..), found N{value}"),
                            );
                        }
                        self.n = Some(value as u64);
                    } else {
                        if self.len == MAX_WORDS {
                            return err(i, format!("more than {MAX_WORDS} words in one block"));
                        }
                        self.words[self.len] = Word {
                            letter,
                            value,
                            column: i as u32 + 1,
                        };
                        self.len += 1;
                    }
                    i = next;
                }
                _ => {
                    let shown = if c.is_ascii_graphic() {
                        format!("`{}`", c as char)
                    } else {
                        format!("byte 0x{c:02x}")
                    };
                    return err(
                        i,
                        format!(
                            "unexpected {shown}: expected a word (a letter and a number), a comment or the end of the line"
                        ),
                    );
                }
            }
        }
        Ok(())
    }
}

const PARAMETERS: &str = "parameters (`#`) are not evaluated by verne: give the program with the values written out (a post's plain output)";
const EXPRESSIONS: &str =
    "expressions (`[ ]`) are not evaluated by verne: give the program with the values written out";

fn skip_blank(text: &[u8], mut i: usize) -> usize {
    while i < text.len() && matches!(text[i], b' ' | b'\t' | b'\r') {
        i += 1;
    }
    i
}

/// Reads the number after a letter at `i` (spaces allowed anywhere in it): `[+-]digits[.digits]`,
/// at least one digit. Returns the value and the index after it.
fn number(text: &[u8], mut i: usize, line: u64) -> Result<(f64, usize), GcodeError> {
    let start = i;
    i = skip_blank(text, i);
    let mut negative = false;
    if i < text.len() && (text[i] == b'-' || text[i] == b'+') {
        negative = text[i] == b'-';
        i = skip_blank(text, i + 1);
    }
    let mut mantissa: u64 = 0;
    let mut digits = 0u32;
    let mut scale = 0i32;
    let mut seen_point = false;
    let mut long = false;
    while i < text.len() {
        match text[i] {
            d @ b'0'..=b'9' => {
                if mantissa < 1_000_000_000_000_000 {
                    mantissa = mantissa * 10 + u64::from(d - b'0');
                    if seen_point {
                        scale += 1;
                    }
                } else {
                    long = true;
                    if !seen_point {
                        scale -= 1;
                    }
                }
                digits += 1;
            }
            b'.' if !seen_point => seen_point = true,
            b' ' | b'\t' => {}
            _ => break,
        }
        i += 1;
    }
    if digits == 0 {
        let at = skip_blank(text, start);
        let found = text.get(at).copied();
        let column = Some(at as u64 + 1);
        if found == Some(b'#') {
            return Err(GcodeError::new(line, column, PARAMETERS));
        }
        if found == Some(b'[') {
            return Err(GcodeError::new(line, column, EXPRESSIONS));
        }
        let shown = match found {
            Some(c) if c.is_ascii_graphic() => format!("`{}`", c as char),
            Some(_) => "a control byte".to_string(),
            None => "the end of the line".to_string(),
        };
        return Err(GcodeError::new(
            line,
            column,
            format!("expected a number after the letter, found {shown}"),
        ));
    }
    // Fast path, correctly rounded: an exact integer mantissa (< 2^53) and one division by
    // an exact power of ten (<= 1e22). Else the standard library's parser.
    let v = if !long && mantissa < (1 << 53) && (0..=22).contains(&scale) {
        mantissa as f64 / POW10[scale as usize]
    } else {
        let s: String = text[start..i]
            .iter()
            .filter(|c| !matches!(c, b' ' | b'\t'))
            .map(|&c| c as char)
            .collect();
        s.trim_start_matches('+').parse::<f64>().map_err(|_| {
            GcodeError::new(
                line,
                Some(start as u64 + 1),
                format!("`{s}` is not a number"),
            )
        })?
    };
    if !v.is_finite() {
        return Err(GcodeError::new(
            line,
            Some(start as u64 + 1),
            "a number too large for a double",
        ));
    }
    let v = if negative { -v.abs() } else { v.abs() };
    // Trailing blanks are part of the number's span already skipped.
    Ok((v, i))
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(s: &str) -> Result<Block, GcodeError> {
        let mut b = Block::new();
        b.lex(s.as_bytes(), 7).map(|_| b)
    }

    #[test]
    fn words_comments_and_spaces() {
        let b = lex("n10 g1 x 1 . 5 Y-.25 (move) z+3. ; end").unwrap();
        assert_eq!(b.n, Some(10));
        let w: Vec<(char, f64)> = b
            .words()
            .iter()
            .map(|w| (w.letter as char, w.value))
            .collect();
        assert_eq!(w, vec![('G', 1.0), ('X', 1.5), ('Y', -0.25), ('Z', 3.0)]);
        assert_eq!(b.words()[1].column, 8);
    }

    #[test]
    fn numbers_are_correctly_rounded() {
        for s in [
            "0.1",
            "123.456789",
            "-0.000001",
            "99999.99999",
            "1234567890.123456789",
        ] {
            let b = lex(&format!("X{s}")).unwrap();
            assert_eq!(b.words()[0].value, s.parse::<f64>().unwrap(), "{s}");
        }
    }

    #[test]
    fn refusals_name_the_column() {
        let e = lex("G1 X#1").unwrap_err();
        assert_eq!((e.line, e.column), (7, Some(5)));
        assert!(e.message.contains("parameters"));
        assert!(lex("o100 sub").unwrap_err().message.contains("o-word"));
        assert!(
            lex("G1 X[1+2]")
                .unwrap_err()
                .message
                .contains("expressions")
        );
        assert!(
            lex("G1 E5")
                .unwrap_err()
                .message
                .contains("unknown word `E`")
        );
        assert!(
            lex("G1 X")
                .unwrap_err()
                .message
                .contains("expected a number")
        );
        assert!(lex("G1 (open").unwrap_err().message.contains("not closed"));
        assert!(lex("G1 N5").unwrap_err().message.contains("first word"));
    }

    #[test]
    fn markers_program_numbers_and_block_delete() {
        assert!(lex("%").unwrap().percent);
        assert!(lex("O0001 (PART)").unwrap().words().is_empty());
        let b = lex("/G0 X1").unwrap();
        assert!(b.deleted);
        assert_eq!(b.words().len(), 2);
    }
}
