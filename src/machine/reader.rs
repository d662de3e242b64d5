//! Reading programs back: ISO G-code (LinuxCNC, Fanuc, Siemens, plain, and common hand-written
//! files) and Heidenhain plain language into a list of straight moves in mm and degrees.
//!
//! Owns: tokenising, modal state (units, absolute/incremental, G0/G1, G93/G94, F, tool-centre
//! point on/off, machine-coordinate blocks). Must not: apply kinematics (that is
//! [`super::roundtrip`] with [`super::kinematics`]).
//!
//! Supported: G0 G1, G17–G19, G20 G21 (and Siemens G700 G710), G40, G43 G43.4 G49, G53, G54–G59
//! and Siemens G505–G599, Heidenhain PRESET SELECT (taken as zero offsets), G80, G90 G91, G93 G94, G4; M codes (M128/M129 switch the
//! tool-centre point); Siemens TRAORI TRAFOOF SUPA ORI…; Heidenhain `L` blocks, FMAX, M91,
//! FUNCTION TCPM. Anything else that moves the tool (arcs, cycles, G28, subprograms) is an
//! error naming the line, never silently skipped.

use super::post::{Units, MM_PER_INCH};
use crate::error::{Error, Result};

/// How the feed of a move is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedMode {
    Rapid,
    /// `feed` is mm/min.
    PerMinute,
    /// `feed` is 1/min (G93).
    InverseTime,
}

/// One straight move read from a program. Unknown values (never programmed, or after a
/// machine-coordinate move) are NaN.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramMove {
    /// 1-based line of the program.
    pub line: usize,
    pub feed_mode: FeedMode,
    /// mm/min or 1/min (see [`FeedMode`]); NaN for rapids.
    pub feed: f64,
    /// The block is in machine coordinates (G53, SUPA, M91), not the program's.
    pub machine_frame: bool,
    /// Tool-centre-point control was on (G43.4, TRAORI, M128, FUNCTION TCPM).
    pub tcp: bool,
    /// X Y Z (mm).
    pub xyz_mm: [f64; 3],
    /// A B C (degrees).
    pub abc_deg: [f64; 3],
}

/// A program read back.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// The units the program was written in (the last G20/G21/G700/G710 or the PGM line).
    pub units: Units,
    pub moves: Vec<ProgramMove>,
}

fn err(line: usize, msg: impl Into<String>) -> Error {
    Error::parse("G-code", format!("line {line}"), msg)
}

struct State {
    units: Units,
    incremental: bool,
    rapid: Option<bool>,
    inverse_time: bool,
    /// mm/min (per-minute mode), 1/min (inverse time is per block).
    feed: Option<f64>,
    tcp: bool,
    xyz: [f64; 3],
    abc: [f64; 3],
}

impl State {
    fn new() -> Self {
        State {
            units: Units::Mm,
            incremental: false,
            rapid: None,
            inverse_time: false,
            feed: None,
            tcp: false,
            xyz: [f64::NAN; 3],
            abc: [f64::NAN; 3],
        }
    }
}

/// Reads a program; Heidenhain plain language is recognised by its `BEGIN PGM` line.
pub fn read(text: &str) -> Result<Program> {
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    if strip_block_number(first)
        .to_ascii_uppercase()
        .starts_with("BEGIN PGM")
    {
        read_heidenhain(text)
    } else {
        read_iso(text)
    }
}

/// A word: address letter(s) and value; keywords (TRAORI, SUPA, ...) have no value.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Word(char, f64),
    Keyword(String),
}

/// Removes comments: `( ... )` anywhere and `;` to the end of the line.
fn strip_comments(line: &str, n: usize) -> Result<String> {
    let mut out = String::new();
    let mut depth = false;
    for c in line.chars() {
        match (depth, c) {
            (false, ';') => break,
            (false, '(') => depth = true,
            (true, ')') => depth = false,
            (true, _) => {}
            (false, c) => out.push(c),
        }
    }
    if depth {
        return Err(err(n, "comment opened with `(` is not closed"));
    }
    Ok(out)
}

fn tokenize(line: &str, n: usize) -> Result<Vec<Token>> {
    let chars: Vec<char> = line.chars().map(|c| c.to_ascii_uppercase()).collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            return Err(err(
                n,
                format!("unexpected `{c}` where a word (letter and number) should start"),
            ));
        }
        if i + 1 < chars.len() && chars[i + 1].is_ascii_alphabetic() {
            let start = i;
            while i < chars.len() && chars[i].is_ascii_alphabetic() {
                i += 1;
            }
            out.push(Token::Keyword(chars[start..i].iter().collect()));
            continue;
        }
        i += 1;
        while i < chars.len() && chars[i] == ' ' {
            i += 1;
        }
        let start = i;
        if i < chars.len() && (chars[i] == '+' || chars[i] == '-') {
            i += 1;
        }
        while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
            i += 1;
        }
        let num: String = chars[start..i].iter().collect();
        let v: f64 = num
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                err(
                    n,
                    format!("`{c}` must be followed by a number, found `{num}`"),
                )
            })?;
        out.push(Token::Word(c, v));
    }
    Ok(out)
}

/// G and M numbers compared in tenths (G43.4 → 434).
fn tenths(v: f64) -> i64 {
    (v * 10.0).round() as i64
}

fn read_iso(text: &str) -> Result<Program> {
    let mut s = State::new();
    let mut moves = Vec::new();
    for (idx, raw) in text.lines().enumerate() {
        let n = idx + 1;
        let body = strip_comments(raw, n)?;
        let body = body.trim().trim_start_matches('/').trim();
        if body.is_empty() || body == "%" {
            continue;
        }
        let tokens = tokenize(body, n)?;
        let mut coords: [Option<f64>; 6] = [None; 6];
        let mut machine_frame = false;
        let mut f_word = None;
        let mut motion_word = None;
        let mut mode_change = None;
        for t in &tokens {
            match t {
                Token::Keyword(k) => match k.as_str() {
                    "TRAORI" => s.tcp = true,
                    "TRAFOOF" => s.tcp = false,
                    "SUPA" => machine_frame = true,
                    "ORIAXES" | "ORIVECT" | "ORIWKS" | "ORIMKS" => {}
                    other => return Err(err(n, format!("unknown word `{other}`"))),
                },
                Token::Word('G', v) => match tenths(*v) {
                    0 => motion_word = Some(true),
                    10 => motion_word = Some(false),
                    20 | 30 => {
                        return Err(err(n, "arcs (G2/G3) are not read; only straight moves"))
                    }
                    40 | 170 | 180 | 190 | 400 | 430 | 800 => {}
                    540..=590 | 5050..=5990 => {}
                    200 | 7000 => s.units = Units::Inch,
                    210 | 7100 => s.units = Units::Mm,
                    700 | 710 => {
                        return Err(err(
                            n,
                            "G70/G71 leave the feed unit to the machine; write G700/G710",
                        ))
                    }
                    434 => s.tcp = true,
                    490 => s.tcp = false,
                    530 => machine_frame = true,
                    900 => s.incremental = false,
                    910 => s.incremental = true,
                    930 => mode_change = Some(true),
                    940 => mode_change = Some(false),
                    _ => return Err(err(n, format!("G{v} is not supported by the reader"))),
                },
                Token::Word('M', v) => match tenths(*v) {
                    1280 => s.tcp = true,
                    1290 => s.tcp = false,
                    _ => {}
                },
                Token::Word(c @ ('X' | 'Y' | 'Z' | 'A' | 'B' | 'C'), v) => {
                    let k = "XYZABC".find(*c).expect("an axis letter");
                    if coords[k].is_some() {
                        return Err(err(n, format!("{c} appears twice")));
                    }
                    coords[k] = Some(*v);
                }
                Token::Word('F', v) => f_word = Some(*v),
                Token::Word('S' | 'T' | 'H' | 'D' | 'P' | 'N' | 'O', _) => {}
                Token::Word(c @ ('I' | 'J' | 'K' | 'R'), _) => {
                    return Err(err(
                        n,
                        format!("{c} (arc word) is not read; only straight moves"),
                    ))
                }
                Token::Word(c, _) => return Err(err(n, format!("unexpected word `{c}`"))),
            }
        }
        if let Some(inv) = mode_change {
            if inv != s.inverse_time {
                // As LinuxCNC: switching feed mode forgets the feed.
                s.feed = None;
            }
            s.inverse_time = inv;
        }
        if let Some(f) = f_word {
            if !(f > 0.0) {
                return Err(err(n, format!("feed F{f} must be positive")));
            }
            if !s.inverse_time {
                s.feed = Some(f * s.units.mm());
            }
        }
        if motion_word.is_some() {
            s.rapid = motion_word;
        }
        if coords.iter().all(Option::is_none) {
            continue;
        }
        let Some(rapid) = s.rapid else {
            return Err(err(n, "coordinates without a motion mode (G0 or G1)"));
        };
        let (feed_mode, feed) = if rapid {
            (FeedMode::Rapid, f64::NAN)
        } else if s.inverse_time {
            let Some(f) = f_word else {
                return Err(err(n, "inverse-time (G93) feed move without an F word"));
            };
            (FeedMode::InverseTime, f)
        } else {
            let Some(f) = s.feed else {
                return Err(err(n, "feed move before any feed rate (F) was programmed"));
            };
            (FeedMode::PerMinute, f)
        };
        moves.push(apply(&mut s, &coords, machine_frame, n, feed_mode, feed));
    }
    Ok(Program {
        units: s.units,
        moves,
    })
}

/// Applies the coordinates of one block to the modal position and returns the move.
fn apply(
    s: &mut State,
    coords: &[Option<f64>; 6],
    machine_frame: bool,
    line: usize,
    feed_mode: FeedMode,
    feed: f64,
) -> ProgramMove {
    let mut xyz = s.xyz;
    let mut abc = s.abc;
    for k in 0..6 {
        let Some(v) = coords[k] else { continue };
        let v = if k < 3 { v * s.units.mm() } else { v };
        let slot = if k < 3 { &mut xyz[k] } else { &mut abc[k - 3] };
        *slot = if s.incremental && !machine_frame {
            *slot + v
        } else {
            v
        };
    }
    let m = ProgramMove {
        line,
        feed_mode,
        feed,
        machine_frame,
        tcp: s.tcp,
        xyz_mm: xyz,
        abc_deg: abc,
    };
    if machine_frame {
        // Where that leaves the program coordinates depends on offsets we do not know.
        for k in 0..3 {
            if coords[k].is_some() {
                s.xyz[k] = f64::NAN;
            }
        }
    } else {
        s.xyz = xyz;
        s.abc = abc;
    }
    m
}

fn strip_block_number(l: &str) -> &str {
    let t = l.trim_start();
    let digits = t.chars().take_while(|c| c.is_ascii_digit()).count();
    if digits > 0 && t[digits..].starts_with(' ') {
        t[digits..].trim_start()
    } else {
        t
    }
}

fn read_heidenhain(text: &str) -> Result<Program> {
    let herr = |n: usize, m: String| Error::parse("Heidenhain program", format!("line {n}"), m);
    let mut s = State::new();
    s.rapid = Some(false);
    let mut moves = Vec::new();
    let mut ended = false;
    for (idx, raw) in text.lines().enumerate() {
        let n = idx + 1;
        let body = strip_block_number(raw).trim();
        if body.is_empty() || body.starts_with(';') || body.starts_with('*') {
            continue;
        }
        // A trailing `; comment` on a block.
        let body = body.split(';').next().unwrap_or("").trim();
        let upper = body.to_ascii_uppercase();
        if ended {
            return Err(herr(n, "text after END PGM".into()));
        }
        let mut parts = upper.split_whitespace();
        let head = parts.next().unwrap_or("");
        match head {
            "BEGIN" | "END" => {
                let w: Vec<&str> = upper.split_whitespace().collect();
                if w.len() != 4 || w[1] != "PGM" {
                    return Err(herr(
                        n,
                        format!("expected `{head} PGM NAME MM|INCH`, got `{body}`"),
                    ));
                }
                s.units = match w[3] {
                    "MM" => Units::Mm,
                    "INCH" => Units::Inch,
                    u => return Err(herr(n, format!("unit must be MM or INCH, got `{u}`"))),
                };
                ended = head == "END";
            }
            "TOOL" | "BLK" | "STOP" => {}
            // The preset (work offset) is taken as zero, as G54–G59 are.
            "PRESET" if parts.next() == Some("SELECT") => {}
            "FUNCTION" => match parts.next() {
                Some("TCPM") => s.tcp = true,
                Some("RESET") if parts.next() == Some("TCPM") => s.tcp = false,
                _ => return Err(herr(n, format!("`{body}` is not read"))),
            },
            "L" => {
                let mut coords: [Option<f64>; 6] = [None; 6];
                let mut rapid = false;
                let mut machine_frame = false;
                for w in parts {
                    let (inc, w) = match w.strip_prefix('I') {
                        Some(rest) if rest.starts_with(['X', 'Y', 'Z', 'A', 'B', 'C']) => {
                            (true, rest)
                        }
                        _ => (false, w),
                    };
                    let c = w.chars().next().unwrap_or(' ');
                    let num = || -> Result<f64> {
                        w[1..]
                            .parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| herr(n, format!("`{w}` is not a letter and a number")))
                    };
                    match c {
                        'X' | 'Y' | 'Z' | 'A' | 'B' | 'C' => {
                            let k = "XYZABC".find(c).expect("an axis letter");
                            let v = num()?;
                            let v = if k < 3 { v * s.units.mm() } else { v };
                            let base = if k < 3 { s.xyz[k] } else { s.abc[k - 3] };
                            // Units were applied here: store as if absolute mm.
                            coords[k] = Some(if inc { base + v } else { v });
                        }
                        'R' if w == "R0" => {}
                        'R' => {
                            return Err(herr(n, format!("radius compensation `{w}` is not read")))
                        }
                        'F' if w == "FMAX" => rapid = true,
                        'F' => {
                            let f = num()?;
                            if !(f > 0.0) {
                                return Err(herr(n, format!("feed {w} must be positive")));
                            }
                            // Inch programs give feeds in 0.1 inch/min.
                            s.feed = Some(match s.units {
                                Units::Mm => f,
                                Units::Inch => f * MM_PER_INCH / 10.0,
                            });
                        }
                        'M' => match w {
                            "M91" => machine_frame = true,
                            "M128" => s.tcp = true,
                            "M129" => s.tcp = false,
                            _ => {}
                        },
                        _ => return Err(herr(n, format!("unexpected `{w}` in an L block"))),
                    }
                }
                if coords.iter().all(Option::is_none) {
                    continue;
                }
                let (feed_mode, feed) = if rapid {
                    (FeedMode::Rapid, f64::NAN)
                } else {
                    match s.feed {
                        Some(f) => (FeedMode::PerMinute, f),
                        None => {
                            return Err(herr(n, "feed move before any feed rate F".into()));
                        }
                    }
                };
                // Coordinates are already absolute mm: apply without unit scaling.
                let saved = (s.units, s.incremental);
                s.units = Units::Mm;
                s.incremental = false;
                let m = apply(&mut s, &coords, machine_frame, n, feed_mode, feed);
                (s.units, s.incremental) = saved;
                moves.push(m);
            }
            h if h.starts_with('M') && h[1..].chars().all(|c| c.is_ascii_digit()) => {}
            _ => {
                return Err(herr(
                    n,
                    format!(
                        "`{body}` is not read (only L blocks, TOOL CALL, FUNCTION TCPM, M codes)"
                    ),
                ))
            }
        }
    }
    Ok(Program {
        units: s.units,
        moves,
    })
}
