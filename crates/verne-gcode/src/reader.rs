//! The interpreter: blocks in, canonical positions out. The modal state of RS274/NGC as
//! LinuxCNC keeps it (motion, plane, distance modes, feed mode, units, return mode), straight
//! moves, arcs interpolated within the chord tolerance ([`crate::arc`]), canned cycles expanded
//! ([`crate::cycle`]). Every code is either applied, counted as not moving the machine, or
//! refused with its line and column.

use std::io::{BufRead, Read};

use super::arc::{self, ArcWords};
use super::block::{Block, Word};
use super::cycle::{self, CycleWords};
use super::error::GcodeError;
use super::types::{AXES, Axis, Kind, Motion, Options, Row, Summary, Units};

/// The motion mode (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MotionMode {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    /// A canned cycle, by its G number.
    Cycle(u16),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FeedMode {
    PerMinute,
    InverseTime,
    PerRevolution,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Plane {
    Xy,
    Zx,
    Yz,
}

/// The modal state and position.
#[derive(Debug, Clone)]
pub(crate) struct State {
    pub units: Units,
    pub incremental: bool,
    pub arc_incremental: bool,
    pub feed_mode: FeedMode,
    pub plane: Plane,
    pub motion: Option<MotionMode>,
    pub retract_to_r: bool,
    /// The modal feed as written (F), and mm per program unit when it was written: linear
    /// moves run at F times the scale mm/min, rotary-only moves at F deg/min.
    pub feed: Option<f64>,
    pub feed_scale: f64,
    pub spindle: Option<f64>,
    pub selected_tool: Option<u32>,
    pub tool: Option<u32>,
    pub position: [f64; 9],
    pub known: u16,
    pub tool_vector: Option<[f64; 3]>,
    /// Sticky cycle words (mm): R, Z, Q; the Z where the cycle began (for G98).
    pub cycle_r: Option<f64>,
    pub cycle_z: Option<f64>,
    pub cycle_q: Option<f64>,
    pub cycle_p: Option<f64>,
    /// The previous motion block was a cycle (the next one continues the series).
    pub cycle_continuing: bool,
}

/// A streaming reader of a G-code program: an iterator of [`Row`]s.
pub struct Reader<R: BufRead> {
    input: R,
    options: Options,
    state: State,
    summary: Summary,
    block: Block,
    buf: Vec<u8>,
    out: Vec<Row>,
    out_pos: usize,
    line: u64,
    ended: bool,
    percent_open: bool,
    failed: bool,
    /// The block being executed has an F word.
    block_f: bool,
}

impl<R: BufRead> Reader<R> {
    /// A reader over `input` with `options`; an invalid option is an error at line 0.
    pub fn new(input: R, options: Options) -> Result<Reader<R>, GcodeError> {
        if !(options.chord_tol_mm.is_finite() && options.chord_tol_mm > 0.0) {
            return Err(GcodeError::new(
                0,
                None,
                "the chord tolerance must be a positive number of mm",
            ));
        }
        if options.max_arc_points == 0 || options.max_line_bytes == 0 {
            return Err(GcodeError::new(
                0,
                None,
                "the reader's limits must be positive",
            ));
        }
        let units = options.units.unwrap_or(Units::Mm);
        Ok(Reader {
            input,
            options,
            state: State {
                units,
                incremental: false,
                arc_incremental: true,
                feed_mode: FeedMode::PerMinute,
                plane: Plane::Xy,
                motion: None,
                retract_to_r: false,
                feed: None,
                feed_scale: units.mm_per_unit(),
                spindle: None,
                selected_tool: None,
                tool: None,
                position: [f64::NAN; 9],
                known: 0,
                tool_vector: None,
                cycle_r: None,
                cycle_z: None,
                cycle_q: None,
                cycle_p: None,
                cycle_continuing: false,
            },
            summary: Summary::new(units),
            block: Block::new(),
            buf: Vec::with_capacity(256),
            out: Vec::with_capacity(16),
            out_pos: 0,
            line: 0,
            ended: false,
            percent_open: false,
            failed: false,
            block_f: false,
        })
    }

    /// What the reader saw so far (complete once the iterator has returned `None`).
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    /// The summary, consuming the reader.
    pub fn into_summary(self) -> Summary {
        self.summary
    }

    /// Reads lines until one yields rows, the program ends, or an error.
    fn advance(&mut self) -> Result<bool, GcodeError> {
        self.out.clear();
        self.out_pos = 0;
        while self.out.is_empty() {
            if self.ended {
                self.count_lines_after_end()?;
                return Ok(false);
            }
            self.buf.clear();
            let limit = self.options.max_line_bytes as u64 + 1;
            let n = (&mut self.input)
                .take(limit)
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| GcodeError::new(0, None, format!("read error: {e}")))?;
            if n == 0 {
                self.finish();
                return Ok(false);
            }
            self.line += 1;
            self.summary.lines = self.line;
            if self.buf.len() as u64 >= limit && self.buf.last() != Some(&b'\n') {
                return Err(GcodeError::new(
                    self.line,
                    None,
                    format!(
                        "line longer than {} bytes: not a G-code block",
                        self.options.max_line_bytes
                    ),
                ));
            }
            let mut text: &[u8] = &self.buf;
            if text.last() == Some(&b'\n') {
                text = &text[..text.len() - 1];
            }
            if text.last() == Some(&b'\r') {
                text = &text[..text.len() - 1];
            }
            if let Some(p) = text.iter().position(|&b| b == b'\r') {
                return Err(GcodeError::new(
                    self.line,
                    Some(p as u64 + 1),
                    "a carriage return inside a line (a file with CR-only line ends?): convert the line ends to LF or CRLF",
                ));
            }
            if self.line == 1 && text.starts_with(b"\xef\xbb\xbf") {
                text = &text[3..];
            }
            let mut block = std::mem::replace(&mut self.block, Block::new());
            let r = block
                .lex(text, self.line)
                .and_then(|_| self.execute(&block));
            self.block = block;
            r?;
        }
        Ok(true)
    }

    fn count_lines_after_end(&mut self) -> Result<(), GcodeError> {
        let mut sink = Vec::new();
        loop {
            sink.clear();
            let n = (&mut self.input)
                .take(self.options.max_line_bytes as u64 + 1)
                .read_until(b'\n', &mut sink)
                .map_err(|e| GcodeError::new(0, None, format!("read error: {e}")))?;
            if n == 0 {
                return Ok(());
            }
            // Blank lines and the closing `%` are not program text.
            let t = sink.trim_ascii();
            if !t.is_empty() && t != b"%" {
                self.summary.lines_after_end += 1;
            }
        }
    }

    fn finish(&mut self) {
        if self.summary.end_line.is_none() {
            self.summary.warn(
                0,
                "the program has no end (M2, M30 or a closing `%`): read to the end of the file",
            );
        }
        if self.summary.units_line.is_none()
            && self.options.units.is_none()
            && self.summary.rows > 0
        {
            self.summary.warn(
                0,
                "no G20/G21: millimetres assumed (state the units with --units, or write G21 at the start)",
            );
        }
        self.ended = true;
    }

    /// One block, in the order of execution of RS274/NGC (LinuxCNC's G-code reference,
    /// "Order of execution"): feed mode, F, S, T, M6, units, plane, distance modes, return
    /// mode, non-modal codes, motion, program end.
    fn execute(&mut self, b: &Block) -> Result<(), GcodeError> {
        if b.percent {
            if self.summary.blocks == 0 && !self.percent_open {
                self.percent_open = true;
            } else {
                self.summary.end_line = Some(self.line);
                self.ended = true;
            }
            return Ok(());
        }
        if b.deleted {
            self.summary.block_deleted += 1;
            if self.summary.block_deleted == 1 {
                self.summary.warn(
                    self.line,
                    "block delete `/`: this block and every later one starting with `/` are skipped, as with the controller's block delete switch on",
                );
            }
            return Ok(());
        }
        let words = b.words();
        if words.is_empty() {
            return Ok(());
        }
        self.summary.blocks += 1;
        let line = self.line;
        let err = |w: &Word, m: String| GcodeError::new(line, Some(u64::from(w.column)), m);

        // Gather the words.
        let mut g_groups: [Option<(u16, Word)>; 16] = [None; 16];
        let mut m_codes: [Option<(u16, Word)>; 8] = [None; 8];
        let mut n_m = 0;
        let mut axes: [Option<(f64, Word)>; 9] = [None; 9];
        let mut other: [Option<(f64, Word)>; 26] = [None; 26];
        for w in words {
            match w.letter {
                b'G' => {
                    let code = decimal_code(w)
                        .ok_or_else(|| err(w, format!("G{} is not a G code", w.value)))?;
                    let group = g_group(code).ok_or_else(|| err(w, refusal_g(code)))?;
                    // G80 with another motion code (`G80 G0 Z50`): the cycle ends and the
                    // other motion follows, as LinuxCNC reads it.
                    if group == GROUP_MOTION {
                        match g_groups[group] {
                            Some((800, _)) => {
                                g_groups[group] = Some((code, *w));
                                continue;
                            }
                            Some(_) if code == 800 => continue,
                            _ => {}
                        }
                    }
                    if let Some((prev, _)) = g_groups[group] {
                        return Err(err(
                            w,
                            format!(
                                "G{} and G{} are in the same modal group: one per block",
                                show_code(prev),
                                show_code(code)
                            ),
                        ));
                    }
                    g_groups[group] = Some((code, *w));
                }
                b'M' => {
                    let code = decimal_code(w)
                        .filter(|c| c % 10 == 0)
                        .ok_or_else(|| err(w, format!("M{} is not an M code", w.value)))?;
                    let code = code / 10;
                    if let Some((group, name)) = m_group(code) {
                        let same = m_codes[..n_m]
                            .iter()
                            .flatten()
                            .find(|(c, _)| m_group(*c).is_some_and(|(g, _)| g == group));
                        if let Some((prev, _)) = same {
                            return Err(err(
                                w,
                                format!(
                                    "M{prev} and M{code} are in the same modal group ({name}): one per block, as LinuxCNC reads it"
                                ),
                            ));
                        }
                    }
                    if n_m == m_codes.len() {
                        return Err(err(w, "too many M codes in one block".into()));
                    }
                    m_codes[n_m] = Some((code, *w));
                    n_m += 1;
                }
                _ => {
                    if let Some(a) = Axis::from_letter(w.letter) {
                        if axes[a as usize].is_some() {
                            return Err(err(w, format!("{} given twice in one block", a.letter())));
                        }
                        axes[a as usize] = Some((w.value, *w));
                    } else {
                        let k = usize::from(w.letter - b'A');
                        if other[k].is_some() {
                            return Err(err(
                                w,
                                format!("{} given twice in one block", w.letter as char),
                            ));
                        }
                        other[k] = Some((w.value, *w));
                    }
                }
            }
        }
        let word = |c: u8| other[usize::from(c - b'A')];

        // Refusals of modal codes that change the geometry (the group table lets them in so
        // that the message names them).
        for (code, w) in g_groups.iter().flatten() {
            if let Some(m) = refused_modal(*code) {
                return Err(err(w, m));
            }
        }
        for (code, w) in m_codes.iter().flatten() {
            if matches!(code, 98 | 99) {
                return Err(err(
                    w,
                    format!(
                        "M{code} (subprogram call or return) is not expanded by verne: expand the program first"
                    ),
                ));
            }
        }

        // Units first: they scale this block's numbers.
        if let Some((code, w)) = g_groups[GROUP_UNITS] {
            let u = if code == 200 { Units::Inch } else { Units::Mm };
            if self.summary.units_line.is_none() {
                if let Some(stated) = self.options.units
                    && stated != u
                {
                    return Err(err(
                        &w,
                        format!(
                            "G{} says {} but the units were stated as {} (--units)",
                            code / 10,
                            u.as_str(),
                            stated.as_str()
                        ),
                    ));
                }
                if self.summary.rows > 0 && self.options.units.is_none() {
                    self.summary.warn(
                        line,
                        format!(
                            "G{} comes after moves that were read in millimetres",
                            code / 10
                        ),
                    );
                }
                self.summary.units_line = Some(line);
            }
            self.state.units = u;
            self.summary.units = u;
        }
        let scale = self.state.units.mm_per_unit();

        // Feed mode, then F.
        if let Some((code, _)) = g_groups[GROUP_FEED_MODE] {
            self.state.feed_mode = match code {
                930 => FeedMode::InverseTime,
                950 => FeedMode::PerRevolution,
                _ => FeedMode::PerMinute,
            };
            if code == 930 {
                self.summary.inverse_time_seen = true;
            }
            if code == 930 {
                // Inverse time: F is not modal; each feed move gives its own.
                self.state.feed = None;
            }
        }
        let f_word = word(b'F');
        self.block_f = f_word.is_some();
        if let Some((f, w)) = f_word {
            if f < 0.0 {
                return Err(err(&w, format!("expected a feed F >= 0, found {f}")));
            }
            self.state.feed = Some(f);
            self.state.feed_scale = scale;
        }
        if let Some((s, w)) = word(b'S') {
            if s < 0.0 {
                return Err(err(
                    &w,
                    format!("expected a spindle speed S >= 0, found {s}"),
                ));
            }
            self.state.spindle = Some(s);
            self.summary.count("S");
        }
        if let Some((t, w)) = word(b'T') {
            if !(t >= 0.0 && t.fract() == 0.0 && t <= f64::from(u32::MAX)) {
                return Err(err(&w, format!("expected a tool number T0.., found T{t}")));
            }
            self.state.selected_tool = Some(t as u32);
        }
        for (code, _) in m_codes.iter().flatten() {
            match code {
                6 => {
                    self.state.tool = self.state.selected_tool;
                    self.summary.count("M6");
                }
                2 | 30 => {}
                c => self.summary.count(&format!("M{c}")),
            }
        }
        if let Some((code, _)) = g_groups[GROUP_PLANE] {
            self.state.plane = match code {
                170 => Plane::Xy,
                180 => Plane::Zx,
                _ => Plane::Yz,
            };
        }
        if let Some((code, _)) = g_groups[GROUP_DISTANCE] {
            self.state.incremental = code == 910;
        }
        if let Some((code, _)) = g_groups[GROUP_ARC_DISTANCE] {
            self.state.arc_incremental = code == 911;
        }
        if let Some((code, _)) = g_groups[GROUP_RETURN] {
            self.state.retract_to_r = code == 990;
        }
        for group in [
            GROUP_CUTTER,
            GROUP_LENGTH,
            GROUP_COORD,
            GROUP_PATH,
            GROUP_SPINDLE,
            GROUP_CANCEL,
        ] {
            if let Some((code, _)) = g_groups[group] {
                self.summary.count(&format!("G{}", show_code(code)));
            }
        }
        // Non-modal: dwell only (the others are refused by the group table).
        if let Some((code, w)) = g_groups[GROUP_NON_MODAL] {
            debug_assert_eq!(code, 40);
            match word(b'P') {
                Some((p, _)) if p >= 0.0 => self.summary.count("G4"),
                _ => {
                    return Err(err(
                        &w,
                        "G4 (dwell) needs P, the time in seconds (>= 0)".into(),
                    ));
                }
            }
            if axes.iter().any(Option::is_some) {
                return Err(err(
                    &w,
                    "G4 (dwell) with axis words: give the move in its own block".into(),
                ));
            }
        }

        // Motion.
        let any_axis = axes.iter().any(Option::is_some);
        if let Some((code, _)) = g_groups[GROUP_MOTION] {
            let before = self.state.motion;
            self.state.motion = match code {
                0 => Some(MotionMode::Rapid),
                10 => Some(MotionMode::Linear),
                20 => Some(MotionMode::ArcCw),
                30 => Some(MotionMode::ArcCcw),
                800 => None,
                c => Some(MotionMode::Cycle(c)),
            };
            // Any other motion mode ends a cycle (G80 or implicitly). A different cycle needs
            // its R, Z, Q and P again, as LinuxCNC requires.
            if before != self.state.motion {
                self.state.cycle_r = None;
                self.state.cycle_z = None;
                self.state.cycle_q = None;
                self.state.cycle_p = None;
            }
            if !matches!(self.state.motion, Some(MotionMode::Cycle(_))) {
                self.state.cycle_continuing = false;
            }
        }
        for a in AXES {
            if axes[a as usize].is_some() {
                self.summary.axes_used |= a.bit();
            }
        }
        let ijk_given = [word(b'I'), word(b'J'), word(b'K')];
        let motion = self.state.motion;
        let motion_in_block = g_groups[GROUP_MOTION].is_some();
        match motion {
            _ if !any_axis && !motion_in_block => {
                if let Some((_, w)) = ijk_given.iter().flatten().next() {
                    if !self.options.ijk_tool_vector {
                        return Err(err(
                            w,
                            "I J K without a motion: they belong to an arc (G2/G3)".into(),
                        ));
                    }
                    // A tool vector alone: a move of the orientation only, if a motion is
                    // modal.
                    self.straight(b, &axes, &ijk_given, motion)?;
                } else if let Some((_, w)) = word(b'R') {
                    return Err(err(&w, "R without a motion that uses it".into()));
                }
            }
            None => {
                if any_axis {
                    let w = axes.iter().flatten().next().map(|(_, w)| *w);
                    let w = w.unwrap_or(words[0]);
                    let why = if g_groups[GROUP_MOTION].is_some() {
                        "G80 cancels the motion mode: axis words need G0, G1, G2, G3 or a cycle"
                    } else {
                        "axis words with no motion mode in force: write G0 or G1 (the program has not given one yet, or a G80 cancelled it)"
                    };
                    return Err(err(&w, why.into()));
                }
            }
            Some(MotionMode::Rapid) | Some(MotionMode::Linear) => {
                if let Some((_, w)) = word(b'R') {
                    return Err(err(
                        &w,
                        "R on a straight move (G0/G1): R belongs to arcs and cycles".into(),
                    ));
                }
                if !self.options.ijk_tool_vector
                    && let Some((_, w)) = ijk_given.iter().flatten().next()
                {
                    return Err(err(
                        w,
                        "I J K on a straight move (G0/G1): they are arc centre offsets; a tool-centre program with I J K tool vectors is read with the tool-vector orientation ([gcode] orientation = \"vector\" in the machine file)".into(),
                    ));
                }
                self.straight(b, &axes, &ijk_given, motion)?;
            }
            Some(MotionMode::ArcCw) | Some(MotionMode::ArcCcw) => {
                if any_axis || motion_in_block {
                    let words = ArcWords {
                        axes: &axes,
                        ijk: ijk_given,
                        r: word(b'R'),
                        p: word(b'P'),
                        first: words[0],
                    };
                    let cw = motion == Some(MotionMode::ArcCw);
                    if !any_axis {
                        // `G2` alone sets the mode.
                        if let Some((_, w)) = ijk_given.iter().flatten().next() {
                            return Err(err(w, "an arc (G2/G3) needs its end point".into()));
                        }
                    } else {
                        let feed = self.feed_for_move(line, f_word.is_some(), &words.first)?;
                        arc::interpolate(
                            &mut self.state,
                            &self.options,
                            line,
                            b.n,
                            cw,
                            &words,
                            feed,
                            &mut self.out,
                        )?;
                    }
                }
            }
            Some(MotionMode::Cycle(code)) => {
                if any_axis {
                    let words = CycleWords {
                        axes: &axes,
                        r: word(b'R'),
                        q: word(b'Q'),
                        p: word(b'P'),
                        l: word(b'L'),
                        first: words[0],
                    };
                    let feed = self.feed_for_move(line, f_word.is_some(), &words.first)?;
                    cycle::expand(
                        &mut self.state,
                        line,
                        b.n,
                        code,
                        &words,
                        feed,
                        &mut self.out,
                    )?;
                }
            }
        }

        // Program end, after the motion of its block.
        if m_codes.iter().flatten().any(|(c, _)| matches!(c, 2 | 30)) {
            self.summary.end_line = Some(line);
            self.ended = true;
        }
        self.summary.rows += self.out.len() as u64;
        Ok(())
    }

    /// The feed of a feed move in the current feed mode (mm/min or, for G93, the inverse
    /// time in 1/min), or the error that the controller would give.
    fn feed_for_move(&self, line: u64, f_in_block: bool, first: &Word) -> Result<Feed, GcodeError> {
        let err = |m: &str| GcodeError::new(line, Some(u64::from(first.column)), m.to_string());
        match self.state.feed_mode {
            FeedMode::InverseTime => match (f_in_block, self.state.feed) {
                (true, Some(f)) if f > 0.0 => Ok(Feed::InverseTime(f)),
                _ => Err(err(
                    "inverse time (G93): every feed move needs its own F > 0",
                )),
            },
            FeedMode::PerMinute => match self.state.feed {
                Some(f) if f > 0.0 => Ok(Feed::PerMinute(f, self.state.feed_scale)),
                Some(_) => Err(err("feed move at F0")),
                None => Err(err("feed move before any F word: the feed is not known")),
            },
            FeedMode::PerRevolution => match (self.state.feed, self.state.spindle) {
                (Some(f), Some(s)) if f > 0.0 && s > 0.0 => {
                    Ok(Feed::PerMinute(f * s, self.state.feed_scale))
                }
                (Some(_), _) => Err(err("feed per revolution (G95) with no spindle speed S > 0")),
                _ => Err(err("feed move before any F word: the feed is not known")),
            },
        }
    }

    /// A straight move (G0/G1): one row at its end.
    fn straight(
        &mut self,
        b: &Block,
        axes: &[Option<(f64, Word)>; 9],
        ijk: &[Option<(f64, Word)>; 3],
        motion: Option<MotionMode>,
    ) -> Result<(), GcodeError> {
        let line = self.line;
        let rapid = motion == Some(MotionMode::Rapid);
        let Some(_) = motion else {
            let w = ijk.iter().flatten().next().map(|(_, w)| *w);
            return Err(GcodeError::new(
                line,
                w.map(|w| u64::from(w.column)),
                "a tool vector with no motion mode in force: write G0 or G1",
            ));
        };
        let first = axes
            .iter()
            .chain(ijk.iter())
            .flatten()
            .next()
            .map(|(_, w)| *w)
            .unwrap_or(Word {
                letter: b'G',
                value: 0.0,
                column: 1,
            });
        let feed = if rapid {
            None
        } else {
            Some(self.feed_for_move(line, self.block_has_f(), &first)?)
        };
        let start = self.state.position;
        let (end, written) = target(&self.state, axes, line)?;
        let mut vector = self.state.tool_vector;
        if ijk.iter().any(Option::is_some) {
            let mut v = [0.0; 3];
            for (k, c) in ijk.iter().enumerate() {
                match c {
                    Some((x, _)) => v[k] = *x,
                    None => {
                        return Err(GcodeError::new(
                            line,
                            Some(u64::from(first.column)),
                            "a tool vector needs I, J and K together",
                        ));
                    }
                }
            }
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if !(n > 1e-9 && n.is_finite()) {
                let w = ijk[0].map(|(_, w)| w).unwrap_or(first);
                return Err(GcodeError::new(
                    line,
                    Some(u64::from(w.column)),
                    "the tool vector I J K is zero: it has no direction",
                ));
            }
            vector = Some([v[0] / n, v[1] / n, v[2] / n]);
        }
        self.state.tool_vector = vector;
        let duration = feed.and_then(|f| f.duration_s(&start, &end, 1.0));
        self.state.position = end;
        self.state.known |= written;
        self.out.push(Row {
            line,
            n: b.n,
            kind: Kind::Line,
            motion: if rapid { Motion::Rapid } else { Motion::Feed },
            feed_per_min: feed.and_then(Feed::per_minute),
            duration_s: duration,
            tool: self.state.tool,
            position: end,
            known: self.state.known,
            written,
            tool_vector: vector,
            comment: b.comment,
        });
        Ok(())
    }

    fn block_has_f(&self) -> bool {
        self.block_f
    }
}

/// The feed of one move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Feed {
    /// F per minute as written, and mm per program unit: linear moves at F times the scale
    /// mm/min, rotary-only moves at F deg/min.
    PerMinute(f64, f64),
    /// G93: the block takes 1/F minutes.
    InverseTime(f64),
}

impl Feed {
    pub fn per_minute(self) -> Option<f64> {
        match self {
            Feed::PerMinute(f, scale) => Some(f * scale),
            Feed::InverseTime(_) => None,
        }
    }

    /// Time from `a` to `b`, s: LinuxCNC's rule (the feed is along X Y Z when they move, else
    /// along U V W, else along A B C in degrees/min). For G93, `fraction` of the block's 1/F
    /// minutes. `None` when a moving axis has no known start.
    pub fn duration_s(self, a: &[f64; 9], b: &[f64; 9], fraction: f64) -> Option<f64> {
        match self {
            Feed::InverseTime(f) => Some(60.0 / f * fraction),
            Feed::PerMinute(f, scale) => {
                let d = |ix: [usize; 3]| -> f64 {
                    ix.iter()
                        .map(|&i| {
                            let v = b[i] - a[i];
                            if v.is_nan() && a[i].is_nan() && b[i].is_nan() {
                                0.0
                            } else {
                                v * v
                            }
                        })
                        .sum::<f64>()
                        .sqrt()
                };
                let xyz = d([0, 1, 2]);
                let uvw = d([6, 7, 8]);
                let abc = d([3, 4, 5]);
                let (len, rate) = if xyz > 0.0 || xyz.is_nan() {
                    (xyz, f * scale)
                } else if uvw > 0.0 || uvw.is_nan() {
                    (uvw, f * scale)
                } else {
                    (abc, f)
                };
                len.is_finite().then(|| 60.0 * len / rate)
            }
        }
    }
}

/// The end point of a move from the written axis words (absolute or incremental, scaled to
/// mm), and the mask of the written axes.
pub(crate) fn target(
    state: &State,
    axes: &[Option<(f64, Word)>; 9],
    line: u64,
) -> Result<([f64; 9], u16), GcodeError> {
    let scale = state.units.mm_per_unit();
    let mut end = state.position;
    let mut written = 0u16;
    for (i, a) in axes.iter().enumerate() {
        let Some((v, w)) = a else { continue };
        let axis = super::types::AXES[i];
        let s = if axis.is_rotary() { 1.0 } else { scale };
        let v = v * s;
        end[i] = if state.incremental {
            if state.known & axis.bit() == 0 {
                return Err(GcodeError::new(
                    line,
                    Some(u64::from(w.column)),
                    format!(
                        "an incremental (G91) move of {} before its position is known: give it absolutely first",
                        axis.letter()
                    ),
                ));
            }
            state.position[i] + v
        } else {
            v
        };
        written |= axis.bit();
    }
    Ok((end, written))
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = Result<Row, GcodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        if self.out_pos < self.out.len() {
            self.out_pos += 1;
            return Some(Ok(self.out[self.out_pos - 1]));
        }
        match self.advance() {
            Ok(true) => {
                self.out_pos = 1;
                Some(Ok(self.out[0]))
            }
            Ok(false) => None,
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}

// Modal groups (indices into the per-block table).
const GROUP_NON_MODAL: usize = 0;
const GROUP_MOTION: usize = 1;
const GROUP_PLANE: usize = 2;
const GROUP_DISTANCE: usize = 3;
const GROUP_ARC_DISTANCE: usize = 4;
const GROUP_FEED_MODE: usize = 5;
const GROUP_UNITS: usize = 6;
const GROUP_CUTTER: usize = 7;
const GROUP_LENGTH: usize = 8;
const GROUP_RETURN: usize = 10;
const GROUP_COORD: usize = 12;
const GROUP_PATH: usize = 13;
const GROUP_SPINDLE: usize = 14;
/// Cancels of modes verne refuses (G15 polar, G50 scaling, G69 rotation): nothing to do.
const GROUP_CANCEL: usize = 15;

/// A G or M number times ten (G43.5 -> 435), if it has at most one decimal.
fn decimal_code(w: &Word) -> Option<u16> {
    let t = w.value * 10.0;
    let r = t.round();
    ((t - r).abs() < 1e-6 && (0.0..=9999.0).contains(&r)).then_some(r as u16)
}

fn show_code(code: u16) -> String {
    if code % 10 == 0 {
        format!("{}", code / 10)
    } else {
        format!("{}.{}", code / 10, code % 10)
    }
}

/// LinuxCNC's modal group of an M code and its name (`Interp::_ems` in interp_array.cc,
/// LinuxCNC 2.9; the RS274/NGC groups with LinuxCNC's additions): 4 stopping, 5 input and
/// output, 6 tool change, 7 spindle (with M19 and the modal state codes M70-M73), 8 coolant,
/// 9 override switches, 10 user-defined M100-M199. `None` for the codes in no group (M98/M99,
/// read as o-words, and the codes LinuxCNC does not know). Two codes of one group in a block
/// are an error in LinuxCNC (`read_m`): M7 and M8 too, although both coolants may be on at
/// once (checked with its `rs274`).
fn m_group(code: u16) -> Option<(u8, &'static str)> {
    Some(match code {
        0 | 1 | 2 | 30 | 60 => (4, "stopping"),
        62..=68 => (5, "input and output"),
        6 | 61 => (6, "tool change"),
        3 | 4 | 5 | 19 | 70..=73 => (7, "spindle"),
        7..=9 => (8, "coolant"),
        48..=53 => (9, "override switches"),
        100..=199 => (10, "user-defined"),
        _ => return None,
    })
}

/// The modal group of a G code that verne reads (applies or refuses by name); `None` for
/// the codes it does not know.
fn g_group(code: u16) -> Option<usize> {
    Some(match code {
        40 => GROUP_NON_MODAL,
        0 | 10 | 20 | 30 | 730 | 740 | 800..=890 => GROUP_MOTION,
        170 | 180 | 190 => GROUP_PLANE,
        900 | 910 => GROUP_DISTANCE,
        901 | 911 => GROUP_ARC_DISTANCE,
        930 | 940 | 950 => GROUP_FEED_MODE,
        200 | 210 => GROUP_UNITS,
        400 | 410 | 420 | 411 | 421 => GROUP_CUTTER,
        430 | 431 | 432 | 434 | 435 | 490 => GROUP_LENGTH,
        980 | 990 => GROUP_RETURN,
        540..=593 => GROUP_COORD,
        610 | 611 | 640 => GROUP_PATH,
        960 | 970 => GROUP_SPINDLE,
        150 | 500 | 690 => GROUP_CANCEL,
        _ => return None,
    })
}

/// Why a code that has a group is refused, if it is.
fn refused_modal(code: u16) -> Option<String> {
    Some(match code {
        410 | 420 | 411 | 421 => format!(
            "G{}: cutter radius compensation moves the path by a radius verne does not know: post the compensated path (G40)",
            show_code(code)
        ),
        430..=432 => format!(
            "G{}: a tool length offset moves Z by a value of the controller's tool table that verne does not know: a tool-centre program gives the tool tip (G43.4/G43.5 or G49)",
            show_code(code)
        ),
        540 => return None,
        550..=593 => format!(
            "G{}: a work offset other than G54 moves the program by values verne does not know: give the program in the workpiece frame (G54, zero offset)",
            show_code(code)
        ),
        870 | 880 => format!(
            "G{}: this canned cycle is not expanded by verne",
            show_code(code)
        ),
        960 => "G96: constant surface speed changes the meaning of S (a lathe mode)".to_string(),
        _ => return None,
    })
}

/// The message for a G code outside every group verne reads.
fn refusal_g(code: u16) -> String {
    let what = match code {
        280 | 281 | 300 | 301 => "a move to a stored home position, which verne does not know",
        520 | 920 | 921 | 922 | 923 => "a coordinate offset, which verne does not apply",
        530 => "a move in machine coordinates",
        100 => "a change of the controller's tables",
        50..=52 => "a spline",
        70 | 80 => "lathe diameter/radius mode",
        160 => "polar coordinates",
        330 | 331 | 760 => "threading",
        380..=389 => "a probing move",
        510 => "scaling",
        680 => "coordinate rotation",
        _ => "a code verne does not read",
    };
    format!(
        "G{} is {what}: the program cannot be read exactly, so it is refused",
        show_code(code)
    )
}
