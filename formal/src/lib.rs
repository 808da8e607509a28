//! slotforge's formal flow (`slotforge prove`): a harness generated from the
//! schedule (`harness`) asserts the pin contract of `docs/timing.md`
//! around `slotforge_top` (slotforge's own Verilog or any design on the port
//! contract), with MISO free and reset held in the first cycle only; an
//! engine (`engine`) proves it for all time or searches it from reset to a
//! bound; a violation is replayed (`replay`) into a VCD that the judge
//! checks like any other waveform.
//!
//! A bounded result is reported as `bounded` with its depth, never as a proof.

mod aiger;
// A public namespace, not an export list: `cache::key`, `cache::load` and
// `cache::store` read as the proof cache's only with the module's name.
pub mod cache;
mod engine;
mod faults;
mod harness;
mod replay;
mod strategy;
mod symsim;
mod tables;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use lut_gen::Schedule;

// The harness: the pin contract as assertions on the ports of any design.
pub use harness::{
    contract, generate, generate_with, not_covered, Clause, FreeInput, Harness, HarnessError,
    PropertyDef, TableForm, AXIS_BYTES_MAX_WAIT, FULL_TABLE_MAX_SLOTS, TREADY_ANY,
};

// The solvers, and the steps a test runs one at a time.
pub use engine::{bmc, prepare, Prepared, Solver, SolverVerdict};

// The default engine on its own (symbolic simulation of an AIGER graph).
pub use aiger::{parse as parse_aiger, Aig};
pub use symsim::{
    prove as prove_aig, prove_generalised, CounterFailure, Counters, Found, SymStats,
};

// A counterexample's replay, and the faults that only a proof finds.
pub use faults::DeepFault;
pub use replay::DUT_SCOPE;

/// Why `prove` could not give a verdict.
#[derive(Debug, thiserror::Error)]
pub enum ProveError {
    /// The schedule has no harness (beyond the harness's limits).
    #[error("{0}")]
    Harness(#[from] HarnessError),
    /// A tool is missing or failed (yosys, yosys-abc, yosys-smtbmc, iverilog).
    #[error("{0}")]
    Tool(String),
    /// The counterexample files could not be written.
    #[error("{0}")]
    Output(String),
}

/// What was established.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// Every property holds in every reachable state, for any MISO input.
    Proved,
    /// No violation from reset within `depth` steps; nothing is claimed beyond.
    Bounded,
    /// A trace from reset violates a property.
    Failed,
}

impl Outcome {
    /// `prove`'s exit code: 0 proved, 1 counterexample, 3 bounded only.
    pub fn exit_code(self) -> u8 {
        match self {
            Outcome::Proved => 0,
            Outcome::Failed => 1,
            Outcome::Bounded => 3,
        }
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PropertyResult {
    pub name: String,
    pub result: Outcome,
    pub what: String,
}

/// A violation from reset, replayed.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Counterexample {
    /// First failing cycle, counted like `check` counts (cycle 0 = the first
    /// cycle after reset); -1 is the reset cycle.
    pub cycle: i64,
    /// The VCD (design pins under [`replay::DUT_SCOPE`]) and its GTKWave save file.
    pub vcd: PathBuf,
    pub gtkw: PathBuf,
    /// The judge on that VCD: its first rejected cycle and its summary (what
    /// `slotforge check MIX VCD --scope replay_tb.h.dut` prints).
    pub check_cycle: Option<u64>,
    pub diagnosis: String,
    /// Whether the Icarus replay (the witness's MISO bits, Icarus's own
    /// power-on values) fails the harness too.  False when the violation
    /// needs power-on values of registers the reset does not set, which the
    /// engine chose freely and the replay cannot set: still a violation of
    /// "correct after one reset cycle from any power-on state".
    pub reproduced: bool,
    /// The command that replays the VCD through the checker
    /// ([`check_command`]): `slotforge check MIX VCD --scope S`.
    #[serde(default)]
    pub check: String,
}

/// `slotforge check MIX VCD --scope S`: the command that checks a
/// counterexample's VCD against the mix, at the design's scope in it.
pub fn check_command(mix: &Path, vcd: &Path) -> String {
    let quote = |p: &Path| {
        let t = p.display().to_string();
        if t.contains(|c: char| c.is_whitespace() || c == '\'' || c == '"') {
            format!("'{}'", t.replace('\'', r"'\''"))
        } else {
            t
        }
    };
    format!(
        "slotforge check {} {} --scope {}",
        quote(mix),
        quote(vcd),
        replay::DUT_SCOPE
    )
}

/// The result of `prove`, for the CLI and the build report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Proof {
    pub mix: String,
    pub solver: Solver,
    pub result: Outcome,
    /// Proved: the frames of PDR's inductive invariant (or k of k-induction);
    /// bounded: steps from reset searched; failed: the failing step.
    pub depth: u64,
    pub properties: Vec<PropertyResult>,
    /// Wall time of the whole run (harness, yosys, engine, replay).
    pub seconds: f64,
    /// Engine time alone.
    pub solver_seconds: f64,
    /// Whether the design is slotforge's own emitted Verilog.
    pub own_design: bool,
    /// A mix with pin-selected modes: `mode_sel` was a free input in every
    /// cycle (the proof covers every sequence of mode requests).
    #[serde(default)]
    pub mode_sel: bool,
    /// `prove --netlist`: the part whose gate-level netlist (with yosys'
    /// cell models, flattened) was proved, e.g. `ice40-hx8k`; null for RTL.
    #[serde(default)]
    pub netlist: Option<String>,
    /// What the result means, in words.
    pub note: String,
    /// The parts of the pin contract the harness does not assert, in plain
    /// sentences (`harness::not_covered`): a proof says nothing of them.
    /// Empty when the properties cover the whole contract.  Required in a
    /// remembered proof too (`cache`): one stored without it is not loaded.
    pub not_covered: Vec<String>,
    /// `prove --netlist`: what a proof of a netlist says nothing of beyond
    /// the contract (the cells are yosys' models of the silicon; no place
    /// and route, no timing). Empty for RTL.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub netlist_caveats: Vec<String>,
    pub counterexample: Option<Counterexample>,
    /// `counterexample.cycle`, repeated at the top level (docs/json.md).
    pub cycle: Option<i64>,
}

#[derive(Debug, Clone)]
pub struct ProveOptions {
    pub solver: Solver,
    /// Time limit of the unbounded engine, seconds.
    pub timeout_s: u64,
    /// Steps the bounded search from reset covers when the proof does not
    /// close (default: start-up plus two whole frames).
    pub depth: Option<u64>,
    /// Time limit of the bounded search, seconds.
    pub bmc_timeout_s: u64,
    /// Where a counterexample's VCD and `.gtkw` go.
    pub out_dir: PathBuf,
    /// The design is slotforge's own Verilog (reported; the harness is the same).
    pub own_design: bool,
    /// The design is this part's gate-level netlist with the cell models
    /// (reported as [`Proof::netlist`]), and what proving it leaves out
    /// (the models stand for the silicon, no timing): `netlist_caveats`.
    pub netlist: Option<(String, Vec<String>)>,
    /// The design's packet frame counter, the register's path under
    /// `slotforge_top` (`hdl::LINK_FRAME_COUNTER` for slotforge's gateware):
    /// the symbolic engine generalises it with the harness's own count at
    /// frame starts (`link_generalised`), so a UART's bytes are proved
    /// without simulating 256 frames.  `None`, or a name the design does
    /// not have: the link's bytes are searched as before.
    pub frame_counter: Option<String>,
    /// The design's mode decision under `slotforge_top` (`hdl::MODE_DECISION`
    /// for slotforge's gateware): with auto select, the link's properties are
    /// proved with it cut (`composed`, `tied`).  `None`, or a name the design
    /// does not have: they are proved with the triggers as before.
    pub mode_decision: Option<String>,
    /// With auto select, the design's trigger runs under `slotforge_top`,
    /// trigger `k`'s named this and `k` (`hdl::TRIGGER_RUN` for slotforge's
    /// gateware): the symbolic engine generalises each with the harness's
    /// own at frame starts (`runs_generalised`).  `None`, or names the
    /// design does not have: the runs are split on as before.
    pub trigger_run: Option<String>,
    /// Assert an AXI4-Stream's bytes (`link.bytes`, `link.packets`) whatever
    /// the slave's `ready_within`, not only up to [`AXIS_BYTES_MAX_WAIT`]
    /// (`prove --axis-bytes`): the proof splits on every wait a beat may
    /// take, minutes on a 48 MHz mix whose slave may wait 64 cycles.
    pub axis_bytes: bool,
}

impl ProveOptions {
    pub fn new(out_dir: impl Into<PathBuf>) -> ProveOptions {
        ProveOptions {
            solver: Solver::Symbolic,
            timeout_s: 1800,
            depth: None,
            bmc_timeout_s: 1800,
            out_dir: out_dir.into(),
            own_design: true,
            netlist: None,
            frame_counter: None,
            mode_decision: None,
            trigger_run: None,
            axis_bytes: false,
        }
    }
}

/// The harness [`prove`] proves `s` under with `opts`: [`generate`]'s, an
/// AXI4-Stream's bytes asserted whatever the slave's wait with
/// [`ProveOptions::axis_bytes`].
pub fn harness_for(s: &Schedule, opts: &ProveOptions) -> Result<Harness, HarnessError> {
    match opts.axis_bytes {
        true => harness::generate_parts(s, TableForm::for_schedule(s), harness::LinkBytes::AnyWait),
        false => harness::generate(s),
    }
}

/// Frames the bounded search covers when the recurrence argument fails
/// (a design that keeps state across frames: look for its violation deeper).
pub const DEEP_FRAMES: u64 = 8;

/// The work directory's files: the harness and the design.
fn write_inputs(dir: &Path, h: &Harness, design: &str) -> Result<(), ProveError> {
    for (name, text) in [("harness.v", h.verilog.as_str()), ("design.v", design)] {
        std::fs::write(dir.join(name), text)
            .map_err(|e| ProveError::Tool(format!("{}: {e}", dir.join(name).display())))?;
    }
    Ok(())
}

/// Proves `design` (Verilog with a `slotforge_top` on the port contract)
/// against the schedule `s`.
pub fn prove(s: &Schedule, design: &str, opts: &ProveOptions) -> Result<Proof, ProveError> {
    let t0 = Instant::now();
    let h = harness_for(s, opts)?;
    // the link's bytes are searched apart (`link_bytes`); the rest is proved
    // by a harness without them, whose state comes round
    let reads_bytes = h
        .properties
        .iter()
        .any(|p| LINK_BYTES.contains(&p.name.as_str()));
    let main = if reads_bytes {
        harness::generate_parts(s, TableForm::for_schedule(s), harness::LinkBytes::Left)?
    } else {
        h.clone()
    };
    let t1 = Instant::now();
    let f = h.frame_cycles;
    // the whole harness with the frame counters generalised: when it
    // decides (proved, or a trace from reset), it is the only run
    let general = match reads_bytes {
        true => match tied(s, &h, design, opts)? {
            Some(t) => Some(t),
            None => link_generalised(s, &h, design, opts, None)?,
        },
        false => None,
    };
    let decided = general
        .as_ref()
        .filter(|g| g.run.result != Outcome::Bounded);
    let whole = decided.is_some();
    let work = work_dir()?;
    let (result, depth, note) = match decided {
        Some(g) => (g.run.result, g.run.depth, g.run.note.clone()),
        None => main_run(s, &main, design, work.path(), opts)?,
    };
    let mut not_covered: Vec<String> = h.not_covered.iter().map(|c| c.sentence(s)).collect();
    not_covered.extend(harness::bounded_modes(s, result, depth));
    let failure = general.as_ref().and_then(|g| g.failure.clone());
    // the generalised run found a state whose bytes fail: not a proof
    let suspect = general.as_ref().is_some_and(|g| g.suspect);
    let bytes = match (general, reads_bytes, result) {
        (Some(g), _, _) if g.run.result != Outcome::Bounded => Some(g.run),
        (_, true, Outcome::Proved) => Some(
            link_bytes(&h, design, f, harness::auto_frames(s), opts)?.tried(failure.as_deref()),
        ),
        _ => None,
    };
    let main_result = result;
    let (result, depth) = match &bytes {
        Some(b) if b.result == Outcome::Failed => (Outcome::Failed, b.depth),
        Some(b) if suspect && b.result == Outcome::Bounded => (Outcome::Bounded, b.depth),
        _ => (result, depth),
    };
    if let Some(b) = bytes.as_ref().filter(|b| b.result == Outcome::Bounded) {
        not_covered.push(bounded_bytes_sentence(b.depth, f, failure.as_deref()));
    }
    let netlist_caveats = opts
        .netlist
        .as_ref()
        .map(|(_, c)| c.clone())
        .unwrap_or_default();
    let note = match &bytes {
        Some(b) if !whole => joined_note(b, (main_result, result), note, not_covered.len()),
        // the whole harness at once: its note is the proof's
        _ => scoped_note(result, note, not_covered.len()),
    };
    let solver_seconds = t1.elapsed().as_secs_f64();
    let bytes_result = bytes.as_ref().map_or(result, |b| b.result);
    let mut properties: Vec<PropertyResult> = h
        .properties
        .iter()
        .map(|p| PropertyResult {
            name: p.name.clone(),
            result: if LINK_BYTES.contains(&p.name.as_str()) {
                bytes_result
            } else {
                main_result
            },
            what: p.what.clone(),
        })
        .collect();
    let counterexample = if result == Outcome::Failed {
        let main_prep;
        let (h, prep, work) = match &bytes {
            Some(b) if b.result == Outcome::Failed => (&h, &b.prep, b.work.path()),
            _ => {
                main_prep = engine::Prepared {
                    dir: work.path().to_path_buf(),
                };
                (&main, &main_prep, work.path())
            }
        };
        let failure = Failure {
            s,
            h,
            design,
            prep,
            work,
            step: depth,
        };
        Some(counterexample(&failure, opts, &mut properties)?)
    } else {
        None
    };
    let cycle = counterexample.as_ref().map(|c| c.cycle);
    Ok(Proof {
        mix: s.mix.name.clone(),
        solver: opts.solver,
        result,
        depth,
        properties,
        seconds: t0.elapsed().as_secs_f64(),
        solver_seconds,
        own_design: opts.own_design,
        mode_sel: h.inputs.iter().any(|i| i.name == harness::MODE_SEL),
        netlist: opts.netlist.as_ref().map(|(part, _)| part.clone()),
        note,
        not_covered,
        netlist_caveats,
        counterexample,
        cycle,
    })
}

/// The harness without the link's bytes (`main`) on `design` by the
/// chosen engine.
fn main_run(
    s: &Schedule,
    main: &Harness,
    design: &str,
    work: &Path,
    opts: &ProveOptions,
) -> Result<(Outcome, u64, String), ProveError> {
    let slave = main.inputs.iter().any(|i| i.name == harness::TREADY_ANY);
    if opts.solver == Solver::Symbolic && slave && harness::auto_frames(s).is_some() {
        if let Some(proved) = composed(s, main, design, opts)? {
            return Ok(proved);
        }
    }
    write_inputs(work, main, design)?;
    let prep = engine::prepare(work, opts.solver)?;
    let f = main.frame_cycles;
    match opts.solver {
        Solver::Symbolic => symbolic(
            &prep,
            f,
            harness::auto_frames(s),
            &harness::trigger_runs(s),
            opts,
        ),
        Solver::Abc => strategy::abc(&prep, f, opts),
        Solver::Pdr | Solver::Cvc5 => strategy::closing(&prep, work, f, opts),
    }
}

/// yosys commands that make the design's mode decision (`opts.mode_decision`)
/// a cut point, a free input in every step; `None` without a name.
fn decision_cut(opts: &ProveOptions) -> Option<String> {
    let w = format!("w:dut.{}", opts.mode_decision.as_ref()?);
    // `opt_clean` first: the readers of the wire then read it, not an alias
    // of its driver's output (`cutpoint` alone left them reading the driver)
    Some(format!(
        "opt_clean; select -assert-count 1 {w}; cutpoint {w};"
    ))
}

/// yosys commands that tie the design's mode decision to the harness's
/// `dec` (which [`Harness::deciding_by_input`] reads from `mode_sel`).
fn decision_tie(opts: &ProveOptions) -> Option<String> {
    let w = format!("dut.{}", opts.mode_decision.as_ref()?);
    Some(format!(
        "opt_clean; select -assert-count 1 w:{w}; cutpoint w:{w}; connect -unset {w}; \
         connect -set {w} dec;"
    ))
}

/// The properties of the link: its FIFO, a UART's line or an AXI4-Stream's
/// beats, the packets.
fn reads_link(p: &PropertyDef) -> bool {
    (p.covers.iter()).any(|c| {
        matches!(
            c,
            Clause::LinkOverflow
                | Clause::UartCharacters
                | Clause::AxisBeats
                | Clause::AxisValidHeld
                | Clause::AxisPayloadHeld
                | Clause::LinkPackets
        )
    })
}

/// Auto select with the link's bytes asserted, in two runs.  The whole
/// harness splits at frame starts on the trigger decisions, and with the
/// link's FIFO and packets the states at frame starts are many (the preset
/// eskin34-adaptive: 495, minutes).  The properties that do not read the
/// link, on the design as it is (split on the decisions; they close as a
/// mix without a link does, `mode` among them: the design's decisions are
/// the triggers'); the link's, with the design's decision and the harness's
/// tied to one free input (`mode_sel`, split on as pin select's): every
/// sequence of modes, the design and the harness in the same mode, which on
/// every real trace they are (`mode`, proved by the first run), so a proof
/// there holds of the design.  An AXI4-Stream's slave is split on in the
/// second run as in any (`Splits`): matrix-102 of the wide feature matrix
/// proves so in about a minute, where the runs before stayed bounded.
/// `Some` when both are proved; `None` otherwise, and the whole harness
/// decides as before.
fn tied(
    s: &Schedule,
    h: &Harness,
    design: &str,
    opts: &ProveOptions,
) -> Result<Option<GeneralRun>, ProveError> {
    // slotforge's own RTL only: the tie stands for the decision at the
    // cycles where the gateware takes it (`nxt <= decided`, `hdl`'s modes
    // block), which is all it reads; another design (or a netlist) might
    // read a wire of that name elsewhere
    if !opts.own_design || opts.netlist.is_some() {
        return Ok(None);
    }
    // the second run is `link_generalised`'s: without it, no first run
    let general = opts.solver == Solver::Symbolic && opts.depth.is_none();
    if !general || opts.frame_counter.is_none() {
        return Ok(None);
    }
    let (Some(_), Some(tie)) = (harness::auto_frames(s), decision_tie(opts)) else {
        return Ok(None);
    };
    let Some(link) = h.asserting(reads_link).deciding_by_input(s) else {
        return Ok(None);
    };
    let rest = h.asserting(|p| !reads_link(p));
    let (first, second) = side_by_side(
        || exactly(s, &rest, design, opts),
        || link_generalised(s, &link, design, opts, Some(&tie)),
    );
    let Some((d1, n1)) = first? else {
        return Ok(None);
    };
    let Some(g) = second? else {
        return Ok(None);
    };
    if g.run.result != Outcome::Proved {
        return Ok(None);
    }
    let note = format!(
        "{PROVED}, in two runs: every property but the link's on the design as it is: {}; \
         {} with the design's mode decision and the harness's tied to one free input (every \
         sequence of modes, those the triggers choose among them): {}",
        how_proved(&n1),
        property_names(&link),
        how_proved(&g.run.note)
    );
    Ok(Some(GeneralRun {
        run: BytesRun {
            note,
            depth: d1.max(g.run.depth),
            ..g.run
        },
        ..g
    }))
}

/// The first of the two runs (`tied`, `composed`): the properties `rest`
/// asserts on the design as it is, by the symbolic engine split on auto
/// select's decisions; its depth and note when proved, else `None` (a tool
/// that fails here fails the runs as before too, with its message).
fn exactly(
    s: &Schedule,
    rest: &Harness,
    design: &str,
    opts: &ProveOptions,
) -> Result<Option<(u64, String)>, ProveError> {
    let work = work_dir()?;
    write_inputs(work.path(), rest, design)?;
    let Ok(prep) = engine::prepare(work.path(), Solver::Symbolic) else {
        return Ok(None);
    };
    let (auto, runs) = (harness::auto_frames(s), harness::trigger_runs(s));
    let (r, depth, note) = symbolic(&prep, rest.frame_cycles, auto, &runs, opts)?;
    Ok((r == Outcome::Proved).then_some((depth, note)))
}

/// The two runs of a proof in two runs, one thread each: they share
/// nothing but their inputs, and each decides in the same number of steps
/// as it would alone (the proof's verdict and note do not depend on which
/// ends first). The second run's work is lost when the first does not
/// prove, where it was not run before.
fn side_by_side<A: Send, B: Send>(
    first: impl FnOnce() -> A + Send,
    second: impl FnOnce() -> B + Send,
) -> (A, B) {
    std::thread::scope(|sc| {
        let b = sc.spawn(second);
        let a = first();
        let b = b.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        (a, b)
    })
}

/// A proof's note after "proved for all time: " (how it was proved).
fn how_proved(note: &str) -> &str {
    note.strip_prefix(PROVED)
        .unwrap_or(note)
        .trim_start_matches(": ")
}

/// The names of the properties `h` asserts, in its order.
fn property_names(h: &Harness) -> String {
    let names: Vec<&str> = h.properties.iter().map(|p| p.name.as_str()).collect();
    names.join(", ")
}

/// The properties that read an AXI4-Stream slave's choices: the FIFO's
/// and the held beats'.
fn reads_slave(p: &PropertyDef) -> bool {
    (p.covers.iter()).any(|c| {
        matches!(
            c,
            Clause::LinkOverflow | Clause::AxisValidHeld | Clause::AxisPayloadHeld
        )
    })
}

/// Auto select with an AXI4-Stream slave, in two runs.  Together the
/// slave's choices and the trigger decisions (functions of the codes) make
/// a FIFO fill per path of codes, which never come round; apart, each
/// closes.  The properties that read the slave, on the design with its mode
/// decision cut ([`decision_cut`]): every sequence of modes at frame
/// starts, those the triggers choose among them, so a proof there holds of
/// the design (their cone then holds no data, and the explicit search of
/// the slave's choices decides).  Every other property on the design as it
/// is (its cone does not read the slave).  `Some` when both are proved;
/// `None` otherwise, and the whole harness's run decides (a violation of
/// the cut design may be of its extra behaviours only).
fn composed(
    s: &Schedule,
    main: &Harness,
    design: &str,
    opts: &ProveOptions,
) -> Result<Option<(Outcome, u64, String)>, ProveError> {
    let (link, rest) = (
        main.asserting(reads_slave),
        main.asserting(|p| !reads_slave(p)),
    );
    let Some(cut) = decision_cut(opts) else {
        return Ok(None);
    };
    let f = main.frame_cycles;
    let cut_run = || -> Result<Option<(Outcome, u64, String)>, ProveError> {
        let work = work_dir()?;
        write_inputs(work.path(), &link, design)?;
        // a design without that wire has nothing to cut: the whole run decides
        let Ok(prep) = engine::prepare_edited(work.path(), Solver::Symbolic, &cut) else {
            return Ok(None);
        };
        symbolic(&prep, f, None, &[], opts).map(Some)
    };
    let (first, second) = side_by_side(cut_run, || exactly(s, &rest, design, opts));
    let Some((r1, d1, n1)) = first? else {
        return Ok(None);
    };
    if r1 != Outcome::Proved {
        return Ok(None);
    }
    let Some((d2, n2)) = second? else {
        return Ok(None);
    };
    Ok(Some((
        Outcome::Proved,
        d1.max(d2),
        format!(
            "{PROVED}, in two runs: {} with the design's mode decision a free input (any mode \
             at every frame start, so every sequence the triggers can choose): {}; every other \
             property on the design as it is: {}",
            property_names(&link),
            how_proved(&n1),
            how_proved(&n2)
        ),
    )))
}

/// The note of a proof whose link's bytes (`b`) ran apart from the rest
/// (`note`, whose result was `main`; the proof's is `result`).
fn joined_note(
    b: &BytesRun,
    (main, result): (Outcome, Outcome),
    note: String,
    uncovered: usize,
) -> String {
    match (b.result, result) {
        (Outcome::Failed, _) => b.note.clone(),
        (_, Outcome::Bounded) if main == Outcome::Proved => format!(
            "NOT a proof of the link's bytes: {}; every other property: {}",
            b.note,
            scoped_note(main, note, uncovered)
        ),
        _ => format!("{}; {}", scoped_note(result, note, uncovered), b.note),
    }
}

/// The properties that read the link's bytes, searched apart ([`link_bytes`]).
const LINK_BYTES: [&str; 2] = ["link.bytes", "link.packets"];

/// Frames from reset the link's bytes are searched when a proof would cost
/// too much (every slice's packet of each, so the frame counter's step from
/// one frame to the next is in it).
pub const LINK_FRAMES: u64 = 2;

/// Steps of symbolic simulation the link's bytes may take to come round:
/// the frame counter's 256 frames and the two the harness starts with.  A
/// mix whose frame makes that longer is searched [`LINK_FRAMES`] only.
pub const LINK_PROOF_STEPS: u64 = 2_000_000;

/// The search of the link's bytes: its result and where it ran.
struct BytesRun {
    result: Outcome,
    depth: u64,
    note: String,
    prep: engine::Prepared,
    work: tempfile::TempDir,
}

/// `link.bytes` and `link.packets` (with every other property: the
/// harness `h` asserts them all) by the symbolic engine from reset: the
/// packets' frame counter (the design's and the harness's) makes the state
/// come round only after 256 frames, so a short frame is simulated until it
/// does (a proof, [`LINK_PROOF_STEPS`]) and a longer one is searched for
/// [`LINK_FRAMES`] frames (bounded).
fn link_bytes(
    h: &Harness,
    design: &str,
    f: u64,
    auto: Option<u64>,
    opts: &ProveOptions,
) -> Result<BytesRun, ProveError> {
    let work = work_dir()?;
    write_inputs(work.path(), h, design)?;
    let prep = engine::prepare(work.path(), Solver::Symbolic)?;
    let text = std::fs::read_to_string(prep.dir.join("design.aag"))
        .map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    let g = aiger::parse(&text).map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    let whole = 258 * f + 2;
    let limit = if whole <= LINK_PROOF_STEPS {
        whole
    } else {
        LINK_FRAMES * f + 2
    };
    let deadline = Instant::now() + std::time::Duration::from_secs(opts.timeout_s);
    // split as the main run is (mode requests, trigger decisions), and on
    // an AXI4-Stream slave's choices: exact
    let mut splits = named_inputs(&prep, harness::MODE_SEL);
    splits.extend(named_inputs(&prep, harness::TREADY_ANY));
    let (found, _) = symsim::prove(
        &g,
        &[],
        &[],
        &splits,
        auto.is_some(),
        f,
        2,
        limit,
        Some(deadline),
    );
    let (result, depth, note) = match found {
        symsim::Found::Violated { step, inputs } => {
            std::fs::write(prep.dir.join("cex.aiw"), symsim::witness_text(&g, &inputs))
                .map_err(|e| ProveError::Tool(format!("cex.aiw: {e}")))?;
            (
                Outcome::Failed,
                step,
                format!(
                    "a trace from reset violates the link's bytes at step {step} (cycle {})",
                    step as i64 - 2
                ),
            )
        }
        symsim::Found::Proved { steps, since } => (
            Outcome::Proved,
            steps,
            format!(
                "the link's bytes ({}) are {PROVED} too: simulated the same way with the \
                 harness's receiver and packet parser to step {steps}, whose state is the \
                 state at step {since} (the frame counters come round after 256 frames)",
                LINK_BYTES.join(", ")
            ),
        ),
        symsim::Found::Bounded { steps } => (
            Outcome::Bounded,
            steps,
            format!(
                "the link's bytes ({}) are BOUNDED only: no violation from reset within {steps} \
                 steps ({:.2} frames), every step simulated exactly with MISO free",
                LINK_BYTES.join(", "),
                steps.saturating_sub(2) as f64 / f as f64
            ),
        ),
    };
    Ok(BytesRun {
        result,
        depth,
        note,
        prep,
        work,
    })
}

impl BytesRun {
    /// A bounded search's note says why the generalised run (tried first)
    /// did not prove it, when it was tried.
    fn tried(mut self, failure: Option<&str>) -> BytesRun {
        if let (Outcome::Bounded, Some(why)) = (self.result, failure) {
            self.note = format!("{}; {why}", self.note);
        }
        self
    }
}

/// What a bounded search of the link's bytes leaves out (`failure`: why
/// generalising the frame counters did not prove them, when tried).
fn bounded_bytes_sentence(depth: u64, f: u64, failure: Option<&str>) -> String {
    format!(
        "the link's bytes (link.bytes, link.packets) after cycle {}: they were searched from \
         reset for {} frames only (bounded), not proved for all time; {}",
        depth.saturating_sub(2),
        frames_text(depth.saturating_sub(2), f),
        failure.unwrap_or(
            "the packets' 8-bit frame counter brings the state round only after 256 frames"
        )
    )
}

/// `cycles` in frames of `f` cycles: whole, or to two decimals (a search
/// stopped at its time limit within a frame is not said to cover it).
fn frames_text(cycles: u64, f: u64) -> String {
    match cycles % f {
        0 => format!("{}", cycles / f),
        _ => format!("{:.2}", cycles as f64 / f as f64),
    }
}

/// The run of the whole harness with the packets' frame counters
/// generalised, and why it did not prove, if it did not.
struct GeneralRun {
    run: BytesRun,
    failure: Option<String>,
    /// It failed on a state it reached (a count whose bytes fail, counters
    /// that differ), not for want of time: `prove` is then not a proof.
    suspect: bool,
}

/// Frames from reset the generalised run may simulate before it gives up
/// (bounded; the search of before then runs): as many as the plain run
/// may take to come round, and one more.
const GENERAL_FRAMES: u64 = DEEP_FRAMES + 1;

/// The whole harness `h` (every property, the link's bytes too) by the
/// symbolic engine from reset, with the design's frame counter
/// (`opts.frame_counter`) and the harness's generalised at every frame
/// start from the first on, step 2 (`symsim::prove_generalised`): the state then
/// comes round after a few frames instead of 256.  Split as the main run
/// is: on an AXI4-Stream slave's choices and pin-selected modes' requests
/// where a step reads them, on auto select's decisions at frame starts.
/// `None` when it does not apply: another engine, a depth given, no
/// counter of that name in the design.  A violation in the frame after a
/// path's first generalisation that holds with the count pinned to its
/// real value is a trace from reset (`Failed`); any other, or a state that
/// does not come round, is `Bounded` and the caller searches as before.
fn link_generalised(
    s: &Schedule,
    h: &Harness,
    design: &str,
    opts: &ProveOptions,
    tie: Option<&str>,
) -> Result<Option<GeneralRun>, ProveError> {
    let name = match (&opts.frame_counter, opts.solver) {
        (Some(n), Solver::Symbolic) if opts.depth.is_none() => n,
        _ => return Ok(None),
    };
    let work = work_dir()?;
    write_inputs(work.path(), h, design)?;
    let prep = match tie {
        None => engine::prepare(work.path(), Solver::Symbolic)?,
        // a design without the tied wire: not this run
        Some(edit) => match engine::prepare_edited(work.path(), Solver::Symbolic, edit) {
            Ok(p) => p,
            Err(_) => return Ok(None),
        },
    };
    let Some(pairs) = counter_pairs(&prep, &format!("dut.{name}"), harness::FRAME_COUNTER) else {
        return Ok(None);
    };
    let text = std::fs::read_to_string(prep.dir.join("design.aag"))
        .map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    let g = aiger::parse(&text).map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    if !g.constraints.is_empty() {
        return Ok(None);
    }
    let f = h.frame_cycles;
    let counters = symsim::Counters {
        pairs,
        from: 2,
        // an AXI4-Stream slave's: a path waiting less subsumes (`split.rs`)
        wait: named_latches(&prep, harness::SLAVE_WAIT).unwrap_or_default(),
        pinned: true,
    };
    let deadline = Instant::now() + std::time::Duration::from_secs(opts.timeout_s);
    // auto select: as deep as the main run may need for its windows (tied,
    // the decisions are a free input, split as pin select's)
    let auto = harness::auto_frames(s).filter(|_| tie.is_none());
    // `+ 1`: the frame start at the last step is compared too (a run that
    // comes round there, as an unseen glove mix's did, closes)
    let limit = (GENERAL_FRAMES + auto.unwrap_or(0)) * f + 2 + 1;
    // an AXI4-Stream slave's choices and mode requests: one path per value
    // where a step reads them, paths in the same state at a step merged
    // (`symsim::split`); auto select's decisions at frame starts (`cases`)
    let splits = Splits::of(&prep, auto.is_some(), tie.is_some());
    let (found, st) = symsim::prove_generalised(
        &g,
        counters,
        &splits.bits(),
        splits.auto,
        f,
        2,
        limit,
        Some(deadline),
    );
    let what = format!(
        "the frame counters ({name} and the harness's {})",
        harness::FRAME_COUNTER
    );
    let (result, depth, note, failure) = match found {
        symsim::Found::Violated { step, inputs } => {
            std::fs::write(prep.dir.join("cex.aiw"), symsim::witness_text(&g, &inputs))
                .map_err(|e| ProveError::Tool(format!("cex.aiw: {e}")))?;
            let note = format!(
                "a trace from reset violates the contract at step {step} (cycle {})",
                step as i64 - 2
            );
            (Outcome::Failed, step, note, None)
        }
        symsim::Found::Proved { steps, since } => {
            let note = general_note(&g, &st, (&what, &splits.words()), steps, since, f);
            (Outcome::Proved, steps, note, None)
        }
        symsim::Found::Bounded { steps } => {
            let why = match (st.counter_failure, st.path_limit) {
                (None, Some(at)) => format!(
                    "with {what} generalised, the run stopped at step {at} with more than {} \
                     paths of the split (states at frame starts and paths waiting) at once",
                    symsim::MAX_PATHS
                ),
                (failure, _) => counter_failure(failure, &what, limit, opts.timeout_s),
            };
            (Outcome::Bounded, steps, why.clone(), Some(why))
        }
    };
    Ok(Some(GeneralRun {
        run: BytesRun {
            result,
            depth,
            note,
            prep,
            work,
        },
        failure,
        suspect: st.counter_failure.is_some(),
    }))
}

/// The note of a proof with generalised frame counters.
fn general_note(
    g: &Aig,
    st: &SymStats,
    (what, how): (&str, &str),
    steps: u64,
    since: u64,
    f: u64,
) -> String {
    let from = st.generalised.unwrap_or(since);
    if st.branches > 0 {
        return split_general_note(g, st, (what, how), steps, f);
    }
    format!(
        "{PROVED}: every step from reset to step {from} simulated exactly with every free \
         input bit a variable of its step (MISO; {} latches, {} gates; {} satisfiability \
         checks); from there, at each frame start, {what}, shown equal in every state, are \
         replaced by one free 8-bit value, so the states simulated from it include every \
         state reachable there; the state at step {steps}, so generalised, is the one at step \
         {since} with every input {} frame(s) later, so those steps reach every reachable \
         state, the link's bytes ({}) included (symbolic simulation with the frame counter \
         generalised: an inductive invariant, checked)",
        g.latches.len(),
        g.ands.len(),
        st.sat_calls,
        (steps - since) / f,
        LINK_BYTES.join(", "),
    )
}

/// The same for a split run (`symsim::split`, `cases`): each path's state
/// at a frame start is one some path had at an earlier or the same frame start.
fn split_general_note(
    g: &Aig,
    st: &SymStats,
    (what, how): (&str, &str),
    steps: u64,
    f: u64,
) -> String {
    format!(
        "{PROVED}: every step from reset simulated exactly with MISO a variable of its step \
         and split {how} (paths in the same state at a step merged: {} merged{}; {} latches, \
         {} gates; {} satisfiability checks); at each frame start, {what}, shown equal in \
         every state, are replaced by one free 8-bit value, so the states simulated from it \
         include every state reachable there; by step {steps} ({:.0} frames) every path's \
         state at a frame start, so generalised, was one some path had at an earlier frame \
         start ({} distinct, up to renaming{}), so those steps reach every reachable state{}, \
         the link's bytes ({}) included (symbolic simulation with the frame counter \
         generalised: an inductive invariant, checked)",
        st.merged,
        match st.subsumed {
            0 => String::new(),
            n => format!(
                ", and {n} more in the same state as one whose slave had waited fewer cycles \
                 (its futures include theirs)"
            ),
        },
        g.latches.len(),
        g.ands.len(),
        st.sat_calls,
        steps.saturating_sub(2) as f64 / f as f64,
        st.branches,
        mid_closed(st),
        match how.contains("tready_any") {
            true => " under every slave the guarantee allows",
            false => "",
        },
        LINK_BYTES.join(", "),
    )
}

/// The inputs a run is split on (`symsim::split`), by what they are, and
/// whether it splits on auto select's decisions (`cases`).
struct Splits {
    mode_sel: Vec<usize>,
    tready: Vec<usize>,
    auto: bool,
    /// `mode_sel` is auto select's decision tied to a free input (`tied`),
    /// not pin select's requests.
    tied: bool,
}

impl Splits {
    fn of(prep: &engine::Prepared, auto: bool, tied: bool) -> Splits {
        Splits {
            mode_sel: named_inputs(prep, harness::MODE_SEL),
            tready: named_inputs(prep, harness::TREADY_ANY),
            auto,
            tied,
        }
    }

    /// The AIG inputs split on where a step reads them.
    fn bits(&self) -> Vec<usize> {
        self.mode_sel.iter().chain(&self.tready).copied().collect()
    }

    /// What the run splits on, in words ("on ... and on ...").
    fn words(&self) -> String {
        let mut on = Vec::new();
        if !self.mode_sel.is_empty() && self.tied {
            on.push(
                "on the tied mode decision (mode_sel, the free input both decisions are tied to: \
                 one path per value in each step that reads it)",
            );
        } else if !self.mode_sel.is_empty() {
            on.push(
                "on the mode requests (mode_sel: one path per value in each step that reads it)",
            );
        }
        if !self.tready.is_empty() {
            on.push(
                "on the slave's choices (tready_any: one path per value in each step that reads it)",
            );
        }
        if self.auto {
            on.push(
                "on auto select's decisions (at each frame start, one path per value of the mode \
                 and trigger-run registers some input reaches, with its condition on the codes)",
            );
        }
        on.join(" and ")
    }
}

/// Why the generalised run did not prove, in words.
fn counter_failure(
    failure: Option<symsim::CounterFailure>,
    what: &str,
    limit: u64,
    timeout_s: u64,
) -> String {
    match failure {
        Some(symsim::CounterFailure::Violated { step, count }) => format!(
            "with {what} generalised (one free value at frame starts), an assertion fails at \
             step {step} from a frame start whose count is {count}: the link's bytes are not \
             proved for every count (a state no search from reset reached, so no \
             counterexample is claimed)"
        ),
        Some(symsim::CounterFailure::Unequal { step, count }) => format!(
            "{what} are not equal in every state at the frame start of step {step}{}, so the \
             link's bytes are not proved for every count",
            count.map_or(String::new(), |c| format!(
                " (after a frame that started at count {c}, a state no search from reset reached)"
            ))
        ),
        None => format!(
            "with {what} generalised, the state did not come round within {limit} steps or \
             {timeout_s} s"
        ),
    }
}

/// The AIG latches of the design's counter `design` and the harness's
/// `harness` (yosys's map), bit by bit; `None` unless both are there with
/// the same width.
fn counter_pairs(
    prep: &engine::Prepared,
    design: &str,
    harness: &str,
) -> Option<Vec<(usize, usize)>> {
    let (d, h) = (named_latches(prep, design)?, named_latches(prep, harness)?);
    (d.len() == h.len()).then(|| d.into_iter().zip(h).collect())
}

/// How every engine's note for a proof begins.
pub(crate) const PROVED: &str = "proved for all time";

/// A proof's note, claiming "for all time" of the whole contract only when
/// the harness asserts all of it (`uncovered` parts it does not).
fn scoped_note(result: Outcome, note: String, uncovered: usize) -> String {
    match (result, note.strip_prefix(PROVED)) {
        (Outcome::Proved, Some(how)) if uncovered > 0 => format!(
            "the asserted properties are {PROVED}{how}; not the whole contract: {uncovered} \
             part{} of it {} not asserted (listed as not covered)",
            if uncovered == 1 { "" } else { "s" },
            if uncovered == 1 { "is" } else { "are" },
        ),
        _ => note,
    }
}

/// The engines' temporary directory; kept, and named on stderr, when
/// `SLOTFORGE_FORMAL_KEEP` is set.
fn work_dir() -> Result<tempfile::TempDir, ProveError> {
    let mut work =
        tempfile::tempdir().map_err(|e| ProveError::Tool(format!("temporary directory: {e}")))?;
    if std::env::var_os("SLOTFORGE_FORMAL_KEEP").is_some() {
        // for inspection: the engines' files stay
        eprintln!("formal work directory: {}", work.path().display());
        work.disable_cleanup(true);
    }
    Ok(work)
}

/// A failed proof's inputs, for replaying its witness.
struct Failure<'a> {
    s: &'a Schedule,
    h: &'a Harness,
    design: &'a str,
    prep: &'a engine::Prepared,
    work: &'a Path,
    /// The failing step the engine reported.
    step: u64,
}

/// Replays the engine's witness on the design, marks the properties it
/// violates, and checks the trace with the cycle-exact checker.
fn counterexample(
    x: &Failure,
    opts: &ProveOptions,
    properties: &mut [PropertyResult],
) -> Result<Counterexample, ProveError> {
    if opts.solver == Solver::Cvc5 {
        // the witness comes from ABC: search again on the AIG
        let aig = engine::prepare(x.work, Solver::Abc)?;
        engine::bmc(&aig, x.step + 1, opts.bmc_timeout_s)?;
    }
    let miso = engine::witness_miso(x.prep, x.s.branches.len())?;
    let r = replay::replay(x.s, x.h, x.design, &miso, x.work, &opts.out_dir)?;
    for p in properties.iter_mut() {
        p.result = if r.failed.contains(&p.name) {
            Outcome::Failed
        } else {
            Outcome::Bounded
        };
    }
    let (report, _) = judge::check_vcd_with(
        x.s,
        &r.vcd,
        Some(replay::DUT_SCOPE),
        judge::CheckOptions::default(),
    )
    .map_err(|e| ProveError::Tool(format!("checking the counterexample: {e}")))?;
    let check_cycle = first_rejected(&report);
    let reproduced = r.step.is_some();
    let step = r.step.unwrap_or(x.step);
    if !reproduced {
        for p in properties.iter_mut() {
            p.result = Outcome::Failed;
        }
    }
    // the mix by its name until the caller, who read its file, names it
    let mix = PathBuf::from(format!("{}.toml", x.s.mix.name));
    Ok(Counterexample {
        check: check_command(&mix, &r.vcd),
        reproduced,
        cycle: step as i64 - 2,
        vcd: r.vcd,
        gtkw: r.gtkw,
        check_cycle,
        diagnosis: report.summary(),
    })
}

/// The `symbolic` engine on the prepared AIG: exact from reset, proved at the
/// first frame whose state recurs (`symsim.rs`), else searched to the depth.
/// `runs`: with auto select, the harness's trigger runs
/// (`harness::trigger_runs`), generalised first (`runs_generalised`).
fn symbolic(
    prep: &engine::Prepared,
    f: u64,
    auto: Option<u64>,
    runs: &[String],
    opts: &ProveOptions,
) -> Result<(Outcome, u64, String), ProveError> {
    let text = std::fs::read_to_string(prep.dir.join("design.aag"))
        .map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    let g = aiger::parse(&text).map_err(|e| ProveError::Tool(format!("design.aag: {e}")))?;
    if !g.constraints.is_empty() {
        // every input is free in every step: an assumption would be ignored
        return Err(ProveError::Tool(
            "the harness assumes something about its inputs, which the symbolic engine cannot honour; use --solver abc".into(),
        ));
    }
    // auto select: split on the trigger decisions, and deep enough for
    // every run of windows to come round
    let cases = auto.is_some();
    let limit = (opts.depth).unwrap_or((DEEP_FRAMES + auto.unwrap_or(0)) * f + 2);
    let deadline = Instant::now() + std::time::Duration::from_secs(opts.timeout_s);
    let choices = named_inputs(prep, harness::TREADY_ANY);
    // the slave's wait count: states equal but for it subsumed in the search
    let wait = named_latches(prep, harness::SLAVE_WAIT).unwrap_or_default();
    let splits = named_inputs(prep, harness::MODE_SEL);
    if cases && choices.is_empty() && opts.depth.is_none() {
        if let Some(decided) = runs_generalised(prep, &g, (f, &splits), runs, opts, deadline)? {
            return Ok(decided);
        }
    }
    let (found, st) = symsim::prove(
        &g,
        &choices,
        &wait,
        &splits,
        cases,
        f,
        2,
        limit,
        Some(deadline),
    );
    Ok(match found {
        symsim::Found::Proved { steps, .. } if st.cases > 0 => (
            Outcome::Proved,
            steps,
            format!(
                "{PROVED}: {}every step from reset simulated exactly with every free input bit a variable of its step (MISO; {} latches, {} gates; {} satisfiability checks), split at each frame start on the values of the registers that are functions of the MISO codes there (the mode and trigger-run registers, the design's and the harness's: one path per value some input reaches, {} in all, each with its condition on the codes kept until those codes have left the state), until every path reached a frame start whose state and condition, up to renaming, a path had reached before ({} distinct states at frame starts, the deepest at step {steps}{}), so those paths reach every reachable state (symbolic simulation split on the trigger decisions)",
                parts_note(&st.parts),
                g.latches.len(),
                g.ands.len(),
                st.sat_calls,
                st.cases,
                st.branches,
                mid_closed(&st)
            ),
        ),
        symsim::Found::Proved { steps, .. } if st.branches > 0 => (
            Outcome::Proved,
            steps,
            format!(
                "{PROVED}: {}every step from reset simulated exactly with every free input bit a variable of its step (MISO), split on mode_sel where a step reads it (one path per value, every value taken; {} latches, {} gates; {} assertion checks went to a SAT solver), until every path reached a frame start whose state, up to renaming, a path had reached before ({} distinct states at frame starts, the deepest at step {steps}{}), so those paths reach every reachable state (symbolic simulation split on requests)",
                parts_note(&st.parts),
                g.latches.len(),
                g.ands.len(),
                st.sat_calls,
                st.branches,
                mid_closed(&st)
            ),
        ),
        symsim::Found::Proved { steps, since } => (
            Outcome::Proved,
            steps,
            format!(
                "{PROVED}: {}every step from reset to step {steps} simulated exactly with every free input bit a variable of its step ({}; {} latches, {} gates; {} assertion checks went to a SAT solver), and the state at step {steps} is the state at step {since} with every input {} frame(s) later (state recurrence; {} nodes), so those steps reach every reachable state (symbolic simulation)",
                parts_note(&st.parts),
                // the requests only where the harness has them (pin select)
                match named_inputs(prep, harness::MODE_SEL).is_empty() {
                    true => "MISO",
                    false => "MISO, and mode_sel for pin-selected modes",
                },
                g.latches.len(),
                g.ands.len(),
                st.sat_calls,
                (steps - since) / f,
                st.state_nodes
            ),
        ),
        symsim::Found::Violated { step, inputs } => {
            std::fs::write(prep.dir.join("cex.aiw"), symsim::witness_text(&g, &inputs))
                .map_err(|e| ProveError::Tool(format!("cex.aiw: {e}")))?;
            (
                Outcome::Failed,
                step,
                format!(
                    "a trace from reset violates the contract at step {step} (cycle {})",
                    step as i64 - 2
                ),
            )
        }
        symsim::Found::Bounded { steps } => (
            Outcome::Bounded,
            steps,
            format!(
                "NOT a proof: {}; no violation from reset within {steps} steps ({} cycles after reset, {:.2} frames)",
                if steps >= limit {
                    format!("the design's state does not come round after whole frames (it keeps state older than a frame: {}), so no bound covers all time", latch_names(prep, &st.kept))
                } else {
                    format!("the simulation stopped at its time limit ({} s)", opts.timeout_s)
                },
                steps.saturating_sub(2),
                steps.saturating_sub(2) as f64 / f as f64
            ),
        ),
    })
}

/// Auto select with the triggers' runs generalised: at each frame start
/// the design's run of trigger `k` (`opts.trigger_run`) and the harness's
/// (`runs[k]`), once shown equal, become one free value
/// (`symsim::prove_generalised`), and the run is split on the rest of the
/// decision's registers as the exact one is.  A run's count then no longer
/// tells frame-start states apart, so the paths come round in a few frames
/// instead of one per count (eskin34-adaptive: 10 frames held).  Decides
/// when proved, or on a violation (a trace from reset: pinned to the
/// counts the generalisations replaced); `None` otherwise (a run the
/// design counts otherwise, no such register, a state that does not come
/// round): the exact run decides, in the time left.
fn runs_generalised(
    prep: &engine::Prepared,
    g: &Aig,
    (f, splits): (u64, &[usize]),
    runs: &[String],
    opts: &ProveOptions,
    deadline: Instant,
) -> Result<Option<(Outcome, u64, String)>, ProveError> {
    let Some(prefix) = &opts.trigger_run else {
        return Ok(None);
    };
    let mut pairs = Vec::new();
    let mut names = Vec::new();
    for (k, h) in runs.iter().enumerate() {
        // a trigger of one frame may keep no run (yosys drops it)
        if let Some(p) = counter_pairs(prep, &format!("dut.{prefix}{k}"), h) {
            pairs.extend(p);
            names.push(format!("{prefix}{k}"));
        }
    }
    if pairs.is_empty() {
        return Ok(None);
    }
    let counters = symsim::Counters {
        pairs,
        // from the second frame start: at the first (step 2) the gateware's
        // run keeps its count where the harness's may count (a free count
        // there is shown unequal a frame later)
        from: 2 + f,
        wait: Vec::new(),
        // a run's count is a function of the codes: pinned, every frame's
        // condition would stay (`Counters::pinned`); a violation after a
        // generalisation is then the exact run's to find
        pinned: false,
    };
    // `+ 1`: the frame start at the last step is compared too
    let limit = GENERAL_FRAMES * f + 2 + 1;
    let (found, st) =
        symsim::prove_generalised(g, counters, splits, true, f, 2, limit, Some(deadline));
    Ok(match found {
        symsim::Found::Proved { steps, .. } => Some((
            Outcome::Proved,
            steps,
            runs_note(g, &st, &names.join(", "), steps, f),
        )),
        symsim::Found::Violated { step, inputs } => {
            std::fs::write(prep.dir.join("cex.aiw"), symsim::witness_text(g, &inputs))
                .map_err(|e| ProveError::Tool(format!("cex.aiw: {e}")))?;
            Some((
                Outcome::Failed,
                step,
                format!(
                    "a trace from reset violates the contract at step {step} (cycle {})",
                    step as i64 - 2
                ),
            ))
        }
        symsim::Found::Bounded { .. } => None,
    })
}

/// The note of auto select proved with its runs generalised.
fn runs_note(g: &Aig, st: &SymStats, names: &str, steps: u64, f: u64) -> String {
    format!(
        "{PROVED}: every step from reset simulated exactly with every free input bit a variable \
         of its step (MISO; {} latches, {} gates; {} satisfiability checks), split at each frame \
         start on the values of the registers that are functions of the MISO codes there (the \
         mode registers, the design's and the harness's: one path per value some input \
         reaches, {} in all, each with its condition on the codes kept until those codes have \
         left the state); at each frame start the triggers' runs of windows ({names} and the \
         harness's), shown equal in every state, are replaced by one free value each, so the \
         states simulated from there include every state reachable there; by step {steps} \
         ({:.0} frames) every path's state and condition at a frame start, so generalised, was \
         one some path had reached before ({} distinct, up to renaming{}), so those paths reach \
         every reachable state (symbolic simulation split on the trigger decisions, the runs \
         generalised: an inductive invariant, checked)",
        g.latches.len(),
        g.ands.len(),
        st.sat_calls,
        st.cases,
        steps.saturating_sub(2) as f64 / f as f64,
        st.branches,
        mid_closed(st),
    )
}

/// A split run's paths closed where a split started them, in words (empty
/// if none): their futures are those of a path that started in their state
/// at the same phase of an earlier frame (`symsim::split`).
fn mid_closed(st: &SymStats) -> String {
    match st.mid_closed {
        0 => String::new(),
        n => format!(
            "; {n} more path(s) ended where a split started them, in the state and condition a \
             path had started in at the same point of an earlier frame"
        ),
    }
}

/// The AIG inputs (bits) of the harness input `name` (yosys's map): an
/// AXI4-Stream slave's `tready_any` (an environment's choice, not data),
/// pin-selected modes' `mode_sel` (a request the run is split on).
fn named_inputs(prep: &engine::Prepared, name: &str) -> Vec<usize> {
    let aim = std::fs::read_to_string(prep.dir.join("design.aim")).unwrap_or_default();
    aim.lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let named = f.len() == 4 && f[0] == "input" && f[3] == name;
            named.then(|| f[1].parse().ok()).flatten()
        })
        .collect()
}

/// The AIG latches of register `name` (yosys's map), least significant
/// bit first; `None` unless it has bits `0..n`, `n > 0`.
fn named_latches(prep: &engine::Prepared, name: &str) -> Option<Vec<usize>> {
    let aim = std::fs::read_to_string(prep.dir.join("design.aim")).ok()?;
    let mut by_bit: std::collections::BTreeMap<usize, usize> = Default::default();
    for l in aim.lines() {
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() == 4 && f[0] == "latch" && f[3] == name {
            by_bit.insert(f[2].parse().ok()?, f[1].parse().ok()?);
        }
    }
    let n = by_bit.len();
    (n > 0 && by_bit.keys().copied().eq(0..n)).then(|| by_bit.into_values().collect())
}

/// How a design with choice inputs was proved, part by part.
fn parts_note(parts: &[usize; 3]) -> String {
    match parts {
        [_, 0, 0] => String::new(),
        [s, i, e] => format!(
            "the assertion split into {} parts by their inputs: {i} that read the slave's choices hold by 2-induction (a relation one step long, whatever the state) with no violation in the first steps from reset; {e} by explicit-state search from reset (the set of states reachable at each step, every choice of the slave enumerated, any other input the part reads enumerated where a step depends on it) until the set at a frame start recurs; for the other {s}, ",
            s + i + e
        ),
    }
}

/// The register names of AIG latches (yosys's map), each once.
fn latch_names(prep: &engine::Prepared, latches: &[usize]) -> String {
    let aim = std::fs::read_to_string(prep.dir.join("design.aim")).unwrap_or_default();
    let mut names: Vec<&str> = aim
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let j: usize = f.get(1)?.parse().ok()?;
            (f.len() == 4 && f[0] == "latch" && latches.contains(&j)).then_some(f[3])
        })
        .collect();
    names.dedup();
    names.join(", ")
}

/// The cycle at which the judge rejects a trace: its first divergence from
/// the cycle-exact model, else its first invariant violation (a violation
/// can be dated before the cycle that revealed it, e.g. a missing sample at
/// its conversion's completion).
pub fn first_rejected(r: &judge::Verdict) -> Option<u64> {
    r.divergences
        .iter()
        .map(|d| d.cycle)
        .min()
        .or_else(|| r.violations.iter().map(|v| v.cycle).min())
}

impl Proof {
    /// The text `prove` prints.
    pub fn summary(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} [{}]: {} ({} properties, depth {}, {:.1} s, solver {:.1} s)",
            self.mix,
            self.solver.name(),
            match (self.result, self.not_covered.is_empty()) {
                (Outcome::Proved, true) => "PROVED (the whole contract)",
                (Outcome::Proved, false) =>
                    "PROVED, EXCEPT the parts of the contract not covered (below)",
                (Outcome::Bounded, _) => "BOUNDED ONLY",
                (Outcome::Failed, _) => "FAILED",
            },
            self.properties.len(),
            self.depth,
            self.seconds,
            self.solver_seconds
        );
        let _ = writeln!(s, "  {}", self.note);
        let _ = writeln!(
            s,
            "  design: {}; properties at the ports only, no internal names; any MISO input{}, one reset cycle",
            match (&self.netlist, self.own_design) {
                (Some(part), _) => format!(
                    "the {part} netlist of slotforge's emitted Verilog (yosys, with the cell models flattened in)"
                ),
                (None, true) => "slotforge's emitted Verilog".to_string(),
                (None, false) => "outside Verilog (--rtl)".to_string(),
            },
            if self.mode_sel {
                ", any sequence of mode_sel requests"
            } else {
                ""
            }
        );
        for p in &self.properties {
            let _ = writeln!(
                s,
                "  {:<8} {}",
                match p.result {
                    Outcome::Proved => "proved",
                    Outcome::Bounded => "bounded",
                    Outcome::Failed => "FAILED",
                },
                p.name
            );
        }
        if !self.not_covered.is_empty() {
            let _ = writeln!(s, "  not covered (the harness does not assert it, so neither a proof nor a bound says anything of it):");
            for n in &self.not_covered {
                let _ = writeln!(s, "    - {n}");
            }
        }
        if !self.netlist_caveats.is_empty() {
            let _ = writeln!(s, "  of a netlist, this proof also says nothing of:");
            for n in &self.netlist_caveats {
                let _ = writeln!(s, "    - {n}");
            }
        }
        if let Some(c) = &self.counterexample {
            if !c.reproduced {
                let _ = writeln!(
                    s,
                    "note: the replay in Icarus does not reproduce the violation: it needs power-on values of registers the reset does not set (the engine chose them; Icarus cannot), so the VCD shows the inputs only and the failing property is not named"
                );
            }
            let _ = writeln!(
                s,
                "counterexample: cycle {} ({} + {})\n{}\nreplay it: {}",
                c.cycle,
                c.vcd.display(),
                c.gtkw.display(),
                c.diagnosis.trim_end(),
                c.check
            );
        }
        s
    }
}
