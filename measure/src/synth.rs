//! The yosys + nextpnr flow of each part ([`Fpga`]): `synth`, `build`'s
//! synthesis step and `hdl/synth.sh` (through `examples/synth.rs`) all run
//! [`place_and_route_for`], so the figures in the report and in
//! `docs/performance.md` come from the same commands.

use std::path::Path;

use judge::tools::Tool;
use lut_gen::{Family, Fpga};

use crate::yosys::{find_program, synthesize_for, Synthesized, SYNTH_JSON};

/// What synthesis and place and route reported for one part.
#[derive(Debug, Clone, PartialEq)]
pub struct Synth {
    pub fpga: Fpga,
    /// Logic cells placed: nextpnr's `ICESTORM_LC` (iCE40), `TRELLIS_COMB`
    /// (ECP5; half a slice), `LUT4` (Gowin: the LUTs placed, the router's
    /// pass-through ones included), all from nextpnr's `--report`.
    pub lcs: u64,
    /// LUTs (`SB_LUT4`, `LUT4`, Gowin's `LUT1`-`LUT4`) and flip-flops
    /// (`SB_DFF*`, `TRELLIS_FF`, Gowin's `DFF*`) from yosys' `stat`.
    pub lut4: u64,
    pub dff: u64,
    /// Block RAMs placed (`ICESTORM_RAM`, `DP16KD`, Gowin's `BSRAM`).
    /// `fmax_mhz`: the report's achieved Fmax of `clk`.
    pub brams: u64,
    pub fmax_mhz: f64,
    /// nextpnr's utilization (its report), the cells used: the family's own
    /// names, `(cell, used, available)`.
    pub cells: Vec<(String, u64, u64)>,
}

/// yosys `synth_ice40` then nextpnr-ice40 (placement seed `seed`) on
/// `dir/slotforge_top.v`, work files and logs (`yosys.log`, `stat.txt`,
/// `nextpnr.log`) in `dir`.  With `pcf` the pins are placed as the board
/// file says; without, IO is left unconstrained (the estimate does not
/// depend on a board).
pub fn place_and_route(
    dir: &Path,
    pcf: Option<&Path>,
    clock_hz: u64,
    seed: u64,
) -> Result<Synth, String> {
    place_and_route_for(Fpga::Ice40Hx8k, dir, pcf, clock_hz, seed)
}

/// [`place_and_route`] for any part: its yosys (`crate::synthesize_for`)
/// and its nextpnr with the constraint file `constraints` of its family.
/// Gowin's nextpnr places no port without a pin: it needs the file.
pub fn place_and_route_for(
    fpga: Fpga,
    dir: &Path,
    constraints: Option<&Path>,
    clock_hz: u64,
    seed: u64,
) -> Result<Synth, String> {
    let y = synthesize_for(fpga, dir)?;
    place(&y, dir, constraints, clock_hz, seed, "")
}

/// The same flow with yosys once and nextpnr once per seed (logs
/// `nextpnr-<seed>.log`): one figure per seed, in `seeds`' order.
pub fn place_and_route_seeds(
    dir: &Path,
    pcf: Option<&Path>,
    clock_hz: u64,
    seeds: &[u64],
) -> Result<Vec<Synth>, String> {
    let y = synthesize_for(Fpga::Ice40Hx8k, dir)?;
    seeds
        .iter()
        .map(|&s| place(&y, dir, pcf, clock_hz, s, &format!("-{s}")))
        .collect()
}

/// The median of the seeds' Fmax (the mean of the middle two for an even
/// count); `None` for no runs.
pub fn median_fmax(runs: &[Synth]) -> Option<f64> {
    let mut f: Vec<f64> = runs.iter().map(|r| r.fmax_mhz).collect();
    f.sort_by(|a, b| a.total_cmp(b));
    let n = f.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(f[n / 2]),
        _ => Some((f[n / 2 - 1] + f[n / 2]) / 2.0),
    }
}

/// A hand-written reference design of the same contract (not in the
/// repository: Verilog-2001 written from docs/timing.md and
/// docs/packet-format.md alone, accepted by `sim --rtl`, `golden --rtl`
/// and `prove --rtl`), measured on this flow (median Fmax of seeds 1-3).
/// The anchor that the emitted design's ratios are printed against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    pub mix: &'static str,
    pub lcs: u64,
    pub lut4: u64,
    pub dff: u64,
    pub brams: u64,
    pub fmax_mhz: f64,
}

/// The hand-written reference designs' figures (not in the repository).
pub const HAND_ANCHORS: [Anchor; 2] = [
    Anchor {
        mix: "eskin34",
        lcs: 166,
        lut4: 112,
        dff: 114,
        brams: 0,
        fmax_mhz: 210.0,
    },
    Anchor {
        mix: "eskin34-uart",
        lcs: 326,
        lut4: 246,
        dff: 186,
        brams: 2,
        fmax_mhz: 165.0,
    },
];

/// The hand-written anchor of mix `name`, if there is one.
pub fn anchor(name: &str) -> Option<&'static Anchor> {
    HAND_ANCHORS.iter().find(|a| a.mix == name)
}

/// The constraint file as nextpnr is given it: a YoWASP nextpnr sees only
/// its working folder, so the file is copied in and named relative to it;
/// a native one takes it where it is (hdl/synth.sh passes a path of its own).
fn constraint_arg(fpga: Fpga, dir: &Path, file: &Path) -> Result<String, String> {
    if fpga.toolchain() == lut_gen::Toolchain::Native {
        let abs = std::path::absolute(file).map_err(|e| format!("{}: {e}", file.display()))?;
        return Ok(abs.to_string_lossy().into_owned());
    }
    let name = file
        .file_name()
        .ok_or(format!("{}: not a file", file.display()))?;
    let inside = dir.join(name);
    if std::path::absolute(&inside).ok() != std::path::absolute(file).ok() {
        std::fs::copy(file, &inside).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    Ok(name.to_string_lossy().into_owned())
}

/// nextpnr of `y`'s part at `seed` on `dir/slotforge.json`; its log is
/// `nextpnr<tag>.log`, its report `report<tag>.json`.
fn place(
    y: &Synthesized,
    dir: &Path,
    constraints: Option<&Path>,
    clock_hz: u64,
    seed: u64,
    tag: &str,
) -> Result<Synth, String> {
    let fpga = y.fpga;
    let (program, part) = fpga.nextpnr();
    let mut args: Vec<String> = part.iter().map(|a| a.to_string()).collect();
    args.extend([
        "--json".into(),
        SYNTH_JSON.into(),
        "--seed".into(),
        seed.to_string(),
    ]);
    args.extend(["--report".into(), format!("report{tag}.json")]);
    args.extend(["--freq".into(), format!("{}", clock_hz as f64 / 1e6)]);
    if fpga == Fpga::Ice40Hx8k {
        // the placed design, for icepack (hdl/synth.sh's bitstream)
        args.extend(["--asc".into(), format!("slotforge{tag}.asc")]);
    }
    match constraints {
        Some(p) => args.extend(
            fpga.family()
                .constraints()
                .nextpnr_args(&constraint_arg(fpga, dir, p)?),
        ),
        None if fpga == Fpga::Ice40Hx8k => args.push("--pcf-allow-unconstrained".into()),
        None => {}
    }
    let n = Tool::new(&find_program(program)?.to_string_lossy())
        .current_dir(dir)
        .args(&args)
        .run()
        .map_err(|e| format!("{program} could not be started: {e}"))?;
    let log = format!("{}{}", n.stdout, n.stderr);
    let log_file = dir.join(format!("nextpnr{tag}.log"));
    let _ = std::fs::write(&log_file, &log);
    if !n.success {
        let tail: Vec<&str> = log.lines().rev().take(20).collect();
        return Err(format!(
            "{program} failed (see {}):\n{}",
            log_file.display(),
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        ));
    }
    // the report is the placed and routed design's (the log's utilisation
    // table is printed before routing adds Gowin's route-through LUTs)
    let report = dir.join(format!("report{tag}.json"));
    let text =
        std::fs::read_to_string(&report).map_err(|e| format!("{}: {e}", report.display()))?;
    parse(fpga, &text, &y.cells).map_err(|e| format!("{}: {e}", report.display()))
}

/// What `Synth::lcs` counts on `fpga`: nextpnr's cell, and what it holds.
pub fn logic_cell_says(fpga: Fpga) -> String {
    let what = match fpga.family() {
        Family::Ice40 => "each a LUT4, a flip-flop or both",
        Family::Ecp5 => "half a slice each",
        Family::Gowin => "the LUTs placed, the router's route-through ones included",
    };
    format!("{}: {what}", names(fpga).logic_cell)
}

/// The family's names for what the report counts: nextpnr's logic cell
/// and block RAM, and yosys' LUT and flip-flop cells.
struct Names {
    logic_cell: &'static str,
    bram: &'static str,
    lut: fn(&str) -> bool,
    ff: fn(&str) -> bool,
}

fn names(fpga: Fpga) -> Names {
    match fpga.family() {
        Family::Ice40 => Names {
            logic_cell: "ICESTORM_LC",
            bram: "ICESTORM_RAM",
            lut: |c| c == "SB_LUT4",
            ff: |c| c.starts_with("SB_DFF"),
        },
        Family::Ecp5 => Names {
            logic_cell: "TRELLIS_COMB",
            bram: "DP16KD",
            lut: |c| c == "LUT4",
            ff: |c| c == "TRELLIS_FF",
        },
        Family::Gowin => Names {
            logic_cell: "LUT4",
            bram: "BSRAM",
            lut: |c| matches!(c, "LUT1" | "LUT2" | "LUT3" | "LUT4"),
            ff: |c| c.starts_with("DFF"),
        },
    }
}

/// The figures of nextpnr's `--report` JSON and yosys's `stat`.  A report
/// without the family's cells or an Fmax is an error, never "0 logic
/// cells".
pub fn parse(fpga: Fpga, report: &str, stat: &[(String, u64)]) -> Result<Synth, String> {
    let n = names(fpga);
    let (program, _) = fpga.nextpnr();
    let v: serde_json::Value =
        serde_json::from_str(report).map_err(|e| format!("{program}'s report: {e}"))?;
    let table: Vec<(String, u64, u64)> = v
        .get("utilization")
        .and_then(|u| u.as_object())
        .map(|u| {
            u.iter()
                .filter_map(|(c, x)| {
                    Some((
                        c.clone(),
                        x.get("used")?.as_u64()?,
                        x.get("available")?.as_u64()?,
                    ))
                })
                .collect()
        })
        .unwrap_or_default();
    let need = |cell: &str| {
        table
            .iter()
            .find(|(c, ..)| c == cell)
            .map(|&(_, used, _)| used)
            .ok_or(format!(
                "no `{cell}` in the utilization of {program}'s report: it could not be parsed"
            ))
    };
    let count = |pick: fn(&str) -> bool| -> u64 {
        stat.iter().filter(|(c, _)| pick(c)).map(|(_, k)| k).sum()
    };
    // the slowest clock's (the gateware has one, `clk`)
    let fmax = v
        .get("fmax")
        .and_then(|f| f.as_object())
        .into_iter()
        .flatten()
        .filter_map(|(_, c)| c.get("achieved")?.as_f64())
        .reduce(f64::min)
        .ok_or(format!("{program} reported no Fmax"))?;
    Ok(Synth {
        fpga,
        lcs: need(n.logic_cell)?,
        brams: need(n.bram)?,
        lut4: count(n.lut),
        dff: count(n.ff),
        fmax_mhz: fmax,
        cells: table.into_iter().filter(|&(_, used, _)| used > 0).collect(),
    })
}
