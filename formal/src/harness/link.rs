//! The link to the host in the harness (a mix with `[link]`): its ports on
//! the design, the AXI4-Stream slave the mix guarantees, and the link's
//! properties.
//!
//! The slave is modelled, not assumed: `m_axis_tready` is a free harness
//! input OR "this beat has waited `ready_within - 1` cycles", which is
//! exactly the set of slaves `link::ReadyDriver` draws from (its `due`:
//! a beat is taken at the latest in its `ready_within`-th cycle of `tvalid`;
//! `ReadyPattern::WorstCase` is the member that is never early).  So every
//! engine, including one that ignores `assume`, sees every slave that
//! honours the guarantee and no other.  The FIFO's depth is the worst-case
//! backlog under that guarantee (`lut_gen::plan_link`), so `link.overflow`
//! is the claim that the depth is enough for every such slave, not only
//! for the worst-case pattern a simulation drives.

use std::fmt::Write;

use lut_gen::Schedule;
use lut_gen::{Dir, Layout};

use super::{packets, uart, width, Clause, FreeInput, PropertyDef};

/// Whether the harness reads the link's bytes (`link.bytes`,
/// `link.packets`): a UART's receiver, or an AXI4-Stream's beats taken,
/// and the packet parser.  `prove` proves
/// the harness without them for all time and searches the one with them
/// from reset (their frame counter keeps the state from coming round).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkBytes {
    /// Asserted; an AXI4-Stream's only for a slave that keeps a beat
    /// waiting at most [`AXIS_BYTES_MAX_WAIT`] cycles.
    Asserted,
    /// Asserted whatever the slave's `ready_within` (`prove --axis-bytes`:
    /// minutes on a 48 MHz mix whose slave may wait 64 cycles).
    AnyWait,
    Left,
}

impl LinkBytes {
    /// Whether an AXI4-Stream's bytes are asserted for a slave that takes
    /// every beat within `within` cycles.
    fn axis_asserted(self, within: u32) -> bool {
        match self {
            LinkBytes::Asserted => within <= AXIS_BYTES_MAX_WAIT,
            LinkBytes::AnyWait => true,
            LinkBytes::Left => false,
        }
    }
}

/// The harness input that lets the slave take a beat early (any cycle).
pub const TREADY_ANY: &str = "tready_any";

/// The harness's count of the cycles the offered beat has waited (the
/// slave must take it when the count reaches `ready_within - 1`).  Only
/// `m_axis_tready` reads it, so of two states equal but for it, the one
/// with the lower count has every future of the other (`symsim`'s split
/// run keeps that one alone).
pub const SLAVE_WAIT: &str = "waited";

/// The largest `ready_within` whose AXI4-Stream bytes the harness asserts
/// (`link.bytes`, `link.packets`).  Why a bound: the proof splits on the
/// slave's choices, and the paths a burst makes grow with the wait a beat
/// may take: the tiny mix at 8 proves in 4 s, eskin34-axis at 64 in 8
/// minutes, modes-auto at 9 / 16 in 137 / 235 s (at most 6 s with the
/// bytes left out); a proof in every build cannot wait that long.  A mix
/// beyond it keeps them listed as not covered, unless asked for
/// ([`LinkBytes::AnyWait`], `prove --axis-bytes`).
pub const AXIS_BYTES_MAX_WAIT: u32 = 8;

/// The guarantee of an AXI4-Stream mix's slave (`ready_within`, >= 1);
/// `None` for a UART link or none.
fn ready_within(s: &Schedule, layout: &Layout) -> Option<u32> {
    let l = s.mix.link.as_ref()?;
    layout.axis.then_some(l.ready_within.max(1))
}

/// The harness's free inputs for the link (after `adc_miso`).
pub(super) fn inputs(layout: &Layout) -> Vec<FreeInput> {
    if layout.axis {
        vec![FreeInput {
            name: TREADY_ANY.into(),
            width: 1,
        }]
    } else {
        Vec::new()
    }
}

/// Wires for the link's ports (named as on the design) and, for
/// AXI4-Stream, the slave that drives `m_axis_tready`.
pub(super) fn declare(v: &mut String, s: &Schedule, layout: &Layout) {
    for p in layout.link_ports() {
        if p.width == 1 {
            let _ = writeln!(v, "  wire {};", p.name);
        } else {
            let _ = writeln!(v, "  wire [{}:0] {};", p.width - 1, p.name);
        }
    }
    let Some(within) = ready_within(s, layout) else {
        return;
    };
    let wb = width(u64::from(within));
    let _ = writeln!(
        v,
        "  // The slave the mix guarantees: tready in any cycle, and at the latest when\n  \
         // a beat has waited ready_within - 1 = {} cycles (it is then taken in its\n  \
         // {within}-th cycle of tvalid). Not an assumption: every slave that honours\n  \
         // the guarantee, and only those, is a choice of `{TREADY_ANY}`.\n  \
         reg [{}:0] {SLAVE_WAIT} = 0;\n  \
         assign m_axis_tready = {TREADY_ANY} || {SLAVE_WAIT} >= {wb}'d{};\n  \
         always @(posedge clk)\n    \
         {SLAVE_WAIT} <= (st != 2'd0 && m_axis_tvalid && !m_axis_tready) ? {SLAVE_WAIT} + {wb}'d1 : {wb}'d0;",
        within - 1,
        wb - 1,
        within - 1,
    );
}

/// `.port(port)` for every link port, after the contract's.
pub(super) fn connections(layout: &Layout) -> String {
    layout
        .link_ports()
        .iter()
        .map(|p| format!(", .{0}({0})", p.name))
        .collect()
}

/// The link's properties: the FIFO never overflows; for AXI4-Stream, a
/// waiting beat keeps `tvalid`, `tdata` and `tlast` until it is taken.
pub(super) fn properties(
    v: &mut String,
    props: &mut Vec<PropertyDef>,
    s: &Schedule,
    layout: &Layout,
    bytes: LinkBytes,
) {
    debug_assert!(layout
        .link_ports()
        .iter()
        .any(|p| p.name == "link_overflow" && p.dir == Dir::Out));
    let within = ready_within(s, layout);
    v.push_str(
        "\n  // The link's FIFO never drops a token: link_overflow stays low.\n  \
         wire ok_link_overflow = link_overflow == 1'b0;\n",
    );
    props.push(PropertyDef {
        name: "link.overflow".into(),
        wire: "ok_link_overflow".into(),
        covers: vec![Clause::LinkOverflow],
        what: match within {
            Some(n) => format!(
                "the link's FIFO never overflows: link_overflow stays low for any input and \
                 any slave that takes every beat within {n} cycles"
            ),
            None => "the link's FIFO never overflows: link_overflow stays low for any input".into(),
        },
    });
    let plan = lut_gen::plan_link(s).and_then(Result::ok);
    let depth = plan.as_ref().map_or(0, |p| p.fifo_depth);
    if within.is_none() {
        if let (LinkBytes::Asserted | LinkBytes::AnyWait, Some(c)) = (bytes, uart::Char::of(s)) {
            uart::receiver(v, props, &c);
            packets::monitor(v, props, s, layout, depth, packets::Line::Uart);
        }
        return;
    }
    v.push_str(
        "  // AXI4-Stream: a beat offered and not taken (tvalid && !tready) at an edge\n  \
         // is offered again after it, with the same tdata and tlast.\n  \
         reg beat_waits = 1'b0;\n  reg [7:0] waiting_tdata = 8'd0;\n  reg waiting_tlast = 1'b0;\n  \
         always @(posedge clk) begin\n    \
         beat_waits <= st != 2'd0 && m_axis_tvalid && !m_axis_tready;\n    \
         waiting_tdata <= m_axis_tdata;\n    waiting_tlast <= m_axis_tlast;\n  end\n  \
         wire ok_axis_tvalid = !beat_waits || m_axis_tvalid;\n  \
         wire ok_axis_payload = !beat_waits || (m_axis_tdata == waiting_tdata && m_axis_tlast == waiting_tlast);\n",
    );
    props.push(PropertyDef {
        name: "axis.tvalid".into(),
        wire: "ok_axis_tvalid".into(),
        covers: vec![Clause::AxisValidHeld],
        what: "a beat offered on m_axis_tvalid stays offered until the slave takes it \
               (AXI4-Stream: tvalid never falls while tready is low)"
            .into(),
    });
    props.push(PropertyDef {
        name: "axis.payload".into(),
        wire: "ok_axis_payload".into(),
        covers: vec![Clause::AxisPayloadHeld],
        what: "m_axis_tdata and m_axis_tlast do not change while a beat waits for tready".into(),
    });
    if within.is_some_and(|w| bytes.axis_asserted(w)) {
        let per_frame = plan.as_ref().and_then(|p| p.tlast) == Some("frame");
        packets::beats(v);
        packets::monitor(
            v,
            props,
            s,
            layout,
            depth,
            packets::Line::Axis { per_frame },
        );
    }
}
