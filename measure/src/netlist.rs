//! The netlist that goes to the chip: yosys' `synth_<family>` of the emitted
//! gateware (`crate::synthesize_for`, the run whose cells `synth --fpga`
//! counts), written back as gate-level Verilog (`write_verilog -noattr`)
//! and joined with the family's cell models (yosys' `<family>/cells_sim.v`)
//! into one self-contained file, so `sim --netlist` and `prove --netlist`
//! hand it to the same `--rtl` path the outside Verilog takes: the same ADC
//! model, the same judge, the same harness.

use std::path::{Path, PathBuf};

use lut_gen::{Fpga, Schedule};

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

/// The family's cell models with their `` `include``s inlined (ECP5 keeps
/// its flip-flops and IO in `.vh` files, which a newer yosys includes from
/// two places), each file once, as one text.
fn cell_models(path: &Path) -> Result<String, String> {
    let mut out = String::new();
    let mut seen = std::collections::BTreeSet::new();
    inline(path, &mut seen, &mut out)?;
    Ok(out)
}

/// `path`'s text into `out` with its includes inlined, a file already
/// inlined (`seen`) left out.
fn inline(
    path: &Path,
    seen: &mut std::collections::BTreeSet<PathBuf>,
    out: &mut String,
) -> Result<(), String> {
    if !seen.insert(path.to_path_buf()) {
        return Ok(());
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for line in text.lines() {
        let inc = line
            .trim()
            .strip_prefix("`include \"")
            .and_then(|r| r.strip_suffix('"'));
        match inc {
            Some(name) => inline(&dir.join(name), seen, out)?,
            // an elaboration check (SystemVerilog's `$error` as a generate
            // item, in a newer ECP5 model): Icarus cannot read it, and the
            // netlist yosys wrote already has the parameters it allows
            None if line.trim_start().starts_with("$error(") => {
                out.push_str("// ");
                out.push_str(line.trim_start());
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    Ok(())
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

/// Writes the gateware's Verilog of `s` into `dir`, synthesizes it for
/// `fpga` (`crate::synthesize_for`: its files and `yosys.log` in `dir`) and
/// returns the netlist with the cell models, also written as
/// [`NETLIST_SIM_FILE`]. A cell the models leave without behaviour is an
/// error naming it.
pub fn netlist(s: &Schedule, fpga: Fpga, dir: &Path) -> Result<Netlist, String> {
    let e = hdl::emit(s, None).map_err(|e| format!("mix `{}`: {e}", s.mix.name))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let v = dir.join(hdl::VERILOG_FILE);
    std::fs::write(&v, e.verilog()).map_err(|e| format!("{}: {e}", v.display()))?;
    let y = crate::synthesize_for(fpga, dir)?;
    let nl =
        std::fs::read_to_string(&y.netlist).map_err(|e| format!("{}: {e}", y.netlist.display()))?;
    let models = y.cell_models.clone();
    let cells_text = cell_models(&models)?;
    let used: Vec<&str> = y
        .cells
        .iter()
        .filter(|(c, n)| *n > 0 && !c.starts_with('$'))
        .map(|(c, _)| c.as_str())
        .collect();
    let hollow = hollow_cells(&used, &cells_text);
    if !hollow.is_empty() {
        return Err(format!(
            "the {fpga} netlist uses {}, which yosys' cell models ({}) declare as a blackbox, without behaviour: a simulation or proof of the netlist would read nothing from it. Check this mix's netlist on iCE40 (`--netlist ice40`), whose cell models cover every cell",
            hollow.join(", "),
            models.display()
        ));
    }
    // only the models the netlist reaches: the whole library cost every
    // reader of this file most of a minute (`crate::cell_prune`)
    let text = format!(
        "// {} netlist of slotforge_top (yosys synth_{}) and the family's cell models it uses ({})\n{}{nl}\n{}",
        fpga,
        fpga.family().name(),
        models.display(),
        prologue(fpga),
        crate::cell_prune::needed_models(&cells_text, &nl)
    );
    std::fs::write(dir.join(NETLIST_SIM_FILE), &text).map_err(|e| e.to_string())?;
    Ok(Netlist {
        fpga,
        cells: y
            .cells
            .iter()
            .filter(|(c, _)| !c.starts_with('$'))
            .map(|(_, n)| *n as usize)
            .sum(),
        text,
        models,
    })
}

/// The cells of `used` that the models in `models` leave without behaviour:
/// a module with no `always`, `assign`, `initial` or instance of another
/// cell (yosys ships ECP5's DP16KD and Gowin's SPX9 so), or no module.
pub fn hollow_cells(used: &[&str], models: &str) -> Vec<String> {
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
    used.iter()
        .filter(|cell| {
            let head = format!("module {cell}");
            let body = models.split("endmodule").find_map(|m| {
                let at = m.find(&head)?;
                let rest = &m[at + head.len()..];
                rest.starts_with(['(', ' ', '#', '\n']).then_some(rest)
            });
            !body.is_some_and(acts)
        })
        .map(|c| c.to_string())
        .collect()
}
