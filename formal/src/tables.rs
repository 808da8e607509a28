//! A memory's table of initial words, as slotforge emits its ROMs and
//! channel tables (`reg [W:0] m [0:N];`, then `initial begin`, `m[0] =
//! (W+1)'hX;` for every word in order, `end`), handed to yosys as a
//! `$readmemh` file instead.
//!
//! Why: yosys makes one `$meminit` cell per assignment and carries each
//! through `proc`, `flatten` and every `opt` until `memory_collect` merges
//! them; a `$readmemh` file of consecutive words is one cell. eskin34's
//! 3,584 table words took 2.7 s of yosys's 6.1 s. yosys makes the same
//! memories of either (a test compares them word for word); eskin34's AIG
//! came out byte for byte the same, others differ in the latches' order
//! (yosys numbers its cells as it makes them). Anything not in exactly that
//! form (a gap, a word out of order, a value wider than the word, an `x`)
//! is left as it is.

/// The text with each table replaced by `initial $readmemh("FILE", m);`
/// and as many empty lines as it had, and each file's name and contents.
pub(crate) fn to_hex_files(text: &str) -> (String, Vec<(String, String)>) {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let mut out = String::with_capacity(text.len());
    let mut files = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if let Some((words, used)) = table_at(&lines[i..]) {
            let name = format!("slotforge_table_{}.hex", files.len());
            let (reg, init) = (lines[i], lines[i + 1]);
            let indent = &init[..init.len() - init.trim_start().len()];
            let mem = memory_name(reg).expect("table_at read it");
            out.push_str(reg);
            out.push_str(&format!("{indent}initial $readmemh(\"{name}\", {mem});\n"));
            // every later line where it was: yosys's messages name the
            // lines of the Verilog as given
            out.push_str(&"\n".repeat(used - 2));
            files.push((name, words));
            i += used;
        } else {
            out.push_str(lines[i]);
            i += 1;
        }
    }
    (out, files)
}

/// `reg [W:0] NAME [0:N];`: (W + 1, NAME, N + 1).
fn declaration(line: &str) -> Option<(u32, &str, usize)> {
    let rest = line.trim().strip_prefix("reg [")?;
    let (msb, rest) = rest.split_once(":0] ")?;
    let (name, rest) = rest.split_once(" [0:")?;
    let last = rest.strip_suffix("];")?;
    let ident = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ident(name) {
        return None;
    }
    let width = msb.parse::<u32>().ok()?.checked_add(1)?;
    Some((width, name, last.parse::<usize>().ok()?.checked_add(1)?))
}

fn memory_name(line: &str) -> Option<&str> {
    declaration(line).map(|(_, name, _)| name)
}

/// A table starting at `lines[0]`: its words (one hex value a line) and
/// the lines it spans.
fn table_at(lines: &[&str]) -> Option<(String, usize)> {
    let (width, name, n) = declaration(lines.first()?)?;
    if lines.get(1)?.trim() != "initial begin" || lines.len() < n + 3 || !(1..=32).contains(&width)
    {
        return None;
    }
    let mut words = String::with_capacity(n * 4);
    for (a, line) in lines[2..2 + n].iter().enumerate() {
        let value = line
            .trim()
            .strip_prefix(&format!("{name}[{a}] = {width}'h"))?
            .strip_suffix(';')?;
        let v = u64::from_str_radix(value, 16).ok()?;
        if value.is_empty() || value.len() > 16 || v >> width != 0 {
            return None;
        }
        words.push_str(value);
        words.push('\n');
    }
    (lines[2 + n].trim() == "end").then_some((words, n + 3))
}

#[cfg(test)]
mod tests {
    use super::to_hex_files;

    const ROM: &str = "module m(input clock, input [1:0] a, output reg [6:0] q);\n\
        \x20   reg [6:0] mem [0:3];\n\
        \x20   initial begin\n\
        \x20     mem[0] = 7'h00;\n\
        \x20     mem[1] = 7'h7f;\n\
        \x20     mem[2] = 7'h2A;\n\
        \x20     mem[3] = 7'h01;\n\
        \x20   end\n\
        \x20   always @(posedge clock) q <= mem[a];\n\
        endmodule\n";

    #[test]
    fn a_table_of_every_word_in_order_becomes_a_readmemh_file() {
        let (text, files) = to_hex_files(ROM);
        assert_eq!(
            files,
            vec![(
                "slotforge_table_0.hex".to_string(),
                "00\n7f\n2A\n01\n".to_string()
            )]
        );
        assert!(text.contains(
            "    reg [6:0] mem [0:3];\n    initial $readmemh(\"slotforge_table_0.hex\", mem);\n\n\n\n\n\n    always"
        ));
        assert!(!text.contains("mem[1]"));
        assert_eq!(
            text.lines().count(),
            ROM.lines().count(),
            "lines where they were"
        );
    }

    #[test]
    fn a_table_not_in_that_form_is_left_as_it_is() {
        for (from, to) in [
            ("mem[2] = 7'h2A;", "mem[3] = 7'h2A;"), // out of order
            ("7'h7f", "7'hff"),                     // wider than the word
            ("7'h2A", "7'h2x"),                     // an unknown bit
            ("mem[3] = 7'h01;\n", ""),              // a word missing
            ("7'h01", "6'h01"),                     // another width
            ("initial begin", "initial  begin // x"),
        ] {
            let edited = ROM.replacen(from, to, 1);
            assert_ne!(edited, ROM);
            let (text, files) = to_hex_files(&edited);
            assert_eq!(
                (text.as_str(), files.len()),
                (edited.as_str(), 0),
                "{from} -> {to}"
            );
        }
    }
}
