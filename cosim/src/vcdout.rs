//! Waveform output of a run: a VCD of `slotforge_top`'s ports over a window
//! of frames, and a GTKWave save file grouping the signals by branch.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use lut_gen::Schedule;

use crate::pins::{Layout, Pins, PORT_NAMES};
use crate::run::Observer;

/// Writes the ports of every cycle in `[from, to)` (cycles counted from the
/// first reset cycle of the run) to a VCD with a 1 ps timescale.  Besides the
/// ports of `slotforge_top`, a sub-scope per branch (`branch_<name>`) repeats
/// that branch's bits for viewing; checkers ignore it.
pub struct VcdWriter {
    w: BufWriter<File>,
    layout: Layout,
    from: u64,
    to: u64,
    half_ps: u64,
    prev: Vec<u64>,
    cur: Vec<u64>,
    widths: Vec<u32>,
    ids: Vec<String>,
    err: Option<std::io::Error>,
}

fn id_code(mut n: usize) -> String {
    let mut s = String::new();
    loop {
        s.push((b'!' + (n % 94) as u8) as char);
        n /= 94;
        if n == 0 {
            return s;
        }
    }
}

impl VcdWriter {
    pub fn create(path: &Path, s: &Schedule, from: u64, to: u64) -> std::io::Result<VcdWriter> {
        let l = Layout::new(s);
        let mut widths = l.port_widths().to_vec();
        let mut w = BufWriter::new(File::create(path)?);
        writeln!(w, "$date slotforge sim $end")?;
        writeln!(w, "$version slotforge cosim (mix {}) $end", s.mix.name)?;
        writeln!(w, "$timescale 1ps $end")?;
        writeln!(w, "$scope module slotforge_top $end")?;
        for (i, n) in PORT_NAMES.iter().enumerate() {
            if matches!(i, 0 | 1 | 7) {
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
        for (b, br) in s.branches.iter().enumerate() {
            writeln!(w, "$scope module branch_{} $end", br.name)?;
            let base = widths.len();
            widths.extend([1, 1, 1, 3, l.en_n[b]]);
            writeln!(w, "$var wire 1 {} cs_n $end", id_code(base))?;
            writeln!(w, "$var wire 1 {} sclk $end", id_code(base + 1))?;
            writeln!(w, "$var wire 1 {} miso $end", id_code(base + 2))?;
            writeln!(w, "$var wire 3 {} mux_sel [2:0] $end", id_code(base + 3))?;
            writeln!(
                w,
                "$var wire {} {} mux_en [{}:0] $end",
                l.en_n[b],
                id_code(base + 4),
                l.en_n[b] - 1
            )?;
            writeln!(w, "$upscope $end")?;
        }
        writeln!(w, "$upscope $end")?;
        writeln!(w, "$enddefinitions $end")?;
        let half_ps = (500_000_000_000u64 / s.grid.clock_hz).max(1);
        let ids = (0..widths.len()).map(id_code).collect();
        Ok(VcdWriter {
            w,
            layout: l,
            from,
            to,
            half_ps,
            prev: Vec::new(),
            cur: Vec::new(),
            widths,
            ids,
            err: None,
        })
    }

    fn write_cycle(&mut self, k: u64, rst: bool, p: &Pins, miso: u64) -> std::io::Result<()> {
        let t = (k - self.from + 1) * 2 * self.half_ps;
        self.cur.clear();
        self.cur.extend([
            1,
            rst as u64,
            miso,
            p.cs_n as u64,
            p.sclk as u64,
            p.mux_sel as u64,
            p.mux_en,
            p.sample_valid as u64,
            p.sample_channel as u64,
            p.sample_value as u64,
        ]);
        for b in 0..self.layout.branches {
            self.cur.extend([
                (p.cs_n >> b & 1) as u64,
                (p.sclk >> b & 1) as u64,
                miso >> b & 1,
                self.layout.sel(p, b) as u64,
                self.layout.en(p, b),
            ]);
        }
        // rst is sampled at the edge that begins cycle k: it changes half a
        // period before it; the outputs and MISO of cycle k change at the edge.
        let first = self.prev.is_empty();
        writeln!(self.w, "#{}", t - self.half_ps)?;
        if first {
            writeln!(self.w, "$dumpvars")?;
        }
        writeln!(self.w, "0{}", self.ids[0])?;
        for i in 1..self.cur.len() {
            if first || (i == 1 && self.prev[1] != self.cur[1]) {
                self.put(i)?;
            }
        }
        if first {
            writeln!(self.w, "$end")?;
        }
        writeln!(self.w, "#{t}")?;
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
        if self.widths[i] == 1 && !matches!(i, 2..=4) {
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

impl Observer for VcdWriter {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &Pins, miso: u64) {
        if cycle >= self.from && cycle < self.to && self.err.is_none() {
            if let Err(e) = self.write_cycle(cycle, rst, pins, miso) {
                self.err = Some(e);
            }
        }
    }
}

/// A GTKWave save file for a VCD written by [`VcdWriter`]: clock and reset,
/// then one group per branch (cs_n, sclk, miso, mux bits), then the sample stream.
pub fn write_gtkw(path: &Path, vcd: &Path, s: &Schedule) -> std::io::Result<()> {
    let l = Layout::new(s);
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "[dumpfile] \"{}\"", vcd.display())?;
    writeln!(w, "[timestart] 0")?;
    writeln!(w, "@28")?;
    writeln!(w, "slotforge_top.clk")?;
    writeln!(w, "slotforge_top.rst")?;
    for (b, br) in s.branches.iter().enumerate() {
        let sc = format!("slotforge_top.branch_{}", br.name);
        writeln!(w, "@800200")?;
        writeln!(w, "-branch {b} {}", br.name)?;
        writeln!(w, "@28")?;
        writeln!(w, "{sc}.cs_n")?;
        writeln!(w, "{sc}.sclk")?;
        writeln!(w, "{sc}.miso")?;
        writeln!(w, "@22")?;
        writeln!(w, "{sc}.mux_sel[2:0]")?;
        writeln!(w, "{sc}.mux_en[{}:0]", l.en_n[b] - 1)?;
        writeln!(w, "@1000200")?;
        writeln!(w, "-branch {b} {}", br.name)?;
    }
    writeln!(w, "@800200")?;
    writeln!(w, "-samples")?;
    writeln!(w, "@28")?;
    writeln!(w, "slotforge_top.sample_valid")?;
    writeln!(w, "@24")?;
    writeln!(w, "slotforge_top.sample_channel[{}:0]", l.channel_bits - 1)?;
    writeln!(w, "slotforge_top.sample_value[13:0]")?;
    writeln!(w, "@1000200")?;
    writeln!(w, "-samples")?;
    w.flush()
}
