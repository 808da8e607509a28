//! Induction strengthened with invariants of the design's own registers
//! (slotforge's emitted Verilog; `--rtl` designs keep the recurrence
//! argument).
//!
//! The contract's properties are true but not inductive: an unreachable
//! state in which the design's counters disagree with the harness's shadow
//! position breaks them.  Here every flip-flop of harness + design gets a
//! candidate invariant that ties it to the shadow position (`cyc`, `slot`,
//! `first`):
//!
//! - a function of the cycle in the slot (the timing generator, the shared
//!   SPI sequencers), or `(cyc + k) mod slot_cycles` for a counter;
//! - a function of the frame position, written per slot as the cycles at
//!   which the value changes (slot ROM outputs, per-branch flags, mux
//!   registers, the merger's pending flags, the harness's own word queue);
//! - the low bits of a harness data register (a shift register equals the
//!   MISO bits the harness recorded).
//!
//! The candidates come from one Icarus run of harness + design from reset
//! over two frames with random MISO (what each register *did*, not a guess
//! at what rust-hdl names mean), and every one is then **asserted**, never
//! assumed: ABC's `pdr` proves contract and invariants together for all
//! time, or the strengthening did not close (a candidate false somewhere,
//! or a register left without one) and `prove` falls back to the
//! recurrence argument.  A wrong candidate can cost time, never soundness.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use lut_gen::Schedule;

use crate::engine::run_tool;
use crate::harness::{width, Harness};
use crate::ProveError;

/// The harness's own shadow position: the keys of every invariant.
const KEYS: [&str; 4] = ["st", "cyc", "slot", "first"];

/// A slot-position table larger than this (change points over a frame) is
/// not worth its logic: the register is left to the engine.
const MAX_CHANGES: usize = 200_000;

/// A flip-flop of harness + design, by its flattened public name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Probe {
    /// Hierarchical path from the harness: `dut.core.timing.cnt.q`, `pw0`.
    pub path: String,
    pub width: usize,
}

impl Probe {
    fn in_design(&self) -> bool {
        self.path.starts_with("dut.")
    }
}

/// What the strengthened induction established.
#[derive(Debug, Clone)]
pub struct Strengthened {
    /// Registers tied to the shadow position (or to the harness's data).
    pub invariants: usize,
    /// Registers of harness + design.
    pub registers: usize,
    /// Engine seconds (induction step and base case), after mining.
    pub solver_seconds: f64,
    pub proved: bool,
}

fn tool_err(what: &str, e: impl std::fmt::Display) -> ProveError {
    ProveError::Tool(format!("{what}: {e}"))
}

/// Every flip-flop output of harness + design that has a public name an
/// Icarus hierarchical reference can reach (yosys, after `flatten`).
pub fn probes(dir: &Path) -> Result<Vec<Probe>, ProveError> {
    run_tool(
        dir,
        "yosys",
        &[
            "-q",
            "-p",
            "read_verilog -formal harness.v; read_verilog -formal design.v; \
             hierarchy -top slotforge_formal; proc; flatten; opt_clean; write_json flops.json",
        ],
        Duration::from_secs(300),
    )?;
    let text =
        std::fs::read_to_string(dir.join("flops.json")).map_err(|e| tool_err("flops.json", e))?;
    let j: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| tool_err("flops.json", e))?;
    let m = &j["modules"]["slotforge_formal"];
    let mut q_bits = BTreeSet::new();
    for cell in m["cells"].as_object().into_iter().flatten().map(|(_, c)| c) {
        let ty = cell["type"].as_str().unwrap_or("");
        if ty.starts_with('$') && ty.contains("dff") {
            for b in cell["connections"]["Q"].as_array().into_iter().flatten() {
                if let Some(b) = b.as_i64() {
                    q_bits.insert(b);
                }
            }
        }
    }
    // One probe per distinct set of flop bits, the shortest name first.
    let mut by_bits: BTreeMap<Vec<i64>, String> = BTreeMap::new();
    for (name, net) in m["netnames"].as_object().into_iter().flatten() {
        if net["hide_name"].as_i64() == Some(1) || KEYS.contains(&name.as_str()) {
            continue;
        }
        let bits: Option<Vec<i64>> = net["bits"]
            .as_array()
            .map(|a| a.iter().map(|b| b.as_i64()).collect::<Option<Vec<i64>>>())
            .unwrap_or(None);
        let Some(bits) = bits else { continue };
        if bits.is_empty() || bits.len() >= 128 || !bits.iter().all(|b| q_bits.contains(b)) {
            continue;
        }
        if !name.split('.').all(plain_identifier) {
            continue;
        }
        let keep = match by_bits.get(&bits) {
            Some(old) => (name.len(), name.as_str()) < (old.len(), old.as_str()),
            None => true,
        };
        if keep {
            by_bits.insert(bits, name.clone());
        }
    }
    let mut v: Vec<Probe> = by_bits
        .into_iter()
        .map(|(bits, path)| Probe {
            path,
            width: bits.len(),
        })
        .collect();
    v.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(v)
}

fn plain_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(f) if f.is_ascii_alphabetic() || f == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '$')
}

/// Steps of the mining run: reset, two whole frames and one slot more.
fn mining_steps(s: &Schedule) -> u64 {
    2 + 2 * s.grid.frame_cycles + s.grid.slot_cycles
}

/// The Icarus bench that logs every change of every probe with its step.
fn mining_bench(s: &Schedule, probes: &[Probe], steps: u64) -> String {
    let nb = s.branches.len();
    // The harness's other free inputs (the AXI4-Stream slave's early tready)
    // are drawn like MISO.
    let others = crate::harness::free_inputs(s).split_off(1);
    let regs: String = others
        .iter()
        .map(|i| format!("  reg [{}:0] {} = 0;\n", i.width - 1, i.name))
        .collect();
    let ports: String = others
        .iter()
        .map(|i| format!(", .{0}({0})", i.name))
        .collect();
    let draw: String = others
        .iter()
        .map(|i| format!(" {} = $random(seed);", i.name))
        .collect();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "`timescale 1ns/1ns\nmodule mine_tb;\n  reg clk = 1'b0;\n  reg [{}:0] adc_miso = 0;\n{regs}  \
         integer edges = 0;\n  integer fd;\n  integer i;\n  integer seed;\n  \
         slotforge_formal h (.clk(clk), .adc_miso(adc_miso){ports});",
        nb - 1
    );
    for (i, p) in probes.iter().enumerate() {
        let _ = writeln!(
            v,
            "  always @(h.{}) $fwrite(fd, \"%0d {i} %h\\n\", edges, h.{});",
            p.path, p.path
        );
    }
    let _ = writeln!(
        v,
        "  initial begin\n    if (!$value$plusargs(\"seed=%d\", seed)) seed = 1;\n    \
         fd = $fopen(\"mine.log\", \"w\");\n    #1;"
    );
    for (i, p) in probes.iter().enumerate() {
        let _ = writeln!(v, "    $fwrite(fd, \"0 {i} %h\\n\", h.{});", p.path);
    }
    let _ = writeln!(
        v,
        "    for (i = 0; i < {steps}; i = i + 1) begin\n      adc_miso = $random(seed);{draw}\n      \
         #1 edges = edges + 1; clk = 1'b1;\n      #1 clk = 1'b0;\n    end\n    \
         $fclose(fd);\n    $finish;\n  end\nendmodule"
    );
    v
}

/// A value with an unknown bit in the simulation (registers narrower than
/// 128 bits only, so no real value is this).
const UNKNOWN: u128 = u128::MAX;

/// Each probe's value at every step from 2 (cycle 0) to `steps`
/// ([`UNKNOWN`] where the simulation showed an unknown bit).
fn read_log(text: &str, n: usize, steps: u64) -> Vec<Option<Vec<u128>>> {
    let mut changes: Vec<Vec<(u64, Option<u128>)>> = vec![Vec::new(); n];
    for line in text.lines() {
        let mut f = line.split_whitespace();
        let (Some(step), Some(idx), Some(val)) = (f.next(), f.next(), f.next()) else {
            continue;
        };
        let (Ok(step), Ok(idx)) = (step.parse::<u64>(), idx.parse::<usize>()) else {
            continue;
        };
        if idx < n {
            // an unknown bit (power-on, no reset): UNKNOWN, which no
            // control table takes and every data bit disagrees with
            let v = u128::from_str_radix(val, 16).ok().or(Some(UNKNOWN));
            changes[idx].push((step, v));
        }
    }
    changes
        .into_iter()
        .map(|ch| {
            let mut out = Vec::with_capacity(steps as usize);
            let mut cur = None;
            let mut it = ch.into_iter().peekable();
            for step in 0..=steps {
                while let Some(&(s, v)) = it.peek() {
                    if s > step {
                        break;
                    }
                    cur = v;
                    it.next();
                }
                if step >= 2 {
                    out.push(cur?);
                }
            }
            Some(out)
        })
        .collect()
}

/// The shadow position of step `2 + pos`.
struct Pos {
    c: u64,
    fs: u64,
    f: u64,
}

impl Pos {
    fn at(&self, pos: u64) -> (u64, u64, bool) {
        (pos % self.c, (pos / self.c) % self.fs, pos < self.f)
    }
}

fn lit(w: usize, v: u128) -> String {
    format!("{w}'h{v:x}")
}

/// A value as a function of the cycle in the slot.
fn by_cycle(vals: &[u128], p: &Pos, w: usize, cb: u32) -> Option<String> {
    let mut t: Vec<Option<u128>> = vec![None; p.c as usize];
    for (pos, &v) in vals.iter().enumerate() {
        let slot = &mut t[(pos as u64 % p.c) as usize];
        match slot {
            Some(old) if *old != v => return None,
            _ => *slot = Some(v),
        }
    }
    let t: Vec<u128> = t.into_iter().map(|v| v.unwrap_or(0)).collect();
    if t.iter().all(|&v| v == t[0]) {
        return Some(format!("@E = {};", lit(w, t[0])));
    }
    // A counter that runs with the cycle: (cyc + k) mod slot_cycles.
    let k = t[0];
    if w <= 64 && (0..p.c).all(|c| t[c as usize] == (c as u128 + k) % p.c as u128) {
        let wrap = p.c as u128 - k;
        return Some(format!(
            "@E = cyc >= {cb}'d{wrap} ? cyc - {cb}'d{wrap} : cyc + {cb}'d{k};"
        ));
    }
    Some(cycle_case(&t, w, cb))
}

/// A value as a function of the frame position: per slot (and per slot of
/// the first frame where it differs), the cycles at which it changes.
fn by_position(vals: &[u128], p: &Pos, w: usize, cb: u32, sb: u32) -> Option<String> {
    // (first, slot) -> change points (cycle, value)
    let mut rows: BTreeMap<(bool, u64), Vec<(u64, u128)>> = BTreeMap::new();
    let mut total = 0usize;
    for (pos, &v) in vals.iter().enumerate() {
        let (cyc, slot, first) = p.at(pos as u64);
        let row = rows.entry((first, slot)).or_default();
        match row.last() {
            Some(&(_, last)) if last == v && cyc != 0 => {}
            _ => {
                if cyc == 0 && !row.is_empty() {
                    return None; // the same slot seen twice with other values
                }
                row.push((cyc, v));
                total += 1;
                if total > MAX_CHANGES {
                    return None;
                }
            }
        }
    }
    let expr = |pts: &[(u64, u128)]| {
        let mut e = lit(w, pts[0].1);
        for &(c, v) in &pts[1..] {
            e = format!("cyc >= {cb}'d{c} ? {} : {e}", lit(w, v));
        }
        e
    };
    let steady: BTreeMap<u64, String> = rows
        .iter()
        .filter(|((first, _), _)| !*first)
        .map(|((_, slot), pts)| (*slot, expr(pts)))
        .collect();
    if steady.len() as u64 != p.fs {
        return None; // not every slot seen outside the first frame
    }
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for e in steady.values() {
        *counts.entry(e.as_str()).or_default() += 1;
    }
    let default = counts
        .iter()
        .max_by_key(|(e, n)| (**n, std::cmp::Reverse(**e)))
        .map(|(e, _)| e.to_string())?;
    let mut s = String::from("case (slot)\n");
    for (slot, e) in &steady {
        if *e != default {
            let _ = writeln!(s, "      {sb}'d{slot}: @E = {e};");
        }
    }
    let _ = writeln!(s, "      default: @E = {default};\n    endcase");
    let mut firsts = String::new();
    for ((first, slot), pts) in &rows {
        let e = expr(pts);
        if *first && steady.get(slot) != Some(&e) {
            let _ = writeln!(firsts, "      {sb}'d{slot}: @E = {e};");
        }
    }
    if !firsts.is_empty() {
        let _ = write!(
            s,
            "    if (first) case (slot)\n{firsts}      default: ;\n    endcase"
        );
    }
    Some(s)
}

/// The mined invariants as Verilog added to the harness, and the yosys
/// `connect` commands that wire the design's registers to it.
pub struct Mined {
    pub verilog: String,
    pub connects: Vec<String>,
    pub invariants: usize,
    pub registers: usize,
}

/// Mines candidate invariants from a simulation of harness + design in `dir`.
pub fn mine(dir: &Path, s: &Schedule) -> Result<Mined, ProveError> {
    let probes = probes(dir)?;
    let steps = mining_steps(s);
    std::fs::write(dir.join("mine_tb.v"), mining_bench(s, &probes, steps))
        .map_err(|e| tool_err("mine_tb.v", e))?;
    run_tool(
        dir,
        "iverilog",
        &[
            "-g2012",
            "-o",
            "mine.vvp",
            "mine_tb.v",
            "harness.v",
            "design.v",
        ],
        Duration::from_secs(300),
    )?;
    // Two runs with different MISO: what differs between them is data.
    let mut runs = Vec::new();
    for seed in ["+seed=1", "+seed=2"] {
        run_tool(
            dir,
            "vvp",
            &["-n", "mine.vvp", seed],
            Duration::from_secs(1800),
        )?;
        let log =
            std::fs::read_to_string(dir.join("mine.log")).map_err(|e| tool_err("mine.log", e))?;
        runs.push(read_log(&log, probes.len(), steps));
        let _ = std::fs::remove_file(dir.join("mine.log"));
    }
    let vals = &runs[0];
    let other = &runs[1];
    let g = &s.grid;
    let pos = Pos {
        c: g.slot_cycles,
        fs: g.frame_slots,
        f: g.frame_cycles,
    };
    let (cb, sb) = (width(g.slot_cycles), width(g.frame_slots));
    let mut v = String::from(
        "\n  // Invariants of the registers against the shadow position (formal/src/strengthen.rs):\n  \
         // mined from a simulation, asserted with the contract, never assumed.\n",
    );
    let mut connects = Vec::new();
    let mut names = Vec::new();
    let partitions = slot_classes(s);
    for (i, (p, pv)) in probes.iter().zip(vals).enumerate() {
        let Some(pv) = pv else { continue };
        let control = other[i].as_ref() == Some(pv) && !pv.contains(&UNKNOWN);
        let w = p.width;
        let iv = format!("iv{i}");
        let decl = if p.in_design() {
            connects.push(format!("connect -nounset -set {iv} {}", p.path));
            format!("  wire [{}:0] {iv};\n", w - 1)
        } else {
            format!("  wire [{}:0] {iv} = {};\n", w - 1, p.path)
        };
        // by position: frames 0 and 1 once each (the row of a slot is built once)
        let two = &pv[..pv.len().min(2 * g.frame_cycles as usize)];
        let table = control
            .then(|| by_cycle(pv, &pos, w, cb).or_else(|| by_position(two, &pos, w, cb, sb)))
            .flatten();
        let check = if let Some(body) = table {
            let _ = write!(
                v,
                "{decl}  reg [{}:0] ie{i};\n  always @* begin\n    {}\n  end\n",
                w - 1,
                body.replace("@E", &format!("ie{i}"))
            );
            format!("iv{i} == ie{i}")
        } else if let Some(a) = (p.in_design() && !control)
            .then(|| agreement(i, &probes, vals, other, &pos, &partitions))
            .flatten()
        {
            let (j, lo, m, from) = (a.j, a.lo, a.m, a.from);
            // Nothing claimed in the first frame before `from`.
            let (fs, fc) = (from / g.slot_cycles, from % g.slot_cycles);
            let early =
                format!("first && (slot < {sb}'d{fs} || (slot == {sb}'d{fs} && cyc < {cb}'d{fc}))");
            let _ = write!(
                v,
                "{decl}  reg [{}:0] ie{i};\n  reg [{}:0] iz{i};\n  always @* begin\n    \
                 if ({early}) ie{i} = {m}'d0;\n    else {}\n    \
                 if ({early}) iz{i} = {w}'d0;\n    else {}\n  end\n",
                m - 1,
                w - 1,
                class_case(&a.class, &a.masks, m, cb, sb).replace("@E", &format!("ie{i}")),
                class_case(&a.class, &a.zeros, w, cb, sb).replace("@E", &format!("iz{i}")),
            );
            format!(
                "((iv{i}[{}:0] ^ {}[{}:{lo}]) & ie{i}) == {m}'d0 && (iv{i} & iz{i}) == {w}'d0",
                m - 1,
                probes[j].path,
                lo + m - 1
            )
        } else {
            if p.in_design() {
                connects.pop();
            }
            continue;
        };
        let _ = writeln!(v, "  wire inv{i} = {check}; // {}", p.path);
        names.push(format!("inv{i}"));
    }
    // One assertion each: ABC's output index names the invariant that fails.
    // The harness's own start: `st` never 3, the position at zero until it runs.
    // The position's registers in range (unreachable wide values would let
    // a run of invariant-keeping states wrap into a bad one).
    let _ = writeln!(
        v,
        "`ifdef FORMAL\n  always @* assert (st != 2'd3);\n  \
         always @* if (st != 2'd2) assert (cyc == 0 && slot == 0 && first);\n  \
         always @* assert (cyc <= {cb}'d{} && slot <= {sb}'d{});",
        g.slot_cycles - 1,
        g.frame_slots - 1
    );
    for n in &names {
        let _ = writeln!(v, "  always @* if (st == 2'd2) assert ({n});");
    }
    v.push_str("`endif\n");
    Ok(Mined {
        verilog: v,
        connects,
        invariants: names.len(),
        registers: probes.len(),
    })
}

/// A design register's agreement with harness register `j`: its bits
/// `[lo + m - 1 : lo]` against the design's `[m - 1 : 0]`, where the masks
/// say, from position `from` of the first frame on.  The masks are per
/// cycle in the slot and per slot class: `class[slot]` picks the row of
/// `masks`.  A class is whether one branch converts in the slot and in the
/// slot before (the shared SPI sequencer shifts a branch's register in
/// every slot, but the harness records its bits only in the branch's own
/// slots, so the bits agree in other cycles of an active slot than of an
/// idle one).
struct Agreement {
    j: usize,
    lo: usize,
    m: usize,
    class: Vec<usize>,
    masks: Vec<Vec<u128>>,
    /// Per class and cycle, the design's bits that are always 0 there (a
    /// shift register cleared when its conversion starts: the harness's
    /// register still holds the previous word in those bits).
    zeros: Vec<Vec<u128>>,
    from: u64,
}

/// The slot classes the masks may be split by: one partition per branch
/// (active or idle in the slot and in the one before), each as the class
/// of every slot of a frame.
fn slot_classes(s: &Schedule) -> Vec<Vec<usize>> {
    let fs = s.grid.frame_slots;
    (0..s.branches.len())
        .map(|b| {
            (0..fs)
                .map(|slot| {
                    let prev = (slot + fs - 1) % fs;
                    2 * usize::from(s.at(slot, b).is_some()) + usize::from(s.at(prev, b).is_some())
                })
                .collect()
        })
        .collect()
}

/// The partitions tried against harness register `path`: a branch's
/// capture register (`w{b}`) only by its own branch's slots (another
/// branch's partition could fit two runs by chance and not be inductive),
/// any other register (the merged stream's word) by every branch's.
fn own_partition<'a>(path: &str, partitions: &'a [Vec<usize>]) -> &'a [Vec<usize>] {
    match path.strip_prefix('w').map(str::parse::<usize>) {
        Some(Ok(b)) if b < partitions.len() => &partitions[b..=b],
        _ => partitions,
    }
}

/// The bits in which a design register always agrees with a harness data
/// register (a shift register and the MISO bits the harness recorded), per
/// cycle in the slot and slot class, over both runs, from the frames after
/// the first; in the first frame claimed only from the position where the
/// power-on and start-up contents (a skipped conversion still shifts) are
/// gone.  The harness register, bits and partition with the most agreeing
/// bits over a frame win.
fn agreement(
    i: usize,
    probes: &[Probe],
    vals: &[Option<Vec<u128>>],
    other: &[Option<Vec<u128>>],
    p: &Pos,
    partitions: &[Vec<usize>],
) -> Option<Agreement> {
    let w = probes[i].width;
    let (Some(x0), Some(x1)) = (&vals[i], &other[i]) else {
        return None;
    };
    let mut best: Option<(u64, Agreement)> = None;
    for (j, q) in probes.iter().enumerate() {
        let (Some(y0), Some(y1)) = (&vals[j], &other[j]) else {
            continue;
        };
        if q.in_design() || y0 == y1 {
            continue; // only the harness's data registers
        }
        // the design's bits may sit anywhere in the harness's register
        // (leading or trailing bits around the data)
        for lo in 0..q.width {
            let m = (q.width - lo).min(w);
            let full = if m >= 128 {
                u128::MAX
            } else {
                (1u128 << m) - 1
            };
            // the agreeing bits per position of the frame, after the first
            let mut at = vec![full; p.f as usize];
            for (x, y) in [(x0, y0), (x1, y1)] {
                for (t, (a, b)) in x.iter().zip(y).enumerate().skip(p.f as usize) {
                    at[t % p.f as usize] &= !(a ^ (b >> lo));
                }
            }
            for class in own_partition(&q.path, partitions) {
                let mut masks = vec![vec![full; p.c as usize]; 4];
                for (t, &k) in at.iter().enumerate() {
                    let t = t as u64;
                    masks[class[(t / p.c) as usize]][(t % p.c) as usize] &= k;
                }
                let mask_at = |t: u64| masks[class[(t / p.c) as usize]][(t % p.c) as usize];
                let total: u64 = (0..p.f).map(|t| u64::from(mask_at(t).count_ones())).sum();
                if total == 0 || best.as_ref().is_some_and(|b| total <= b.0) {
                    continue;
                }
                let mut from = 0u64;
                for (x, y) in [(x0, y0), (x1, y1)] {
                    for (t, (a, b)) in x.iter().zip(y).enumerate().take(p.f as usize) {
                        if (a ^ (b >> lo)) & mask_at(t as u64) != 0 {
                            from = from.max(t as u64 + 1);
                        }
                    }
                }
                let a = Agreement {
                    j,
                    lo,
                    m,
                    class: class.clone(),
                    masks,
                    zeros: Vec::new(),
                    from,
                };
                best = Some((total, a));
            }
        }
    }
    best.map(|(_, a)| with_zeros(a, w, [x0, x1], p))
}

/// `a` with the design register's bits that are 0 in every sample of a
/// slot class and cycle (both runs, the frames after the first), and `from`
/// late enough that the first frame keeps them too.
fn with_zeros(mut a: Agreement, w: usize, runs: [&Vec<u128>; 2], p: &Pos) -> Agreement {
    let full = if w >= 128 {
        u128::MAX
    } else {
        (1u128 << w) - 1
    };
    let mut zeros = vec![vec![full; p.c as usize]; 4];
    for x in runs {
        for (t, v) in x.iter().enumerate().skip(p.f as usize) {
            let t = (t as u64) % p.f;
            zeros[a.class[(t / p.c) as usize]][(t % p.c) as usize] &= !v;
        }
    }
    let zero_at = |t: u64| zeros[a.class[(t / p.c) as usize]][(t % p.c) as usize];
    for x in runs {
        for (t, v) in x.iter().enumerate().take(p.f as usize) {
            if v & zero_at(t as u64) != 0 {
                a.from = a.from.max(t as u64 + 1);
            }
        }
    }
    // The claims start where nothing is claimed (an idle slot): starting
    // them at any other position makes a cliff no induction step crosses
    // (the state before claims nothing, the state after claims bits).
    let empty = |t: u64| {
        let (k, c) = (a.class[(t / p.c) as usize], (t % p.c) as usize);
        a.masks[k][c] == 0 && zeros[k][c] == 0
    };
    if a.from > 0 {
        a.from = (a.from..p.f).find(|&t| empty(t)).unwrap_or(p.f);
    }
    a.zeros = zeros;
    a
}

/// The masks as Verilog: a case on the slot (slots with the same masks
/// together, the most common as the default) of cases on the cycle.
fn class_case(class: &[usize], masks: &[Vec<u128>], w: usize, cb: u32, sb: u32) -> String {
    let mut rows: BTreeMap<&[u128], Vec<usize>> = BTreeMap::new();
    for (slot, &k) in class.iter().enumerate() {
        rows.entry(&masks[k]).or_default().push(slot);
    }
    let default = rows
        .iter()
        .max_by_key(|(_, v)| v.len())
        .map(|(k, _)| *k)
        .unwrap_or(&[]);
    let indent = |c: String| c.replace('\n', "\n    ");
    let mut s = String::from("case (slot)\n");
    for (row, v) in &rows {
        if *row == default {
            continue;
        }
        let labels: Vec<String> = v.iter().map(|slot| format!("{sb}'d{slot}")).collect();
        let _ = writeln!(
            s,
            "      {}: {}",
            labels.join(", "),
            indent(cycle_case(row, w, cb))
        );
    }
    let _ = write!(
        s,
        "      default: {}\n    endcase",
        indent(cycle_case(default, w, cb))
    );
    s
}

/// A case on the cycle in the slot, the most common value as the default.
fn cycle_case(t: &[u128], w: usize, cb: u32) -> String {
    let mut counts: BTreeMap<u128, usize> = BTreeMap::new();
    for &v in t {
        *counts.entry(v).or_default() += 1;
    }
    let default = counts
        .iter()
        .max_by_key(|(v, n)| (**n, std::cmp::Reverse(**v)))
        .map(|(v, _)| *v)
        .unwrap_or(0);
    let mut s = String::from("case (cyc)\n");
    for (c, &v) in t.iter().enumerate() {
        if v != default {
            let _ = writeln!(s, "      {cb}'d{c}: @E = {};", lit(w, v));
        }
    }
    let _ = write!(s, "      default: @E = {};\n    endcase", lit(w, default));
    s
}

/// The harness with the mined invariants before its `endmodule`.
fn strengthened_harness(h: &Harness, m: &Mined) -> String {
    let cut = h.verilog.rfind("endmodule").unwrap_or(h.verilog.len());
    format!("{}{}{}", &h.verilog[..cut], m.verilog, &h.verilog[cut..])
}

/// Mines the invariants (`harness.v` and `design.v` in `dir`), adds them to
/// the harness and runs ABC's `pdr` on contract + invariants for at most
/// `secs` seconds.  `proved` is true only when pdr proves them all.
pub fn prove(dir: &Path, s: &Schedule, h: &Harness, secs: u64) -> Result<Strengthened, ProveError> {
    let m = mine(dir, s)?;
    std::fs::write(dir.join("harness_inv.v"), strengthened_harness(h, &m))
        .map_err(|e| tool_err("harness_inv.v", e))?;
    // A script file, one command a line: yosys's `-p` splitting does not
    // pass `connect`'s hierarchical names through reliably.
    let script = format!(
        "read_verilog -formal harness_inv.v\nread_verilog -formal design.v\n\
         hierarchy -top slotforge_formal\nproc\nflatten\n{}\n\
         prep -top slotforge_formal\nmemory_map\nopt -full\nasync2sync\nchformal -assume -early\n\
         setundef -anyseq\nopt -full\ntechmap\nopt -fast\ndffunmap\nabc -g AND -fast\nopt_clean\n\
         write_aiger -I -B -zinit -map strong.aim strong.aig\n",
        m.connects.join("\n")
    );
    std::fs::write(dir.join("strong.ys"), script).map_err(|e| tool_err("strong.ys", e))?;
    run_tool(
        dir,
        "yosys",
        &["-q", "-s", "strong.ys"],
        Duration::from_secs(600),
    )?;
    // k-induction: ABC's `ind` is the inductive step (any K consecutive
    // states that keep every assertion are followed by one that does), and
    // `bmc3` from reset over more than K steps is the base case.
    let t = Instant::now();
    let step = run_tool(
        dir,
        "yosys-abc",
        &[
            "-c",
            &format!("read_aiger strong.aig; fold; strash; orpos; ind -F {K} -T {secs}"),
        ],
        Duration::from_secs(secs),
    )?;
    let base_steps = K + 2;
    let base = run_tool(
        dir,
        "yosys-abc",
        &[
            "-c",
            &format!("read_aiger strong.aig; fold; strash; bmc3 -F {base_steps} -T {secs}"),
        ],
        Duration::from_secs(secs),
    )?;
    let base_ok = matches!(
        crate::engine::parse_abc(&base, base_steps)?,
        crate::engine::Verdict::Bounded { steps } if steps >= base_steps
    );
    Ok(Strengthened {
        invariants: m.invariants,
        registers: m.registers,
        solver_seconds: t.elapsed().as_secs_f64(),
        proved: base_ok && step.contains("Networks are equivalent"),
    })
}

/// The induction depth: ABC's `ind` tries k = 1 ..= K.
pub const K: u64 = 16;

#[cfg(test)]
mod tests {
    use super::*;

    const P: Pos = Pos { c: 4, fs: 3, f: 12 };

    #[test]
    fn a_register_that_follows_the_cycle_is_a_counter_or_a_table() {
        // (cyc + 2) mod 4 over three frames: the counter form, no table
        let cnt: Vec<u128> = (0..36).map(|t| (t % 4 + 2) % 4).collect();
        let e = by_cycle(&cnt, &P, 3, 2).unwrap();
        assert!(e.contains("cyc >= 2'd2 ? cyc - 2'd2 : cyc + 2'd2"), "{e}");
        // a strobe in cycle 1 of every slot: a case with the idle default
        let strobe: Vec<u128> = (0..36).map(|t| u128::from(t % 4 == 1)).collect();
        let e = by_cycle(&strobe, &P, 1, 2).unwrap();
        assert!(
            e.contains("2'd1: @E = 1'h1;") && e.contains("default: @E = 1'h0;"),
            "{e}"
        );
        // different values in the same cycle of two slots: not a function of the cycle
        let mut per_slot = strobe.clone();
        per_slot[6] = 1; // cycle 2 of slot 1 only
        assert!(by_cycle(&per_slot, &P, 1, 2).is_none());
    }

    #[test]
    fn a_register_that_follows_the_slot_is_a_table_with_a_first_frame() {
        // the slot's number, loaded in cycle 1; in frame 0, slot 0 holds 3
        let v: Vec<u128> = (0..24u64)
            .map(|t| {
                let (cyc, slot, first) = P.at(t);
                let s = if cyc >= 1 { slot } else { (slot + 2) % 3 };
                if first && t < 4 {
                    3
                } else {
                    u128::from(s)
                }
            })
            .collect();
        let e = by_position(&v, &P, 2, 2, 2).unwrap();
        assert!(e.contains("2'd1: @E = cyc >= 2'd1 ? 2'h1 : 2'h0;"), "{e}");
        assert!(
            e.contains("if (first) case (slot)\n      2'd0: @E = 2'h3;"),
            "{e}"
        );
        // a value that is not the same in the same position of two runs
        // is told apart by `mine` (two seeds), not here; a frame that does
        // not cover every slot is refused
        assert!(by_position(&v[..12], &P, 2, 2, 2).is_none());
    }

    #[test]
    fn a_shift_register_agrees_with_the_recorded_bits_only_where_it_does() {
        let probes = vec![
            Probe {
                path: "dut.sh".into(),
                width: 4,
            },
            Probe {
                path: "exp_val".into(),
                width: 5,
            },
        ];
        // exp_val the recorded bits; sh equals its low 4 bits except bit 3 in
        // cycle 2, and bit 0 in every cycle of slot 1 (the branch is idle
        // there: its register shifts bits the harness does not record)
        let run = |seed: u128| {
            let w: Vec<u128> = (0..24u128).map(|t| (t * 7 + seed * 13) % 32).collect();
            let sh: Vec<u128> = w
                .iter()
                .enumerate()
                .map(|(t, &x)| {
                    let x = if t % 4 == 2 { (x & 15) ^ 8 } else { x & 15 };
                    if (t / 4) % 3 == 1 {
                        x ^ 1
                    } else {
                        x
                    }
                })
                .collect();
            vec![Some(sh), Some(w)]
        };
        let (a, b) = (run(1), run(2));
        // one class for every slot: bit 0 never agrees anywhere
        let one = vec![vec![0, 0, 0]];
        let g = agreement(0, &probes, &a, &b, &P, &one).unwrap();
        assert_eq!((g.j, g.lo, g.m, g.from), (1, 0, 4, 0));
        assert_eq!(g.masks[0], vec![14, 14, 6, 14]);
        // active in slots 0 and 2 (classes: active after active, idle after
        // active, active after idle): bit 0 is claimed where it agrees, and
        // this partition wins over the single class
        let classes = vec![vec![0, 0, 0], vec![3, 1, 2]];
        let g = agreement(0, &probes, &a, &b, &P, &classes).unwrap();
        assert_eq!(g.class, vec![3, 1, 2]);
        assert_eq!(g.masks[1], vec![14, 14, 6, 14]);
        assert_eq!(g.masks[2], vec![15, 15, 7, 15]);
        assert_eq!(g.masks[3], vec![15, 15, 7, 15]);
        let v = class_case(&g.class, &g.masks, g.m, 2, 2);
        assert!(v.contains("2'd1: case (cyc)"), "{v}");
        assert!(
            v.contains("2'd1: case (cyc)\n          2'd2: @E = 4'h6;"),
            "{v}"
        );
        assert!(
            v.contains("default: case (cyc)\n          2'd2: @E = 4'h7;"),
            "{v}"
        );
        // a branch's capture register is split by its own branch's slots only
        assert_eq!(own_partition("w1", &classes), &classes[1..]);
        assert_eq!(own_partition("w0", &classes), &classes[..1]);
        assert_eq!(own_partition("exp_val", &classes), &classes[..]);
        // a harness register the same in both runs is control, not data
        assert!(agreement(0, &probes, &a, &a, &P, &classes).is_none());
        let control = vec![Some(vec![0u128; 24]), Some(vec![0u128; 24])];
        assert!(agreement(0, &probes, &control, &control, &P, &classes).is_none());
    }

    #[test]
    fn bits_always_zero_in_a_slot_class_are_claimed_there_only() {
        // every bit set except bit 2, which is 0 throughout slot 1 of every
        // frame (a register cleared when an idle slot starts)
        let run: Vec<u128> = (0..24u64)
            .map(|t| if (t / 4) % 3 == 1 { 0b1011 } else { 0b1111 })
            .collect();
        let a = Agreement {
            j: 1,
            lo: 0,
            m: 4,
            class: vec![3, 1, 2],
            masks: vec![vec![0; 4]; 4],
            zeros: Vec::new(),
            from: 0,
        };
        let z = with_zeros(a, 4, [&run, &run], &P);
        assert_eq!(z.zeros[1], vec![0b0100; 4]);
        assert_eq!(z.zeros[3], vec![0; 4]);
        assert_eq!(z.from, 0);
        // a first frame that breaks the claim (position 5): nothing claimed
        // before it, and the claims start at the next position that claims
        // nothing (8, slot 2), not at 6 where claims would appear from none
        let mut late = run.clone();
        late[5] = 0b1111;
        let a = Agreement {
            zeros: Vec::new(),
            ..z
        };
        assert_eq!(with_zeros(a, 4, [&late, &run], &P).from, 8);
    }
}
