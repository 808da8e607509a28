//! sigrok-cli's SPI decoder as a detector of the fault campaign: it reads
//! each branch's CS, SCLK and MISO as a logic analyser would and knows only
//! the part's SPI mode and word size.  A run passes when, per branch, the
//! words it decodes are the sample values the design emitted for that
//! branch's channels, in order, and there are as many as the schedule has
//! conversions in the window.  It has no view of the mux pins.
//!
//! The window starts at frame 1 (where faults land); one cycle is one
//! nanosecond of the VCD sigrok reads (its SPI decoder counts edges, not
//! time).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

use judge::Observer;
use lut_gen::Pins;
use lut_gen::Schedule;
use lut_gen::{AdcPart, Start};

use judge::tools::{self, ToolError};

/// Every branch's CS/SCLK/MISO changes and the sample stream, from frame 1.
pub struct SpiCapture {
    /// Observer cycle of the window's first cycle (the last of frame 0).
    from: u64,
    last: Vec<Option<u8>>,
    /// Per branch: (time, cs | sclk << 1 | miso << 2) at every change.
    changes: Vec<Vec<(u64, u8)>>,
    samples: Vec<(u16, u16)>,
    end: u64,
    /// Cycles seen as a [`CycleSink`] (a VCD's cycles carry no number).
    seen: u64,
}

impl SpiCapture {
    /// A capture for a run of `s` with `reset` reset cycles.
    pub fn new(s: &Schedule, reset: u64) -> SpiCapture {
        let nb = s.branches.len();
        SpiCapture {
            // a cycle early, so that a CS falling at frame 1's first cycle is an edge
            from: reset + s.grid.frame_cycles - 1,
            last: vec![None; nb],
            changes: vec![Vec::new(); nb],
            samples: Vec::new(),
            end: 0,
            seen: 0,
        }
    }
}

impl Observer for SpiCapture {
    fn cycle(&mut self, cycle: u64, rst: bool, p: &Pins, miso: u64) {
        if rst || cycle < self.from {
            return;
        }
        let t = cycle - self.from;
        self.end = t + 1;
        for (b, last) in self.last.iter_mut().enumerate() {
            let v = (p.cs_n >> b & 1) as u8
                | ((p.sclk >> b & 1) as u8) << 1
                | ((miso >> b & 1) as u8) << 2;
            if *last != Some(v) {
                *last = Some(v);
                self.changes[b].push((t, v));
            }
        }
        if p.sample_valid {
            self.samples.push((p.sample_channel, p.sample_value));
        }
    }
}

/// Icarus's VCD, read back cycle by cycle from its first (reset) cycle, as
/// the in-process engines' observers see it; x/z bits read as 0.
impl judge::CycleSink for SpiCapture {
    fn cycle(&mut self, rst: Option<bool>, pins: &Pins, _: &Pins, miso: u64, _: u64) {
        let c = self.seen;
        self.seen += 1;
        Observer::cycle(self, c, rst.unwrap_or(false), pins, miso);
    }
}

/// sigrok's SPI decoder options for a part, and the code in a decoded word.
struct PartDecoder {
    options: &'static str,
    wordsize: u32,
    shift: u32,
    mask: u16,
}

impl PartDecoder {
    fn of(part: &AdcPart) -> PartDecoder {
        // Mode 3 (CS parts) reads stream bits 1..=w at the w rising edges:
        // bit 0, a leading zero, comes before the first; mode 0 reads 0..w.
        let (options, shift) = if part.start == Start::Cnv {
            ("cs_polarity=active-high:cpol=0:cpha=0", part.trailing_bits)
        } else {
            (
                "cs_polarity=active-low:cpol=1:cpha=1",
                part.trailing_bits + 1,
            )
        };
        PartDecoder {
            options,
            wordsize: part.word_sclks(),
            shift,
            mask: ((1u32 << part.bits) - 1) as u16,
        }
    }
}

/// The branch's lanes as a VCD sigrok reads (1-bit signals `cs`, `sclk`, `miso`).
fn vcd(changes: &[(u64, u8)], end: u64) -> String {
    let mut out = judge::wire_header("1 ns", "top", &["cs", "sclk", "miso"]);
    let mut prev: Option<u8> = None;
    for &(t, v) in changes {
        let _ = writeln!(out, "#{t}");
        for (k, id) in ['!', '"', '#'].iter().enumerate() {
            let bit = v >> k & 1;
            if prev.map(|p| p >> k & 1) != Some(bit) {
                let _ = writeln!(out, "{bit}{id}");
            }
        }
        prev = Some(v);
    }
    let _ = writeln!(out, "#{end}");
    out
}

/// The codes sigrok decodes from one branch's VCD.
fn decode(file: &Path, part: &AdcPart) -> Result<Vec<u16>, String> {
    let d = PartDecoder::of(part);
    let dec = format!(
        "spi:clk=sclk:miso=miso:cs=cs:{}:wordsize={}",
        d.options, d.wordsize
    );
    let name = file
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("spi.vcd");
    let dir = file.parent().unwrap_or(Path::new("."));
    let out = tools::run(
        "sigrok-cli",
        &["-I", "vcd", "-i", name, "-P", &dec, "-A", "spi=miso-data"],
        dir,
        Duration::from_secs(120),
    )
    .map_err(|e| e.to_string())?;
    if !out.success {
        return Err(format!("sigrok-cli failed: {}", out.stderr.trim()));
    }
    out.stdout
        .lines()
        .map(|l| {
            let w = l.rsplit(':').next().unwrap_or("").trim();
            u32::from_str_radix(w, 16)
                .map(|w| (w >> d.shift) as u16 & d.mask)
                .map_err(|_| format!("sigrok-cli printed `{l}`"))
        })
        .collect()
}

/// Whether sigrok-cli can run here.
pub fn available() -> Result<(), ToolError> {
    if tools::present("sigrok-cli") {
        Ok(())
    } else {
        Err(ToolError::Missing("sigrok-cli".into()))
    }
}

/// The detector's verdict on a capture of `frames` frames: `Err` names the
/// first branch where the decode and the design disagree.
pub fn check(
    s: &Schedule,
    cap: &SpiCapture,
    frames: u64,
    dir: &Path,
) -> Result<Result<(), String>, String> {
    let f = s.grid.frame_cycles;
    let total = frames * f;
    let slack = s.mix.branches.iter().map(|b| b.chain as u64).sum::<u64>() + 2;
    for (b, br) in s.branches.iter().enumerate() {
        let part = &s.mix.branches[b].adc;
        let file = dir.join(format!("b{b}.vcd"));
        std::fs::write(&file, vcd(&cap.changes[b], cap.end)).map_err(|e| e.to_string())?;
        let words = decode(&file, part)?;
        let read = br.spi.read_cycles;
        let count = |margin: u64| -> usize {
            s.instants(frames)
                .filter(|i| i.branch == b && i.cycle >= f && i.cycle + read + margin < total)
                .map(|i| s.words_of(i.channel).count())
                .sum()
        };
        let values: Vec<u16> = cap
            .samples
            .iter()
            .filter(|(c, _)| s.mix.channels.get(*c as usize).map(|c| c.branch) == Some(b))
            .map(|&(_, v)| v)
            .collect();
        let name = &br.name;
        if words.len() != count(0) {
            return Ok(Err(format!(
                "branch {name}: sigrok decoded {} words, the schedule has {} conversions",
                words.len(),
                count(0)
            )));
        }
        if let Some(k) = (0..words.len().min(values.len())).find(|&k| words[k] != values[k]) {
            return Ok(Err(format!(
                "branch {name}: word {k}: SPI (sigrok) read {:#06x}, the design emitted {:#06x}",
                words[k], values[k]
            )));
        }
        if values.len() > words.len() || values.len() < count(slack) {
            return Ok(Err(format!(
                "branch {name}: the design emitted {} samples for {} decoded words",
                values.len(),
                words.len()
            )));
        }
    }
    Ok(Ok(()))
}
