//! The cell models a netlist needs, out of a family's whole library: the
//! modules the netlist instantiates and the modules those instantiate, in
//! the library's order, with every line outside a module (defines,
//! `` `ifdef``s, the timescale) kept. yosys' iCE40 library holds the
//! UltraPlus SPRAM's model, whose 16K-word memory alone took `read_verilog`
//! most of a minute in every `prove --netlist` of an HX8K netlist that has
//! no SPRAM.

use std::collections::BTreeSet;

/// One stretch of the library: a module (its name, when it has one a
/// plain identifier names) or the lines between modules.
struct Piece<'a> {
    module: Option<&'a str>,
    text: String,
}

/// The modules of `models` that `netlist` needs (transitively), and every
/// line outside a module.
pub fn needed_models(models: &str, netlist: &str) -> String {
    let pieces = pieces(models);
    let names: BTreeSet<&str> = pieces.iter().filter_map(|p| p.module).collect();
    let named =
        |text: &str| -> Vec<&str> { words(text).filter_map(|w| names.get(w).copied()).collect() };
    let mut keep: BTreeSet<&str> = named(netlist).into_iter().collect();
    loop {
        let more: BTreeSet<&str> = (pieces.iter())
            .filter(|p| p.module.is_some_and(|m| keep.contains(m)))
            .flat_map(|p| named(&p.text))
            .filter(|w| !keep.contains(w))
            .collect();
        if more.is_empty() {
            break;
        }
        keep.extend(more);
    }
    let kept = pieces.into_iter().filter(|p| match p.module {
        Some(m) => keep.contains(m),
        None => true,
    });
    kept.map(|p| p.text).collect()
}

/// `models` split at `module` and `endmodule` lines (one line may be both).
/// A module whose name cannot be read is kept as text outside a module
/// (never dropped).
fn pieces(models: &str) -> Vec<Piece<'_>> {
    let mut out = vec![];
    let mut cur = Piece {
        module: None,
        text: String::new(),
    };
    let mut inside = false;
    for line in models.lines() {
        let t = line.trim_start();
        if !inside && t.starts_with("module ") {
            let lead = leading_attributes(&mut cur.text);
            out.push(std::mem::replace(
                &mut cur,
                Piece {
                    module: words(&t["module ".len()..]).next(),
                    text: lead,
                },
            ));
            inside = true;
        }
        cur.text.push_str(line);
        cur.text.push('\n');
        // a model on one line (`module ... endmodule`) ends where it starts
        if inside && (t.starts_with("endmodule") || words(t).last() == Some("endmodule")) {
            out.push(std::mem::replace(
                &mut cur,
                Piece {
                    module: None,
                    text: String::new(),
                },
            ));
            inside = false;
        }
    }
    out.push(cur);
    out
}

/// The lines at the end of `text` that belong to the module after them:
/// its attributes (`(* blackbox *)`, which would dangle at the end of the
/// file without it) and the blank and comment lines around them; cut from
/// `text`.
fn leading_attributes(text: &mut String) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let own = |l: &str| {
        let t = l.trim();
        t.is_empty() || t.starts_with("//") || (t.starts_with("(*") && t.ends_with("*)"))
    };
    let n = lines.iter().rev().take_while(|l| own(l)).count();
    let keep = lines.len() - n;
    let lead: String = lines[keep..].iter().map(|l| format!("{l}\n")).collect();
    *text = lines[..keep].iter().map(|l| format!("{l}\n")).collect();
    lead
}

/// The identifiers of `text`, in order.
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '$'))
        .filter(|w| !w.is_empty())
}
