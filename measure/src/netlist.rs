//! The netlist that goes to the chip: yosys' `synth_<family>` of the emitted
//! gateware, written back as gate-level Verilog (`write_verilog -noattr`)
//! and joined with the family's cell models (yosys' `<family>/cells_sim.v`)
//! into one self-contained file, so `sim --netlist` and `prove --netlist`
//! hand it to the same `--rtl` path the outside Verilog takes: the same ADC
//! model, the same judge, the same harness.

use std::path::{Path, PathBuf};

use judge::tools::Tool;
use lut_gen::{Fpga, Schedule};

/// The gate-level netlist (alone) as yosys writes it, in the work folder.
pub const NETLIST_FILE: &str = "netlist.v";
/// The netlist with the cell models, the file the simulators read.
pub const NETLIST_SIM_FILE: &str = "netlist_sim.v";

/// A family's netlist of one schedule's gateware.
#[derive(Debug, Clone)]
pub struct Netlist {
    pub fpga: Fpga,
    /// The netlist followed by the cell models (includes inlined).
    pub text: String,
    /// Cell instances in the netlist (the family's primitives).
    pub cells: usize,
    /// Where the cell models were read from.
    pub models: PathBuf,
}

impl Netlist {
    /// What a proof or a simulation of this netlist says nothing of, one
    /// plain sentence each (`prove --netlist`'s `not_covered`).
    pub fn not_covered(&self) -> Vec<String> {
        vec![
            format!(
                "the {} silicon itself: its cells are yosys' simulation models ({}), taken as the chip's behaviour",
                self.fpga,
                self.models.display()
            ),
            format!(
                "what place and route does after yosys (nextpnr's packing and routing for the {}) and any timing: setup, hold and clock-to-out are `synth --fpga`'s Fmax, not this check's",
                self.fpga
            ),
        ]
    }
}

/// Where yosys keeps its share folder (`<family>/cells_sim.v`): beside the
/// `yosys` found on PATH (`bin/../share/yosys`), else the Debian place.
fn share_dir() -> Result<PathBuf, String> {
    let mut places = vec![];
    if let Some(path) = std::env::var_os("PATH") {
        for d in std::env::split_paths(&path) {
            if d.join("yosys").is_file() {
                if let Some(prefix) = d.parent() {
                    places.push(prefix.join("share").join("yosys"));
                }
            }
        }
    }
    places.push(PathBuf::from("/usr/share/yosys"));
    places
        .iter()
        .find(|p| p.join("ice40").join("cells_sim.v").is_file())
        .cloned()
        .ok_or_else(|| {
            format!(
                "yosys' cell models (<share>/ice40/cells_sim.v) were not found in {}: install yosys (`make tools`)",
                places
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
}

/// The family's cell models with their `` `include``s inlined (ECP5 keeps
/// its flip-flops and IO in `.vh` files), as one text.
fn cell_models(fpga: Fpga) -> Result<(PathBuf, String), String> {
    let dir = share_dir()?.join(fpga.family().name());
    let path = dir.join("cells_sim.v");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = String::with_capacity(text.len() * 2);
    for line in text.lines() {
        let inc = line
            .trim()
            .strip_prefix("`include \"")
            .and_then(|r| r.strip_suffix('"'));
        match inc {
            Some(name) => {
                let p = dir.join(name);
                let t = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
                out.push_str(&t);
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    Ok((path, out))
}

/// What a family's models need to be read as Verilog-2005 by Icarus as
/// well as by Verilator: the iCE40 models give some ports default values
/// (`input CE = 1'b1`, SystemVerilog) unless told not to; the netlist
/// connects every port of every cell yosys makes, so nothing relies on them.
fn prologue(fpga: Fpga) -> &'static str {
    match fpga.family() {
        lut_gen::Family::Ice40 => "`define NO_ICE40_DEFAULT_ASSIGNMENTS\n",
        lut_gen::Family::Ecp5 | lut_gen::Family::Gowin => "",
    }
}

/// Writes the gateware's Verilog of `s` into `dir`, synthesizes it for `fpga` with
/// yosys (log `netlist.log`) and returns the netlist with the cell models;
/// `dir` also gets [`NETLIST_FILE`] and [`NETLIST_SIM_FILE`].
pub fn netlist(s: &Schedule, fpga: Fpga, dir: &Path) -> Result<Netlist, String> {
    let e = hdl::emit(s, None).map_err(|e| format!("mix `{}`: {e}", s.mix.name))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let v = dir.join(hdl::VERILOG_FILE);
    std::fs::write(&v, e.verilog()).map_err(|e| format!("{}: {e}", v.display()))?;
    let y = Tool::new("yosys")
        .current_dir(dir)
        .args(["-q", "-l", "netlist.log", "-p"])
        .arg(format!(
            "read_verilog {}; synth_{} -top {}; write_verilog -noattr {NETLIST_FILE}",
            hdl::VERILOG_FILE,
            fpga.family().name(),
            lut_gen::TOP_MODULE,
        ))
        .run()
        .map_err(|e| format!("yosys could not be started: {e}"))?;
    if !y.success {
        return Err(format!(
            "yosys synth_{} failed (see {}):\n{}",
            fpga.family().name(),
            dir.join("netlist.log").display(),
            y.stderr
        ));
    }
    let nl_path = dir.join(NETLIST_FILE);
    let nl =
        std::fs::read_to_string(&nl_path).map_err(|e| format!("{}: {e}", nl_path.display()))?;
    let (models, cells_text) = cell_models(fpga)?;
    let hollow = hollow_cells(&nl, &cells_text);
    if !hollow.is_empty() {
        return Err(format!(
            "the {fpga} netlist uses {}, which yosys' cell models ({}) declare as a blackbox, without behaviour: a simulation or proof of the netlist would read nothing from it. On this family a mix whose slot ROM stays in logic can be checked; the iCE40's models cover every cell",
            hollow.join(", "),
            models.display()
        ));
    }
    let text = format!(
        "// {} netlist of slotforge_top (yosys synth_{}) and the family's cell models ({})\n{}{nl}\n{cells_text}",
        fpga,
        fpga.family().name(),
        models.display(),
        prologue(fpga)
    );
    std::fs::write(dir.join(NETLIST_SIM_FILE), &text).map_err(|e| e.to_string())?;
    Ok(Netlist {
        fpga,
        cells: count_cells(&nl),
        text,
        models,
    })
}

/// Cell instances in a `write_verilog -noattr` netlist: its lines that
/// open an instance (`  SB_LUT4 #(`, `  SB_DFF \q_reg  (`): a module name
/// (the families' primitives are upper case, Verilog's keywords lower case)
/// at the body's indent.
fn count_cells(nl: &str) -> usize {
    nl.lines().filter(|l| is_instance(l)).count()
}

/// Whether a netlist line opens a cell instance ([`count_cells`]).
fn is_instance(l: &str) -> bool {
    let t = l.trim_start();
    l.len() - t.len() == 2
        && t.chars().next().is_some_and(|c| c.is_ascii_uppercase())
        && t.trim_end().ends_with('(')
}

/// The cell types `nl` instantiates (`  SB_LUT4 #(`, `  DP16KD \\x  (`).
fn cell_types(nl: &str) -> std::collections::BTreeSet<&str> {
    nl.lines()
        .filter(|l| is_instance(l))
        .filter_map(|l| l.split_whitespace().next())
        .collect()
}

/// The cells of `nl` that the models in `models` leave without behaviour:
/// a module with no `always`, `assign`, `initial` or instance of another
/// cell (yosys ships ECP5's DP16KD and Gowin's SPX9 so), or no module.
fn hollow_cells(nl: &str, models: &str) -> Vec<String> {
    let acts = |body: &str| {
        ["always", "assign", "initial", "generate"]
            .iter()
            .any(|k| body.contains(k))
            || body.lines().any(|l| {
                let t = l.trim_start();
                let word: String = t
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                word.starts_with(|c: char| c.is_ascii_uppercase()) && t.contains('(')
            })
    };
    cell_types(nl)
        .into_iter()
        .filter(|cell| {
            let head = format!("module {cell}");
            let body = models.split("endmodule").find_map(|m| {
                let at = m.find(&head)?;
                let rest = &m[at + head.len()..];
                rest.starts_with(['(', ' ', '#', '\n']).then_some(rest)
            });
            !body.is_some_and(acts)
        })
        .map(str::to_string)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_instances_not_declarations() {
        let nl = "module m(a);\n  input a;\n  wire [3:0] b;\n  SB_LUT4 #(\n    .LUT_INIT(16'h1)\n  ) _1_ (\n  );\n  SB_DFF \\q_reg  (\n  );\n  assign b = 0;\nendmodule\n";
        assert_eq!(count_cells(nl), 2);
    }

    #[test]
    fn cells_without_behaviour_are_found() {
        let nl = "  SB_LUT4 #(\n  ) _1_ (\n  );\n  DP16KD \\r  (\n  );\n  WRAP _2_ (\n  );\n  GONE _3_ (\n  );\n";
        let models = "module SB_LUT4 (output O, input I0);\n  assign O = I0;\nendmodule\n\
                      module DP16KD(\n  input A, output B\n);\n  parameter X = 1;\nendmodule\n\
                      module WRAP (input A, output B);\n  SB_LUT4 l (.O(B), .I0(A));\nendmodule\n";
        assert_eq!(hollow_cells(nl, models), ["DP16KD", "GONE"]);
    }
}
