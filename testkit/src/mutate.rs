//! A small, deterministic mutation generator for the emitted Verilog
//! (`slotforge_top.v`), for mutation-testing the checker: every mutant is the
//! original text with ONE principled edit at one site.
//!
//! Operators ([`Operator`]):
//! - `relop`: `==` <-> `!=`, `<` -> `<=`, `>` -> `>=`;
//! - `const`: a sized literal (`8'h1f`, `5'b10000`, `14'd3`) by its value +1
//!   or -1 (alternating by site, modulo its width), in expressions,
//!   `localparam`s and ROM images;
//! - `reset`: a reset value (an assignment inside `if (rst) begin ... end`)
//!   inverted: `1'b0` <-> `1'b1`, anything else `v` -> `~(v)`;
//! - `andor`: binary `&` <-> `|`, `&&` <-> `||`;
//! - `arith`: `+` -> `-`, `<<` -> `>>`;
//! - `dropnot`: a `~` dropped;
//! - `concat`: the last two elements of a concatenation `{.., a, b}` swapped;
//! - `stuck`: an output assignment (`assign out = ..;`, or `out = ..;` for an
//!   output port of the enclosing module) stuck at 0 or all ones
//!   (alternating by site).
//!
//! Comment lines, power-up `initial` values of registers (the reset
//! overrides them) and the `unused_*` lint sinks are never mutated: edits
//! there are equivalent by construction.  [`select`] picks sites per
//! operator evenly spread over the file, so the mutant set is a pure
//! function of the text.

use std::fmt;

/// A mutation operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Operator {
    RelOp,
    Const,
    Reset,
    AndOr,
    Arith,
    DropNot,
    Concat,
    Stuck,
}

impl Operator {
    pub const ALL: [Operator; 8] = [
        Operator::RelOp,
        Operator::Const,
        Operator::Reset,
        Operator::AndOr,
        Operator::Arith,
        Operator::DropNot,
        Operator::Concat,
        Operator::Stuck,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Operator::RelOp => "relop",
            Operator::Const => "const",
            Operator::Reset => "reset",
            Operator::AndOr => "andor",
            Operator::Arith => "arith",
            Operator::DropNot => "dropnot",
            Operator::Concat => "concat",
            Operator::Stuck => "stuck",
        }
    }
}

impl fmt::Display for Operator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One place where an operator applies: replace `text[start..end]` by
/// `replacement`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Site {
    pub op: Operator,
    /// 1-based line number.
    pub line: usize,
    /// Byte range in the whole text.
    pub start: usize,
    pub end: usize,
    pub original: String,
    pub replacement: String,
}

/// A mutated design.
#[derive(Debug, Clone)]
pub struct Mutant {
    /// Index in the selected list.
    pub id: usize,
    pub site: Site,
    pub text: String,
}

impl Mutant {
    /// `op@line: original -> replacement`.
    pub fn describe(&self) -> String {
        format!(
            "#{} {}@{}: `{}` -> `{}`",
            self.id, self.site.op, self.site.line, self.site.original, self.site.replacement
        )
    }
}

impl Site {
    pub fn apply(&self, text: &str) -> String {
        let mut s = String::with_capacity(text.len() + self.replacement.len());
        s.push_str(&text[..self.start]);
        s.push_str(&self.replacement);
        s.push_str(&text[self.end..]);
        s
    }
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// All mutation sites of `text`, in text order per line.
pub fn sites(text: &str) -> Vec<Site> {
    let mut out = Vec::new();
    let mut offset = 0usize;
    let mut outputs: Vec<String> = Vec::new();
    let mut in_initial = false;
    let mut rst_depth: Option<usize> = None; // indentation of `if (rst) begin`
    for (i, raw) in text.split_inclusive('\n').enumerate() {
        let line_start = offset;
        offset += raw.len();
        let lineno = i + 1;
        let line = raw.trim_end_matches(['\n', '\r']);
        // drop a trailing comment
        let code = match line.find("//") {
            Some(k) => &line[..k],
            None => line,
        };
        let t = code.trim();
        let indent = code.len() - code.trim_start().len();
        if t.starts_with("module ") {
            outputs.clear();
            in_initial = false;
            rst_depth = None;
        }
        if t.starts_with("output ") {
            if let Some(name) = t
                .trim_end_matches([',', ';'])
                .split_whitespace()
                .last()
                .filter(|n| n.bytes().all(is_ident))
            {
                outputs.push(name.to_string());
            }
            continue;
        }
        if t == "initial begin" {
            in_initial = true;
            continue;
        }
        if in_initial {
            if t == "end" {
                in_initial = false;
            } else if t.starts_with("mem[") {
                // ROM image: its constants are the LUT
                lits(code, line_start, lineno, &mut out);
            }
            continue;
        }
        if t.is_empty() || t.contains("unused_") || t.starts_with("input ") {
            continue;
        }
        if t == "if (rst) begin" {
            rst_depth = Some(indent);
            continue;
        }
        if let Some(d) = rst_depth {
            if t == "end" && indent == d {
                rst_depth = None;
                continue;
            }
            // reset values
            if let Some((_, (rs, re))) = assignment(code) {
                let v = &code[rs..re];
                let rep = match v {
                    "1'b0" => "1'b1".to_string(),
                    "1'b1" => "1'b0".to_string(),
                    _ => format!("~({v})"),
                };
                out.push(Site {
                    op: Operator::Reset,
                    line: lineno,
                    start: line_start + rs,
                    end: line_start + re,
                    original: v.to_string(),
                    replacement: rep,
                });
            }
            continue;
        }
        let b = code.as_bytes();
        let declaration = t.starts_with("reg ") || t.starts_with("wire ");
        if declaration && !t.contains('=') {
            continue;
        }
        // relational operators
        for (k, w) in b.windows(2).enumerate() {
            let rep = match w {
                b"==" => "!=",
                b"!=" => "==",
                _ => continue,
            };
            out.push(site(Operator::RelOp, lineno, line_start + k, 2, rep));
        }
        for (k, &c) in b.iter().enumerate() {
            if (c == b'<' || c == b'>') && k > 0 && b[k - 1] == b' ' && b.get(k + 1) == Some(&b' ')
            {
                let rep = if c == b'<' { "<=" } else { ">=" };
                out.push(site(Operator::RelOp, lineno, line_start + k, 1, rep));
            }
        }
        // constants
        lits(code, line_start, lineno, &mut out);
        // and/or
        for (k, _) in code.match_indices(" & ") {
            out.push(site(Operator::AndOr, lineno, line_start + k + 1, 1, "|"));
        }
        for (k, _) in code.match_indices(" | ") {
            out.push(site(Operator::AndOr, lineno, line_start + k + 1, 1, "&"));
        }
        for (k, _) in code.match_indices("&&") {
            out.push(site(Operator::AndOr, lineno, line_start + k, 2, "||"));
        }
        for (k, _) in code.match_indices("||") {
            out.push(site(Operator::AndOr, lineno, line_start + k, 2, "&&"));
        }
        // arithmetic and shifts
        for (k, _) in code.match_indices(" + ") {
            out.push(site(Operator::Arith, lineno, line_start + k + 1, 1, "-"));
        }
        for (k, _) in code.match_indices(" << ") {
            out.push(site(Operator::Arith, lineno, line_start + k + 1, 2, ">>"));
        }
        // dropped inversions
        for (k, _) in code.match_indices('~') {
            out.push(site(Operator::DropNot, lineno, line_start + k, 1, ""));
        }
        // concatenations: swap the last two top-level elements
        concat(code, line_start, lineno, &mut out);
        // stuck-at outputs
        let body = t.strip_prefix("assign ").unwrap_or(t);
        if let Some((lhs, _)) = body.split_once(" = ") {
            if outputs.iter().any(|o| o == lhs.trim()) {
                // a constant output is the Const operator's: stuck at a
                // literal is that literal again or a constant changed
                if let Some((_, (rs, re))) = assignment(code)
                    .filter(|(_, (rs, _))| !code[*rs..].starts_with(|c: char| c.is_ascii_digit()))
                {
                    let v = &code[rs..re];
                    out.push(Site {
                        op: Operator::Stuck,
                        line: lineno,
                        start: line_start + rs,
                        end: line_start + re,
                        original: v.to_string(),
                        replacement: String::new(), // decided in `select`
                    });
                }
            }
        }
    }
    out
}

fn site(op: Operator, line: usize, at: usize, len: usize, rep: &str) -> Site {
    Site {
        op,
        line,
        start: at,
        end: at + len,
        original: String::new(),
        replacement: rep.to_string(),
    }
}

/// `lhs = rhs;` : (end of lhs, byte range of rhs) within `code`.
fn assignment(code: &str) -> Option<(usize, (usize, usize))> {
    let eq = code.find(" = ")?;
    let rs = eq + 3;
    let re = code.rfind(';')?;
    (re > rs).then_some((eq, (rs, re)))
}

/// Sized literals `N'[bhd]digits` in `code`.
fn lits(code: &str, line_start: usize, lineno: usize, out: &mut Vec<Site>) {
    let b = code.as_bytes();
    let mut k = 0;
    while k < b.len() {
        if b[k] == b'\'' && k > 0 && b[k - 1].is_ascii_digit() && k + 1 < b.len() {
            let mut s = k;
            while s > 0 && b[s - 1].is_ascii_digit() {
                s -= 1;
            }
            if s > 0 && is_ident(b[s - 1]) {
                k += 1;
                continue;
            }
            let base = b[k + 1].to_ascii_lowercase();
            let radix = match base {
                b'b' => 2,
                b'h' => 16,
                b'd' => 10,
                _ => {
                    k += 1;
                    continue;
                }
            };
            let mut e = k + 2;
            while e < b.len() && (b[e].is_ascii_hexdigit() || b[e] == b'_') {
                e += 1;
            }
            let width: u32 = code[s..k].parse().unwrap_or(0);
            let digits: String = code[k + 2..e].chars().filter(|&c| c != '_').collect();
            if (1..=64).contains(&width) && u128::from_str_radix(&digits, radix).is_ok() {
                out.push(Site {
                    op: Operator::Const,
                    line: lineno,
                    start: line_start + s,
                    end: line_start + e,
                    original: code[s..e].to_string(),
                    replacement: String::new(), // decided in `select`
                });
            }
            k = e;
        } else {
            k += 1;
        }
    }
}

/// A literal `N'[bhd]digits` with its value moved by `delta` (mod 2^N), in the same base.
fn bump(lit: &str, delta: i128) -> String {
    let (w, rest) = lit.split_once('\'').unwrap();
    let width: u32 = w.parse().unwrap();
    let base = rest.as_bytes()[0].to_ascii_lowercase();
    let radix = match base {
        b'b' => 2,
        b'h' => 16,
        _ => 10,
    };
    let digits: String = rest[1..].chars().filter(|&c| c != '_').collect();
    let v = u128::from_str_radix(&digits, radix).unwrap() as i128;
    let m = 1i128 << width;
    let n = (v + delta).rem_euclid(m) as u128;
    match base {
        b'b' => format!("{width}'b{n:b}"),
        b'h' => format!("{width}'h{n:x}"),
        _ => format!("{width}'d{n}"),
    }
}

/// Concatenations `{a, b, ..}` (not replications `{N{..}}`): swap the last two elements.
fn concat(code: &str, line_start: usize, lineno: usize, out: &mut Vec<Site>) {
    let b = code.as_bytes();
    for (open, &c) in b.iter().enumerate() {
        if c != b'{' {
            continue;
        }
        // a replication count right before: `{6{`
        let mut p = open;
        while p > 0 && b[p - 1].is_ascii_digit() {
            p -= 1;
        }
        if p < open && p > 0 && b[p - 1] == b'{' {
            continue;
        }
        // find the matching brace and top-level commas
        let mut depth = 0usize;
        let mut commas = Vec::new();
        let mut close = None;
        for (k, &d) in b.iter().enumerate().skip(open) {
            match d {
                b'{' | b'(' | b'[' => depth += 1,
                b'}' | b')' | b']' => {
                    depth -= 1;
                    if depth == 0 {
                        close = Some(k);
                        break;
                    }
                }
                b',' if depth == 1 => commas.push(k),
                _ => {}
            }
        }
        let (Some(close), Some(&last)) = (close, commas.last()) else {
            continue;
        };
        let prev = if commas.len() >= 2 {
            commas[commas.len() - 2] + 1
        } else {
            open + 1
        };
        let a = code[prev..last].trim();
        let z = code[last + 1..close].trim();
        let lead = code[prev..last].len() - code[prev..last].trim_start().len();
        out.push(Site {
            op: Operator::Concat,
            line: lineno,
            start: line_start + prev + lead,
            end: line_start + close,
            original: code[prev + lead..close].to_string(),
            replacement: format!("{z}, {a}"),
        });
    }
}

/// Picks at most `per_op[op]` sites of each operator, evenly spread over
/// that operator's sites in text order, and fills in the replacements that
/// alternate by pick (constants +1 / -1, stuck-at 0 / 1).  Deterministic.
pub fn select(all: &[Site], per_op: &[(Operator, usize)]) -> Vec<Site> {
    let mut picked = Vec::new();
    for &(op, n) in per_op {
        let of: Vec<&Site> = all.iter().filter(|s| s.op == op).collect();
        let n = n.min(of.len());
        for j in 0..n {
            // the middle of the j-th of n equal stretches
            let idx = (2 * j + 1) * of.len() / (2 * n);
            let mut s = of[idx].clone();
            match op {
                Operator::Const => {
                    s.replacement = bump(&s.original, if j % 2 == 0 { 1 } else { -1 })
                }
                Operator::Stuck => s.replacement = if j % 2 == 0 { "0" } else { "~0" }.to_string(),
                _ => {}
            }
            picked.push(s);
        }
    }
    picked.sort_by_key(|s| s.start);
    picked
}

/// The mutants of `text` for the selection `per_op`; `original` of every
/// site is filled in from the text.
pub fn mutants(text: &str, per_op: &[(Operator, usize)]) -> Vec<Mutant> {
    select(&sites(text), per_op)
        .into_iter()
        .enumerate()
        .map(|(id, mut site)| {
            site.original = text[site.start..site.end].to_string();
            Mutant {
                id,
                text: site.apply(text),
                site,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "module m(a, q, y);
    input wire a;
    output reg [3:0] q;
    output reg y;
    localparam k_last = 4'hf;
    // a comment == with & operators
    initial begin
       q = 4'h0;
    end
    always @(*) begin
        y = (q == k_last) & ~a;
        q = {a, q[2:0]} + 4'b1;
        if (rst) begin
            y = 1'b0;
            q = k_last;
        end
        q = {{3{1'b0}}, a, y};
    end
    wire unused_x = a == 1'b0;
endmodule
";

    #[test]
    fn finds_sites_of_every_operator_and_skips_comments() {
        let all = sites(SRC);
        let count = |op| all.iter().filter(|s| s.op == op).count();
        assert_eq!(count(Operator::RelOp), 1, "{all:#?}");
        assert_eq!(count(Operator::Reset), 2);
        assert_eq!(count(Operator::AndOr), 1);
        assert_eq!(count(Operator::DropNot), 1);
        assert_eq!(count(Operator::Arith), 1);
        assert_eq!(count(Operator::Concat), 2);
        // k_last, 4'b1, 1'b0 of the replication
        assert_eq!(count(Operator::Const), 3);
        // y = ..., q = ..., q = {..} (outputs outside the reset block)
        assert_eq!(count(Operator::Stuck), 3);
        assert!(all
            .iter()
            .all(|s| s.line != 6 && s.line != 8 && s.line != 19));
    }

    #[test]
    fn mutants_are_single_edits() {
        let all: Vec<(Operator, usize)> = Operator::ALL.iter().map(|&o| (o, 10)).collect();
        let ms = mutants(SRC, &all);
        assert!(ms.len() >= 10);
        for m in &ms {
            assert_ne!(m.text, SRC, "{}", m.describe());
            let d = SRC.len() as isize - m.text.len() as isize;
            assert_eq!(
                d,
                m.site.original.len() as isize - m.site.replacement.len() as isize
            );
        }
        let show: Vec<String> = ms.iter().map(|m| m.describe()).collect();
        let joined = show.join("\n");
        assert!(joined.contains("`==` -> `!=`"), "{joined}");
        assert!(joined.contains("`4'hf` -> `4'h0`"), "{joined}");
        assert!(joined.contains("`1'b0` -> `1'b1`"), "{joined}");
        assert!(joined.contains("`k_last` -> `~(k_last)`"), "{joined}");
        assert!(joined.contains("`a, y` -> `y, a`"), "{joined}");
        assert!(joined.contains("`~` -> ``"), "{joined}");
        // deterministic
        let again = mutants(SRC, &all);
        assert!(ms.iter().zip(&again).all(|(a, b)| a.text == b.text));
    }

    #[test]
    fn bump_wraps_in_the_width_and_keeps_the_base() {
        assert_eq!(bump("4'hf", 1), "4'h0");
        assert_eq!(bump("5'b10000", -1), "5'b1111");
        assert_eq!(bump("14'd0", -1), "14'd16383");
        assert_eq!(bump("16'h1f3", 1), "16'h1f4");
    }
}
