//! Outside Verilog (`--rtl FILE.v`): read a user's file and check that its
//! top module honours the pin contract of a schedule before any back end
//! simulates it.
//!
//! The check is a small scanner of the top module (name
//! [`lut_gen::TOP_MODULE`]), not a Verilog front end: it finds the
//! module, reads its port list in ANSI style (`input wire [N:0] name`) or
//! non-ANSI style (a list of names plus `input [N:0] name;` declarations in
//! the body), with `wire`/`reg`/`logic` and similar net types, and evaluates
//! the ranges with the module's integer `parameter`/`localparam` constants
//! (`+ - * / % ** << >>`, comparisons, `?:`, `$clog2`).  What it cannot
//! evaluate (a macro, a parameter of an unknown type) is reported with the
//! port it was needed for.  Every contract port (names, directions: the
//! [`PORTS`] table; widths: [`Layout::width`]) must be present with its
//! direction and width; an extra output is allowed (ignored), an extra
//! input or inout is not (nothing would drive it).

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use lut_gen::Schedule;
use lut_gen::{Dir, Layout, PORTS, TOP_MODULE};

use crate::error::SimError;

/// Why a user's Verilog cannot stand in for the emitted one (exit 2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtlError {
    pub file: PathBuf,
    /// The port concerned, if the error is about one.
    pub port: Option<String>,
    pub message: String,
}

impl fmt::Display for RtlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.message)
    }
}

impl std::error::Error for RtlError {}

/// A port's direction as declared (the contract has no inouts).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PortDir {
    Input,
    Output,
    Inout,
}

impl PortDir {
    pub fn verilog(self) -> &'static str {
        match self {
            PortDir::Input => "input",
            PortDir::Output => "output",
            PortDir::Inout => "inout",
        }
    }

    fn of(d: Dir) -> PortDir {
        match d {
            Dir::In => PortDir::Input,
            Dir::Out => PortDir::Output,
        }
    }
}

/// One port of the scanned module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PortDecl {
    pub name: String,
    /// `None`: in the port list but never declared with a direction.
    pub dir: Option<PortDir>,
    /// Packed ranges `[msb:lsb]`, outermost first, evaluated; or why one
    /// could not be evaluated.
    pub ranges: Result<Vec<(i64, i64)>, String>,
    /// `integer` (32 bits) rather than a net or variable of bits.
    pub integer: bool,
    /// Has an unpacked dimension (`name [3:0]`).
    pub unpacked: bool,
    /// Line of the declaration (1-based).
    pub line: usize,
}

impl PortDecl {
    /// Width in bits, or why it is unknown.
    pub fn width(&self) -> Result<u32, String> {
        let r = self.ranges.clone()?;
        if self.integer && r.is_empty() {
            return Ok(32);
        }
        let mut w: i64 = 1;
        for (m, l) in r {
            w = w.saturating_mul((m - l).abs() + 1);
        }
        u32::try_from(w).map_err(|_| format!("width {w} out of range"))
    }

    /// How it was declared, e.g. `output [1:0]` (for messages).
    pub fn shape(&self) -> String {
        let d = self.dir.map_or("(no direction)", |d| d.verilog());
        match &self.ranges {
            Ok(r) => {
                let mut s = d.to_string();
                if self.integer {
                    s.push_str(" integer");
                }
                for (m, l) in r {
                    s.push_str(&format!(" [{m}:{l}]"));
                }
                s
            }
            Err(_) => d.to_string(),
        }
    }
}

/// Reads `path`, checks its `slotforge_top` against `s`'s pin contract and
/// returns the Verilog text.
pub fn load_rtl(s: &Schedule, path: &Path) -> Result<String, SimError> {
    let bytes =
        std::fs::read(path).map_err(|e| SimError::Rtl(err(path, None, lut_gen::io_words(&e))))?;
    let text = String::from_utf8_lossy(&bytes).into_owned();
    check_ports(s, path, &text).map_err(SimError::Rtl)?;
    Ok(text)
}

fn err(file: &Path, port: Option<&str>, message: String) -> RtlError {
    RtlError {
        file: file.to_path_buf(),
        port: port.map(str::to_string),
        message,
    }
}

/// Checks that `text`'s top module has exactly the contract's ports for `s`
/// (extra outputs allowed); `file` names the text in errors.
pub fn check_ports(s: &Schedule, file: &Path, text: &str) -> Result<(), RtlError> {
    let layout = Layout::new(s);
    let ports = scan_ports(text, TOP_MODULE).map_err(|m| err(file, None, m))?;
    let find = |n: &str| ports.iter().find(|p| p.name == n);
    // `mux_sel`/`mux_en` only when some branch has a mux
    for p in layout.ports() {
        let want_w = layout.width(p.role);
        let want_dir = PortDir::of(p.dir);
        let want = if p.vector || want_w > 1 {
            format!(
                "{} [{}:0] ({want_w} bit{})",
                want_dir.verilog(),
                want_w - 1,
                plural(want_w)
            )
        } else {
            format!("{} (1 bit)", want_dir.verilog())
        };
        let Some(d) = find(p.name) else {
            return Err(err(
                file,
                Some(p.name),
                format!(
                    "module {TOP_MODULE} has no port `{}`: expected {want} (the pin contract for mix `{}`)",
                    p.name, s.mix.name
                ),
            ));
        };
        let at = format!("module {TOP_MODULE}, line {}: port `{}`", d.line, p.name);
        let Some(dir) = d.dir else {
            return Err(err(
                file,
                Some(p.name),
                format!("{at} has no input/output declaration: expected {want}"),
            ));
        };
        if dir != want_dir {
            return Err(err(
                file,
                Some(p.name),
                format!("{at}: expected {want}, found {}", d.shape()),
            ));
        }
        if d.unpacked {
            return Err(err(
                file,
                Some(p.name),
                format!("{at}: expected {want}, found an unpacked array"),
            ));
        }
        let w = d.width().map_err(|m| {
            err(
                file,
                Some(p.name),
                format!("{at}: cannot evaluate its width ({m}); expected {want}"),
            )
        })?;
        if w != want_w {
            return Err(err(
                file,
                Some(p.name),
                format!(
                    "{at}: expected {want}, found {} ({w} bit{})",
                    d.shape(),
                    plural(w)
                ),
            ));
        }
        if let Ok(r) = &d.ranges {
            if r.iter().any(|(m, l)| m < l) {
                return Err(err(
                    file,
                    Some(p.name),
                    format!(
                        "{at}: expected {want}, found the ascending range {} (bit 0 must be the least significant)",
                        d.shape()
                    ),
                ));
            }
        }
    }
    no_extra_input(file, &layout, &ports)
}

/// An input or inout outside the contract would be driven by nothing; the
/// mix's link ports (a UART's or AXI4-Stream's, `m_axis_tready` an input the
/// testbench drives) and its mode ports are the contract's too. Extra
/// outputs are ignored.
fn no_extra_input(file: &Path, layout: &Layout, ports: &[PortDecl]) -> Result<(), RtlError> {
    let link = layout.link_ports();
    // a mix with modes: `mode_sel` (pin select) is the contract's too
    let modes = layout.mode_ports();
    let contract = |n: &str| {
        PORTS.iter().any(|p| p.name == n)
            || link.iter().any(|p| p.name == n)
            || modes.iter().any(|p| p.name == n)
    };
    let Some(x) = ports
        .iter()
        .find(|d| !contract(&d.name) && d.dir != Some(PortDir::Output))
    else {
        return Ok(());
    };
    Err(err(
        file,
        Some(&x.name),
        format!(
            "module {TOP_MODULE}, line {}: port `{}` ({}) is not in the pin contract, and nothing would drive it (only extra outputs are allowed); contract ports: {}",
            x.line,
            x.name,
            x.dir.map_or("no direction", |d| d.verilog()),
            PORTS
                .iter()
                .map(|p| p.name)
                .chain(link.iter().map(|p| p.name))
                .chain(modes.iter().map(|p| p.name))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ))
}

fn plural(n: u32) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

// ---- tokens ----

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    /// A `` `macro `` use.
    Macro(String),
    Num(String),
    Str,
    Op(&'static str),
    Other(char),
}

#[derive(Debug, Clone)]
struct Token {
    t: Tok,
    line: usize,
}

const OPS: [&str; 23] = [
    "<<<", ">>>", "**", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||", "+:", "-:", "::", "(", ")",
    "[", "]", "{", "}", ",", ";", "=",
];
const OPS1: &str = "+-*/%<>?:~!&|^#.@";

const DIRECTIVES: [&str; 16] = [
    "timescale",
    "define",
    "undef",
    "undefineall",
    "include",
    "ifdef",
    "ifndef",
    "else",
    "elsif",
    "endif",
    "default_nettype",
    "resetall",
    "celldefine",
    "endcelldefine",
    "unconnected_drive",
    "nounconnected_drive",
];

/// The index just past the first `close` at or after `i` (a block
/// comment's or an attribute's end), counting the lines it spans.
fn past(b: &[u8], mut i: usize, close: &[u8], line: &mut usize) -> usize {
    while i < b.len() && !b[i..].starts_with(close) {
        if b[i] == b'\n' {
            *line += 1;
        }
        i += 1;
    }
    i + close.len()
}

fn ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// The index just past the identifier characters from `i`.
fn past_ident(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && ident_char(b[i]) {
        i += 1;
    }
    i
}

/// The index just past the string literal opening at `i` (or its line's end).
fn past_string(b: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
        if b[i] == b'\\' {
            i += 1;
        }
        i += 1;
    }
    i + 1
}

/// The end of a directive's line (with `\` continuations), counting them.
fn past_directive(b: &[u8], mut i: usize, line: &mut usize) -> usize {
    while i < b.len() && b[i] != b'\n' {
        if b[i] == b'\\' && i + 1 < b.len() && b[i + 1] == b'\n' {
            *line += 1;
            i += 1;
        }
        i += 1;
    }
    i
}

/// The index just past the number starting at `s`:
/// `[size] ['[s]base digits] | decimal` (reals kept as text).
fn past_number(b: &[u8], s: usize) -> usize {
    let mut i = s;
    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
        i += 1;
    }
    let mut j = i;
    while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
        j += 1;
    }
    if j < b.len() && b[j] == b'\'' {
        i = j + 1;
        if i < b.len() && (b[i] == b's' || b[i] == b'S') {
            i += 1;
        }
        if i < b.len() && b"bBoOdDhH".contains(&b[i]) {
            i += 1;
        }
        while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
            i += 1;
        }
        while i < b.len() && (b[i].is_ascii_hexdigit() || b"_xXzZ?".contains(&b[i])) {
            i += 1;
        }
    } else if i < b.len() && (b[i] == b'.' || b[i] == b'e' || b[i] == b'E') {
        while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'_') {
            i += 1;
        }
    }
    if i == s {
        i += 1;
    }
    i
}

fn lex(text: &str) -> Vec<Token> {
    let b = text.as_bytes();
    let mut i = 0;
    let mut line = 1;
    let mut out = Vec::new();
    while i < b.len() {
        let c = b[i];
        let start = i;
        let t = if c == b'\n' {
            line += 1;
            i += 1;
            None
        } else if c.is_ascii_whitespace() {
            i += 1;
            None
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            None
        } else if b[i..].starts_with(b"/*") {
            i = past(b, i + 2, b"*/", &mut line);
            None
        } else if b[i..].starts_with(b"(*") && !b[i..].starts_with(b"(*)") {
            // attribute instance
            i = past(b, i + 2, b"*)", &mut line);
            None
        } else if c == b'"' {
            i = past_string(b, i);
            Some(Tok::Str)
        } else if c == b'`' {
            i = past_ident(b, i + 1);
            let name = &text[start + 1..i];
            if DIRECTIVES.contains(&name) {
                // the rest of the line
                i = past_directive(b, i, &mut line);
                None
            } else {
                Some(Tok::Macro(name.to_string()))
            }
        } else if c == b'\\' {
            while i < b.len() && !b[i].is_ascii_whitespace() {
                i += 1;
            }
            Some(Tok::Ident(text[start + 1..i].to_string()))
        } else if c.is_ascii_alphabetic() || c == b'_' || c == b'$' {
            i = past_ident(b, i);
            Some(Tok::Ident(text[start..i].to_string()))
        } else if c.is_ascii_digit() || c == b'\'' {
            i = past_number(b, i);
            Some(Tok::Num(text[start..i].to_string()))
        } else if let Some(op) = OPS.iter().find(|o| b[i..].starts_with(o.as_bytes())) {
            i += op.len();
            Some(Tok::Op(op))
        } else {
            let ch = text[i..].chars().next().unwrap_or('?');
            i += ch.len_utf8();
            Some(match OPS1.find(ch) {
                Some(k) => Tok::Op(&OPS1[k..k + 1]),
                None => Tok::Other(ch),
            })
        };
        if let Some(t) = t {
            out.push(Token { t, line });
        }
    }
    out
}

fn is_kw(t: &Token, kw: &str) -> bool {
    matches!(&t.t, Tok::Ident(s) if s == kw)
}

fn is_op(t: &Token, op: &str) -> bool {
    matches!(&t.t, Tok::Op(o) if *o == op)
}

fn ident(t: &Token) -> Option<&str> {
    match &t.t {
        Tok::Ident(s) => Some(s),
        _ => None,
    }
}

const NET_TYPES: [&str; 13] = [
    "wire", "reg", "logic", "tri", "tri0", "tri1", "wand", "wor", "triand", "trior", "uwire",
    "var", "bit",
];

fn direction(t: &Token) -> Option<PortDir> {
    match ident(t)? {
        "input" => Some(PortDir::Input),
        "output" => Some(PortDir::Output),
        "inout" => Some(PortDir::Inout),
        _ => None,
    }
}

/// Index of the token closing the bracket opened at `open`.
fn close_of(toks: &[Token], open: usize) -> Result<usize, String> {
    let mut depth = 0i32;
    for (k, t) in toks.iter().enumerate().skip(open) {
        if is_op(t, "(") || is_op(t, "[") || is_op(t, "{") {
            depth += 1;
        } else if is_op(t, ")") || is_op(t, "]") || is_op(t, "}") {
            depth -= 1;
            if depth == 0 {
                return Ok(k);
            }
        }
    }
    Err(format!(
        "unbalanced bracket opened on line {}",
        toks[open].line
    ))
}

/// Splits `toks` at depth-0 commas.
fn split_commas(toks: &[Token]) -> Vec<&[Token]> {
    let mut v = Vec::new();
    let mut depth = 0i32;
    let mut s = 0;
    for (k, t) in toks.iter().enumerate() {
        if is_op(t, "(") || is_op(t, "[") || is_op(t, "{") {
            depth += 1;
        } else if is_op(t, ")") || is_op(t, "]") || is_op(t, "}") {
            depth -= 1;
        } else if depth == 0 && is_op(t, ",") {
            v.push(&toks[s..k]);
            s = k + 1;
        }
    }
    v.push(&toks[s..]);
    v
}

type Params = BTreeMap<String, Result<i64, String>>;

/// A declaration's head: `[net type] [signed] [integer] [range]*` then names.
struct Head {
    integer: bool,
    ranges: Result<Vec<(i64, i64)>, String>,
    /// Index of the first token after the head.
    end: usize,
}

fn head(toks: &[Token], mut k: usize, params: &Params) -> Result<Head, String> {
    let mut integer = false;
    while k < toks.len() {
        match ident(&toks[k]) {
            Some(n) if NET_TYPES.contains(&n) || n == "signed" || n == "unsigned" => k += 1,
            Some("integer") | Some("int") => {
                integer = true;
                k += 1
            }
            _ => break,
        }
    }
    let mut ranges: Result<Vec<(i64, i64)>, String> = Ok(Vec::new());
    while k < toks.len() && is_op(&toks[k], "[") {
        let c = close_of(toks, k)?;
        let r = range(&toks[k + 1..c], params);
        ranges = match (ranges, r) {
            (Ok(mut v), Ok(r)) => {
                v.push(r);
                Ok(v)
            }
            (Err(e), _) | (_, Err(e)) => Err(e),
        };
        k = c + 1;
    }
    Ok(Head {
        integer,
        ranges,
        end: k,
    })
}

fn range(toks: &[Token], params: &Params) -> Result<(i64, i64), String> {
    let text = render(toks);
    let parts: Vec<usize> = {
        let mut depth = 0i32;
        let mut v = Vec::new();
        let mut q = 0; // ?: nesting
        for (k, t) in toks.iter().enumerate() {
            if is_op(t, "(") || is_op(t, "[") || is_op(t, "{") {
                depth += 1;
            } else if is_op(t, ")") || is_op(t, "]") || is_op(t, "}") {
                depth -= 1;
            } else if depth == 0 && is_op(t, "?") {
                q += 1;
            } else if depth == 0 && is_op(t, ":") {
                if q > 0 {
                    q -= 1;
                } else {
                    v.push(k);
                }
            }
        }
        v
    };
    if parts.len() != 1 {
        return Err(format!("`[{text}]` is not a range [msb:lsb]"));
    }
    let m = eval(&toks[..parts[0]], params).map_err(|e| format!("`[{text}]`: {e}"))?;
    let l = eval(&toks[parts[0] + 1..], params).map_err(|e| format!("`[{text}]`: {e}"))?;
    Ok((m, l))
}

fn render(toks: &[Token]) -> String {
    toks.iter()
        .map(|t| match &t.t {
            Tok::Ident(s) | Tok::Num(s) => s.clone(),
            Tok::Macro(s) => format!("`{s}"),
            Tok::Str => "\"..\"".into(),
            Tok::Op(o) => o.to_string(),
            Tok::Other(c) => c.to_string(),
        })
        .collect::<Vec<_>>()
        .join("")
}

// ---- constant expressions ----

fn eval(toks: &[Token], params: &Params) -> Result<i64, String> {
    let mut p = Expr { toks, k: 0, params };
    let v = p.ternary()?;
    if p.k != toks.len() {
        return Err(format!(
            "cannot evaluate `{}` (unexpected `{}`)",
            render(toks),
            render(&toks[p.k..p.k + 1])
        ));
    }
    Ok(v)
}

struct Expr<'a> {
    toks: &'a [Token],
    k: usize,
    params: &'a Params,
}

const BINARY: [(&str, u8); 18] = [
    ("||", 1),
    ("&&", 2),
    ("|", 3),
    ("^", 4),
    ("&", 5),
    ("==", 6),
    ("!=", 6),
    ("<", 7),
    ("<=", 7),
    (">", 7),
    (">=", 7),
    ("<<", 8),
    (">>", 8),
    ("<<<", 8),
    (">>>", 8),
    ("+", 9),
    ("-", 9),
    ("*", 10),
];

impl Expr<'_> {
    fn peek_op(&self) -> Option<&'static str> {
        match self.toks.get(self.k).map(|t| &t.t) {
            Some(Tok::Op(o)) => Some(o),
            _ => None,
        }
    }

    fn ternary(&mut self) -> Result<i64, String> {
        let c = self.binary(1)?;
        if self.peek_op() == Some("?") {
            self.k += 1;
            let a = self.ternary()?;
            if self.peek_op() != Some(":") {
                return Err("`?` without `:`".into());
            }
            self.k += 1;
            let b = self.ternary()?;
            return Ok(if c != 0 { a } else { b });
        }
        Ok(c)
    }

    fn prec(op: &str) -> Option<u8> {
        match op {
            "/" | "%" => Some(10),
            "**" => Some(11),
            _ => BINARY.iter().find(|(o, _)| *o == op).map(|(_, p)| *p),
        }
    }

    fn binary(&mut self, min: u8) -> Result<i64, String> {
        let mut l = self.unary()?;
        while let Some(op) = self.peek_op() {
            let Some(p) = Self::prec(op) else { break };
            if p < min {
                break;
            }
            self.k += 1;
            // `**` is right-associative
            let r = self.binary(if op == "**" { p } else { p + 1 })?;
            let ov = || format!("overflow in `{op}`");
            l = match op {
                "||" => (l != 0 || r != 0) as i64,
                "&&" => (l != 0 && r != 0) as i64,
                "|" => l | r,
                "^" => l ^ r,
                "&" => l & r,
                "==" => (l == r) as i64,
                "!=" => (l != r) as i64,
                "<" => (l < r) as i64,
                "<=" => (l <= r) as i64,
                ">" => (l > r) as i64,
                ">=" => (l >= r) as i64,
                "<<" | "<<<" => l
                    .checked_shl(u32::try_from(r).map_err(|_| ov())?)
                    .ok_or_else(ov)?,
                ">>" | ">>>" => l
                    .checked_shr(u32::try_from(r).map_err(|_| ov())?)
                    .ok_or_else(ov)?,
                "+" => l.checked_add(r).ok_or_else(ov)?,
                "-" => l.checked_sub(r).ok_or_else(ov)?,
                "*" => l.checked_mul(r).ok_or_else(ov)?,
                "/" => l.checked_div(r).ok_or("division by zero")?,
                "%" => l.checked_rem(r).ok_or("division by zero")?,
                "**" => l
                    .checked_pow(u32::try_from(r).map_err(|_| ov())?)
                    .ok_or_else(ov)?,
                _ => unreachable!(),
            };
        }
        Ok(l)
    }

    fn unary(&mut self) -> Result<i64, String> {
        let Some(t) = self.toks.get(self.k) else {
            return Err("expression ends early".into());
        };
        self.k += 1;
        match &t.t {
            Tok::Op("-") => Ok(-self.unary()?),
            Tok::Op("+") => self.unary(),
            Tok::Op("~") => Ok(!self.unary()?),
            Tok::Op("!") => Ok((self.unary()? == 0) as i64),
            Tok::Op("(") => {
                let v = self.ternary()?;
                if self.peek_op() != Some(")") {
                    return Err("missing `)`".into());
                }
                self.k += 1;
                Ok(v)
            }
            Tok::Num(n) => number(n),
            Tok::Ident(f) if f == "$clog2" => {
                if self.peek_op() != Some("(") {
                    return Err("`$clog2` without `(`".into());
                }
                let v = self.unary()?;
                Ok(if v <= 1 {
                    0
                } else {
                    64 - (v - 1).leading_zeros() as i64
                })
            }
            Tok::Ident(n) => match self.params.get(n) {
                Some(Ok(v)) => Ok(*v),
                Some(Err(e)) => Err(format!("parameter `{n}`: {e}")),
                None => Err(format!(
                    "`{n}` is not a parameter or localparam of the module"
                )),
            },
            Tok::Macro(m) => Err(format!(
                "the macro `{m}` (macros are not expanded; use a parameter)"
            )),
            _ => Err(format!("unexpected `{}`", render(std::slice::from_ref(t)))),
        }
    }
}

fn number(n: &str) -> Result<i64, String> {
    let clean: String = n
        .chars()
        .filter(|c| *c != '_' && !c.is_whitespace())
        .collect();
    let bad = || format!("`{n}` is not an integer constant");
    match clean.find('\'') {
        None => clean.parse::<i64>().map_err(|_| bad()),
        Some(q) => {
            let rest = clean[q + 1..].trim_start_matches(['s', 'S']);
            let (radix, digits) = match rest.chars().next() {
                Some('b' | 'B') => (2, &rest[1..]),
                Some('o' | 'O') => (8, &rest[1..]),
                Some('d' | 'D') => (10, &rest[1..]),
                Some('h' | 'H') => (16, &rest[1..]),
                _ => return Err(bad()),
            };
            i64::from_str_radix(digits, radix).map_err(|_| bad())
        }
    }
}

// ---- the module ----

/// The ports of module `module` in `text`, in port-list order.
///
/// Errors when the module is missing, defined twice, or its header cannot
/// be read; a width that cannot be evaluated is recorded in the port
/// (`PortDecl::ranges`), so that the message can name the port.
pub fn scan_ports(text: &str, module: &str) -> Result<Vec<PortDecl>, String> {
    let toks = lex(text);
    let (start, end) = module_span(&toks, module)?;
    let toks = &toks[..end];
    let mut params = Params::new();
    let k = skip_imports(toks, start + 1);
    let k = header_params(toks, k, module, &mut params)?;
    if !(k < toks.len() && is_op(&toks[k], "(")) {
        // no port list: no ports, but the body must still read
        body_declarations(toks, k, &params, &mut [])?;
        return Ok(Vec::new());
    }
    let c = close_of(toks, k)?;
    let items = split_commas(&toks[k + 1..c]);
    let ansi = items
        .iter()
        .any(|it| it.first().and_then(direction).is_some());
    if ansi {
        return ansi_ports(&items, module, &params);
    }
    // body parameters may size non-ANSI ports; ANSI ones see only the header's
    collect_body_params(toks, c + 1, &mut params);
    let mut ports = bare_ports(&items, module)?;
    body_declarations(toks, c + 1, &params, &mut ports)?;
    Ok(ports)
}

/// One module of the text: its name, the index of its name token and that
/// of its `endmodule`.
struct ModuleSpan {
    name: String,
    start: usize,
    end: usize,
}

/// Every module of the text, in order.
fn modules(toks: &[Token]) -> Result<Vec<ModuleSpan>, String> {
    let mut mods = Vec::new();
    let mut k = 0;
    while k < toks.len() {
        if is_kw(&toks[k], "module") || is_kw(&toks[k], "macromodule") {
            let name = toks.get(k + 1).and_then(ident).unwrap_or("?").to_string();
            let end = (k + 1..toks.len())
                .find(|&j| is_kw(&toks[j], "endmodule"))
                .ok_or_else(|| format!("module {name} (line {}) has no endmodule", toks[k].line))?;
            mods.push(ModuleSpan {
                name,
                start: k + 1,
                end,
            });
            k = end + 1;
        } else {
            k += 1;
        }
    }
    Ok(mods)
}

/// The name token and `endmodule` of the one module named `module`.
fn module_span(toks: &[Token], module: &str) -> Result<(usize, usize), String> {
    let mods = modules(toks)?;
    let mine: Vec<_> = mods.iter().filter(|m| m.name == module).collect();
    match mine.as_slice() {
        [] => Err(format!(
            "no module named {module} ({})",
            modules_found(&mods)
        )),
        [m] => Ok((m.start, m.end)),
        _ => Err(format!(
            "module {module} is defined {} times (lines {})",
            mine.len(),
            mine.iter()
                .map(|m| toks[m.start].line.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// The modules there are, for a message about one that is missing.
fn modules_found(mods: &[ModuleSpan]) -> String {
    if mods.is_empty() {
        return "no module at all".to_string();
    }
    let names: Vec<&str> = mods.iter().take(8).map(|m| m.name.as_str()).collect();
    let more = mods.len().saturating_sub(names.len());
    format!(
        "modules found: {}{}",
        names.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    )
}

/// Past the SV package imports of a module header.
fn skip_imports(toks: &[Token], mut k: usize) -> usize {
    while k < toks.len() && is_kw(&toks[k], "import") {
        while k < toks.len() && !is_op(&toks[k], ";") {
            k += 1;
        }
        k += 1;
    }
    k
}

/// Reads the header's `#( ... )` parameter list, if there is one at `k`,
/// into `params`; returns the index after it.
fn header_params(
    toks: &[Token],
    k: usize,
    module: &str,
    params: &mut Params,
) -> Result<usize, String> {
    if !(k < toks.len() && is_op(&toks[k], "#")) {
        return Ok(k);
    }
    if !toks.get(k + 1).is_some_and(|t| is_op(t, "(")) {
        return Err(format!("module {module}: `#` without a parameter list"));
    }
    let c = close_of(toks, k + 1)?;
    // `type` parameters are skipped up to the next `parameter`
    let mut kind_params = true;
    for item in split_commas(&toks[k + 2..c]) {
        let mut j = 0;
        if item
            .first()
            .is_some_and(|t| is_kw(t, "parameter") || is_kw(t, "localparam"))
        {
            j = 1;
            kind_params = true;
        }
        if item.first().is_some_and(|t| is_kw(t, "type")) {
            kind_params = false;
        }
        if kind_params {
            param_item(&item[j..], params);
        }
    }
    Ok(c + 1)
}

/// A non-ANSI port list: names only, directions come from the body.
fn bare_ports(items: &[&[Token]], module: &str) -> Result<Vec<PortDecl>, String> {
    let mut ports = Vec::new();
    for item in items.iter().filter(|it| !it.is_empty()) {
        match item {
            [t] if ident(t).is_some() => ports.push(PortDecl {
                name: ident(t).unwrap().to_string(),
                dir: None,
                ranges: Ok(Vec::new()),
                integer: false,
                unpacked: false,
                line: t.line,
            }),
            _ => {
                return Err(format!(
                "module {module}, line {}: port expression `{}` is not supported (list port names)",
                item[0].line,
                render(item)
            ))
            }
        }
    }
    Ok(ports)
}

/// An ANSI port list: every item declares its port.
fn ansi_ports(items: &[&[Token]], module: &str, params: &Params) -> Result<Vec<PortDecl>, String> {
    let mut ports = Vec::new();
    let mut prev: Option<(PortDir, Head)> = None;
    for item in items.iter().filter(|it| !it.is_empty()) {
        ports.push(ansi_port(item, module, params, &mut prev)?);
    }
    Ok(ports)
}

/// One ANSI port declaration.  `prev` is the previous declaration, whose
/// direction (and, for a bare name, type) the item inherits.
fn ansi_port(
    item: &[Token],
    module: &str,
    params: &Params,
    prev: &mut Option<(PortDir, Head)>,
) -> Result<PortDecl, String> {
    let (dir, h) = match item.first().and_then(direction) {
        Some(d) => (d, head(item, 1, params)?),
        None => inherited_head(item, module, params, prev.as_ref())?,
    };
    let Some(nt) = item.get(h.end) else {
        return Err(format!(
            "module {module}, line {}: a port declaration without a name: `{}`",
            item[0].line,
            render(item)
        ));
    };
    let Some(name) = ident(nt) else {
        return Err(format!(
            "module {module}, line {}: cannot read the port declaration `{}`",
            nt.line,
            render(item)
        ));
    };
    let after = item.get(h.end + 1);
    if let Some(real) = after.and_then(ident) {
        // `input my_type name`: a user type
        *prev = None;
        return Ok(PortDecl {
            name: real.to_string(),
            dir: Some(dir),
            ranges: Err(format!(
                "its type `{name}` is not a net, reg, logic or integer"
            )),
            integer: false,
            unpacked: false,
            line: nt.line,
        });
    }
    let port = PortDecl {
        name: name.to_string(),
        dir: Some(dir),
        ranges: h.ranges.clone(),
        integer: h.integer,
        unpacked: after.is_some_and(|t| is_op(t, "[")),
        line: nt.line,
    };
    *prev = Some((dir, h));
    Ok(port)
}

/// The direction and head of an ANSI item without a direction of its own.
fn inherited_head(
    item: &[Token],
    module: &str,
    params: &Params,
    prev: Option<&(PortDir, Head)>,
) -> Result<(PortDir, Head), String> {
    let h = head(item, 0, params)?;
    let Some((d, ph)) = prev else {
        return Err(format!(
            "module {module}, line {}: port `{}` has no direction",
            item[0].line,
            render(item)
        ));
    };
    // a bare name inherits the previous declaration
    if h.end == 0 {
        Ok((
            *d,
            Head {
                integer: ph.integer,
                ranges: ph.ranges.clone(),
                end: 0,
            },
        ))
    } else {
        Ok((*d, h))
    }
}

/// Past a `function` or `task` starting at `j`, if one does.
fn skip_subroutine(toks: &[Token], j: usize) -> Option<usize> {
    let end_kw = match ident(&toks[j]) {
        Some("function") => "endfunction",
        Some("task") => "endtask",
        _ => return None,
    };
    Some(
        (j..toks.len())
            .find(|&x| is_kw(&toks[x], end_kw))
            .unwrap_or(toks.len()),
    )
}

/// The `;` ending the statement that starts at `from` (brackets nest).
fn stmt_end(toks: &[Token], from: usize) -> usize {
    let mut depth = 0i32;
    for (x, t) in toks.iter().enumerate().skip(from) {
        if is_op(t, "(") || is_op(t, "[") || is_op(t, "{") {
            depth += 1;
        } else if is_op(t, ")") || is_op(t, "]") || is_op(t, "}") {
            depth -= 1;
        } else if depth <= 0 && is_op(t, ";") {
            return x;
        }
    }
    toks.len()
}

/// Non-ANSI ports: directions and ranges from the body's declarations,
/// which start at token `from`.
fn body_declarations(
    toks: &[Token],
    from: usize,
    params: &Params,
    ports: &mut [PortDecl],
) -> Result<(), String> {
    let mut nets: BTreeMap<String, Head> = BTreeMap::new();
    let mut j = from;
    while j < toks.len() {
        let t = &toks[j];
        if let Some(past) = skip_subroutine(toks, j) {
            j = past;
        } else if let Some(dir) = direction(t) {
            let e = stmt_end(toks, j);
            let h = head(&toks[..e], j + 1, params)?;
            declare_ports(&toks[h.end..e], dir, &h, ports);
            j = e + 1;
        } else if ident(t).is_some_and(|n| NET_TYPES.contains(&n) || n == "integer")
            && (j == 0 || is_op(&toks[j - 1], ";") || is_kw(&toks[j - 1], "end") || j == from)
        {
            let e = stmt_end(toks, j);
            let h = head(&toks[..e], j, params)?;
            for item in split_commas(&toks[h.end..e]) {
                if let Some(name) = item.first().and_then(ident) {
                    nets.insert(
                        name.to_string(),
                        Head {
                            integer: h.integer,
                            ranges: h.ranges.clone(),
                            end: 0,
                        },
                    );
                }
            }
            j = e + 1;
        } else {
            j += 1;
        }
    }
    // `output q; reg [3:0] q;`: the range may sit on the net declaration
    for p in ports {
        if p.ranges.as_ref().is_ok_and(|r| r.is_empty()) && !p.integer {
            if let Some(h) = nets.get(&p.name) {
                p.ranges = h.ranges.clone();
                p.integer = h.integer;
            }
        }
    }
    Ok(())
}

/// A body's `input [3:0] a, b;`: sets the direction and shape of the
/// listed ports.
fn declare_ports(names: &[Token], dir: PortDir, h: &Head, ports: &mut [PortDecl]) {
    for item in split_commas(names) {
        let Some(name) = item.first().and_then(ident) else {
            continue;
        };
        if let Some(p) = ports.iter_mut().find(|p| p.name == name) {
            p.dir = Some(dir);
            p.ranges = h.ranges.clone();
            p.integer = h.integer;
            p.unpacked = item.get(1).is_some_and(|t| is_op(t, "["));
            p.line = item[0].line;
        }
    }
}

/// `[type] [range] NAME = expr` (one item of a parameter declaration).
fn param_item(item: &[Token], params: &mut Params) {
    let mut j = 0;
    while j < item.len() {
        match ident(&item[j]) {
            Some("integer" | "int" | "signed" | "unsigned" | "logic" | "bit" | "reg") => j += 1,
            _ => break,
        }
    }
    let mut typed_ok = true;
    while j < item.len() && is_op(&item[j], "[") {
        match close_of(item, j) {
            Ok(c) => j = c + 1,
            Err(_) => return,
        }
    }
    // `real`, `string`, a user type...: a name followed by a name
    if item.get(j + 1).is_some_and(|t| ident(t).is_some()) {
        typed_ok = false;
        j += 1;
    }
    let Some(name) = item.get(j).and_then(ident) else {
        return;
    };
    let v = if !item.get(j + 1).is_some_and(|t| is_op(t, "=")) {
        Err("it has no value".to_string())
    } else if !typed_ok {
        Err("it is not of an integer type".to_string())
    } else {
        eval(&item[j + 2..], params)
    };
    params.insert(name.to_string(), v);
}

/// Every module-level `parameter`/`localparam` after token `from`, in order.
fn collect_body_params(toks: &[Token], from: usize, params: &mut Params) {
    let mut j = from;
    while j < toks.len() {
        if let Some(past) = skip_subroutine(toks, j) {
            j = past;
            continue;
        }
        if is_kw(&toks[j], "parameter") || is_kw(&toks[j], "localparam") {
            let e = (j..toks.len())
                .find(|&x| is_op(&toks[x], ";"))
                .unwrap_or(toks.len());
            for item in split_commas(&toks[j + 1..e]) {
                param_item(item, params);
            }
            j = e + 1;
            continue;
        }
        j += 1;
    }
}

/// `expr`'s value under `params` (tests only, through `for_tests`: the
/// evaluator behind every port width [`scan_ports`] reads).
pub fn eval_const(
    expr: &str,
    params: &BTreeMap<String, Result<i64, String>>,
) -> Result<i64, String> {
    eval(&lex(expr), params)
}
