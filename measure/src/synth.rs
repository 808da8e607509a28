//! The one yosys + nextpnr-ice40 flow (an iCE40-HX8K, ct256): `build`'s
//! synthesis step and `hdl/synth.sh` (through `examples/synth.rs`) both run
//! [`place_and_route`], so the figures in the report and in
//! `docs/performance.md` come from the same commands.

use std::path::Path;

use judge::tools::Tool;

/// What place and route reported.
#[derive(Debug, Clone, PartialEq)]
pub struct Synth {
    /// Logic cells placed (`ICESTORM_LC`).
    pub lcs: u64,
    /// `SB_LUT4` and flip-flops (`SB_DFF*`) from yosys' `stat`.
    pub lut4: u64,
    pub dff: u64,
    /// Block RAMs (`ICESTORM_RAM`).
    pub brams: u64,
    pub fmax_mhz: f64,
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
    synthesize(dir)?;
    place(dir, pcf, clock_hz, seed, "")
}

/// The same flow with yosys once and nextpnr once per seed (logs
/// `nextpnr-<seed>.log`): one figure per seed, in `seeds`' order.
pub fn place_and_route_seeds(
    dir: &Path,
    pcf: Option<&Path>,
    clock_hz: u64,
    seeds: &[u64],
) -> Result<Vec<Synth>, String> {
    synthesize(dir)?;
    seeds
        .iter()
        .map(|&s| place(dir, pcf, clock_hz, s, &format!("-{s}")))
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

/// yosys `synth_ice40` on `dir/slotforge_top.v` (`yosys.log`, `stat.txt`,
/// `slotforge.json` in `dir`).
fn synthesize(dir: &Path) -> Result<(), String> {
    let y = Tool::new("yosys")
        .current_dir(dir)
        .args(["-q", "-l", "yosys.log", "-p"])
        .arg(format!(
            "read_verilog {}; synth_ice40 -top {} -json slotforge.json; check -assert; tee -q -o stat.txt stat",
            hdl::VERILOG_FILE,
            lut_gen::TOP_MODULE,
        ))
        .run()
        .map_err(|e| format!("yosys could not be started: {e}"))?;
    if !y.success {
        return Err(format!(
            "yosys failed (see {}):\n{}",
            dir.join("yosys.log").display(),
            y.stderr
        ));
    }
    Ok(())
}

/// nextpnr-ice40 at `seed` on `dir/slotforge.json`; its log is
/// `nextpnr<tag>.log`.
fn place(
    dir: &Path,
    pcf: Option<&Path>,
    clock_hz: u64,
    seed: u64,
    tag: &str,
) -> Result<Synth, String> {
    let n = Tool::new("nextpnr-ice40")
        .current_dir(dir)
        .args(["--hx8k", "--package", "ct256", "--json", "slotforge.json"])
        .arg("--seed")
        .arg(seed.to_string())
        .arg("--asc")
        .arg(format!("slotforge{tag}.asc"))
        .arg("--report")
        .arg(format!("report{tag}.json"))
        .arg("--freq")
        .arg(format!("{}", clock_hz as f64 / 1e6));
    let n = match pcf {
        // nextpnr runs in `dir`: a relative path is the caller's, so it
        // goes absolute first (hdl/synth.sh passes target/synth/<mix>/...)
        Some(p) => n
            .arg("--pcf")
            .arg(std::path::absolute(p).map_err(|e| format!("{}: {e}", p.display()))?),
        None => n.arg("--pcf-allow-unconstrained"),
    };
    let n = n
        .run()
        .map_err(|e| format!("nextpnr-ice40 could not be started: {e}"))?;
    let log = format!("{}{}", n.stdout, n.stderr);
    let log_file = dir.join(format!("nextpnr{tag}.log"));
    let _ = std::fs::write(&log_file, &log);
    if !n.success {
        let tail: Vec<&str> = log.lines().rev().take(20).collect();
        return Err(format!(
            "nextpnr-ice40 failed (see {}):\n{}",
            log_file.display(),
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        ));
    }
    let stat = std::fs::read_to_string(dir.join("stat.txt")).unwrap_or_default();
    parse(&log, &stat).map_err(|e| format!("{}: {e}", log_file.display()))
}

/// The figures of nextpnr's log and yosys's `stat`.  A log without the
/// utilisation table or an Fmax is an error, never "0 logic cells".
fn parse(log: &str, stat: &str) -> Result<Synth, String> {
    let need = |cell: &str| {
        used(log, cell).ok_or(format!(
            "no `{cell}: used/available` line in nextpnr-ice40's log: it could not be parsed"
        ))
    };
    Ok(Synth {
        lcs: need("ICESTORM_LC")?,
        brams: need("ICESTORM_RAM")?,
        lut4: cells(stat, |c| c == "SB_LUT4"),
        dff: cells(stat, |c| c.starts_with("SB_DFF")),
        fmax_mhz: fmax(log).ok_or("nextpnr-ice40 reported no Fmax")?,
    })
}

/// `CELL: used/available` from nextpnr's utilisation table (the last one).
fn used(log: &str, cell: &str) -> Option<u64> {
    let key = format!("{cell}:");
    log.lines()
        .filter_map(|l| Some(&l[l.find(&key)? + key.len()..]))
        .filter_map(|r| r.trim().split('/').next()?.trim().parse().ok())
        .next_back()
}

/// The sum of yosys `stat` counts of the cells `pick` accepts (the last
/// `stat` block only: the top module after synthesis).
fn cells(stat: &str, pick: impl Fn(&str) -> bool) -> u64 {
    let last = stat.rfind("Number of cells").map_or(stat, |i| &stat[i..]);
    last.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            let (c, n) = (w.next()?, w.next()?);
            pick(c).then(|| n.parse::<u64>().ok()).flatten()
        })
        .sum()
}

/// The last `Max frequency for clock '...': F MHz` of nextpnr's log.
fn fmax(log: &str) -> Option<f64> {
    log.lines()
        .filter(|l| l.contains("Max frequency for clock"))
        .filter_map(|l| l.rsplit("': ").next()?.split(' ').next()?.parse().ok())
        .next_back()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_nextpnr_and_yosys_figures() {
        let log = "Info: Device utilisation:\nInfo:     ICESTORM_LC:   263/ 7680     3%\nInfo:    ICESTORM_RAM:     3/   32     9%\n\
                   Info: Max frequency for clock 'clk$SB_IO_IN_$glb_clk': 98.50 MHz (PASS at 48.00 MHz)\n\
                   Info: Max frequency for clock 'clk$SB_IO_IN_$glb_clk': 117.00 MHz (PASS at 48.00 MHz)\n";
        assert_eq!(used(log, "ICESTORM_LC"), Some(263));
        assert_eq!(used(log, "ICESTORM_RAM"), Some(3));
        assert_eq!(parse(log, "").unwrap().lcs, 263);
        assert_eq!(fmax(log), Some(117.0));
        let stat = "   Number of cells: 9\n     SB_CARRY  4\n     SB_DFF 10\n     SB_DFFER 7\n     SB_LUT4 120\n";
        assert_eq!(cells(stat, |c| c == "SB_LUT4"), 120);
        assert_eq!(cells(stat, |c| c.starts_with("SB_DFF")), 17);
    }

    #[test]
    fn median_of_seeds_is_the_middle_run() {
        let run = |f| Synth {
            lcs: 1,
            lut4: 1,
            dff: 1,
            brams: 0,
            fmax_mhz: f,
        };
        assert_eq!(
            median_fmax(&[run(150.0), run(120.0), run(170.0)]),
            Some(150.0)
        );
        assert_eq!(median_fmax(&[run(100.0), run(120.0)]), Some(110.0));
        assert_eq!(median_fmax(&[]), None);
        assert_eq!(anchor("eskin34").map(|a| a.lcs), Some(166));
        assert!(anchor("softslip1k").is_none());
    }

    #[test]
    fn a_log_that_cannot_be_parsed_is_an_error_not_zero_cells() {
        // a nextpnr whose table changed its words: no utilisation line
        let log = "Info: Device utilisation:\nInfo:     LOGIC_CELLS:   263/ 7680     3%\n\
                   Info: Max frequency for clock 'clk': 98.50 MHz (PASS at 48.00 MHz)\n";
        let e = parse(log, "").unwrap_err();
        assert!(
            e.contains("ICESTORM_LC") && e.contains("could not be parsed"),
            "{e}"
        );
        let no_fmax = "Info:     ICESTORM_LC:   263/ 7680     3%\nInfo:    ICESTORM_RAM:     3/   32     9%\n";
        assert!(parse(no_fmax, "").unwrap_err().contains("Fmax"));
    }
}
