//! `slotforge synth MIX --fpga PART`: the gateware synthesized and placed
//! for one FPGA part on its board (yosys and nextpnr of that family, the
//! board's pins), its cells and Fmax as a table or JSON.

use std::path::{Path, PathBuf};

use lut_gen::Fpga;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// The part: ice40-hx8k (iCE40-HX8K Breakout Board), ecp5-25k (ULX3S)
    /// or gw1n-9 (Tang Nano 9K); a family's name (ice40, ecp5, gowin) also
    /// does.
    #[arg(long, value_parser = Fpga::parse, default_value = "ice40-hx8k")]
    pub fpga: Fpga,
    /// A board file of that part (see constraints/) instead of the one
    /// slotforge ships for it.
    #[arg(long)]
    pub board: Option<PathBuf>,
    /// Keep the work here: the Verilog, the constraint file, yosys' and
    /// nextpnr's logs and reports, the gate-level netlist (created if
    /// missing). Without it the work goes to a temporary folder.
    #[arg(short = 'o', long = "out")]
    pub out: Option<PathBuf>,
    /// nextpnr's placement seed.
    #[arg(long, value_parser = super::whole_number, default_value_t = 1)]
    pub seed: u64,
    /// The figures as JSON (docs/json.md) instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> u8 {
    // Modes are ROM tables and a mode register in the same Verilog: placed
    // like any other design.
    let s = match super::load_any_modes(&a.mix, super::Limits::Emitter) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let tmp;
    let dir: &Path = match &a.out {
        Some(d) => d,
        None => match tempfile::tempdir() {
            Ok(t) => {
                tmp = t;
                tmp.path()
            }
            Err(e) => {
                eprintln!("error: no temporary folder: {e}");
                return 1;
            }
        },
    };
    let constraints = match prepare(&a, &s, dir) {
        Ok(c) => c,
        Err(code) => return code,
    };
    match measure::place_and_route_for(a.fpga, dir, Some(&constraints), s.grid.clock_hz, a.seed) {
        Ok(r) => {
            let board = board_name(&a);
            if a.json {
                println!("{}", to_json(&s, &r, &board, a.seed));
            } else {
                print!("{}", to_text(&s, &r, &board, a.seed));
            }
            0
        }
        Err(e) => {
            eprintln!("error: {}: {e}", a.fpga);
            1
        }
    }
}

/// The board's name: the file given, or the part's own board.
fn board_name(a: &Args) -> String {
    match &a.board {
        Some(p) => hdl::Board::load(p).map_or(p.display().to_string(), |b| b.name),
        None => a.fpga.board().0.to_string(),
    }
}

/// Emits the Verilog and the board's constraint file into `dir`; returns
/// the constraint file's path.  A board of another part is bad input
/// (exit 2); a mix with more port bits than the board has pins, or beyond
/// the gateware's limits, does not fit (exit 1).
fn prepare(a: &Args, s: &lut_gen::Schedule, dir: &Path) -> Result<PathBuf, u8> {
    super::write_files(dir, &[])?;
    let board = match &a.board {
        Some(p) => {
            let b = hdl::Board::load(p).map_err(|e| {
                eprintln!("error: {e}");
                2u8
            })?;
            if b.fpga != a.fpga {
                let (_, stock) = a.fpga.board();
                eprintln!(
                    "error: board file {} is for {} (its `fpga`), not --fpga {}: use --fpga {}, or a board file of {} (constraints/{stock})",
                    p.display(),
                    b.fpga,
                    a.fpga,
                    b.fpga,
                    a.fpga
                );
                return Err(2);
            }
            p.clone()
        }
        None => {
            let (_, file) = a.fpga.board();
            super::write_files(dir, &[(file, hdl::stock_board(a.fpga).to_string())])?;
            dir.join(file)
        }
    };
    let e = hdl::emit(s, Some(&board)).map_err(|e| {
        // the stock board is named as it ships, not by its copy in `dir`
        let (_, file) = a.fpga.board();
        let shown = board.display().to_string();
        let message = match a.board {
            None => e
                .to_string()
                .replace(&shown, &format!("constraints/{file}")),
            Some(_) => e.to_string(),
        };
        eprintln!("error: {}: {message}", a.mix.display());
        match (&e, &a.board) {
            (hdl::HdlError::Board { .. }, Some(_)) => 2u8,
            _ => 1,
        }
    })?;
    let file = a.fpga.family().constraints().file();
    let keep = [hdl::VERILOG_FILE, file];
    let files: Vec<(&str, String)> = e
        .files()
        .iter()
        .filter(|(n, _)| keep.contains(&n.as_str()))
        .map(|(n, t)| (n.as_str(), t.clone()))
        .collect();
    super::write_files(dir, &files)?;
    Ok(dir.join(file))
}

/// The figures as the table the user reads.
fn to_text(s: &lut_gen::Schedule, r: &measure::Synth, board: &str, seed: u64) -> String {
    let mhz = s.grid.clock_hz as f64 / 1e6;
    let (pnr, _) = r.fpga.nextpnr();
    let mut t = format!(
        "{} on {} ({}, board {board}): {} and {pnr}, seed {seed}\n",
        s.mix.name,
        r.fpga,
        r.fpga.part_number(),
        r.fpga.yosys()
    );
    let yosys = r.fpga.yosys();
    let rows = [
        ("LUTs", format!("{:<6} mapped by {yosys}", r.lut4)),
        ("flip-flops", format!("{:<6} mapped by {yosys}", r.dff)),
        ("block RAMs", format!("{:<6} placed by {pnr}", r.brams)),
        (
            "logic cells",
            format!(
                "{:<6} placed by {pnr} ({})",
                r.lcs,
                measure::logic_cell_says(r.fpga)
            ),
        ),
        (
            "Fmax",
            format!(
                "{:.1} MHz = {:.2}x the {mhz} MHz clock",
                r.fmax_mhz,
                r.fmax_mhz / mhz
            ),
        ),
    ];
    for (k, v) in rows {
        t.push_str(&format!("  {k:<12} {v}\n"));
    }
    if let Some((names, select)) = modes(s) {
        t.push_str(&format!(
            "  {:<12} {} (select {select}): every mode's tables in this gateware\n",
            "modes",
            names.join(", ")
        ));
    }
    t.push_str(&format!("{pnr}'s cells used (of available):\n"));
    for (c, used, avail) in &r.cells {
        t.push_str(&format!("  {c:<14} {used:>6} of {avail}\n"));
    }
    t
}

/// A mix with modes: their names and how they are chosen (`pin`, `auto`).
fn modes(s: &lut_gen::Schedule) -> Option<(Vec<String>, &'static str)> {
    let m = s.mode_plan().filter(|m| m.names.len() > 1)?;
    Some((m.names.clone(), m.select.name()))
}

/// The same figures as JSON (fields in docs/json.md).
fn to_json(s: &lut_gen::Schedule, r: &measure::Synth, board: &str, seed: u64) -> String {
    let mhz = s.grid.clock_hz as f64 / 1e6;
    let cells: Vec<serde_json::Value> = r
        .cells
        .iter()
        .map(|(c, u, a)| serde_json::json!({"cell": c, "used": u, "available": a}))
        .collect();
    let v = serde_json::json!({
        "mix": s.mix.name,
        "fpga": r.fpga.name(),
        "part": r.fpga.part_number(),
        "board": board,
        "seed": seed,
        "clock_mhz": mhz,
        "luts": r.lut4,
        "flip_flops": r.dff,
        "block_rams": r.brams,
        "logic_cells": r.lcs,
        "fmax_mhz": (r.fmax_mhz * 100.0).round() / 100.0,
        "fmax_over_clock": (r.fmax_mhz / mhz * 100.0).round() / 100.0,
        "cells": cells,
        "modes": modes(s).map(|(names, select)| serde_json::json!({"names": names, "select": select})),
    });
    serde_json::to_string_pretty(&v).expect("JSON of plain values")
}
