//! The formal back ends: yosys turns harness + design into an AIG (or SMT-LIB
//! for yosys-smtbmc), ABC's `bmc3` searches from reset and `pdr` (IC3)
//! proves for all time; cvc5 through `yosys-smtbmc -i` is the k-induction
//! alternative.  `docs/formal.md` (and the team's measurements) say why
//! these and not z3 or boolector.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::ProveError;

/// The prover behind `--solver`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Exact symbolic simulation of the AIG from reset with a state
    /// recurrence check (`symsim.rs`): the default.
    Symbolic,
    /// ABC over AIGER: `bmc3` from reset to the recurrence bound, and the
    /// recurrence miter (`aiger.rs`) that makes that bound cover all time.
    Abc,
    /// ABC's `pdr` (IC3) on the plain harness.
    Pdr,
    /// cvc5 through yosys-smtbmc: k-induction (`-i`) with base case from reset.
    Cvc5,
}

impl std::str::FromStr for Solver {
    type Err = String;
    fn from_str(s: &str) -> Result<Solver, String> {
        match s {
            "symbolic" => Ok(Solver::Symbolic),
            "abc" => Ok(Solver::Abc),
            "pdr" => Ok(Solver::Pdr),
            "cvc5" => Ok(Solver::Cvc5),
            "z3" | "boolector" => Err(format!(
                "solver `{s}` is not supported: Debian's {s} fails on yosys 0.23's SMT-LIB \
                 output of this design (z3 never finishes reading it, boolector breaks the \
                 pipe); use `symbolic` (the default), `abc`, `pdr` or `cvc5`"
            )),
            _ => Err(format!("unknown solver `{s}` (symbolic, abc, pdr, cvc5)")),
        }
    }
}

impl Solver {
    pub fn name(self) -> &'static str {
        match self {
            Solver::Symbolic => "symbolic",
            Solver::Abc => "abc",
            Solver::Pdr => "pdr",
            Solver::Cvc5 => "cvc5",
        }
    }
}

/// What one engine run found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SolverVerdict {
    /// Holds in every reachable state.
    Proved,
    /// Violated at this step from the first step (0 = the step before reset's edge).
    Violated { step: u64 },
    /// No violation within this many steps; nothing said beyond them.
    Bounded { steps: u64 },
}

/// Runs `program args`, in `dir`, returning stdout+stderr; a missing program
/// is named (through the one tool runner, `judge::tools`).
pub fn run_tool(
    dir: &Path,
    program: &str,
    args: &[&str],
    timeout: Duration,
) -> Result<String, ProveError> {
    // The engines take their own time limits; this one only guards a hung tool.
    // (generous: a loaded machine stretches wall time well past CPU time)
    let guard = timeout * 4 + Duration::from_secs(120);
    let out = judge::tools::run(program, args, dir, guard).map_err(|e| match e {
        judge::tools::ToolError::Missing(_) => ProveError::Tool(format!(
            "cannot run `{program}`: not installed (install it with `make tools`)"
        )),
        other => ProveError::Tool(format!("`{program}`: {other}")),
    })?;
    let mut text = out.stdout;
    text.push_str(&out.stderr);
    if !out.success {
        let tail: Vec<&str> = text.lines().rev().take(12).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(ProveError::Tool(format!(
            "`{program} {}` failed:\n{}",
            args.join(" "),
            tail.join("\n")
        )));
    }
    Ok(text)
}

/// Files of a prepared design in the work directory.
pub struct Prepared {
    pub dir: PathBuf,
}

/// yosys: harness + design to `design.aig` (+ `design.aim`) or `design.smt2`.
pub fn prepare(dir: &Path, solver: Solver) -> Result<Prepared, ProveError> {
    prepare_edited(dir, solver, "")
}

/// [`prepare`] for the symbolic engine, with yosys commands `edit` run on
/// the flattened harness and design before anything is optimised (a cut
/// point, a wire tied to another: `formal::composed`, `formal::tied`).
pub fn prepare_edited(dir: &Path, solver: Solver, edit: &str) -> Result<Prepared, ProveError> {
    let design = write_for_yosys(dir)?;
    let read = format!("read_verilog -formal harness.v; read_verilog -formal {design};");
    let script = match solver {
        // As SymbiYosys's `abc pdr` engine prepares an AIG (docs/formal.md),
        // but flattened before the first `opt`: `prep` optimises each of the
        // dozen modules apart and again after flattening, which was 1 s of
        // eskin34's 5.6 s in yosys for the same AIG give or take 15 gates.
        // After `setundef`, `opt -fast` (not `-full`) and no `opt` on the
        // bit-level netlist: the first `opt -full` has done the word-level
        // work, and the two passes after it were 0.7 of 4.7 s for an AIG a
        // few duplicate latches larger (eskin34: 345 latches, not 336).
        Solver::Symbolic | Solver::Abc | Solver::Pdr => format!(
            "{read} hierarchy -check -top slotforge_formal; proc; flatten; {edit} opt_clean; \
             memory -nomap; memory_map; opt -full; async2sync; \
             chformal -assume -early; setundef -anyseq; opt -fast; techmap; opt_clean; \
             dffunmap; abc -g AND -fast; opt_clean; write_aiger -I -B -zinit -map design.aim design.aig; \
             write_aiger -ascii -I -B -zinit design.aag"
        ),
        Solver::Cvc5 => format!(
            "{read} prep -flatten -top slotforge_formal; memory_map; opt -full; async2sync; \
             dffunmap; write_smt2 -wires design.smt2"
        ),
    };
    run_tool(
        dir,
        "yosys",
        &["-q", "-p", &script],
        Duration::from_secs(600),
    )?;
    Ok(Prepared {
        dir: dir.to_path_buf(),
    })
}

/// `design.v` as yosys reads it, with its memories' tables in `$readmemh`
/// files (`tables.rs`), written beside it; its name.
fn write_for_yosys(dir: &Path) -> Result<&'static str, ProveError> {
    let io = |p: &Path, e: std::io::Error| ProveError::Tool(format!("{}: {e}", p.display()));
    let path = dir.join("design.v");
    let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
    let (read, tables) = crate::tables::to_hex_files(&text);
    if tables.is_empty() {
        return Ok("design.v");
    }
    let files = [("design.yosys.v", read.as_str())]
        .into_iter()
        .chain(tables.iter().map(|(n, t)| (n.as_str(), t.as_str())));
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
    }
    Ok("design.yosys.v")
}

/// ABC's `bmc3` from reset for at most `frames` steps and `secs` seconds.
pub fn bmc(p: &Prepared, frames: u64, secs: u64) -> Result<SolverVerdict, ProveError> {
    let cmd = format!(
        "read_aiger design.aig; fold; strash; bmc3 -F {frames} -T {secs}; write_cex -a cex.aiw"
    );
    let out = abc(p, &cmd, secs)?;
    parse_abc(&out, frames)
}

/// ABC's `pdr` for at most `secs` seconds.
pub fn pdr(p: &Prepared, secs: u64) -> Result<Option<SolverVerdict>, ProveError> {
    let cmd = format!("read_aiger design.aig; fold; strash; pdr -T {secs}; write_cex -a cex.aiw");
    let out = abc(p, &cmd, secs)?;
    if out.contains("Property proved") {
        return Ok(Some(SolverVerdict::Proved));
    }
    match parse_abc(&out, 0)? {
        v @ SolverVerdict::Violated { .. } => Ok(Some(v)),
        _ => Ok(None),
    }
}

/// Runs one `yosys-abc` script in the work directory for at most `secs`
/// seconds; its output.
fn abc(p: &Prepared, script: &str, secs: u64) -> Result<String, ProveError> {
    run_tool(
        &p.dir,
        "yosys-abc",
        &["-c", script],
        Duration::from_secs(secs),
    )
}

/// Reads ABC's verdict: "Output 0 of miter ... was asserted in frame N." or
/// "No output asserted in N frames.".
pub(crate) fn parse_abc(out: &str, frames: u64) -> Result<SolverVerdict, ProveError> {
    for line in out.lines() {
        if let Some(i) = line.find("was asserted in frame ") {
            let n: String = line[i + 22..]
                .chars()
                .take_while(|c| c.is_ascii_digit())
                .collect();
            let step = n
                .parse()
                .map_err(|_| ProveError::Tool(format!("ABC: cannot read `{line}`")))?;
            return Ok(SolverVerdict::Violated { step });
        }
        if let Some(i) = line.find("No output asserted in ") {
            let n: String = line[i + 22..]
                .chars()
                .take_while(|c| c.is_ascii_digit())
                .collect();
            if let Ok(steps) = n.parse() {
                return Ok(SolverVerdict::Bounded { steps });
            }
        }
    }
    if frames > 0 {
        // bmc3 stopped at its time limit: the last frame it finished.
        let mut done = 0;
        for line in out.lines() {
            if let Some(rest) = line.trim_start().strip_prefix(|c: char| c.is_ascii_digit()) {
                let _ = rest;
            }
            let t = line.trim_start();
            let num: String = t.chars().take_while(|c| c.is_ascii_digit()).collect();
            if !num.is_empty() && t[num.len()..].trim_start().starts_with(':') {
                if let Ok(n) = num.parse::<u64>() {
                    done = n;
                }
            }
        }
        return Ok(SolverVerdict::Bounded { steps: done });
    }
    Ok(SolverVerdict::Bounded { steps: 0 })
}

/// The recurrence check (`aiger.rs`): whether, for every input, the state
/// at step `2F + 2` equals the state a second copy started `F` steps later
/// reaches at step `F + 2`.  `Some(true)`: it does; `Some(false)`: some
/// input breaks it (no design bug: only the argument fails); `None`: ABC
/// did not finish.
pub fn recurrence(p: &Prepared, frame_cycles: u64, secs: u64) -> Result<Option<bool>, ProveError> {
    let check = 2 * frame_cycles + 2;
    let build = crate::aiger::recurrence_miter;
    Ok(
        match bmc_on_miter(p, "recur.aig", build, frame_cycles, secs)? {
            SolverVerdict::Violated { .. } => Some(false),
            SolverVerdict::Bounded { steps } if steps > check => Some(true),
            _ => None,
        },
    )
}

/// Builds a two-copy miter of the design (`build(aig, shared MISO inputs,
/// F, 2F + 2)`), writes it as `name` and runs `bmc3` on it two steps past
/// the recurrence step: the one ABC run behind [`recurrence`] and
/// [`combined`].
fn bmc_on_miter(
    p: &Prepared,
    name: &str,
    build: fn(&crate::aiger::Aig, &[usize], u64, u64) -> Vec<u8>,
    frame_cycles: u64,
    secs: u64,
) -> Result<SolverVerdict, ProveError> {
    let aag = std::fs::read_to_string(p.dir.join("design.aag"))
        .map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    let g = crate::aiger::parse(&aag).map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    // the outside world (MISO, an AXI4-Stream slave's choices) is one for
    // both copies; their power-on values (unnamed -zinit inputs) are not
    let shared = named_inputs(p, None)?
        .iter()
        .map(|&(idx, _)| idx)
        .collect::<Vec<_>>();
    let check = 2 * frame_cycles + 2;
    std::fs::write(p.dir.join(name), build(&g, &shared, frame_cycles, check))
        .map_err(|e| ProveError::Tool(format!("{name}: {e}")))?;
    let frames = check + 2;
    let cmd = format!("read_aiger {name}; strash; bmc3 -F {frames} -T {secs}");
    let out = abc(p, &cmd, secs)?;
    parse_abc(&out, frames)
}

/// What the combined miter (`aiger::combined_miter`) found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Combined {
    /// No violation from reset within `2F + 2` steps and the state recurs:
    /// proved for all time.
    Holds,
    /// An assertion fails from reset at this step (before the recurrence step).
    Fails { step: u64 },
    /// A violation at the recurrence step: either check; the caller decides.
    AtCheck,
}

/// The search from reset and the recurrence check in one `bmc3` run on the
/// combined miter: the two copies' unrolling is shared with the search
/// instead of repeated.  `None`: ABC did not finish in `secs`.
pub fn combined(
    p: &Prepared,
    frame_cycles: u64,
    secs: u64,
) -> Result<Option<Combined>, ProveError> {
    let check = 2 * frame_cycles + 2;
    let build = crate::aiger::combined_miter;
    Ok(
        match bmc_on_miter(p, "combined.aig", build, frame_cycles, secs)? {
            SolverVerdict::Violated { step } if step < check => Some(Combined::Fails { step }),
            SolverVerdict::Violated { .. } => Some(Combined::AtCheck),
            SolverVerdict::Bounded { steps } if steps > check => Some(Combined::Holds),
            _ => None,
        },
    )
}

/// `(input index, bit)` of every bit of the input `name` (every named
/// input with None) in the AIG (yosys's map).
fn named_inputs(p: &Prepared, name: Option<&str>) -> Result<Vec<(usize, usize)>, ProveError> {
    let aim = std::fs::read_to_string(p.dir.join("design.aim"))
        .map_err(|e| ProveError::Tool(format!("design.aim: {e}")))?;
    let mut v = Vec::new();
    for line in aim.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() == 4 && f[0] == "input" && name.is_none_or(|n| f[3] == n) {
            if let (Ok(idx), Ok(bit)) = (f[1].parse(), f[2].parse()) {
                v.push((idx, bit));
            }
        }
    }
    Ok(v)
}

/// cvc5 through yosys-smtbmc: k-induction of depth `k` (base case from reset).
pub fn smt_induction(p: &Prepared, k: u64, secs: u64) -> Result<Option<SolverVerdict>, ProveError> {
    let k = k.to_string();
    let out = run_tool(
        &p.dir,
        "yosys-smtbmc",
        &[
            "-s",
            "cvc5",
            "-i",
            "-t",
            &k,
            "--dump-vcd",
            "smt_cex.vcd",
            "design.smt2",
        ],
        Duration::from_secs(secs),
    );
    let out = match out {
        Ok(o) => o,
        // yosys-smtbmc exits 1 when induction or the base case fails.
        Err(ProveError::Tool(t)) if t.contains("FAILED") || t.contains("failed") => t,
        Err(e) => return Err(e),
    };
    if out.contains("PASSED") && !out.contains("FAILED") {
        return Ok(Some(SolverVerdict::Proved));
    }
    Ok(None)
}

/// The MISO values of a counterexample, per step, from ABC's AIGER witness
/// and the yosys map (`input <index> <bit> <name>`).
pub fn witness_miso(p: &Prepared, branches: usize) -> Result<Vec<u64>, ProveError> {
    let miso_inputs: Vec<(usize, usize)> = named_inputs(p, Some("adc_miso"))?
        .into_iter()
        .filter(|&(_, bit)| bit < branches)
        .collect();
    let cex = std::fs::read_to_string(p.dir.join("cex.aiw"))
        .map_err(|e| ProveError::Tool(format!("ABC wrote no witness: {e}")))?;
    let mut lines = cex.lines().map(str::trim).filter(|l| !l.is_empty());
    // "1", "b0", the initial latch values, then one input vector per step.
    let _status = lines.next();
    let _prop = lines.next();
    let _init = lines.next();
    let mut steps = Vec::new();
    for l in lines {
        if l == "." {
            break;
        }
        let bytes = l.as_bytes();
        let mut m = 0u64;
        for &(idx, bit) in &miso_inputs {
            if bytes.get(idx) == Some(&b'1') {
                m |= 1 << bit;
            }
        }
        steps.push(m);
    }
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn abc_verdicts() {
        assert_eq!(
            parse_abc(
                "Output 0 of miter \"x\" was asserted in frame 57.  Time = 0.1 sec",
                100
            )
            .unwrap(),
            SolverVerdict::Violated { step: 57 }
        );
        assert_eq!(
            parse_abc(
                "No output asserted in 1000 frames. Resource limit reached",
                1000
            )
            .unwrap(),
            SolverVerdict::Bounded { steps: 1000 }
        );
    }

    #[test]
    fn solvers() {
        assert_eq!("pdr".parse::<Solver>(), Ok(Solver::Pdr));
        assert!("z3"
            .parse::<Solver>()
            .unwrap_err()
            .contains("not supported"));
        assert!("yices".parse::<Solver>().unwrap_err().contains("unknown"));
    }
}
