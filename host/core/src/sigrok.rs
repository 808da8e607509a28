//! A sigrok protocol decoder for one mix's packets: a Python file for
//! libsigrokdecode (`pd.py`, and the `__init__.py` it is loaded by),
//! stacked on sigrok's `uart` decoder.  The packet format's constants come
//! from `link::format` and the channel table, slices and modes from the
//! schedule, written into the file: the decoder needs no slotforge at
//! run time (PulseView and sigrok-cli load it as it is).

use link::format::{CRC_INIT, END, SYNC, WORD_BYTES};
use lut_gen::Schedule;

/// The decoder's files and how sigrok runs it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SigrokDecoder {
    /// Its id (`-P ID`), also its folder's name: `slotforge_` and the
    /// mix's name with every other character than a letter or digit as `_`.
    pub id: String,
    /// `(file name, text)` of each file of the folder.
    pub files: Vec<(&'static str, String)>,
    /// The `uart` decoder's options for the mix's line
    /// (`baudrate=..:parity=..:stop_bits=..`).
    pub uart_options: String,
}

const PD_TEMPLATE: &str = include_str!("sigrok_pd.py");

/// The decoder of `s`'s link; an error in words for a mix whose link is
/// not a UART (or that has none).
pub fn sigrok_decoder(s: &Schedule) -> Result<SigrokDecoder, String> {
    let spec = s
        .mix
        .link
        .ok_or("the mix has no [link]: there is no line to decode")?;
    let plan =
        match lut_gen::plan_link(s) {
            Some(Ok(p)) if p.kind == "uart" => p,
            None => return Err("the mix has no [link]: there is no line to decode".into()),
            Some(Ok(_)) => return Err(
                "link.kind is \"axis\": sigrok decodes a UART line (an AXI4-Stream's beats are \
                 the same bytes: `slotforge decode` reads a dump of them)"
                    .into(),
            ),
            Some(Err(e)) => return Err(format!("the link cannot carry the mix: {}", e.message)),
        };
    let id = decoder_id(&s.mix.name);
    // the line's real baud (the divider's), which sigrok's UART samples by
    let uart = format!(
        "baudrate={}:parity={}:stop_bits={}",
        plan.baud.round() as u64,
        spec.parity.name(),
        spec.stop_bits
    );
    let names: Vec<&str> = s.mix.channels.iter().map(|c| c.name.as_str()).collect();
    let modes: Vec<&str> = match s.modes.len() > 1 {
        true => s
            .mode_plan()
            .map(|m| m.names.iter().map(String::as_str).collect()),
        false => None,
    }
    .unwrap_or_default();
    let pd = PD_TEMPLATE
        .replace("@MIX@", &s.mix.name)
        .replace("@ID@", &id)
        .replace("@UART@", &uart)
        .replace("@CHANNELS@", &py_list(&names))
        .replace("@MODES@", &py_list(&modes))
        .replace("@SLICES@", &s.grid.slices_per_frame.to_string())
        .replace(
            "@MODE_BITS@",
            &s.mode_plan().map_or(0, |m| m.select_bits()).to_string(),
        )
        .replace("@SYNC@", &format!("0x{SYNC:02X}"))
        .replace("@END@", &format!("0x{END:02X}"))
        .replace("@WORD@", &WORD_BYTES.to_string())
        .replace("@CRC_INIT@", &format!("0x{CRC_INIT:04X}"));
    let init = format!(
        "##\n## sigrok protocol decoder `{id}`: the packets of slotforge mix `{}`\n\
         ## on a UART line ({uart}); written by `slotforge sigrok`.\n##\n\n\
         '''\nThe packets of slotforge mix {}: header (frame, slice, mode), one\n\
         record per sample (channel and code), trailer (overflow count, CRC).\n\
         Stack it on the uart decoder set to {uart}.\n'''\n\nfrom .pd import Decoder\n",
        s.mix.name, s.mix.name
    );
    Ok(SigrokDecoder {
        id,
        files: vec![("__init__.py", init), ("pd.py", pd)],
        uart_options: uart,
    })
}

/// `slotforge_` and the mix's name, every character but an ASCII letter
/// or digit as `_` (a Python module's name, which sigrok loads it as).
fn decoder_id(mix: &str) -> String {
    let tail: String = mix
        .chars()
        .map(|c| match c.is_ascii_alphanumeric() {
            true => c.to_ascii_lowercase(),
            false => '_',
        })
        .collect();
    format!("slotforge_{tail}")
}

/// A Python list of string literals.
fn py_list(items: &[&str]) -> String {
    let quoted: Vec<String> = items.iter().map(|s| py_str(s)).collect();
    format!("[{}]", quoted.join(", "))
}

fn py_str(s: &str) -> String {
    let mut out = String::from("'");
    for c in s.chars() {
        match c {
            '\\' | '\'' => {
                out.push('\\');
                out.push(c);
            }
            c if (c as u32) < 0x20 || c == '\u{7f}' => {
                out.push_str(&format!("\\x{:02x}", c as u32))
            }
            c => out.push(c),
        }
    }
    out.push('\'');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_python_module_names() {
        assert_eq!(decoder_id("eskin34-uart"), "slotforge_eskin34_uart");
        assert_eq!(decoder_id("Mix.2 a"), "slotforge_mix_2_a");
    }

    #[test]
    fn names_are_python_string_literals() {
        assert_eq!(py_list(&["a", "it's", "b\\c"]), r"['a', 'it\'s', 'b\\c']");
        assert_eq!(py_str("x\ny"), r"'x\x0ay'");
    }
}
