//! The FuseSoC core description (CAPI2 `slotforge_top.core`) of the emitted
//! files, so the gateware drops into any flow FuseSoC and Edalize drive.
//!
//! It is written from the list of files [`crate::emit`] makes, so a
//! constraint file another part of the emitter adds (an LPF for ECP5, a CST
//! for Gowin) joins its family's target by its extension without a change
//! here. Deterministic: no dates, no paths, only the mix and the version.

use std::fmt::Write as _;

use lut_gen::{Fpga, Schedule, TOP_MODULE};

/// The emitted core description's file name.
pub const CORE_FILE: &str = "slotforge_top.core";

/// The launcher written beside the core: FuseSoC's `EDALIZE_LAUNCHER` that
/// runs each tool a flow calls, or its YoWASP build when only that is
/// installed (and Edalize's `nextpnr-gowin` as nextpnr-himbaechel).
pub const LAUNCHER_FILE: &str = "edalize-launcher.sh";

/// The launcher's text.
pub const LAUNCHER: &str = include_str!("edalize-launcher.sh");

/// A constraint file's kind, by its extension: CAPI2's `file_type` and the
/// family whose flow reads it (`None`: every flow may, e.g. timing).
pub fn constraint_kind(name: &str) -> Option<(&'static str, Option<Fpga>)> {
    let ext = name.rsplit_once('.')?.1;
    match ext {
        "pcf" => Some(("PCF", Some(Fpga::Ice40Hx8k))),
        "lpf" => Some(("LPF", Some(Fpga::Ecp5_25k))),
        "cst" => Some(("CST", Some(Fpga::Gw1n9))),
        "sdc" => Some(("SDC", None)),
        "xdc" => Some(("xdc", None)),
        _ => None,
    }
}

/// The Edalize tool (the flow of the open tools) for a part, and its
/// options: the part as the rest of slotforge names it (`Fpga::nextpnr`).
fn flow(f: Fpga, clock_hz: u64) -> (&'static str, Vec<(&'static str, String)>) {
    // nextpnr checks timing at the mix's clock (its default is 12 MHz)
    let part = format!("[{}, --freq, {}]", f.nextpnr().1.join(", "), mhz(clock_hz));
    match f {
        Fpga::Ice40Hx8k => (
            "icestorm",
            vec![("pnr", "next".into()), ("nextpnr_options", part)],
        ),
        Fpga::Ecp5_25k => ("trellis", vec![("nextpnr_options", part)]),
        // Edalize's apicula flow names the device itself
        Fpga::Gw1n9 => (
            "apicula",
            vec![
                ("device", "GW1NR-LV9QN88PC6/I5".into()),
                ("nextpnr_options", format!("[--freq, {}]", mhz(clock_hz))),
            ],
        ),
    }
}

/// A clock in MHz as nextpnr's `--freq` takes it: `48`, `12.288`.
fn mhz(hz: u64) -> String {
    let t = format!("{:.6}", hz as f64 / 1e6);
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A VLNV part: FuseSoC allows letters, digits, `_`, `.` and `-`; anything
/// else in a mix's name becomes `_` (an empty name, `mix`).
pub fn vlnv_part(name: &str) -> String {
    let t: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if t.is_empty() {
        "mix".into()
    } else {
        t
    }
}

/// The core's VLNV: `slotforge:<mix>:slotforge_top:<version>`.
pub fn vlnv(s: &Schedule) -> String {
    format!(
        "slotforge:{}:{TOP_MODULE}:{}",
        vlnv_part(&s.mix.name),
        env!("CARGO_PKG_VERSION")
    )
}

/// A fileset of `files` (none: nothing written), one `file_type`.
fn fileset(t: &mut String, name: &str, files: &[&str], file_type: &str, copy: bool) {
    if files.is_empty() {
        return;
    }
    let _ = writeln!(t, "  {name}:\n    files:");
    for f in files {
        if copy {
            // read by the tool from its work directory, beside the Verilog
            let _ = writeln!(t, "      - {f}: {{copyto: {f}}}");
        } else {
            let _ = writeln!(t, "      - {f}");
        }
    }
    let _ = writeln!(t, "    file_type: {file_type}");
}

/// The CAPI2 text for a schedule whose emitted files are `names`; `pinned`:
/// the constraint file is a board's (else the PCF is a template with no
/// pin, which no flow may read).
pub fn core_file(s: &Schedule, names: &[&str], pinned: bool) -> String {
    let mut names = names.to_vec();
    names.sort_unstable();
    let mut t = String::from("CAPI=2:\n");
    let _ = writeln!(
        t,
        "# FuseSoC core of slotforge's gateware, generated with the files beside it; do not edit."
    );
    let _ = writeln!(
        t,
        "# ecp5 and gowin with only the YoWASP tools (or nextpnr-himbaechel): set\n# EDALIZE_LAUNCHER=\"sh $PWD/{LAUNCHER_FILE}\" (the file beside this one)"
    );
    let _ = writeln!(t, "name: {}", vlnv(s));
    let desc = format!("slotforge acquisition gateware for mix {}", s.mix.name);
    // a JSON string is a YAML double-quoted scalar: any mix name is safe
    let _ = writeln!(
        t,
        "description: {}\n",
        serde_json::to_string(&desc).expect("a string serializes")
    );
    let ends = |x: &'static str| move |n: &&str| n.ends_with(x);
    let verilog: Vec<&str> = names.iter().copied().filter(ends(".v")).collect();
    let roms: Vec<&str> = names.iter().copied().filter(ends(".hex")).collect();
    let _ = writeln!(t, "filesets:");
    fileset(&mut t, "rtl", &verilog, "verilogSource", false);
    fileset(&mut t, "rom", &roms, "user", true);
    let mut sets: Vec<(String, Option<Fpga>)> = vec![];
    for n in &names {
        if let Some((ty, fpga)) = constraint_kind(n).filter(|(_, f)| pinned || f.is_none()) {
            let set = format!("constraints_{}", ty.to_ascii_lowercase());
            fileset(&mut t, &set, &[n], ty, false);
            sets.push((set, fpga));
        }
    }
    let _ = writeln!(t, "\ntargets:");
    // the vendors' flows (Vivado, Quartus, Libero) read the SDC or XDC: the
    // default target carries them for a target of the user's own
    let timing: Vec<&str> = sets
        .iter()
        .filter(|(_, p)| p.is_none())
        .map(|(n, _)| n.as_str())
        .collect();
    let mut default = vec!["rtl", "rom"];
    default.extend(timing);
    let _ = writeln!(
        t,
        "  default:\n    filesets: [{}]\n    toplevel: {TOP_MODULE}",
        default.join(", ")
    );
    let _ = writeln!(
        t,
        "  # the Verilog under Verilator's lint at -Wall (the one waiver is inline)\n  lint:\n    default_tool: verilator\n    filesets: [rtl, rom]\n    toplevel: {TOP_MODULE}\n    tools:\n      verilator:\n        mode: lint-only\n        verilator_options: [-Wall]"
    );
    for f in Fpga::ALL {
        targets(&mut t, f, &sets, s.grid.clock_hz);
    }
    t
}

/// The synthesis target of one part, with its family's constraint files.
/// A part with none gets a target only where its place and route takes
/// ports without pins (iCE40, told so); `verilog --board` writes the file.
fn targets(t: &mut String, f: Fpga, sets: &[(String, Option<Fpga>)], clock_hz: u64) {
    let (tool, mut options) = flow(f, clock_hz);
    let mut filesets = vec!["rtl".to_string(), "rom".to_string()];
    filesets.extend(
        sets.iter()
            .filter(|(_, p)| *p == Some(f))
            .map(|(n, _)| n.clone()),
    );
    if filesets.len() == 2 {
        match f {
            Fpga::Ice40Hx8k => {
                let o = &mut options
                    .iter_mut()
                    .find(|(k, _)| *k == "nextpnr_options")
                    .expect("ice40 options")
                    .1;
                *o = format!("{}, --pcf-allow-unconstrained]", o.trim_end_matches(']'));
            }
            _ => {
                let _ = writeln!(
                    t,
                    "  # {f}: no target: its place and route needs the pins (`verilog --board`)"
                );
                return;
            }
        }
    }
    let _ = writeln!(
        t,
        "  # {f}: yosys + nextpnr through Edalize's {tool} flow\n  {}:\n    default_tool: {tool}\n    filesets: [{}]\n    toplevel: {TOP_MODULE}\n    tools:\n      {tool}:",
        f.family(),
        filesets.join(", ")
    );
    for (k, v) in options {
        let _ = writeln!(t, "        {k}: {v}");
    }
}
