//! The link stage (`slotforge_link`): packetizer, FIFO, serializer and UART
//! transmitter after the merged sample stream, as docs/packet-format.md
//! ("Timing") states it register by register.
//!
//! Like the merger and the word reader, the block is custom Verilog
//! generated per mix (exact counter widths, the FIFO exactly as deep as the
//! schedule's worst-case backlog) with its Rust twin in `update`, the two
//! written register for register; the judge predicts the line from its own
//! model (`link::TxModel`), never from this file.

use std::fmt::Write as _;

use crate::rhdl::*;

use crate::widths::{CH_BITS, VALUE_BITS};

/// What the link is built for (from `lut_gen::LinkPlan`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkParams {
    pub slice_cycles: u64,
    /// Slots per slice: the link counts the core's slot starts
    /// (`slot_tick`) to find a slice's first cycle.
    pub slots_per_slice: u64,
    pub slices_per_frame: u64,
    /// Clock cycles per UART bit.
    pub div: u32,
    /// 0 none, 1 even, 2 odd.
    pub parity: u8,
    pub stop_bits: u8,
    /// FIFO depth in tokens.
    pub depth: usize,
    /// CRC-16/MODBUS initial value (0xFFFF; another only as a fault).
    pub crc_init: u16,
    /// An AXI4-Stream master instead of the UART (`div`, `parity` and
    /// `stop_bits` unused): where `tlast` goes.
    pub axis: Option<link::Tlast>,
    /// A mix with modes: bits of the `mode` input (the core's mode in
    /// force), which each boundary's token carries to its header
    /// (docs/packet-format.md, "Modes"); 0: no modes, no input.
    pub mode_bits: u32,
}

/// The most mode bits the link's FIFO entry carries (above its 28 bits).
pub const MAX_LINK_MODE_BITS: u32 = 4;

impl LinkParams {
    pub(crate) fn of(s: &lut_gen::Schedule) -> Result<Option<LinkParams>, String> {
        let Some(r) = lut_gen::plan_link(s) else {
            return Ok(None);
        };
        let p = r.map_err(|e| e.message)?;
        let mode_bits = p.tx_config(s).mode_bits;
        if mode_bits > MAX_LINK_MODE_BITS {
            return Err(format!(
                "the link carries at most {} modes in its packets, the mix has more",
                1 << MAX_LINK_MODE_BITS
            ));
        }
        Ok(Some(LinkParams {
            slice_cycles: s.grid.slice_cycles,
            slots_per_slice: s.grid.slots_per_slice,
            slices_per_frame: s.grid.slices_per_frame,
            div: p.baud_divider.max(1),
            axis: p.axis().map(|a| a.tlast),
            parity: match p.parity {
                "even" => 1,
                "odd" => 2,
                _ => 0,
            },
            stop_bits: p.stop_bits,
            depth: p.fifo_depth,
            crc_init: link::format::CRC_INIT,
            mode_bits,
        }))
    }

    /// Bits per character: start, 8 data, parity, stop.
    fn char_bits(&self) -> u32 {
        1 + 8 + (self.parity != 0) as u32 + self.stop_bits as u32
    }

    /// The character of `byte`, bit 0 (the start bit) first.
    fn frame(&self, byte: u8) -> u16 {
        let mut f = (byte as u16) << 1;
        let mut top = 9;
        if self.parity != 0 {
            let odd_ones = byte.count_ones() % 2 == 1;
            let pbit = if self.parity == 1 {
                odd_ones
            } else {
                !odd_ones
            };
            f |= (pbit as u16) << 9;
            top = 10;
        }
        for i in 0..self.stop_bits {
            f |= 1 << (top + i as u16);
        }
        f
    }
}

/// Token layout in the twin's FIFO: `{boundary, sample, channel[9:0],
/// code[15:0]}`; the Verilog keeps the boundary flag beside the block RAM
/// (`fbnd`), which holds the rest (`RAM_BITS`).
const TOKEN_BITS: usize = 2 + CH_BITS + VALUE_BITS;
const RAM_BITS: usize = TOKEN_BITS - 1;

/// The registers of the link (the Rust twin's state).
#[derive(Debug, Clone, Default)]
struct Regs {
    /// The index in its slice of the slot that starts after the core's
    /// next `slot_tick` (0 after reset, when the core's first slot is
    /// next), and `bnd`: this cycle starts a slice (a tick at `spos == 0`
    /// the cycle before). The core's timebase counts the cycles; the link
    /// counts only slots.
    spos: u64,
    bnd: bool,
    mem: Vec<u32>,
    wr: usize,
    rd: usize,
    n: usize,
    have: bool,
    tok: u32,
    /// The next byte slot of the token (0-3 trailer, 4-7 header, 8-11
    /// record); a token without a boundary starts at 8.
    bcnt: u8,
    started: bool,
    hframe: u8,
    hslice: u16,
    /// A mix with modes: the mode of the last header's frame and of the
    /// frame before it.
    fmode: u8,
    pmode: u8,
    crc: u16,
    /// UART: the character in transit is one the CRC covers (not its own
    /// two bytes); its data bits go into `crc` as they reach the line.
    in_crc: bool,
    ovfc: u8,
    ovf: bool,
    busy: bool,
    /// UART: the bit on the line (0 the start bit). Not read off `chr`:
    /// the FIFO's handshake would then depend on the bytes' values, which
    /// `prove` would have to carry (the frame counter does not come round
    /// after a frame).
    bitn: u32,
    dv: u32,
    /// UART: the character still to send, shifted right with zeros: its
    /// bit 0 is the line (`link_tx`); 1 alone, the last stop bit (and
    /// idle, where it stays).
    chr: u16,
    /// AXIS: the byte offered and its `tlast` (`busy` is `tvalid`).
    tdata: u8,
    tlast: bool,
}

#[derive(LogicBlock)]
pub struct UartLink {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub valid: Signal<In, Bit>,
    pub ch: Signal<In, Bits<CH_BITS>>,
    pub val: Signal<In, Bits<VALUE_BITS>>,
    /// The core's `slot_tick`: the next cycle starts a slot.
    pub slot_tick: Signal<In, Bit>,
    pub tx: Signal<Out, Bit>,
    pub ovf: Signal<Out, Bit>,
    _p: LinkParams,
    _r: Regs,
    /// The `mode` input (a mix with modes) during the cycle the next edge
    /// ends: the core's mode in force, which `RtlSim` sets once the core
    /// switches (0 until then: the gateware refuses mode mixes).
    pub(crate) _mode: u8,
}

/// The AXI4-Stream form of the link: the same packetizer, FIFO and
/// serializer, one byte per beat (docs/packet-format.md, "AXI4-Stream").
#[derive(LogicBlock)]
pub struct AxisLink {
    pub clock: Signal<In, Clock>,
    pub rst: Signal<In, Bit>,
    pub valid: Signal<In, Bit>,
    pub ch: Signal<In, Bits<CH_BITS>>,
    pub val: Signal<In, Bits<VALUE_BITS>>,
    /// The core's `slot_tick`: the next cycle starts a slot.
    pub slot_tick: Signal<In, Bit>,
    pub tready: Signal<In, Bit>,
    pub tdata: Signal<Out, Bits<8>>,
    pub tvalid: Signal<Out, Bit>,
    pub tlast: Signal<Out, Bit>,
    pub ovf: Signal<Out, Bit>,
    _p: LinkParams,
    _r: Regs,
    /// The `mode` input (a mix with modes) during the cycle the next edge
    /// ends: the core's mode in force, which `RtlSim` sets once the core
    /// switches (0 until then: the gateware refuses mode mixes).
    pub(crate) _mode: u8,
}

impl AxisLink {
    pub fn new(p: LinkParams) -> AxisLink {
        let mut l = AxisLink {
            clock: Default::default(),
            rst: Default::default(),
            valid: Default::default(),
            ch: Default::default(),
            val: Default::default(),
            slot_tick: Default::default(),
            tready: Default::default(),
            tdata: Default::default(),
            tvalid: Default::default(),
            tlast: Default::default(),
            ovf: Default::default(),
            _p: p,
            _r: Regs::default(),
            _mode: 0,
        };
        l._r.mem = vec![0; p.depth + 1];
        reset_regs(&p, &mut l._r);
        l
    }
}

impl Logic for AxisLink {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            if self.rst.val() {
                reset_regs(&self._p, &mut self._r);
            } else {
                let (v, c, x) = (
                    self.valid.val(),
                    self.ch.val().to_u64() as u32,
                    self.val.val().to_u64() as u32,
                );
                let t = self.slot_tick.val();
                let m = self._mode;
                edge(&self._p, &mut self._r, (v, c, x, m), t, self.tready.val());
            }
        }
        self.tdata.next = (self._r.tdata as u64).into();
        self.tvalid.next = self._r.busy;
        self.tlast.next = self._r.tlast;
        self.ovf.next = self._r.ovf;
    }

    fn connect(&mut self) {
        self.tdata.connect();
        self.tvalid.connect();
        self.tlast.connect();
        self.ovf.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(link_verilog(&self._p))
    }
}

/// The registers' values after reset (the FIFO's memory and its read
/// register `tok` keep their contents).
fn reset_regs(p: &LinkParams, r: &mut Regs) {
    let mem = std::mem::take(&mut r.mem);
    *r = Regs {
        spos: 0,
        bnd: p.slice_cycles == 1,
        mem,
        tok: r.tok,
        crc: 0xFFFF,
        chr: 1,
        ..Default::default()
    };
}

/// CRC-16/MODBUS after one more bit (the line's order: LSB first).
fn crc1(c: u16, bit: bool) -> u16 {
    if (c & 1 == 1) != bit {
        (c >> 1) ^ 0xA001
    } else {
        c >> 1
    }
}

/// CRC-16/MODBUS after one more byte (the AXI4-Stream link's, a beat a
/// cycle).
fn crc8(c: u16, d: u8) -> u16 {
    (0..8).fold(c, |c, i| crc1(c, d >> i & 1 == 1))
}

impl UartLink {
    pub fn new(p: LinkParams) -> UartLink {
        let mut l = UartLink {
            clock: Default::default(),
            rst: Default::default(),
            valid: Default::default(),
            ch: Default::default(),
            val: Default::default(),
            slot_tick: Default::default(),
            tx: Signal::new_with_default(true),
            ovf: Default::default(),
            _p: p,
            _r: Regs {
                mem: vec![0; p.depth + 1],
                ..Default::default()
            },
            _mode: 0,
        };
        // the Verilog's initial values are its reset values
        reset_regs(&p, &mut l._r);
        l
    }

    fn edge(&mut self, valid: bool, ch: u32, val: u32, tick: bool) {
        let m = self._mode;
        edge(&self._p, &mut self._r, (valid, ch, val, m), tick, false);
    }
}

/// The link's Rust twin on its own, stepped by hand without the core: for
/// this crate's tests (`crate::for_tests`), which drive its inputs and
/// read its line and slice boundaries (no rust-hdl type in its face).
pub struct Twin {
    p: LinkParams,
    r: Regs,
}

impl Twin {
    /// The twin after reset, as [`UartLink::new`] starts it.
    pub fn new(p: LinkParams) -> Twin {
        let mut r = Regs {
            mem: vec![0; p.depth + 1],
            ..Default::default()
        };
        reset_regs(&p, &mut r);
        Twin { p, r }
    }

    /// The UART line this cycle.
    pub fn line(&self) -> bool {
        self.r.chr & 1 == 1
    }

    /// Whether this cycle starts a slice.
    pub fn boundary(&self) -> bool {
        self.r.bnd
    }

    /// One clock edge: `input` is (valid, channel, code, mode) as for
    /// `edge`, `tick` the core's slot start.
    pub fn edge(&mut self, input: (bool, u32, u32, u8), tick: bool) {
        edge(&self.p, &mut self.r, input, tick, false);
    }
}

/// The registers after one clock edge (the UART's, or with `p.axis` the
/// AXIS master's, whose slave drives `tready` in the cycle the edge ends).
/// `input`: the sample stream and the `mode` input, (valid, channel,
/// code, mode).
fn edge(p: &LinkParams, r: &mut Regs, input: (bool, u32, u32, u8), tick: bool, tready: bool) {
    let (valid, ch, val, mode) = input;
    let p = *p;
    let bnd = r.bnd;
    let push = bnd || valid;
    let last_tick = r.dv + 1 == p.div;
    let ready = match p.axis {
        None => !r.busy || (last_tick && r.bitn + 1 == p.char_bits()),
        Some(_) => !r.busy || tready,
    };
    let load = ready && r.have;
    let pop = !r.have && r.n != 0;
    let room = r.n < p.depth || pop;
    // next state, from the values before the edge
    let mut nx = r.clone();
    nx.bnd = tick && r.spos == 0;
    if tick {
        nx.spos = (r.spos + 1) % p.slots_per_slice;
    }
    if pop {
        let t = r.mem[r.rd];
        nx.tok = t;
        nx.rd = (r.rd + 1) % (p.depth + 1);
        nx.have = true;
        // a token without a boundary skips to its record; a trailer only
        // once a header went out (its flag is `fbnd`, in flip-flops: the
        // slot is decided here, not behind the block RAM's output)
        nx.bcnt = match (t >> 27 & 1 == 1, r.started) {
            (false, _) => 8,
            (true, true) => 0,
            (true, false) => 4,
        };
    }
    // the free entry `wr` (never a queued token: at most `depth` of the
    // `depth + 1` entries are) takes every cycle's token; it is kept when
    // `wr` advances
    let mode = (mode as u32) & ((1 << p.mode_bits) - 1);
    nx.mem[r.wr] = mode << 28 | (bnd as u32) << 27 | (valid as u32) << 26 | ch << 16 | val;
    if push {
        if room {
            nx.wr = (r.wr + 1) % (p.depth + 1);
        } else {
            nx.ovfc = r.ovfc.saturating_add(1);
            nx.ovf = true;
        }
    }
    nx.n = r.n + (push && room) as usize - pop as usize;
    // empty and nothing to take: back to entry 0 (the Verilog's rewind)
    if r.n == 0 && !push {
        nx.wr = 0;
        nx.rd = 0;
    }
    shift(&p, r, &mut nx, tready, last_tick);
    if load {
        load_byte(&p, r, &mut nx);
    }
    *r = nx;
}

/// The byte in transit: one more bit period (UART) or the beat taken (AXIS).
fn shift(p: &LinkParams, r: &Regs, nx: &mut Regs, tready: bool, last_tick: bool) {
    if r.busy && p.axis.is_some() {
        nx.busy = !tready;
    } else if r.busy {
        if last_tick {
            nx.dv = 0;
            if r.bitn + 1 == p.char_bits() {
                nx.busy = false;
            } else {
                nx.bitn = r.bitn + 1;
                nx.chr = r.chr >> 1;
                // the data bit that goes out next (bits 1..=8 of the
                // character) enters the CRC
                if r.in_crc && r.bitn < 8 {
                    nx.crc = crc1(r.crc, r.chr >> 1 & 1 == 1);
                }
            }
        } else {
            nx.dv = r.dv + 1;
        }
    }
}

/// The byte slot the serializer sends next (a token without a boundary
/// starts at its record: the pop set `bcnt` so).
fn slot(r: &Regs) -> u8 {
    r.bcnt
}

/// The next byte of the packet (slot [`slot`]) starts
/// out; the CRC and the header's frame/slice counters follow it.
fn load_byte(p: &LinkParams, r: &Regs, nx: &mut Regs) {
    let slot = slot(r);
    // a token ends with its record, or its header when it has none
    let last = slot == 11 || (slot == 7 && r.tok >> 26 & 1 == 0);
    // a header: its frame's mode (the token's), and the one before at a
    // frame's first slice (no modes: the slice alone)
    if slot == 4 {
        nx.fmode = (r.tok >> 28) as u8;
        if r.hslice == 0 {
            nx.pmode = r.fmode;
        }
    }
    let field = link::format::slice_field(r.hslice, r.fmode, r.pmode, p.mode_bits);
    let byte = match slot {
        0 => 0x5A,
        1 => r.ovfc,
        2 => r.crc as u8,
        3 => (r.crc >> 8) as u8,
        4 => 0xA5,
        5 => r.hframe,
        6 => (field >> 8) as u8,
        7 => field as u8,
        8 => ((r.tok >> 24) & 3) as u8,
        9 => (r.tok >> 16) as u8,
        10 => (r.tok >> 8) as u8,
        _ => r.tok as u8,
    };
    nx.chr = p.frame(byte);
    nx.busy = true;
    nx.bitn = 0;
    nx.dv = 0;
    nx.tdata = byte;
    // the trailer of a frame's last slice goes out when the next
    // header's slice has wrapped to 0
    nx.tlast = slot == 3 && (p.axis == Some(link::Tlast::Slice) || r.hslice == 0);
    nx.bcnt = slot + 1;
    nx.have = !last;
    match (p.axis, slot) {
        (_, 2 | 3) => {}
        // UART: the CRC follows the line bit by bit (`shift`); a header
        // restarts it
        (None, 4) => nx.crc = p.crc_init,
        (None, _) => {}
        (Some(_), 4) => nx.crc = crc8(p.crc_init, byte),
        (Some(_), _) => nx.crc = crc8(r.crc, byte),
    }
    nx.in_crc = !matches!(slot, 2 | 3);
    if slot == 7 {
        nx.started = true;
        if r.hslice as u64 + 1 == p.slices_per_frame {
            nx.hslice = 0;
            nx.hframe = r.hframe.wrapping_add(1);
        } else {
            nx.hslice = r.hslice + 1;
        }
    }
}

impl UartLink {
    fn reset(&mut self) {
        reset_regs(&self._p, &mut self._r);
    }
}

impl Logic for UartLink {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            if self.rst.val() {
                self.reset();
            } else {
                let (v, c, x) = (
                    self.valid.val(),
                    self.ch.val().to_u64() as u32,
                    self.val.val().to_u64() as u32,
                );
                self.edge(v, c, x, self.slot_tick.val());
            }
        }
        self.tx.next = self._r.chr & 1 == 1;
        self.ovf.next = self._r.ovf;
    }

    fn connect(&mut self) {
        self.tx.connect();
        self.ovf.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(link_verilog(&self._p))
    }
}

/// Bits to hold `0..=n`.
fn width(n: u64) -> usize {
    (64 - n.leading_zeros() as usize).max(1)
}

/// The link's register and counter widths.
#[derive(Clone, Copy)]
struct Widths {
    /// Slot in the slice, FIFO address (`depth + 1` entries), FIFO count.
    pw: usize,
    aw: usize,
    nw: usize,
    /// UART only: bit-period divider, bits per character, bit counter.
    dw: usize,
    cb: usize,
    bw: usize,
    /// Header slice counter.
    hw: usize,
}

/// A `w`-bit decimal literal.
fn lit(w: usize, v: u64) -> String {
    format!("{w}'d{v}")
}

fn link_verilog(p: &LinkParams) -> String {
    let mut s = String::new();
    let cb = p.char_bits() as usize;
    let w = Widths {
        pw: width(p.slots_per_slice - 1),
        aw: width(p.depth as u64),
        nw: width(p.depth as u64),
        dw: width(p.div as u64 - 1),
        cb,
        bw: width(cb as u64 - 1),
        hw: width(p.slices_per_frame - 1),
    };
    declarations(&mut s, p, w);
    wires(&mut s, p, w);
    byte_out(&mut s, w.hw, p.mode_bits);
    crc_and_character(&mut s, p, w);
    let _ = writeln!(
        s,
        "// the FIFO's memory: its free entry `wr` takes this cycle's token in\n// every cycle (kept only when `wr` advances: no write enable behind the\n// core's `valid`), read into `tok` when the serializer takes the oldest\nalways @(posedge clock) begin\n  if (!rst) begin\n    mem[wr] <= token;\n    fbnd[wr] <= bnd;\n  end\n  if (!rst & pop) tok <= mem[rd];\nend\n"
    );
    let _ = writeln!(s, "always @(posedge clock) begin\n  if (rst) begin");
    register_reset(&mut s, p, w);
    fifo_update(&mut s, p, w);
    transmitter_update(&mut s, p, w);
    let _ = writeln!(s, "  end\nend\n");
    if p.axis.is_some() {
        let _ = writeln!(
            s,
            "always @(*) begin\n  tdata = tdata_r;\n  tvalid = busy;\n  tlast = tlast_r;\n  ovf = ovf_r;\nend"
        );
    } else {
        let _ = writeln!(s, "always @(*) begin\n  tx = chr[0];\n  ovf = ovf_r;\nend");
    }
    s
}

/// What the link is, then its registers with their initial values.
fn declarations(s: &mut String, p: &LinkParams, w: Widths) {
    let Widths {
        pw, aw, nw, dw, cb, ..
    } = w;
    let rb = RAM_BITS + p.mode_bits as usize;
    let axis = p.axis.is_some();
    if axis {
        let _ = writeln!(
            s,
            "// AXI4-Stream link: one byte per beat, FIFO of {} tokens (the schedule's\n// worst-case backlog under the slave's guarantee); packets: docs/packet-format.md",
            p.depth
        );
    } else {
        let _ = writeln!(
            s,
            "// UART link: {} cycles per bit, {cb} bits per character, FIFO of {} tokens\n// (the schedule's worst-case backlog); packets: docs/packet-format.md",
            p.div, p.depth
        );
    }
    // the slice's boundary from the core's timebase: the link counts the
    // core's slot starts (`slot_tick`), not cycles; `bnd` (this cycle
    // starts a slice) is registered
    let one = (p.slice_cycles == 1) as u8;
    let _ = writeln!(
        s,
        "// the index in its slice of the slot the core's next slot_tick announces\nreg [{}:0] spos;\ninitial spos = {};\nreg bnd;\ninitial bnd = 1'b{one};",
        pw - 1,
        lit(pw, 0)
    );
    // the FIFO's tokens in block RAM where the family has it; `tok`, the
    // token being sent, is its read register (no initial value: a block
    // RAM's output has none; it is read only once a token was taken).
    // One entry more than the depth: a pop never reads the entry written
    // at the same edge, so the RAM needs no read-first emulation (a write
    // register, a bypass; `no_rw_check`)
    // Zeros at power-on, as the Rust twin's: a block RAM's initial
    // contents cost nothing, and no stale entry holds a power-on value
    // that `prove` would have to enumerate (an AXI4-Stream link's FIFO is
    // searched state by state, every power-on value a state of its own).
    let _ = writeln!(
        s,
        "(* ram_style = \"block\", no_rw_check *)\nreg [{}:0] mem [0:{}];\ninteger mem_i;\ninitial for (mem_i = 0; mem_i <= {}; mem_i = mem_i + 1) mem[mem_i] = {rb}'d0;",
        rb - 1,
        p.depth,
        p.depth
    );
    // each entry's boundary flag in flip-flops: a popped token's first
    // byte slot is set at the pop, so the byte multiplexer's select is a
    // register, not a compare behind the block RAM's slow output
    let _ = writeln!(
        s,
        "reg [{}:0] fbnd;\ninitial fbnd = {}'d0;",
        p.depth,
        p.depth + 1
    );
    for (n, w) in [("wr", aw), ("rd", aw), ("n", nw)] {
        let _ = writeln!(s, "reg [{}:0] {n};\ninitial {n} = {w}'d0;", w - 1);
    }
    let _ = writeln!(
        s,
        "reg have;\ninitial have = 1'b0;\nreg [{}:0] tok;\n// its next byte slot (0-3 trailer, 4-7 header, 8-11 record)\nreg [3:0] bcnt;\ninitial bcnt = 4'd0;",
        rb - 1,
    );
    mode_registers(s, p.mode_bits);
    let _ = writeln!(
        s,
        "reg started;\ninitial started = 1'b0;\nreg [7:0] hframe;\ninitial hframe = 8'd0;\nreg [{}:0] hslice;\ninitial hslice = {};",
        w.hw - 1,
        lit(w.hw, 0)
    );
    let _ = writeln!(
        s,
        "reg [15:0] crc;\ninitial crc = 16'hffff;\nreg [7:0] ovfc;\ninitial ovfc = 8'd0;\nreg ovf_r;\ninitial ovf_r = 1'b0;"
    );
    if axis {
        let _ = writeln!(
            s,
            "// busy: a byte is offered (tvalid)\nreg busy;\ninitial busy = 1'b0;\nreg [7:0] tdata_r;\ninitial tdata_r = 8'd0;\nreg tlast_r;\ninitial tlast_r = 1'b0;\n"
        );
    } else {
        let _ = writeln!(
            s,
            "reg busy;\ninitial busy = 1'b0;\nreg [{}:0] bitn;\ninitial bitn = {}'d0;\nreg [{}:0] dv;\ninitial dv = {dw}'d0;",
            w.bw - 1,
            w.bw,
            dw - 1
        );
        let _ = writeln!(
            s,
            "// the character still to send, shifted right with zeros: chr[0] is the\n// line; 1 alone is the last stop bit (and idle, where it stays)\nreg [{}:0] chr;\ninitial chr = {cb}'d1;\n// the character in transit is covered by the CRC (not one of its bytes)\nreg in_crc;\ninitial in_crc = 1'b0;\n",
            cb - 1
        );
    }
}

/// A mix with modes: the modes of the last header's frame and of the
/// frame before it (nothing without modes).
fn mode_registers(s: &mut String, b: u32) {
    if b > 0 {
        let _ = writeln!(
            s,
            "// the modes of the last header's frame and of the frame before it\nreg [{}:0] fmode;\ninitial fmode = {b}'d0;\nreg [{}:0] pmode;\ninitial pmode = {b}'d0;",
            b - 1,
            b - 1
        );
    }
}

/// The handshake and FIFO wires of one cycle.
fn wires(s: &mut String, p: &LinkParams, w: Widths) {
    let Widths { nw, dw, cb, .. } = w;
    let _ = writeln!(s, "wire push = bnd | valid;");
    if p.axis.is_some() {
        // a beat is taken at an edge where tvalid and tready are high
        let _ = writeln!(s, "wire ready = !busy | tready;");
    } else {
        let _ = writeln!(s, "wire last_tick = dv == {};", lit(dw, p.div as u64 - 1));
        let _ = writeln!(
            s,
            "// the bit counter, not `chr`'s contents, ends a character: the FIFO's\n// handshake stays independent of the bytes' values (and `prove` of them)\nwire chr_end = bitn == {};\n// the next bit is a data bit\nwire data_next = bitn < {};\nwire ready = !busy | (last_tick & chr_end);",
            lit(w.bw, cb as u64 - 1),
            lit(w.bw, 8)
        );
    }
    let _ = writeln!(s, "wire load = ready & have;");
    let _ = writeln!(s, "wire pop = !have & (n != {nw}'d0);");
    let _ = writeln!(s, "wire room = (n < {}) | pop;", lit(nw, p.depth as u64));
    // a token ends with its record, or its header when it has none
    let _ = writeln!(s, "wire [3:0] slot = bcnt;");
    let _ = writeln!(
        s,
        "wire last = (slot == 4'd11) | ((slot == 4'd7) & !tok[{}]);",
        RAM_BITS - 1
    );
    if p.mode_bits > 0 {
        let top = RAM_BITS + p.mode_bits as usize - 1;
        let _ = writeln!(s, "wire [{top}:0] token = {{mode, valid, ch, val}};");
        // the header's slice field: the two modes above the slice
        let pad = match 16 - 2 * p.mode_bits as usize - w.hw {
            0 => String::new(),
            n => format!("{n}'d0, "),
        };
        let _ = writeln!(s, "wire [15:0] hfield = {{fmode, pmode, {pad}hslice}};");
    } else {
        let _ = writeln!(s, "wire [{}:0] token = {{valid, ch, val}};", RAM_BITS - 1);
    }
}

/// Bits `lo..lo + 8` of the `w`-bit register `r` as a byte (zeros above
/// its top).
fn byte_of(r: &str, w: usize, lo: usize) -> String {
    match w {
        _ if w <= lo => "8'd0".into(),
        _ if w >= lo + 8 => format!("{r}[{}:{lo}]", lo + 7),
        _ => format!("{{{}'d0, {r}[{}:{lo}]}}", lo + 8 - w, w - 1),
    }
}

/// The byte of the slot being sent.
fn byte_out(s: &mut String, hw: usize, mode_bits: u32) {
    let _ = writeln!(s, "reg [7:0] byte_out;\nalways @(*) begin\n  case (slot)");
    let (hi, lo) = if mode_bits > 0 {
        ("hfield[15:8]".to_string(), "hfield[7:0]".to_string())
    } else {
        (byte_of("hslice", hw, 8), byte_of("hslice", hw, 0))
    };
    for (i, e) in [
        "8'h5a",
        "ovfc",
        "crc[7:0]",
        "crc[15:8]",
        "8'ha5",
        "hframe",
        &hi,
        &lo,
    ]
    .iter()
    .enumerate()
    {
        let _ = writeln!(s, "    4'd{i}: byte_out = {e};");
    }
    let _ = writeln!(
        s,
        "    4'd8: byte_out = {{{}'d0, tok[{}:24]}};",
        8 - (CH_BITS - 8),
        CH_BITS + 15
    );
    let _ = writeln!(
        s,
        "    4'd9: byte_out = tok[23:16];\n    4'd10: byte_out = tok[15:8];\n    default: byte_out = tok[7:0];\n  endcase\nend\n"
    );
}

/// The CRC after the outgoing byte, and (UART) its character with start,
/// parity and stop bits.
fn crc_and_character(s: &mut String, p: &LinkParams, w: Widths) {
    if p.axis.is_some() {
        // CRC-16/MODBUS of one byte: a beat may leave every cycle
        let _ = writeln!(
            s,
            "function [15:0] crc8;\n  input [15:0] c;\n  input [7:0] d;\n  integer i;\n  reg [15:0] x;\n  begin\n    x = c ^ {{8'h00, d}};\n    for (i = 0; i < 8; i = i + 1)\n      x = x[0] ? ((x >> 1) ^ 16'ha001) : (x >> 1);\n    crc8 = x;\n  end\nendfunction\n"
        );
        let _ = writeln!(
            s,
            "wire [15:0] crc_next = crc8((slot == 4'd4) ? 16'h{:04x} : crc, byte_out);\n",
            p.crc_init
        );
        return;
    }
    // UART: CRC-16/MODBUS one bit at a time, the data bit that goes out
    // next (`chr[1]`) in line order: 16 flip-flops and a few LUTs instead
    // of a byte-wide XOR tree behind the byte multiplexer
    let _ = writeln!(
        s,
        "wire [15:0] crc_bit = {{1'b0, crc[15:1]}} ^ ({{16{{crc[0] ^ chr[1]}}}} & 16'ha001);"
    );
    let stops = "1'b1, ".repeat(p.stop_bits as usize);
    let parity = match p.parity {
        1 => "^byte_out, ",
        2 => "~^byte_out, ",
        _ => "",
    };
    let _ = writeln!(
        s,
        "wire [{}:0] chr_load = {{{stops}{parity}byte_out, 1'b0}};\n",
        w.cb - 1
    );
}

/// The reset branch of the register update.
fn register_reset(s: &mut String, p: &LinkParams, w: Widths) {
    let Widths {
        pw, aw, nw, dw, cb, ..
    } = w;
    let one = (p.slice_cycles == 1) as u8;
    let _ = writeln!(s, "    spos <= {};\n    bnd <= 1'b{one};", lit(pw, 0),);
    let out_reset = if p.axis.is_some() {
        "    tdata_r <= 8'd0;\n    tlast_r <= 1'b0;".to_string()
    } else {
        format!(
            "    bitn <= {}'d0;\n    dv <= {dw}'d0;\n    chr <= {cb}'d1;\n    in_crc <= 1'b0;",
            w.bw
        )
    };
    let _ = writeln!(
        s,
        "    wr <= {aw}'d0;\n    rd <= {aw}'d0;\n    n <= {nw}'d0;\n    have <= 1'b0;\n    bcnt <= 4'd0;\n    started <= 1'b0;\n    hframe <= 8'd0;\n    hslice <= {};\n    crc <= 16'hffff;\n    ovfc <= 8'd0;\n    ovf_r <= 1'b0;\n    busy <= 1'b0;\n{out_reset}{}\n  end else begin",
        lit(w.hw, 0),
        match p.mode_bits {
            0 => String::new(),
            b => format!("\n    fmode <= {b}'d0;\n    pmode <= {b}'d0;"),
        }
    );
}

/// The slice position and the token FIFO: push, pop, overflow, count.
fn fifo_update(s: &mut String, p: &LinkParams, w: Widths) {
    let Widths { pw, aw, nw, .. } = w;
    let _ = writeln!(
        s,
        "    bnd <= slot_tick & (spos == {});\n    if (slot_tick) spos <= (spos == {}) ? {} : spos + {};",
        lit(pw, 0),
        lit(pw, p.slots_per_slice - 1),
        lit(pw, 0),
        lit(pw, 1)
    );
    let wrap = |r: &str| {
        format!(
            "({r} == {}) ? {aw}'d0 : {r} + {aw}'d1",
            lit(aw, p.depth as u64)
        )
    };
    let _ = writeln!(
        s,
        "    if (pop) begin\n      rd <= {};\n      have <= 1'b1;\n      // a token without a boundary skips to its record; a trailer only\n      // once a header went out\n      bcnt <= !fbnd[rd] ? 4'd8 : started ? 4'd0 : 4'd4;\n    end",
        wrap("rd"),
    );
    let _ = writeln!(
        s,
        "    if (push) begin\n      if (room) begin\n        wr <= {};\n      end else begin\n        if (ovfc != 8'hff) ovfc <= ovfc + 8'd1;\n        ovf_r <= 1'b1;\n      end\n    end",
        wrap("wr")
    );
    // A one-bit count (a FIFO of one token) has no padding bits: `{0'd0, x}`
    // is not Verilog.
    let zext = |bit: &str| {
        if nw == 1 {
            format!("({bit})")
        } else {
            format!("{{{}'d0, {bit}}}", nw - 1)
        }
    };
    let _ = writeln!(s, "    n <= n + {} - {};", zext("push & room"), zext("pop"));
    // an empty FIFO with nothing to take rewinds to entry 0: where the
    // pointers stand then no longer depends on every token before (a frame
    // of T tokens would shift them by T mod depth + 1 each frame), so the
    // link's state comes round with the frame, not after several (`prove`)
    let _ = writeln!(
        s,
        "    if ((n == {nw}'d0) & !push) begin\n      wr <= {aw}'d0;\n      rd <= {aw}'d0;\n    end"
    );
}

/// The byte in transit (bit periods or the beat taken), and the next byte's
/// load with the CRC and header counters.
fn transmitter_update(s: &mut String, p: &LinkParams, w: Widths) {
    let Widths { dw, .. } = w;
    if p.axis.is_some() {
        let _ = writeln!(s, "    if (busy & tready) busy <= 1'b0;");
    } else {
        let _ = writeln!(
        s,
"    if (busy) begin\n      if (last_tick) begin\n        dv <= {dw}'d0;\n        if (chr_end) busy <= 1'b0;\n        else begin\n          bitn <= bitn + {}'d1;\n          chr <= chr >> 1;\n          if (in_crc & data_next) crc <= crc_bit;\n        end\n      end else dv <= dv + {dw}'d1;\n    end",
        w.bw
    );
    }
    let tlast_frame = format!("(slot == 4'd3) & (hslice == {})", lit(w.hw, 0));
    let load_out = match p.axis {
        Some(t) => format!(
            "      tdata_r <= byte_out;\n      tlast_r <= {};",
            if t == link::Tlast::Slice {
                "slot == 4'd3"
            } else {
                &tlast_frame
            }
        ),
        None => format!(
            "      chr <= chr_load;\n      bitn <= {}'d0;\n      dv <= {dw}'d0;",
            w.bw
        ),
    };
    let crc_load = match p.axis {
        Some(_) => "      if (slot != 4'd2 && slot != 4'd3) crc <= crc_next;".to_string(),
        None => format!(
            "      if (slot == 4'd4) crc <= 16'h{:04x};\n      in_crc <= (slot != 4'd2) && (slot != 4'd3);",
            p.crc_init
        ),
    };
    let crc_load = match p.mode_bits {
        0 => crc_load,
        b => format!(
            "{crc_load}\n      if (slot == 4'd4) begin\n        fmode <= tok[{}:{RAM_BITS}];\n        if (hslice == {}) pmode <= fmode;\n      end",
            RAM_BITS + b as usize - 1,
            lit(w.hw, 0)
        ),
    };
    let _ = writeln!(
        s,
        "    if (load) begin\n{load_out}\n      busy <= 1'b1;\n      bcnt <= slot + 4'd1;\n      have <= !last;\n{crc_load}\n      if (slot == 4'd7) begin\n        started <= 1'b1;\n        if (hslice == {}) begin\n          hslice <= {};\n          hframe <= hframe + 8'd1;\n        end else hslice <= hslice + {};\n      end\n    end",
        lit(w.hw, p.slices_per_frame - 1),
        lit(w.hw, 0),
        lit(w.hw, 1)
    );
}
