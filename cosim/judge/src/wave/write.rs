//! Waveform output of a run: a VCD of `slotforge_top`'s ports over a window
//! of frames, and a GTKWave save file grouping the signals by branch.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use lut_gen::Schedule;

use crate::check::{run_dut, Dut, Observer, RunOptions};
use crate::model::Verdict;
use lut_gen::{Dir, Layout, Pins, Role, PORTS, TOP_MODULE};

/// The time in picoseconds of clock edge `n` of a run (edge `2k + 1` falls
/// before cycle `k` (counted from the first reset cycle), edge `2k + 2`
/// rises to begin it): the exact time `n / (2 clock)` rounded once, so
/// intervals read off a waveform carry no accumulated drift.  Every VCD
/// slotforge writes (here and the Icarus testbench's clock) uses it.
pub fn edge_ps(clock_hz: u64, n: u64) -> u64 {
    let f = clock_hz as u128;
    ((n as u128 * 1_000_000_000_000 + f) / (2 * f)) as u64
}

/// The lanes of a branch that its view in the waveform shows, in order (a
/// branch without a mux has no mux lanes: [`Layout::has_lane`]).
const BRANCH_VIEW: [Role; 6] = [
    Role::CsN,
    Role::Sclk,
    Role::Mosi,
    Role::Miso,
    Role::MuxSel,
    Role::MuxEn,
];

/// Branch `b`'s lanes in its view, in [`BRANCH_VIEW`] order.
fn view(l: &Layout, b: usize) -> impl Iterator<Item = Role> + '_ {
    BRANCH_VIEW.into_iter().filter(move |&r| l.has_lane(r, b))
}

/// Writes the ports of every cycle in `[from, to)` (cycles counted from the
/// first reset cycle of the run) to a VCD with a 1 ps timescale, at the
/// run's own times ([`edge_ps`]: time 0 is the start of the run, cycle `k`
/// begins at the rising edge `(k + 1)` clock periods later).  Besides the
/// ports of `slotforge_top`, a sub-scope per branch (`branch_<name>`) repeats
/// that branch's bits for viewing; checkers ignore it.
pub struct VcdWriter {
    w: BufWriter<File>,
    layout: Layout,
    from: u64,
    to: u64,
    clock_hz: u64,
    prev: Vec<u128>,
    cur: Vec<u128>,
    widths: Vec<u32>,
    ids: Vec<String>,
    err: Option<std::io::Error>,
}

/// The VCD identifier code of signal `n` (printable ASCII from `!`, base
/// 94): every VCD slotforge writes numbers its signals this way.
pub fn id_code(mut n: usize) -> String {
    let mut s = String::new();
    loop {
        s.push((b'!' + (n % 94) as u8) as char);
        n /= 94;
        if n == 0 {
            return s;
        }
    }
}

/// The header of a VCD of 1-bit wires `names` in one scope, the wire at
/// index `i` coded [`id_code`]`(i)`; `timescale` as VCD writes it (`1 ns`).
/// What a logic analyser's or sigrok's VCD looks like, for the checks and
/// tests that make one.
pub fn wire_header(timescale: &str, scope: &str, names: &[&str]) -> String {
    let mut h = format!("$timescale {timescale} $end\n$scope module {scope} $end\n");
    for (i, n) in names.iter().enumerate() {
        h += &format!("$var wire 1 {} {n} $end\n", id_code(i));
    }
    h + "$upscope $end\n$enddefinitions $end\n"
}

impl VcdWriter {
    pub fn create(path: &Path, s: &Schedule, from: u64, to: u64) -> std::io::Result<VcdWriter> {
        let l = Layout::new(s);
        let mut widths = l.port_widths().to_vec();
        let mut w = BufWriter::new(File::create(path)?);
        writeln!(w, "$date slotforge sim $end")?;
        writeln!(w, "$version slotforge cosim (mix {}) $end", s.mix.name)?;
        writeln!(w, "$timescale 1ps $end")?;
        writeln!(w, "$scope module {TOP_MODULE} $end")?;
        for (i, port) in PORTS.iter().enumerate() {
            let n = port.name;
            if widths[i] == 0 {
                continue; // a port the mix does not have (`mux_sel` without muxes)
            }
            if !port.vector {
                writeln!(w, "$var wire 1 {} {n} $end", id_code(i))?;
            } else {
                writeln!(
                    w,
                    "$var wire {} {} {n} [{}:0] $end",
                    widths[i],
                    id_code(i),
                    widths[i] - 1
                )?;
            }
        }
        // The link's ports follow the branch views in the value list.
        let views: usize = (0..s.branches.len()).map(|b| view(&l, b).count()).sum();
        let link_at = PORTS.len() + views;
        for (k, lp) in l.link_ports().iter().enumerate() {
            if lp.width == 1 {
                writeln!(w, "$var wire 1 {} {} $end", id_code(link_at + k), lp.name)?;
            } else {
                writeln!(
                    w,
                    "$var wire {} {} {} [{}:0] $end",
                    lp.width,
                    id_code(link_at + k),
                    lp.name,
                    lp.width - 1
                )?;
            }
        }
        for (b, br) in s.branches.iter().enumerate() {
            writeln!(w, "$scope module branch_{} $end", br.name)?;
            for r in view(&l, b) {
                let (hi, lo) = l.lane_bits(r, b);
                let n = hi - lo + 1;
                let i = widths.len();
                widths.push(n);
                if matches!(r, Role::MuxSel | Role::MuxEn) {
                    writeln!(
                        w,
                        "$var wire {n} {} {} [{}:0] $end",
                        id_code(i),
                        r.key(),
                        n - 1
                    )?;
                } else {
                    writeln!(w, "$var wire 1 {} {} $end", id_code(i), l.lane_key(r, b))?;
                }
            }
            writeln!(w, "$upscope $end")?;
        }
        widths.extend(l.link_ports().iter().map(|lp| lp.width));
        // The mode ports follow the link's (a mix with modes).
        for mp in l.mode_ports() {
            let i = widths.len();
            widths.push(l.mode_bits);
            if l.mode_bits == 1 {
                writeln!(w, "$var wire 1 {} {} $end", id_code(i), mp.name)?;
            } else {
                let n = l.mode_bits;
                writeln!(
                    w,
                    "$var wire {n} {} {} [{}:0] $end",
                    id_code(i),
                    mp.name,
                    n - 1
                )?;
            }
        }
        writeln!(w, "$upscope $end")?;
        writeln!(w, "$enddefinitions $end")?;
        let ids = (0..widths.len()).map(id_code).collect();
        Ok(VcdWriter {
            w,
            layout: l,
            from,
            to,
            clock_hz: s.grid.clock_hz,
            prev: Vec::new(),
            cur: Vec::new(),
            widths,
            ids,
            err: None,
        })
    }

    fn write_cycle(&mut self, k: u64, rst: bool, p: &Pins, miso: u64) -> std::io::Result<()> {
        let (fall, rise) = (
            edge_ps(self.clock_hz, 2 * k + 1),
            edge_ps(self.clock_hz, 2 * k + 2),
        );
        self.cur.clear();
        self.cur.extend(Role::ALL.map(|r| match r {
            Role::Clock => 1,
            Role::Reset => rst as u128,
            Role::Miso => miso as u128,
            r => p.value(r),
        }));
        for b in 0..self.layout.branches {
            for r in view(&self.layout, b) {
                let (hi, lo) = self.layout.lane_bits(r, b);
                let v = if r == Role::Miso {
                    miso as u128
                } else {
                    p.value(r)
                };
                self.cur.push((v >> lo) & ((1u128 << (hi - lo + 1)) - 1));
            }
        }
        let l = &self.layout;
        self.cur
            .extend(l.link_ports().iter().map(|lp| lp.signal.get(l, p) as u128));
        self.cur
            .extend(l.mode_ports().iter().map(|mp| match mp.dir {
                Dir::In => p.mode_sel as u128,
                _ => p.mode as u128,
            }));
        // rst is sampled at the edge that begins cycle k: it changes half a
        // period before it; the outputs and MISO of cycle k change at the edge.
        let first = self.prev.is_empty();
        writeln!(self.w, "#{fall}")?;
        if first {
            writeln!(self.w, "$dumpvars")?;
        }
        writeln!(self.w, "0{}", self.ids[0])?;
        for i in 1..self.cur.len() {
            if self.widths[i] == 0 {
                continue;
            }
            if first || (i == 1 && self.prev[1] != self.cur[1]) {
                self.put(i)?;
            }
        }
        if first {
            writeln!(self.w, "$end")?;
        }
        writeln!(self.w, "#{rise}")?;
        writeln!(self.w, "1{}", self.ids[0])?;
        if !first {
            for i in 2..self.cur.len() {
                if self.prev[i] != self.cur[i] {
                    self.put(i)?;
                }
            }
        }
        std::mem::swap(&mut self.prev, &mut self.cur);
        Ok(())
    }

    fn put(&mut self, i: usize) -> std::io::Result<()> {
        // a 1-bit value as a scalar change, except the branch-lane ports
        // (`adc_cs_n` of a one-branch mix is still a vector)
        let lanes = i < PORTS.len()
            && matches!(
                Role::ALL[i],
                Role::Miso | Role::CsN | Role::Sclk | Role::Mosi
            );
        if self.widths[i] == 1 && !lanes {
            writeln!(self.w, "{}{}", self.cur[i], self.ids[i])
        } else {
            writeln!(self.w, "b{:b} {}", self.cur[i], self.ids[i])
        }
    }

    /// Flushes the file; reports the first write error.
    pub fn finish(mut self) -> std::io::Result<()> {
        if let Some(e) = self.err.take() {
            return Err(e);
        }
        self.w.flush()
    }
}

/// Runs `dut` for `frames` frames under the ADC model and the checker, with
/// its pins in cycles `[from, to)` (counted from the first reset cycle)
/// written to the VCD `path`: how the judge's tests and benchmarks make a
/// waveform of a run.
pub fn write_run<D: Dut + ?Sized>(
    path: &Path,
    s: &Schedule,
    dut: &mut D,
    frames: u64,
    opts: &RunOptions,
    (from, to): (u64, u64),
) -> std::io::Result<Verdict> {
    let mut w = VcdWriter::create(path, s, from, to)?;
    let r = run_dut(s, dut, frames, opts, "gen", Some(&mut w));
    w.finish()?;
    Ok(r)
}

impl Observer for VcdWriter {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        if cycle >= self.from && cycle < self.to && self.err.is_none() {
            if let Err(e) = self.write_cycle(cycle, rst, pins, miso) {
                self.err = Some(e);
            }
        }
    }
}

/// The GTKWave translate file of a VCD: `<stem>.channels.txt` beside it.
pub fn channels_path(vcd: &Path) -> std::path::PathBuf {
    let stem = vcd
        .file_stem()
        .map_or("wave".into(), |s| s.to_string_lossy());
    vcd.with_file_name(format!("{stem}.channels.txt"))
}

/// A GTKWave translate (filter) file: each `sample_channel` value as the
/// trace shows it (decimal) and the channel's name.
pub fn channels_text(s: &Schedule) -> String {
    let mut t = String::from("# sample_channel value -> channel name (GTKWave translate file)\n");
    for (i, c) in s.mix.channels.iter().enumerate() {
        t.push_str(&format!("{i} {}\n", c.name));
    }
    t
}

/// A GTKWave save file for a VCD written by [`VcdWriter`]: clock and reset,
/// then one group per branch (cs_n, or cnv for a CNV-started part; sclk,
/// miso, and the mux bits of a branch that has a mux), then the sample
/// stream with `sample_channel` shown as channel names through the
/// translate file written beside the save file ([`channels_path`]; named
/// in the save file the way `vcd` is, so it is found wherever the VCD is),
/// then the link's ports when the mix has a link: every port the VCD has.
pub fn write_gtkw(path: &Path, vcd: &Path, s: &Schedule) -> std::io::Result<()> {
    let l = Layout::new(s);
    let names = channels_path(vcd);
    let beside = path.with_file_name(names.file_name().unwrap_or_default());
    std::fs::write(&beside, channels_text(s))?;
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "[dumpfile] \"{}\"", vcd.display())?;
    writeln!(w, "[timestart] 0")?;
    writeln!(w, "@28")?;
    let top = TOP_MODULE;
    writeln!(w, "{top}.{}", Role::Clock.name())?;
    writeln!(w, "{top}.{}", Role::Reset.name())?;
    for (b, br) in s.branches.iter().enumerate() {
        let sc = format!("{top}.branch_{}", br.name);
        writeln!(w, "@800200")?;
        writeln!(w, "-branch {b} {}", br.name)?;
        writeln!(w, "@28")?;
        for r in [Role::CsN, Role::Sclk, Role::Mosi, Role::Miso] {
            if l.has_lane(r, b) {
                writeln!(w, "{sc}.{}", l.lane_key(r, b))?;
            }
        }
        if l.muxed[b] {
            writeln!(w, "@22")?;
            for r in [Role::MuxSel, Role::MuxEn] {
                let (hi, lo) = l.lane_bits(r, b);
                writeln!(w, "{sc}.{}[{}:0]", r.key(), hi - lo)?;
            }
        }
        writeln!(w, "@1000200")?;
        writeln!(w, "-branch {b} {}", br.name)?;
    }
    writeln!(w, "@800200")?;
    writeln!(w, "-samples")?;
    writeln!(w, "@28")?;
    writeln!(w, "{top}.{}", Role::SampleValid.name())?;
    // 0x2000: translated by filter file 1; 0x24: decimal, right-justified
    writeln!(w, "@2024")?;
    writeln!(w, "^1 {}", names.display())?;
    let ch = Role::SampleChannel;
    writeln!(w, "{top}.{}[{}:0]", ch.name(), l.width(ch) - 1)?;
    writeln!(w, "@24")?;
    let v = Role::SampleValue;
    writeln!(w, "{top}.{}[{}:0]", v.name(), l.width(v) - 1)?;
    writeln!(w, "@1000200")?;
    writeln!(w, "-samples")?;
    gtkw_link(&mut w, &l)?;
    gtkw_modes(&mut w, &l)?;
    w.flush()
}

/// The mode ports' group (decimal: the mode's number); nothing without modes.
fn gtkw_modes(w: &mut impl Write, l: &Layout) -> std::io::Result<()> {
    if l.mode_ports().is_empty() {
        return Ok(());
    }
    writeln!(w, "@800200")?;
    writeln!(w, "-modes")?;
    for mp in l.mode_ports() {
        if l.mode_bits == 1 {
            writeln!(w, "@28")?;
            writeln!(w, "{TOP_MODULE}.{}", mp.name)?;
        } else {
            writeln!(w, "@24")?;
            writeln!(w, "{TOP_MODULE}.{}[{}:0]", mp.name, l.mode_bits - 1)?;
        }
    }
    writeln!(w, "@1000200")?;
    writeln!(w, "-modes")
}

/// The link's group of a save file: its ports as [`VcdWriter`] dumps them
/// (`tdata` in hex, the rest as bits); nothing without a link.
fn gtkw_link(w: &mut impl Write, l: &Layout) -> std::io::Result<()> {
    if l.link_ports().is_empty() {
        return Ok(());
    }
    let top = TOP_MODULE;
    writeln!(w, "@800200")?;
    writeln!(w, "-link")?;
    for lp in l.link_ports() {
        if lp.width == 1 {
            writeln!(w, "@28")?;
            writeln!(w, "{top}.{}", lp.name)?;
        } else {
            writeln!(w, "@22")?;
            writeln!(w, "{top}.{}[{}:0]", lp.name, lp.width - 1)?;
        }
    }
    writeln!(w, "@1000200")?;
    writeln!(w, "-link")
}
