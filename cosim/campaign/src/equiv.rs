//! Equivalence at the ports, for all time: is a faulty gateware
//! indistinguishable from the clean one for every input sequence (MISO and
//! reset) from power-up?  A gateware fault whose run passes every detector
//! is counted as a miss unless this proves it equivalent.
//!
//! yosys builds a miter of the two flattened netlists (`miter -equiv`: one
//! assertion that every output agrees) and writes it as an AIG; ABC merges
//! the registers it proves equal by induction (`scorr`: signal
//! correspondence, which reduces the miter of two nearly equal designs to
//! their difference), then `pdr` (IC3) proves the assertion in every
//! reachable state or finds a counterexample.  Every register starts at
//! zero in both copies and every input (`rst`, MISO) is free, so the
//! reachable states include every run after any reset.  Verilog x values
//! are zero in both copies (`setundef -zero`), as synthesis would pick one
//! value for both.  Only an answer counts: "undecided" is not a proof.
//! (`miter -ignore_gold_x` is not used: with it, a slot-ROM word of another
//! channel was "proved" equivalent; `cosim/campaign/tests/equiv.rs` keeps that case.)

use std::path::Path;
use std::time::Duration;

use serde::Serialize;

use judge::tools::{self, ToolError};

/// What the check found.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "verdict", rename_all = "kebab-case")]
pub enum Equivalence {
    /// Every output equal in every cycle of every run (ABC pdr).
    Proved { seconds: f64 },
    /// A run where an output differs exists (ABC's counterexample frame).
    Differs { frame: Option<u64> },
    /// No answer: a time limit, or a tool's failure (the reason).
    Undecided { why: String },
    /// Not compared with the clean design, but the faulty design proves
    /// the full pin contract for all time (`prove`): no run can tell it
    /// from a correct one at the ports.
    ContractProved,
}

impl Equivalence {
    /// An answer that excuses a fault no detector caught.
    pub fn is_proof(&self) -> bool {
        matches!(
            self,
            Equivalence::Proved { .. } | Equivalence::ContractProved
        )
    }
}

/// Time ABC's pdr gets per fault.
pub const PDR_SECONDS: u64 = 60;

// Every register from zero (`setattr -unset init` drops the power-on
// values the gateware declares, `setundef -zero -init` makes each 0),
// `rst` free: every run after any reset is covered, and a fault's
// difference shows from a state pdr reaches quickly (from the power-on
// state it may need a whole frame's depth).
const YOSYS_SCRIPT: &str = "\
read_verilog gold.v; hierarchy -top slotforge_top; proc; setattr -unset init; flatten; opt_clean; rename slotforge_top gold; design -stash gold
read_verilog gate.v; hierarchy -top slotforge_top; proc; setattr -unset init; flatten; opt_clean; rename slotforge_top gate; design -stash gate
design -copy-from gold -as gold gold; design -copy-from gate -as gate gate
miter -equiv -flatten -make_assert gold gate miter; hierarchy -top miter
memory_map; opt -full; async2sync; setundef -zero -init; opt -full; techmap; opt -fast; dffunmap
abc -g AND -fast; opt_clean; write_aiger -zinit miter.aig
";

/// Proves (or refutes) that `gate` (Verilog with `slotforge_top`) is
/// equivalent to `gold` at the ports; `dir` holds the work files.
pub fn check(gold: &str, gate: &str, dir: &Path) -> Result<Equivalence, ToolError> {
    let io = |e: std::io::Error| ToolError::Io(e.to_string());
    std::fs::write(dir.join("gold.v"), gold).map_err(io)?;
    std::fs::write(dir.join("gate.v"), gate).map_err(io)?;
    std::fs::write(dir.join("miter.ys"), YOSYS_SCRIPT).map_err(io)?;
    let y = tools::run(
        "yosys",
        &["-q", "-l", "yosys.log", "-s", "miter.ys"],
        dir,
        Duration::from_secs(300),
    )?;
    if !y.success {
        let log = std::fs::read_to_string(dir.join("yosys.log")).unwrap_or(y.stderr);
        return Ok(Equivalence::Undecided {
            why: format!("yosys could not build the miter: {}", last_lines(&log, 5)),
        });
    }
    let cmd = format!("read_aiger miter.aig; fold; strash; scorr; pdr -T {PDR_SECONDS}");
    let a = match tools::run(
        "yosys-abc",
        &["-c", &cmd],
        dir,
        Duration::from_secs(PDR_SECONDS + 30),
    ) {
        Err(ToolError::Timeout(t, s)) => {
            return Ok(Equivalence::Undecided {
                why: format!("{t} ran past {s} s"),
            })
        }
        r => r?,
    };
    Ok(verdict(&a.stdout, a.seconds))
}

/// ABC's answer, read from its output.
pub fn verdict(out: &str, seconds: f64) -> Equivalence {
    if out.contains("Property proved") {
        return Equivalence::Proved { seconds };
    }
    if let Some(l) = out.lines().find(|l| l.contains("was asserted in frame")) {
        let frame = l.split("frame").nth(1).and_then(|r| {
            r.split_whitespace()
                .next()?
                .trim_end_matches('.')
                .parse()
                .ok()
        });
        return Equivalence::Differs { frame };
    }
    Equivalence::Undecided {
        why: format!("ABC pdr: {}", last_lines(out, 2)),
    }
}

fn last_lines(s: &str, n: usize) -> String {
    let v: Vec<&str> = s.lines().filter(|l| !l.trim().is_empty()).collect();
    v[v.len().saturating_sub(n)..].join(" / ")
}
