//! Readable names for rust-hdl's Verilog: a deterministic post-pass over
//! its text.
//!
//! rust-hdl names a child by its path with `$` between the parts: modules
//! `top$branches$0$act`, instances `branches$0`, the wires to a child
//! `branches$0$clock`, array ports `ch$0`.  `$` is legal in a Verilog
//! identifier but reads as a system task, and no engineer searches for it.
//! Here every such name becomes plain: the parts joined by `_`, a `Vec` child
//! `branches$b` read as `branch<b>`, `seqs$i` as `spi_seq<i>`, `merge` (the
//! module) as `merger`, and a module under `slotforge_core` is named
//! `slotforge_<path>`.  rust-hdl also emits one module per flip-flop (a
//! `DFF` child is a module of its own, named after its path); the modules of
//! equal text (every `W`-bit register) become one, `slotforge_dff<W>`.
//!
//! A new name never equals a name the text already has or another new one:
//! on a clash the separator becomes `__`, then a number is appended.

use std::collections::{BTreeMap, BTreeSet};

/// The prefix rust-hdl's core modules get (emit renames `top` to it).
const CORE_PREFIX: &str = "slotforge_core$";

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// Every identifier of `text` as `(start, end)`: a run of identifier
/// characters that starts with a letter or `_` (so `$display` and the
/// digits of `10'h3f` are not one).
fn idents(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        if !is_ident(b[i]) {
            i += 1;
            continue;
        }
        let start = i;
        while i < b.len() && is_ident(b[i]) {
            i += 1;
        }
        if b[start].is_ascii_alphabetic() || b[start] == b'_' {
            out.push((start, i));
        }
    }
    out
}

/// The readable parts of a `$` path: `branches`, `b` -> `branch<b>`;
/// `seqs`, `i` -> `spi_seq<i>`.
fn parts(path: &str) -> Vec<String> {
    let raw: Vec<&str> = path.split('$').collect();
    let mut out = vec![];
    let mut k = 0;
    while k < raw.len() {
        let index = raw
            .get(k + 1)
            .filter(|x| x.bytes().all(|c| c.is_ascii_digit()));
        match (raw[k], index) {
            ("branches", Some(b)) => {
                out.push(format!("branch{b}"));
                k += 2;
            }
            ("seqs", Some(i)) => {
                out.push(format!("spi_seq{i}"));
                k += 2;
            }
            ("cmds", Some(i)) => {
                out.push(format!("cmd{i}"));
                k += 2;
            }
            ("pulses", Some(i)) => {
                out.push(format!("cnv_pulse{i}"));
                k += 2;
            }
            ("holds", Some(i)) => {
                out.push(format!("hold_off{i}"));
                k += 2;
            }
            // the core's `adc_mosi` is a `Vec` of one signal (none in a mix
            // without a command word): the port reads as the contract's
            ("adc_mosi", Some(_)) if raw.len() == 2 => {
                out.push("adc_mosi".into());
                k += 2;
            }
            (p, _) => {
                out.push(p.to_string());
                k += 1;
            }
        }
    }
    out
}

/// The readable name of a `$` identifier, its parts joined by `sep`.
pub fn candidate(old: &str, is_module: bool, sep: &str) -> String {
    match old.strip_prefix(CORE_PREFIX).filter(|_| is_module) {
        Some(path) => {
            let mut p = parts(path);
            if p == ["merge"] {
                p[0] = "merger".into();
            }
            format!("slotforge{sep}{}", p.join(sep))
        }
        None => parts(old).join(sep),
    }
}

/// A name not in `taken`, from `want(sep)`: `_`, then `__`, then numbered.
fn fresh(taken: &BTreeSet<String>, want: impl Fn(&str) -> String) -> String {
    for sep in ["_", "__"] {
        let n = want(sep);
        if !taken.contains(&n) {
            return n;
        }
    }
    let base = want("__");
    (2..)
        .map(|k| format!("{base}_{k}"))
        .find(|n| !taken.contains(n))
        .expect("some number is free")
}

/// Replace every identifier of `text` that `map` has.
fn replace(text: &str, map: &BTreeMap<String, String>) -> String {
    let mut out = String::with_capacity(text.len());
    let mut last = 0;
    for (s, e) in idents(text) {
        if let Some(new) = map.get(&text[s..e]) {
            out.push_str(&text[last..s]);
            out.push_str(new);
            last = e;
        }
    }
    out.push_str(&text[last..]);
    out
}

/// The names of the modules `text` declares, in order.
fn module_names(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("module "))
        .map(|rest| {
            rest.split(|c: char| !c.is_ascii() || !is_ident(c as u8))
                .next()
                .unwrap_or("")
                .to_string()
        })
        .collect()
}

/// `text` with every `$` identifier renamed (see the module doc).
pub fn rename(text: &str) -> String {
    let modules: BTreeSet<String> = module_names(text).into_iter().collect();
    let mut taken: BTreeSet<String> = idents(text)
        .into_iter()
        .map(|(s, e)| &text[s..e])
        .filter(|n| !n.contains('$'))
        .map(str::to_string)
        .collect();
    let mut map = BTreeMap::new();
    for (s, e) in idents(text) {
        let old = &text[s..e];
        if !old.contains('$') || map.contains_key(old) {
            continue;
        }
        let m = modules.contains(old);
        let new = fresh(&taken, |sep| candidate(old, m, sep));
        taken.insert(new.clone());
        map.insert(old.to_string(), new);
    }
    replace(text, &map)
}

/// One module's text (from `module` to its `endmodule` line) and its name.
struct Chunk<'a> {
    name: String,
    text: &'a str,
}

/// `text` cut into module chunks and the text between them.
fn chunks(text: &str) -> Vec<Result<Chunk<'_>, &str>> {
    let mut out = vec![];
    let mut rest = text;
    while let Some(at) = find_line(rest, "module ") {
        out.push(Err(&rest[..at]));
        let name = module_names(&rest[at..]).remove(0);
        let end_line = format!("endmodule // {name}\n");
        let end = match rest[at..].find(&end_line) {
            Some(k) => at + k + end_line.len(),
            // a module ended by a bare `endmodule` (the wrapper): leave it be
            None => {
                let k = rest[at..]
                    .find("endmodule\n")
                    .map_or(rest.len() - at, |k| k + 10);
                at + k
            }
        };
        out.push(Ok(Chunk {
            name,
            text: &rest[at..end],
        }));
        rest = &rest[end..];
    }
    out.push(Err(rest));
    out
}

/// Where the first line of `text` that starts with `prefix` begins.
fn find_line(text: &str, prefix: &str) -> Option<usize> {
    let mut at = 0;
    for l in text.split_inclusive('\n') {
        if l.starts_with(prefix) {
            return Some(at);
        }
        at += l.len();
    }
    None
}

/// A flip-flop module's width (rust-hdl's `DFF`: ports `d`, `q`, `clock`).
fn dff_width(c: &Chunk) -> Option<u32> {
    if !c
        .text
        .starts_with(&format!("module {}(d,q,clock);", c.name))
    {
        return None;
    }
    let decl = c
        .text
        .lines()
        .find(|l| l.trim_start().starts_with("output reg"))?;
    match decl.split('[').nth(1) {
        None => Some(1),
        Some(r) => r
            .split(':')
            .next()?
            .trim()
            .parse::<u32>()
            .ok()
            .map(|h| h + 1),
    }
}

/// The flip-flop modules of equal text merged into one, `slotforge_dff<W>`.
fn merge_dffs(text: &str) -> String {
    let cs = chunks(text);
    let mut taken: BTreeSet<String> = idents(text)
        .into_iter()
        .map(|(s, e)| text[s..e].to_string())
        .collect();
    // body with the module's own name blanked -> the shared name
    let mut shared: BTreeMap<String, String> = BTreeMap::new();
    let mut map: BTreeMap<String, String> = BTreeMap::new();
    let mut keep = vec![];
    // each chunk's text as written (a register's with its parameter)
    let mut texts: Vec<String> = vec![];
    let mut inits: Vec<(String, String)> = vec![];
    for c in cs.iter() {
        let Ok(c) = c else {
            keep.push(true);
            texts.push(String::new());
            continue;
        };
        let Some(w) = dff_width(c) else {
            keep.push(true);
            texts.push(c.text.to_string());
            continue;
        };
        // the initial value (the register's reset value) is the shared
        // module's parameter `INIT`, set by each instance
        let (text, init) = with_init_parameter(c.text, w);
        let body = text.replace(&c.name, "");
        let first = !shared.contains_key(&body);
        let name = shared
            .entry(body)
            .or_insert_with(|| {
                let n = fresh(&taken, |sep| format!("slotforge{sep}dff{w}"));
                taken.insert(n.clone());
                n
            })
            .clone();
        map.insert(c.name.clone(), name);
        keep.push(first);
        texts.push(text);
        if let Some(lit) = init {
            inits.push((c.name.clone(), lit));
        }
    }
    let mut out = String::with_capacity(text.len());
    for ((c, k), text) in cs.iter().zip(keep).zip(&texts) {
        match (c, k) {
            (Err(t), _) => out.push_str(t),
            (Ok(_), true) => out.push_str(text),
            // the separating blank line of a dropped module goes with it
            (Ok(_), false) => {
                if out.ends_with("\n\n") {
                    out.pop();
                }
            }
        }
    }
    replace(&set_inits(&out, &inits), &map)
}

/// A flip-flop module's text with its initial value as a parameter `INIT`
/// (default 0), and that value when it is not 0.
fn with_init_parameter(text: &str, width: u32) -> (String, Option<String>) {
    let Some(at) = text.find("q = ") else {
        return (text.to_string(), None);
    };
    let Some(end) = text[at..].find(';').map(|e| at + e) else {
        return (text.to_string(), None);
    };
    let lit = text[at + 4..end].to_string();
    let mut t = format!("{}q = INIT{}", &text[..at], &text[end..]);
    let Some(decl) = t.find("    // Module arguments") else {
        return (text.to_string(), None);
    };
    let param = format!(
        "    // the initial value: the register's reset value (set per instance)\n    parameter [{}:0] INIT = {width}'h0;\n\n",
        width - 1
    );
    t.insert_str(decl, &param);
    let zero = lit.ends_with("'h0");
    (t, (!zero).then_some(lit))
}

/// Every instance of the flip-flop modules `inits` names given its initial
/// value (`name #(.INIT(1'h1)) inst(`).
fn set_inits(text: &str, inits: &[(String, String)]) -> String {
    if inits.is_empty() {
        return text.to_string();
    }
    let by_name: BTreeMap<&str, &str> = inits
        .iter()
        .map(|(n, l)| (n.as_str(), l.as_str()))
        .collect();
    let mut out = String::with_capacity(text.len() + 64 * inits.len());
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        let indent = &line[..line.len() - t.len()];
        let module = t.split(' ').next().unwrap_or("");
        match by_name.get(module) {
            Some(lit) if !indent.is_empty() && t.trim_end().ends_with('(') => {
                let rest = &t[module.len()..];
                out.push_str(&format!("{indent}{module} #(.INIT({lit})){rest}"));
            }
            _ => out.push_str(line),
        }
    }
    out
}

/// rust-hdl's text with readable names: no `$` in any identifier, one
/// module per register width.
pub fn readable(text: &str) -> String {
    merge_dffs(&rename(text))
}
