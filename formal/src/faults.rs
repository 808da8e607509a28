//! Gateware fault classes that a simulation of a few frames from reset with
//! an ADC stimulus does not reach, and `prove` does: each is an edit of the
//! emitted Verilog's `slotforge_top` wrapper (so every engine that runs
//! Verilog sees the same faulty design).
//!
//! - [`DeepFault::LateCounter`]: an age counter that misbehaves only after
//!   many frames: in one cycle of frame `frames` it flips `mux_sel[0]`.  A
//!   run of fewer frames never sees it; `prove`'s recurrence check notices
//!   that the design keeps state across frames and searches deeper.
//! - [`DeepFault::RareCollision`]: a merger collision under a rare input: a
//!   word that leaves in the cycle right after another (two conversions
//!   finished together) is dropped when it carries the same code.  The
//!   stimuli give every conversion its own code, so simulation never drives
//!   it; with MISO free the solver does at the first collision.

use lut_gen::Schedule;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeepFault {
    LateCounter { frames: u64 },
    RareCollision,
}

impl DeepFault {
    pub fn name(self) -> String {
        match self {
            DeepFault::LateCounter { frames } => format!("late-counter@frame{frames}"),
            DeepFault::RareCollision => "rare-collision".into(),
        }
    }

    /// `verilog` (slotforge's emitted `slotforge_top.v` for `s`) with the fault.
    pub fn apply(self, s: &Schedule, verilog: &str) -> Result<String, String> {
        let anchor = "    slotforge_core core (";
        if !verilog.contains(anchor) {
            return Err("not slotforge's emitted wrapper (no `slotforge_core core (`)".into());
        }
        match self {
            DeepFault::LateCounter { frames } => {
                // a concatenation when some branch has no mux; no port when none has one
                let sel = "    assign mux_sel = ";
                let at = verilog
                    .find(sel)
                    .ok_or("no `assign mux_sel` in the wrapper (no branch has a mux)")?;
                let end = at + verilog[at..].find(';').ok_or("unterminated assign")?;
                // During cycle c the age is c + 1; flip in cycle frames * F + 1.
                let hit = frames * s.grid.frame_cycles + 2;
                let logic = format!(
                    "    // FAULT late-counter: an age counter flips mux_sel[0] in frame {frames}.\n    \
                     reg [39:0] fault_age = 40'd0;\n    \
                     always @(posedge clk) fault_age <= rst ? 40'd0 : fault_age + 40'd1;\n    \
                     wire fault_hit = fault_age == 40'd{hit};\n"
                );
                let width = lut_gen::Layout::new(s).width(lut_gen::Role::MuxSel);
                let mut v = String::with_capacity(verilog.len() + logic.len() + 32);
                v.push_str(&verilog[..end]);
                v.push_str(&format!(" ^ {{{{{}{{1'b0}}}}, fault_hit}}", width - 1));
                let rest = &verilog[end..];
                let k = rest.find(anchor).expect("anchor after the assigns");
                v.push_str(&rest[..k]);
                v.push_str(&logic);
                v.push_str(&rest[k..]);
                Ok(v)
            }
            DeepFault::RareCollision => {
                let port = "        .sample_valid(sample_valid),";
                if !verilog.contains(port) {
                    return Err("no `.sample_valid(sample_valid),` in the wrapper".into());
                }
                let logic = "    // FAULT rare-collision: a word right behind another with the same code is dropped.\n    \
                     wire core_valid;\n    reg fault_pv = 1'b0;\n    reg [15:0] fault_pval = 16'd0;\n    \
                     always @(posedge clk) begin\n        fault_pv <= core_valid;\n        fault_pval <= core_value;\n    end\n    \
                     assign sample_valid = core_valid && !(fault_pv && core_value == fault_pval);\n";
                let v = verilog.replacen(port, "        .sample_valid(core_valid),", 1);
                Ok(v.replacen(anchor, &format!("{logic}{anchor}"), 1))
            }
        }
    }
}
