//! Checking VCD files from any simulator.
#![allow(clippy::manual_is_multiple_of)]
//!
//! A hand-written streaming reader (one line buffer, so memory stays flat in
//! the file size) rather than the `vcd` or `wellen` crates: `vcd` 0.7 rejects
//! legal forms (`$var logic`, other scope types, long identifier codes) and
//! `wellen` panics on some malformed values and silently drops steps where
//! time goes backwards; every malformed input here
//! must be a clear error instead.
//!
//! Rules:
//! - ports are found by the names of `docs/timing.md` in one scope (given, or
//!   the only scope that has them all; scopes whose ports share identifier
//!   codes, like an Icarus testbench and its DUT, are the same);
//! - vectors are left-extended (0 for a leading 0/1, x/z for a leading x/z),
//!   bit-blasted vectors (`name [3]`) are accepted;
//! - a rising `clk` edge is a 0 -> 1 change over a timestep (x -> 1 is not an
//!   edge); at an edge at time T the outputs are the values once timestep T
//!   has closed, `rst` and `adc_miso` the values before T;
//! - without a dumped `clk`, edges are inferred: the clock period is the gcd of
//!   the intervals between timesteps that change an output, its phase the first
//!   such timestep (a first pass over the file finds both);
//! - x/z is a violation on any output after reset, on `sample_channel` /
//!   `sample_value` only while `sample_valid`, on `adc_miso` when it is captured.

use std::collections::HashMap;
use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use lut_gen::Schedule;
use lut_gen::{LinkPort, ModePort, Role, AXIS_PORTS, PORT_NAMES, TOP_MODULE};

use crate::check::{CheckOptions, Checker};
use crate::model::Verdict;
use crate::wave::lex::{self, At, BodyStart, Ev, Lexed};
use crate::wave::lock::{LockError, LockInfo, WindowCheck};
use lut_gen::{Layout, Pins};

/// Why a VCD could not be checked (exit 2).
#[derive(Debug)]
pub enum VcdError {
    Io(PathBuf, std::io::Error),
    /// Bad syntax at a line.
    Malformed {
        file: PathBuf,
        line: u64,
        message: String,
    },
    /// The file ends in the middle of something.
    Truncated {
        file: PathBuf,
        line: u64,
        message: String,
    },
    /// The ports of `docs/timing.md` are not (all) there, or do not fit the mix.
    Ports {
        file: PathBuf,
        message: String,
    },
    /// The capture did not start at reset and its frame phase could not be found.
    Phase {
        file: PathBuf,
        error: LockError,
    },
}

impl fmt::Display for VcdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VcdError::Io(p, e) => write!(f, "{}: {}", p.display(), lut_gen::io_words(e)),
            VcdError::Malformed {
                file,
                line,
                message,
            } => write!(f, "{}:{line}: malformed VCD: {message}", file.display()),
            VcdError::Truncated {
                file,
                line,
                message,
            } => write!(f, "{}:{line}: truncated VCD: {message}", file.display()),
            VcdError::Ports { file, message } => write!(f, "{}: {message}", file.display()),
            VcdError::Phase { file, error } => write!(f, "{}: {error}", file.display()),
        }
    }
}

impl std::error::Error for VcdError {}

// ------------------------------------------------------------------ lexer

struct Lexer<R> {
    rd: R,
    line: Vec<u8>,
    pos: usize,
    lineno: u64,
    /// Bytes read before the current line (where the body starts, for the lexer).
    line_start: u64,
    read: u64,
    eof: bool,
    ends_with_newline: bool,
    file: PathBuf,
}

impl<R: BufRead> Lexer<R> {
    fn new(rd: R, file: &Path) -> Self {
        Lexer {
            rd,
            line: Vec::with_capacity(256),
            pos: 0,
            lineno: 0,
            line_start: 0,
            read: 0,
            eof: false,
            ends_with_newline: true,
            file: file.to_path_buf(),
        }
    }

    /// The next whitespace-separated token as a range of `self.line`.
    #[inline]
    fn next(&mut self) -> Result<Option<(usize, usize)>, VcdError> {
        loop {
            let l = &self.line;
            let mut i = self.pos;
            while i < l.len() && l[i].is_ascii_whitespace() {
                i += 1;
            }
            if i < l.len() {
                let s = i;
                while i < l.len() && !l[i].is_ascii_whitespace() {
                    i += 1;
                }
                self.pos = i;
                return Ok(Some((s, i)));
            }
            if self.eof {
                return Ok(None);
            }
            self.line.clear();
            self.pos = 0;
            let n = self
                .rd
                .read_until(b'\n', &mut self.line)
                .map_err(|e| VcdError::Io(self.file.clone(), e))?;
            if n == 0 {
                self.eof = true;
                return Ok(None);
            }
            self.line_start = self.read;
            self.read += n as u64;
            self.lineno += 1;
            self.ends_with_newline = self.line.last() == Some(&b'\n');
        }
    }

    fn tok(&self, r: (usize, usize)) -> &[u8] {
        &self.line[r.0..r.1]
    }

    fn malformed(&self, m: impl Into<String>) -> VcdError {
        VcdError::Malformed {
            file: self.file.clone(),
            line: self.lineno,
            message: m.into(),
        }
    }

    fn truncated(&self, m: impl Into<String>) -> VcdError {
        VcdError::Truncated {
            file: self.file.clone(),
            line: self.lineno,
            message: m.into(),
        }
    }

    /// Tokens up to `$end` (exclusive).
    fn until_end(&mut self, what: &str) -> Result<Vec<String>, VcdError> {
        let mut v = Vec::new();
        loop {
            match self.next()? {
                None => return Err(self.truncated(format!("end of file inside {what}"))),
                Some(r) => {
                    let t = self.tok(r);
                    if t == b"$end" {
                        return Ok(v);
                    }
                    v.push(String::from_utf8_lossy(t).into_owned());
                }
            }
        }
    }
}

// ------------------------------------------------------------------ header

#[derive(Debug, Clone)]
struct Var {
    scope: String,
    name: String,
    width: u32,
    /// (msb, lsb) of the declared range, if any.
    range: Option<(i64, i64)>,
    id: Vec<u8>,
}

struct Header {
    vars: Vec<Var>,
    timescale: String,
}

fn parse_header<R: BufRead>(lx: &mut Lexer<R>) -> Result<Header, VcdError> {
    let mut scopes: Vec<String> = Vec::new();
    let mut vars = Vec::new();
    let mut timescale = String::from("1s");
    loop {
        let Some(r) = lx.next()? else {
            return Err(lx.truncated("end of file before $enddefinitions"));
        };
        let t = lx.tok(r).to_vec();
        match t.as_slice() {
            b"$enddefinitions" => {
                lx.until_end("$enddefinitions")?;
                return Ok(Header { vars, timescale });
            }
            b"$scope" => {
                let v = lx.until_end("$scope")?;
                let name = v
                    .get(1)
                    .or(v.first())
                    .cloned()
                    .ok_or_else(|| lx.malformed("$scope without a name"))?;
                scopes.push(name);
            }
            b"$upscope" => {
                lx.until_end("$upscope")?;
                if scopes.pop().is_none() {
                    return Err(lx.malformed("$upscope without $scope"));
                }
            }
            b"$timescale" => timescale = lx.until_end("$timescale")?.join(""),
            b"$var" => {
                let v = lx.until_end("$var")?;
                if v.len() < 4 {
                    return Err(
                        lx.malformed("$var needs a type, a width, an identifier code and a name")
                    );
                }
                let width: u32 = v[1]
                    .parse()
                    .map_err(|_| lx.malformed(format!("$var width `{}` is not a number", v[1])))?;
                if width == 0 {
                    return Err(lx.malformed("$var width 0"));
                }
                let reference = v[3..].join("");
                let (name, range) = match reference.find('[') {
                    Some(i) => {
                        let rng = reference[i..].trim_start_matches('[').trim_end_matches(']');
                        let parsed = match rng.split_once(':') {
                            Some((a, b)) => a.trim().parse().ok().zip(b.trim().parse().ok()),
                            None => rng.trim().parse().ok().map(|x: i64| (x, x)),
                        };
                        (reference[..i].to_string(), parsed)
                    }
                    None => (reference, None),
                };
                vars.push(Var {
                    scope: scopes.join("."),
                    name,
                    width,
                    range,
                    id: v[2].as_bytes().to_vec(),
                });
            }
            t if t.starts_with(b"$") => {
                let what = String::from_utf8_lossy(t).into_owned();
                lx.until_end(&what)?;
            }
            other => {
                return Err(lx.malformed(format!(
                    "unexpected `{}` in the header",
                    String::from_utf8_lossy(other)
                )))
            }
        }
    }
}

// ------------------------------------------------------------------ ports

// Indices into the port table.
const CLK: usize = Role::Clock as usize;
const RST: usize = Role::Reset as usize;
const MISO: usize = Role::Miso as usize;
const CS: usize = Role::CsN as usize;
const SCLK: usize = Role::Sclk as usize;
const MOSI: usize = Role::Mosi as usize;
const SEL: usize = Role::MuxSel as usize;
const EN: usize = Role::MuxEn as usize;
const VALID: usize = Role::SampleValid as usize;
const CHAN: usize = Role::SampleChannel as usize;
const VALUE: usize = Role::SampleValue as usize;
/// The first of the link's ports in [`State`].
const LINK: usize = PORT_NAMES.len();
/// The mode ports' slots ([`lut_gen::MODE_PORTS`]: `mode_sel`, `mode`),
/// after the most link ports a mix has ([`AXIS_PORTS`]).
const MODE_SEL: usize = LINK + AXIS_PORTS.len();
const MODE: usize = MODE_SEL + 1;
/// Port slots: [`PORT_NAMES`], the link's, the mode ports.
const NPORT: usize = MODE + 1;

/// How one identifier code feeds a port: var bit j -> port bit `lsb + j`
/// (or `lsb - j` when the range is ascending).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sink {
    port: u8,
    pub(crate) width: u32,
    lsb: i64,
    down: bool,
}

#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Val {
    pub(crate) v: u128,
    pub(crate) x: u128,
}

struct Resolved {
    /// id code -> sinks (empty for signals we do not need).
    ids: Ids,
    has_clk: bool,
    /// `rst` is dumped (without it, every cycle counts as out of reset).
    has_rst: bool,
    scope: String,
    widths: [u32; 11],
    /// The link's ports, read after [`PORT_NAMES`] (none without a link).
    link: &'static [LinkPort],
    /// The mode ports the mix has and their width (none without modes).
    modes: (&'static [ModePort], u32),
}

fn resolve(
    h: &Header,
    layout: &Layout,
    want: Option<&str>,
    file: &Path,
) -> Result<Resolved, VcdError> {
    let ps = PortSearch { h, file };
    let widths = layout.port_widths();
    let scope = ps.scope(want, widths)?;
    let mut ids: HashMap<Vec<u8>, Vec<Sink>> = HashMap::new();
    for v in &h.vars {
        ids.entry(v.id.clone()).or_default();
    }
    let (has_clk, has_rst) = ps.port_sinks(scope, widths, &mut ids)?;
    ps.link_sinks(scope, layout, &mut ids)?;
    ps.mode_sinks(scope, layout, &mut ids)?;
    Ok(Resolved {
        ids: Ids::new(ids),
        has_clk,
        has_rst,
        scope: scope.to_string(),
        widths,
        link: layout.link_ports(),
        modes: (layout.mode_ports(), layout.mode_bits),
    })
}

/// The header's scopes, searched for the design's ports.
struct PortSearch<'a> {
    h: &'a Header,
    file: &'a Path,
}

impl<'a> PortSearch<'a> {
    fn err(&self, message: String) -> VcdError {
        VcdError::Ports {
            file: self.file.to_path_buf(),
            message,
        }
    }

    fn vars(&self, sc: &'a str, name: &'a str) -> impl Iterator<Item = &'a Var> {
        self.h
            .vars
            .iter()
            .filter(move |v| v.scope == sc && v.name == name)
    }

    fn has(&self, sc: &str, name: &str) -> bool {
        self.vars(sc, name).next().is_some()
    }

    fn width_of(&self, sc: &str, p: &str) -> u32 {
        self.vars(sc, p).map(|v| v.width).sum()
    }

    /// Whether port `p` has width `w` in scope `c` (an absent `rst` fits any
    /// mix; a port the mix does not have, `w == 0`, is not read).
    fn fits(&self, c: &str, p: &str, w: u32) -> bool {
        let got = self.width_of(c, p);
        got == w || w == 0 || (p == PORT_NAMES[RST] && got == 0)
    }

    /// The scope holding the design's ports: the one named `want`, or the
    /// one with all of them at this mix's widths.
    fn scope(&self, want: Option<&str>, widths: [u32; 11]) -> Result<&'a str, VcdError> {
        let mut scopes: Vec<&str> = self.h.vars.iter().map(|v| v.scope.as_str()).collect();
        scopes.sort_unstable();
        scopes.dedup();
        // `clk` and `rst` may be absent (a capture without them: cycles are then
        // inferred, and the frame phase found from the pins, `lock.rs`).
        // A mix without multiplexers has no `mux_sel`/`mux_en` (width 0).
        let required: Vec<&str> = PORT_NAMES
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != CLK && *i != RST && widths[*i] > 0)
            .map(|(_, p)| *p)
            .collect();
        let candidates: Vec<&str> = match want {
            Some(w) => self.named_scope(&scopes, w)?,
            None => scopes
                .iter()
                .copied()
                .filter(|s| required.iter().all(|p| self.has(s, p)))
                .collect(),
        };
        let candidates = self.of_mix_widths(candidates, widths)?;
        let Some(&scope) = candidates.last() else {
            return Err(self.no_scope(&scopes, &required));
        };
        let ids_of = |sc: &str| -> Vec<Vec<Vec<u8>>> {
            PORT_NAMES
                .iter()
                .map(|p| self.vars(sc, p).map(|v| v.id.clone()).collect())
                .collect()
        };
        if candidates.len() > 1 {
            let first = ids_of(candidates[0]);
            if candidates.iter().any(|c| ids_of(c)[1..] != first[1..]) {
                return Err(self.err(format!(
                    "several scopes have the ports of {TOP_MODULE}: {}; choose one with --scope",
                    candidates.join(", ")
                )));
            }
        }
        Ok(scope)
    }

    /// The one scope named `w` (or ending in `.w`).
    fn named_scope(&self, scopes: &[&'a str], w: &str) -> Result<Vec<&'a str>, VcdError> {
        let m: Vec<&str> = scopes
            .iter()
            .copied()
            .filter(|s| *s == w || s.ends_with(&format!(".{w}")))
            .collect();
        if m.is_empty() {
            return Err(self.err(format!(
                "no scope `{w}` in the VCD (scopes: {})",
                scopes.join(", ")
            )));
        }
        if m.len() > 1 {
            return Err(self.err(format!("scope `{w}` is ambiguous: {}", m.join(", "))));
        }
        Ok(m)
    }

    /// A design's inner modules may carry ports of the same names (the
    /// gateware's fixed-width core does): keep the scopes whose widths are
    /// the mix's.
    fn of_mix_widths(
        &self,
        candidates: Vec<&'a str>,
        widths: [u32; 11],
    ) -> Result<Vec<&'a str>, VcdError> {
        let exact: Vec<&str> = candidates
            .iter()
            .copied()
            .filter(|c| {
                PORT_NAMES
                    .iter()
                    .zip(widths)
                    .skip(1)
                    .all(|(p, w)| self.fits(c, p, w))
            })
            .collect();
        if !exact.is_empty() {
            return Ok(exact);
        }
        if candidates.len() > 1 {
            let c = candidates[0];
            let (p, w) = PORT_NAMES
                .iter()
                .zip(widths)
                .skip(1)
                .find(|(p, w)| !self.fits(c, p, *w))
                .expect("a candidate whose widths differ");
            return Err(self.err(format!(
                "the scopes with {TOP_MODULE}'s ports ({}) do not have this mix's widths (`{p}`: {w} bit(s) expected, {} in `{c}`): is the VCD from another mix?",
                candidates.join(", "),
                self.width_of(c, p)
            )));
        }
        Ok(candidates)
    }

    /// No scope has the ports: name the closest one's missing ports.
    fn no_scope(&self, scopes: &[&str], required: &[&str]) -> VcdError {
        let best = scopes
            .iter()
            .map(|s| (required.iter().filter(|p| self.has(s, p)).count(), *s))
            .max();
        let hint = match best {
            Some((n, s)) if n > 0 => {
                let missing: Vec<&str> = required
                    .iter()
                    .copied()
                    .filter(|p| !self.has(s, p))
                    .collect();
                format!("; scope `{s}` lacks {}", missing.join(", "))
            }
            _ => String::new(),
        };
        self.err(format!(
            "no scope has all the ports of {TOP_MODULE} ({}){hint}",
            required.join(", ")
        ))
    }

    /// The sinks of the pin contract's ports in `scope`; whether `clk` and
    /// `rst` are dumped there.
    fn port_sinks(
        &self,
        scope: &str,
        widths: [u32; 11],
        ids: &mut HashMap<Vec<u8>, Vec<Sink>>,
    ) -> Result<(bool, bool), VcdError> {
        // clk may sit in an enclosing scope (a testbench) if the DUT's is not dumped.
        let mut has_clk = false;
        let mut has_rst = true;
        for (p, name) in PORT_NAMES.iter().enumerate() {
            if widths[p] == 0 {
                continue; // a port this mix does not have
            }
            let vs: Vec<&Var> = self.vars(scope, name).collect();
            if vs.is_empty() {
                if p == CLK {
                    continue;
                }
                if p == RST {
                    has_rst = false;
                    continue;
                }
                return Err(self.err(format!("port `{name}` not found in scope `{scope}`")));
            }
            let mut covered = 0u32;
            for v in vs {
                let sink = self.sink(scope, name, p, v, widths[p])?;
                covered += v.width;
                ids.get_mut(&v.id).unwrap().push(sink);
            }
            if covered != widths[p] {
                return Err(self.err(format!(
                    "port `{name}` in `{scope}` has {covered} bit(s), the mix needs {}",
                    widths[p]
                )));
            }
            if p == CLK {
                has_clk = true;
            }
        }
        Ok((has_clk, has_rst))
    }

    /// How var `v` (of port `name`, slot `p`, `width` bits) feeds its port.
    fn sink(
        &self,
        scope: &str,
        name: &str,
        p: usize,
        v: &Var,
        width: u32,
    ) -> Result<Sink, VcdError> {
        let (msb, lsb) = v.range.unwrap_or((v.width as i64 - 1, 0));
        let down = msb >= lsb;
        let low = msb.min(lsb);
        if low < 0
            || msb.max(lsb) >= width as i64
            || (msb - lsb).unsigned_abs() + 1 != v.width as u64
        {
            return Err(self.err(format!(
                "port `{name}` in `{scope}` is declared {}{} but the mix needs {} bit(s) [{}:0]",
                v.width,
                v.range
                    .map(|(a, b)| format!(" [{a}:{b}]"))
                    .unwrap_or_default(),
                width,
                width - 1
            )));
        }
        Ok(Sink {
            port: p as u8,
            width: v.width,
            lsb,
            down,
        })
    }

    /// The sinks of the mix's link ports in `scope`.
    fn link_sinks(
        &self,
        scope: &str,
        layout: &Layout,
        ids: &mut HashMap<Vec<u8>, Vec<Sink>>,
    ) -> Result<(), VcdError> {
        for (k, lp) in layout.link_ports().iter().enumerate() {
            let v = self
                .vars(scope, lp.name)
                .find(|v| v.width == lp.width)
                .ok_or_else(|| {
                    self.err(format!(
                        "port `{}` (the mix's link) not found in scope `{scope}`",
                        lp.name
                    ))
                })?;
            ids.get_mut(&v.id).unwrap().push(Sink {
                port: (LINK + k) as u8,
                width: lp.width,
                lsb: 0,
                down: true,
            });
        }
        Ok(())
    }
}

/// Identifier code -> sinks.  Codes of up to three characters (every
/// simulator's first 830 000 signals) index a table directly: hashing the
/// code of every value change was a tenth of `check`'s time.
pub(crate) struct Ids {
    short: Vec<u32>,
    /// Per code, its range of `flat`.
    spans: Vec<(u32, u32)>,
    /// Every code's sinks, one after another.
    pub(crate) flat: Vec<Sink>,
    long: HashMap<Vec<u8>, usize>,
}

const NO_ID: u32 = u32::MAX;

impl Ids {
    fn new(map: HashMap<Vec<u8>, Vec<Sink>>) -> Ids {
        let mut ids = Ids {
            short: Vec::new(),
            spans: Vec::new(),
            flat: Vec::new(),
            long: HashMap::new(),
        };
        for (code, sinks) in map {
            let i = ids.spans.len();
            let from = ids.flat.len() as u32;
            ids.flat.extend(sinks);
            ids.spans.push((from, ids.flat.len() as u32));
            match Ids::slot(&code) {
                Some(k) => {
                    if ids.short.len() <= k {
                        ids.short.resize(k + 1, NO_ID);
                    }
                    ids.short[k] = i as u32;
                }
                None => {
                    ids.long.insert(code, i);
                }
            }
        }
        ids
    }

    /// The table index of a code of 1-3 printable characters.
    #[inline]
    fn slot(code: &[u8]) -> Option<usize> {
        if code.is_empty() || code.len() > 3 {
            return None;
        }
        let mut k = 0usize;
        for &c in code {
            if !(b'!'..=b'~').contains(&c) {
                return None;
            }
            k = k * 95 + (c - b'!' + 1) as usize;
        }
        Some(k)
    }

    /// The range of `flat` a code feeds (empty for a signal not needed).
    #[inline]
    pub(crate) fn span(&self, code: &[u8]) -> Option<std::ops::Range<usize>> {
        let i = match Ids::slot(code) {
            Some(k) => match self.short.get(k) {
                Some(&i) if i != NO_ID => i as usize,
                _ => return None,
            },
            None => *self.long.get(code)?,
        };
        let (a, b) = self.spans[i];
        Some(a as usize..b as usize)
    }
}

impl PortSearch<'_> {
    /// The sinks of the mix's mode ports in `scope` (docs/timing.md, "Mode
    /// switches"): `mode_sel` (pin select) and `mode`, each `mode_bits` wide.
    fn mode_sinks(
        &self,
        scope: &str,
        layout: &Layout,
        ids: &mut HashMap<Vec<u8>, Vec<Sink>>,
    ) -> Result<(), VcdError> {
        for mp in layout.mode_ports() {
            let slot = if mp.dir == lut_gen::Dir::In {
                MODE_SEL
            } else {
                MODE
            };
            let vs: Vec<&Var> = self.vars(scope, mp.name).collect();
            if vs.is_empty() {
                return Err(self.err(format!(
                    "port `{}` (the mix switches modes) not found in scope `{scope}`",
                    mp.name
                )));
            }
            for v in vs {
                let sink = self.sink(scope, mp.name, slot, v, layout.mode_bits)?;
                ids.get_mut(&v.id).unwrap().push(sink);
            }
        }
        Ok(())
    }
}

// ------------------------------------------------------------------ body

/// Parses a vector/scalar value into (value, x/z mask), left-extended to `width`.
#[inline]
pub(crate) fn parse_value(s: &[u8], width: u32) -> Option<Val> {
    let mut v = 0u128;
    let mut x = 0u128;
    let n = s.len();
    if n == 0 {
        return None;
    }
    let take = n.min(128);
    for &ch in &s[n - take..] {
        v <<= 1;
        x <<= 1;
        match ch {
            b'0' | b'l' | b'L' => {}
            b'1' | b'h' | b'H' => v |= 1,
            b'x' | b'X' | b'z' | b'Z' | b'u' | b'U' | b'w' | b'W' | b'-' => x |= 1,
            _ => return None,
        }
    }
    for &ch in &s[..n - take] {
        if !matches!(
            ch,
            b'0' | b'1'
                | b'x'
                | b'X'
                | b'z'
                | b'Z'
                | b'l'
                | b'L'
                | b'h'
                | b'H'
                | b'u'
                | b'U'
                | b'w'
                | b'W'
                | b'-'
        ) {
            return None;
        }
    }
    if (n as u32) < width && n < 128 && matches!(s[0], b'x' | b'X' | b'z' | b'Z') {
        let w = width.min(128);
        let ext = (if w == 128 {
            u128::MAX
        } else {
            (1u128 << w) - 1
        }) & !((1u128 << n) - 1);
        x |= ext;
    }
    Some(Val { v, x })
}

/// The ports of [`PORT_NAMES`], then the link's (`Layout::link_ports`).
struct State {
    port: [Val; NPORT],
    /// The link is AXI4-Stream: its slots are [`AXIS_PORTS`]'s.
    axis: bool,
}

impl State {
    #[inline]
    fn apply(&mut self, sink: &Sink, val: Val) -> bool {
        let p = &mut self.port[sink.port as usize];
        let (old_v, old_x) = (p.v, p.x);
        let wmask = if sink.width >= 128 {
            u128::MAX
        } else {
            (1u128 << sink.width) - 1
        };
        let (vv, vx) = (val.v & wmask, val.x & wmask);
        if sink.down {
            let m = wmask << sink.lsb;
            p.v = (p.v & !m) | (vv << sink.lsb);
            p.x = (p.x & !m) | (vx << sink.lsb);
        } else {
            // ascending range [lsb:msb]: var bit j (from the right) is port bit lsb + width-1-j
            for j in 0..sink.width {
                let pb = sink.lsb as u32 + sink.width - 1 - j;
                p.v = (p.v & !(1 << pb)) | (((vv >> j) & 1) << pb);
                p.x = (p.x & !(1 << pb)) | (((vx >> j) & 1) << pb);
            }
        }
        p.v != old_v || p.x != old_x
    }

    /// The pins' values and their x/z masks.
    fn pins(&self) -> (Pins, Pins) {
        let pick = |f: fn(&Val) -> u128| {
            let g = |i: usize| f(&self.port[i]);
            Pins {
                cs_n: g(CS) as u16,
                sclk: g(SCLK) as u16,
                mosi: g(MOSI) as u16,
                mux_sel: g(SEL) as u64,
                mux_en: g(EN),
                sample_valid: g(VALID) & 1 == 1,
                sample_channel: g(CHAN) as u16,
                sample_value: g(VALUE) as u16,
                link_tx: !self.axis && g(LINK) & 1 == 1,
                link_overflow: g(if self.axis { LINK + 4 } else { LINK + 1 }) & 1 == 1,
                axis_tdata: if self.axis { g(LINK) as u8 } else { 0 },
                axis_tvalid: self.axis && g(LINK + 1) & 1 == 1,
                axis_tlast: self.axis && g(LINK + 2) & 1 == 1,
                axis_tready: self.axis && g(LINK + 3) & 1 == 1,
                mode_sel: g(MODE_SEL) as u8,
                mode: g(MODE) as u8,
            }
        };
        (pick(|p| p.v), pick(|p| p.x))
    }
}

/// Where cycles come from: the dumped clock, or an inferred period.
#[derive(Clone, Copy)]
enum Clocking {
    Clk,
    Inferred { period: u64, phase: u64 },
}

/// A sink for recovered cycles: `(rst, pins, xz, miso, miso_xz)`.
pub trait CycleSink {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, xz: &Pins, miso: u64, miso_xz: u64);
}

impl CycleSink for Checker {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, xz: &Pins, miso: u64, miso_xz: u64) {
        self.cycle_xz(rst, pins, xz, miso, miso_xz)
    }
}

/// Counts cycles only (the bare-parse baseline for benchmarks).
#[derive(Default)]
pub struct CountCycles(pub u64);

impl CycleSink for CountCycles {
    fn cycle(&mut self, _: Option<bool>, _: &Pins, _: &Pins, _: u64, _: u64) {
        self.0 += 1;
    }
}

/// What the body pass learnt.
#[derive(Debug, Clone, Copy, Default)]
pub struct BodyInfo {
    pub cycles: u64,
    pub last_time: u64,
    /// gcd of intervals between output-changing timesteps, and the first of them.
    pub period: u64,
    pub phase: Option<u64>,
    /// The longest stretch between two consecutive timesteps, in time units.
    pub max_gap: u64,
    /// The shortest interval between two output-changing timesteps (0: fewer than two).
    pub min_out_gap: u64,
    last_out: Option<u64>,
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A cycle waiting for the next edge, which tells the MISO it carried.
type Pending = Option<(Option<bool>, Pins, Pins)>;

/// The ports an edge reads as they were before its timestep (clk, rst,
/// MISO, an AXIS link's tready): kept apart, and narrow (MISO has a bit per
/// branch, at most 16; the others one), so that closing a timestep copies
/// 32 bytes, not every port.
#[derive(Clone, Copy)]
struct Before {
    clk: (u32, u32),
    rst: (u32, u32),
    miso: (u32, u32),
    tready: (u32, u32),
}

impl Before {
    fn of(port: &[Val; NPORT]) -> Before {
        let n = |v: &Val| (v.v as u32, v.x as u32);
        Before {
            clk: n(&port[CLK]),
            rst: n(&port[RST]),
            miso: n(&port[MISO]),
            tready: n(&port[LINK + 3]),
        }
    }
}

/// A narrow value back as a port value.
fn val((v, x): (u32, u32)) -> Val {
    Val {
        v: v as u128,
        x: x as u128,
    }
}

/// Applies the body's events in file order: port values, timesteps, and
/// the clock edges (dumped or inferred) that hand cycles to the sink.
struct Applier<'a> {
    res: &'a Resolved,
    clocking: Option<Clocking>,
    sink: &'a mut dyn CycleSink,
    st: State,
    before: Before,
    /// `st.pins()`, recomputed only after an output changed (`dirty`): most
    /// edges of a dump change nothing but the clock.
    pins: (Pins, Pins),
    dirty: bool,
    time: u64,
    seen_time: bool,
    out_changed: bool,
    first_step: bool,
    info: BodyInfo,
    pending: Pending,
}

/// The inputs an edge samples: MISO and, with an AXIS link, tready.
type Inputs = (Val, Option<Val>);

impl Applier<'_> {
    fn inputs(&self, b: &Before) -> Inputs {
        (val(b.miso), self.st.axis.then_some(val(b.tready)))
    }

    /// The outputs now, and their x/z masks.
    #[inline]
    fn pins(&mut self) -> (Pins, Pins) {
        if self.dirty {
            self.pins = self.st.pins();
            self.dirty = false;
        }
        self.pins
    }

    /// Hands on the pending cycle with the inputs the edge ending it
    /// samples: MISO and, for an AXIS link, tready (an input like MISO: the
    /// cycle's value is the one that edge samples).
    fn edge(&mut self, rst: Option<bool>, pins: Pins, xz: Pins, (miso, tready): Inputs) {
        if let Some((r, mut p, mut x)) = self.pending.take() {
            if let Some(t) = tready {
                p.axis_tready = t.v & 1 == 1;
                x.axis_tready = t.x & 1 == 1;
            }
            self.sink.cycle(r, &p, &x, miso.v as u64, miso.x as u64);
        }
        self.info.cycles += 1;
        self.pending = Some((rst, pins, xz));
    }

    fn rst_of(&self, v: &Val) -> Option<bool> {
        if !self.res.has_rst {
            Some(false)
        } else if v.x & 1 != 0 {
            None
        } else {
            Some(v.v & 1 == 1)
        }
    }

    /// Closes timestep `t` (the next one at `next`).
    fn close(&mut self, t: u64, next: Option<u64>) {
        let info = &mut self.info;
        if self.out_changed && !self.first_step {
            match info.phase {
                None => info.phase = Some(t),
                Some(p0) => info.period = gcd(info.period, t - p0),
            }
            if let Some(prev) = info.last_out {
                let g = t - prev;
                info.min_out_gap = if info.min_out_gap == 0 {
                    g
                } else {
                    info.min_out_gap.min(g)
                };
            }
            info.last_out = Some(t);
        }
        match self.clocking {
            None => {}
            Some(Clocking::Clk) => {
                let (b, a) = (val(self.before.clk), self.st.port[CLK]);
                if b.x & 1 == 0 && a.x & 1 == 0 && b.v & 1 == 0 && a.v & 1 == 1 {
                    // Only at an edge: half the timesteps are falling edges.
                    let (pins, xz) = self.pins();
                    let rst = self.rst_of(&val(self.before.rst));
                    self.edge(rst, pins, xz, self.inputs(&self.before));
                }
            }
            Some(Clocking::Inferred { period, phase }) => {
                let (pins, xz) = self.pins();
                if t >= phase && (t - phase) % period == 0 {
                    let rst = self.rst_of(&val(self.before.rst));
                    self.edge(rst, pins, xz, self.inputs(&self.before));
                }
                if let Some(n) = next {
                    let mut e = if t < phase {
                        phase
                    } else {
                        t - (t - phase) % period + period
                    };
                    let rst = self.rst_of(&self.st.port[RST]);
                    let now = Before::of(&self.st.port);
                    while e < n {
                        self.edge(rst, pins, xz, self.inputs(&now));
                        e = e.saturating_add(period);
                    }
                }
            }
        }
    }

    /// Applies one chunk's events.
    fn chunk(&mut self, lexed: &Lexed, at: &At, file: &Path) -> Result<(), VcdError> {
        for ev in &lexed.evs {
            match *ev {
                Ev::Set { sink, v, x } => {
                    let s = &self.res.ids.flat[sink as usize];
                    let val = Val {
                        v: v as u128,
                        x: x as u128,
                    };
                    let out = self.st.apply(s, val) && s.port as usize >= CS;
                    self.out_changed |= out;
                    self.dirty |= out;
                }
                Ev::Wide { sink, idx } => {
                    let s = &self.res.ids.flat[sink as usize];
                    let out = self.st.apply(s, lexed.wide[idx as usize]) && s.port as usize >= CS;
                    self.out_changed |= out;
                    self.dirty |= out;
                }
                Ev::Time { t: nt, line } => self.timestamp(nt, at.line0 + line as u64, file)?,
            }
        }
        Ok(())
    }

    fn timestamp(&mut self, nt: u64, line: u64, file: &Path) -> Result<(), VcdError> {
        let time = self.time;
        if self.seen_time && nt < time {
            return Err(VcdError::Malformed {
                file: file.to_path_buf(),
                line,
                message: format!("time goes backwards from {time} to {nt}"),
            });
        }
        if !self.seen_time || nt > time {
            if self.seen_time {
                self.info.max_gap = self.info.max_gap.max(nt - time);
            }
            if self.seen_time || self.out_changed {
                self.close(time, Some(nt));
                self.first_step = false;
            }
            self.before = Before::of(&self.st.port);
            self.out_changed = false;
            self.time = nt;
            self.seen_time = true;
        }
        Ok(())
    }
}

/// Reads the body (from `start`) into `sink` through the parallel lexer.
fn body(
    path: &Path,
    start: BodyStart,
    res: &Resolved,
    clocking: Option<Clocking>,
    sink: &mut dyn CycleSink,
    read: &dyn Fn(u64),
) -> Result<BodyInfo, VcdError> {
    let mut st = State {
        port: [Val { v: 0, x: 0 }; NPORT],
        axis: res.link.len() == AXIS_PORTS.len(),
    };
    for (k, lp) in res.link.iter().enumerate() {
        st.port[LINK + k].x = (1u128 << lp.width) - 1;
    }
    for mp in res.modes.0 {
        let slot = if mp.dir == lut_gen::Dir::In {
            MODE_SEL
        } else {
            MODE
        };
        st.port[slot].x = (1u128 << res.modes.1) - 1;
    }
    for (i, w) in res.widths.iter().enumerate() {
        st.port[i].x = if *w >= 128 {
            u128::MAX
        } else {
            (1u128 << w) - 1
        };
    }
    let mut ap = Applier {
        res,
        clocking,
        sink,
        before: Before::of(&st.port),
        pins: st.pins(),
        dirty: false,
        st,
        time: 0,
        seen_time: false,
        out_changed: false,
        first_step: true,
        info: BodyInfo::default(),
        pending: None,
    };
    let (last_line, newline) = lex::for_each_chunk(path, start, &res.ids, read, |lexed, at| {
        ap.chunk(lexed, at, path)
    })?;
    if !newline {
        return Err(VcdError::Truncated {
            file: path.to_path_buf(),
            line: last_line,
            message: "the last line is incomplete".into(),
        });
    }
    let time = ap.time;
    ap.close(time, None);
    if let Some((r, mut p, mut x)) = ap.pending.take() {
        let (miso, tready) = ap.inputs(&Before::of(&ap.st.port));
        if let Some(t) = tready {
            p.axis_tready = t.v & 1 == 1;
            x.axis_tready = t.x & 1 == 1;
        }
        ap.sink.cycle(r, &p, &x, miso.v as u64, miso.x as u64);
    }
    ap.info.last_time = time;
    Ok(ap.info)
}

/// Without a dumped `clk`, at most this many frames (of at least 2^16
/// cycles) may pass between two timesteps: outputs change every frame, and
/// a long reset fits.
const INFERRED_GAP_FRAMES: u64 = 16;

/// Without a dumped `clk`, the closest two output changes must be at most
/// this many inferred cycles apart.
const INFERRED_MIN_GAP: u64 = 64;

/// Header facts of a VCD.
#[derive(Debug, Clone)]
pub struct VcdInfo {
    pub scope: String,
    pub timescale: String,
    pub clock_dumped: bool,
    /// Inferred clock period in timescale units (only without a dumped clock).
    pub inferred_period: Option<u64>,
    pub clock_cycles: u64,
    /// How the frame phase was found, when the capture did not start at reset.
    pub lock: Option<LockInfo>,
}

fn open(path: &Path) -> Result<Lexer<BufReader<File>>, VcdError> {
    let f = File::open(path).map_err(|e| VcdError::Io(path.to_path_buf(), e))?;
    Ok(Lexer::new(BufReader::with_capacity(1 << 20, f), path))
}

/// A progress display's hook: told (bytes read, bytes in all) as the
/// waveform's body is read.  A VCD without `clk` is read twice (the first
/// pass infers the clock) and both passes count; an FST counts the bytes of
/// its VCD transcoding.
pub type OnBytes<'a> = &'a dyn Fn(u64, u64);

/// Streams the cycles of a VCD, or of an FST (through its VCD
/// transcoding, `fst.rs`), into `sink`.
pub fn read_cycles(
    s: &Schedule,
    path: &Path,
    scope: Option<&str>,
    sink: &mut dyn CycleSink,
) -> Result<VcdInfo, VcdError> {
    read_cycles_with(s, path, scope, sink, &|_, _| {})
}

/// [`read_cycles`], telling `on_bytes` how far it is.
pub fn read_cycles_with(
    s: &Schedule,
    path: &Path,
    scope: Option<&str>,
    sink: &mut dyn CycleSink,
    on_bytes: OnBytes,
) -> Result<VcdInfo, VcdError> {
    if !crate::wave::fst::is_fst(path) {
        return read_vcd_cycles(s, path, scope, sink, on_bytes);
    }
    let fst_err = |message: String| VcdError::Ports {
        file: path.to_path_buf(),
        message,
    };
    let mut tmp = tempfile::Builder::new()
        .suffix(".vcd")
        .tempfile()
        .map_err(|e| VcdError::Io(path.to_path_buf(), e))?;
    crate::wave::fst::to_vcd(path, tmp.as_file_mut()).map_err(fst_err)?;
    // Errors name the FST, not the temporary file.
    let named = format!("{} (as VCD)", path.display());
    read_vcd_cycles(s, tmp.path(), scope, sink, on_bytes)
        .map_err(|e| e.with_file(Path::new(&named)))
}

impl VcdError {
    fn with_file(self, f: &Path) -> VcdError {
        let f = f.to_path_buf();
        match self {
            VcdError::Io(_, e) => VcdError::Io(f, e),
            VcdError::Malformed { line, message, .. } => VcdError::Malformed {
                file: f,
                line,
                message,
            },
            VcdError::Truncated { line, message, .. } => VcdError::Truncated {
                file: f,
                line,
                message,
            },
            VcdError::Ports { message, .. } => VcdError::Ports { file: f, message },
            VcdError::Phase { error, .. } => VcdError::Phase { file: f, error },
        }
    }
}

fn read_vcd_cycles(
    s: &Schedule,
    path: &Path,
    scope: Option<&str>,
    sink: &mut dyn CycleSink,
    on_bytes: OnBytes,
) -> Result<VcdInfo, VcdError> {
    let layout = Layout::new(s);
    let mut lx = open(path)?;
    let h = parse_header(&mut lx)?;
    let res = resolve(&h, &layout, scope, path)?;
    let start = BodyStart {
        offset: lx.line_start + lx.pos as u64,
        line: lx.lineno,
        header_newline: lx.line.ends_with(b"\n"),
    };
    let size = std::fs::metadata(path)
        .map(|m| m.len().saturating_sub(start.offset))
        .unwrap_or(0);
    // without `clk` the body is read twice
    let passes = if res.has_clk { 1 } else { 2 };
    let clocking = if res.has_clk {
        Clocking::Clk
    } else {
        let first = |b: u64| on_bytes(b, passes * size);
        let info = body(path, start, &res, None, &mut CountCycles(0), &first)?;
        // One timestamp off the clock grid makes the gcd (the period) tiny
        // and the cycle count enormous: refuse a period that no two output
        // changes are close to (a sample gives two one cycle apart; SCLK
        // toggles every few cycles), or that puts more than a bounded number
        // of cycles between two timesteps, instead of reading for hours.
        let gap_limit = INFERRED_GAP_FRAMES * s.grid.frame_cycles.max(1 << 16);
        let off_grid = |why: String| {
            VcdError::Ports {
            file: path.to_path_buf(),
            message: format!(
                "`clk` is not dumped in `{}` and the inferred clock period ({} time units, the gcd of the intervals between output changes) {why}: a timestamp is off the clock grid? dump `clk`",
                res.scope, info.period
            ),
        }
        };
        match info.phase {
            Some(_) if info.period > 0 && info.min_out_gap / info.period > INFERRED_MIN_GAP => {
                return Err(off_grid(format!(
                    "leaves the closest two output changes {} cycles apart (more than {INFERRED_MIN_GAP})",
                    info.min_out_gap / info.period
                )))
            }
            Some(_) if info.period > 0 && info.max_gap / info.period > gap_limit => {
                return Err(off_grid(format!(
                    "puts {} cycles between two timesteps (more than {INFERRED_GAP_FRAMES} frames of {} cycles)",
                    info.max_gap / info.period,
                    s.grid.frame_cycles
                )))
            }
            Some(phase) if info.period > 0 => Clocking::Inferred { period: info.period, phase: phase % info.period },
            _ => {
                return Err(VcdError::Ports {
                    file: path.to_path_buf(),
                    message: format!("`clk` is not dumped in `{}` and too few output changes to infer the clock period", res.scope),
                })
            }
        }
    };
    let last = |b: u64| on_bytes((passes - 1) * size + b, passes * size);
    let info = body(path, start, &res, Some(clocking), sink, &last)?;
    Ok(VcdInfo {
        scope: res.scope,
        timescale: h.timescale,
        clock_dumped: res.has_clk,
        inferred_period: match clocking {
            Clocking::Inferred { period, .. } => Some(period),
            Clocking::Clk => None,
        },
        clock_cycles: info.cycles,
        lock: None,
    })
}

/// Checks a VCD against the schedule: every invariant and, unless
/// `opts.model` is false, cycle-exact equality with the reference model.
/// A VCD that does not start at reset is checked from where its frame phase
/// is found (`lock.rs`).
pub fn check_vcd_with(
    s: &Schedule,
    path: &Path,
    scope: Option<&str>,
    opts: CheckOptions,
) -> Result<(Verdict, VcdInfo), VcdError> {
    check_vcd_progress(s, path, scope, opts, &|_, _| {})
}

/// [`check_vcd_with`], telling `on_bytes` how far the reading is.
pub fn check_vcd_progress(
    s: &Schedule,
    path: &Path,
    scope: Option<&str>,
    opts: CheckOptions,
    on_bytes: OnBytes,
) -> Result<(Verdict, VcdInfo), VcdError> {
    let mut check = WindowCheck::new(s, opts);
    let mut info = read_cycles_with(s, path, scope, &mut check, on_bytes)?;
    let (report, lock) = check.finish("vcd").map_err(|error| VcdError::Phase {
        file: path.to_path_buf(),
        error,
    })?;
    info.lock = lock;
    Ok((report, info))
}

/// Checks a VCD with the default options.
pub fn check_vcd(
    s: &Schedule,
    path: impl AsRef<Path>,
    scope: Option<&str>,
) -> Result<Verdict, VcdError> {
    check_vcd_with(s, path.as_ref(), scope, CheckOptions::default()).map(|r| r.0)
}

/// Reads a whole file through the same reader without checking (benchmark baseline).
pub fn parse_only(s: &Schedule, path: &Path, scope: Option<&str>) -> Result<u64, VcdError> {
    let mut c = CountCycles(0);
    read_cycles(s, path, scope, &mut c)?;
    Ok(c.0)
}
