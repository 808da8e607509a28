//! sigrok-cli's SPI decoder as a detector of the fault campaign: it reads
//! each branch's CS, SCLK and MISO as a logic analyser would and knows only
//! the part's SPI mode and word size.  A run passes when, per branch, the
//! words it decodes are the sample values the design emitted for that
//! branch's channels, in order, and there are as many as the schedule has
//! conversions in the window.  It has no view of the mux pins.  A branch
//! whose converter takes a command word has its `adc_mosi` lane decoded as
//! well: each word must be the one the schedule sends in that conversion
//! (`Schedule::commands_in_frame`), and the prepared conversions after reset
//! are no samples.
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
use lut_gen::{AdcPart, CnvRead, Start};

use judge::tools::{self, ToolError};

/// Every branch's CS/SCLK/MISO changes and the sample stream, from frame 1.
pub struct SpiCapture {
    /// Observer cycle of the window's first cycle (the last of frame 0).
    from: u64,
    last: Vec<Option<u8>>,
    /// Each branch's `adc_mosi` bit, if it has one.
    mosi: Vec<Option<u32>>,
    /// Per branch: (time, cs | sclk << 1 | miso << 2 | mosi << 3) at every change.
    changes: Vec<Vec<(u64, u8)>>,
    samples: Vec<(u16, u16)>,
    end: u64,
    /// Cycles seen as a [`CycleSink`] (a VCD's cycles carry no number).
    seen: u64,
    /// A mix with modes: the `mode` pin at each frame's first cycle, so
    /// each frame is decoded against its mode's schedule (sigrok sees no
    /// mode rule: the model and the invariants judge the switches).
    modes: Vec<u8>,
    reset: u64,
    frame_cycles: u64,
}

impl SpiCapture {
    /// The `mode` pin at each frame's first cycle (tests only, through
    /// `for_tests`).
    pub fn modes(&self) -> &[u8] {
        &self.modes
    }

    /// A capture for a run of `s` with `reset` reset cycles.
    pub fn new(s: &Schedule, reset: u64) -> SpiCapture {
        let nb = s.branches.len();
        SpiCapture {
            // a cycle early, so that a CS falling at frame 1's first cycle is an edge
            from: reset + s.grid.frame_cycles - 1,
            last: vec![None; nb],
            mosi: lut_gen::Layout::new(s).mosi_lo,
            changes: vec![Vec::new(); nb],
            samples: Vec::new(),
            end: 0,
            seen: 0,
            modes: Vec::new(),
            reset,
            frame_cycles: s.grid.frame_cycles,
        }
    }
}

impl Observer for SpiCapture {
    fn cycle(&mut self, cycle: u64, rst: bool, p: &Pins, miso: u64) {
        if !rst && cycle >= self.reset && (cycle - self.reset).is_multiple_of(self.frame_cycles) {
            self.modes.push(p.mode);
        }
        if rst || cycle < self.from {
            return;
        }
        let t = cycle - self.from;
        self.end = t + 1;
        for (b, last) in self.last.iter_mut().enumerate() {
            let mosi = self.mosi[b].map_or(0, |i| (p.mosi >> i & 1) as u8);
            let v = (p.cs_n >> b & 1) as u8
                | ((p.sclk >> b & 1) as u8) << 1
                | ((miso >> b & 1) as u8) << 2
                | mosi << 3;
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
        let (options, shift) = if part.start == Start::Cnv && part.read == CnvRead::CnvLow {
            // read while CNV is low: CNV frames the read as an active-low CS
            ("cs_polarity=active-low:cpol=0:cpha=0", part.trailing_bits)
        } else if part.start == Start::Cnv {
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

/// Which lane of a branch a decoder reads: `miso` (the samples) or `mosi`
/// (the command words).
#[derive(Clone, Copy, PartialEq)]
enum Wire {
    Miso,
    Mosi,
}

/// Every branch's lanes as one VCD sigrok reads: `cs{b}`, `sclk{b}`,
/// `miso{b}` and `mosi{b}` for branch `b`, each 1 bit.
fn vcd(cap: &SpiCapture) -> String {
    const LANES: [&str; 4] = ["cs", "sclk", "miso", "mosi"];
    let nb = cap.changes.len();
    let names: Vec<String> = (0..nb)
        .flat_map(|b| LANES.map(|l| format!("{l}{b}")))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut out = judge::wire_header("1 ns", "top", &names);
    // every branch's changes in time order (a VCD's times only increase)
    let mut changes: Vec<(u64, usize, u8)> = (cap.changes.iter().enumerate())
        .flat_map(|(b, c)| c.iter().map(move |&(t, v)| (t, b, v)))
        .collect();
    changes.sort_unstable_by_key(|&(t, b, _)| (t, b));
    let mut prev: Vec<Option<u8>> = vec![None; nb];
    let mut now = None;
    for (t, b, v) in changes {
        if now != Some(t) {
            let _ = writeln!(out, "#{t}");
            now = Some(t);
        }
        for k in 0..LANES.len() {
            let bit = v >> k & 1;
            if prev[b].map(|p| p >> k & 1) != Some(bit) {
                let _ = writeln!(out, "{bit}{}", judge::id_code(LANES.len() * b + k));
            }
        }
        prev[b] = Some(v);
    }
    let _ = writeln!(out, "#{}", cap.end);
    out
}

/// The codes in the words sigrok decoded from a branch's `miso`.
fn codes(words: &[u32], part: &AdcPart) -> Vec<u16> {
    let d = PartDecoder::of(part);
    (words.iter())
        .map(|&w| (w >> d.shift) as u16 & d.mask)
        .collect()
}

/// The command words in the words sigrok decoded from a branch's `mosi`,
/// first bit first (the word's bits are the top of each SPI word).
fn command_bits(words: &[u32], part: &AdcPart) -> Vec<Vec<bool>> {
    let d = PartDecoder::of(part);
    let n = part.command.as_ref().map_or(0, |c| c.bits.len() as u32);
    (words.iter())
        .map(|&w| (0..n).map(|i| w >> (d.wordsize - 1 - i) & 1 == 1).collect())
        .collect()
}

/// The command words sigrok decodes from branch `b`'s `mosi` lane of
/// `file` (the VCD [`check`] writes, `spi.vcd`), first bit first.
pub fn decode_commands(file: &Path, s: &Schedule, b: usize) -> Result<Vec<Vec<bool>>, String> {
    let part = &s.mix.branches[b].adc;
    let words = words(file, &[(b, Wire::Mosi, part)])?;
    Ok(command_bits(&words[0], part))
}

/// The words sigrok-cli's SPI decoder reads on each of `lanes` (branch,
/// wire, part) of `file`, in one run: one decoder instance a lane, each
/// reading its wire as the decoder's `miso` (instance `k` prints its
/// words as `spi-{k + 1}: XX`).  A run of sigrok-cli costs its start as
/// much as a decode: one a lane was most of a campaign's decodes.
fn words(file: &Path, lanes: &[(usize, Wire, &AdcPart)]) -> Result<Vec<Vec<u32>>, String> {
    let mut args: Vec<String> = vec!["-I".into(), "vcd".into(), "-i".into()];
    let name = file.file_name().and_then(|n| n.to_str());
    args.push(name.unwrap_or("spi.vcd").into());
    for &(b, wire, part) in lanes {
        let d = PartDecoder::of(part);
        let lane = if wire == Wire::Miso { "miso" } else { "mosi" };
        args.push("-P".into());
        args.push(format!(
            "spi:clk=sclk{b}:miso={lane}{b}:cs=cs{b}:{}:wordsize={}",
            d.options, d.wordsize
        ));
    }
    args.extend(["-A".into(), "spi=miso-data".into()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let dir = file.parent().unwrap_or(Path::new("."));
    let out = tools::run("sigrok-cli", &args, dir, Duration::from_secs(120))
        .map_err(|e| e.to_string())?;
    if !out.success {
        return Err(format!("sigrok-cli failed: {}", out.stderr.trim()));
    }
    let mut words = vec![Vec::new(); lanes.len()];
    for l in out.stdout.lines() {
        let bad = || format!("sigrok-cli printed `{l}`");
        let (who, w) = l.split_once(':').ok_or_else(bad)?;
        let k: usize = (who.strip_prefix("spi-").and_then(|k| k.parse().ok())).ok_or_else(bad)?;
        let w = u32::from_str_radix(w.trim(), 16).map_err(|_| bad())?;
        words.get_mut(k.wrapping_sub(1)).ok_or_else(bad)?.push(w);
    }
    Ok(words)
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
/// first branch where the decode and the design disagree.  Every branch's
/// `miso` and every commanded branch's `mosi` are decoded in one run of
/// sigrok-cli, from `spi.vcd` in `dir`.
pub fn check(
    s: &Schedule,
    cap: &SpiCapture,
    frames: u64,
    dir: &Path,
) -> Result<Result<(), String>, String> {
    let file = dir.join("spi.vcd");
    std::fs::write(&file, vcd(cap)).map_err(|e| e.to_string())?;
    let nb = s.branches.len();
    let part = |b: usize| &s.mix.branches[b].adc;
    let mut lanes: Vec<(usize, Wire, &AdcPart)> =
        (0..nb).map(|b| (b, Wire::Miso, part(b))).collect();
    lanes.extend(
        (0..nb)
            .filter(|&b| s.has_command(b))
            .map(|b| (b, Wire::Mosi, part(b))),
    );
    let words = words(&file, &lanes)?;
    for b in 0..nb {
        let commands = (lanes.iter().zip(&words))
            .find(|((l, wire, _), _)| *l == b && *wire == Wire::Mosi)
            .map(|(_, w)| command_bits(w, part(b)));
        let decoded = Decoded {
            codes: codes(&words[b], part(b)),
            commands,
        };
        if let Err(e) = check_branch(s, cap, frames, b, &decoded) {
            return Ok(Err(e));
        }
    }
    Ok(Ok(()))
}

/// What sigrok decoded of one branch: the codes on `miso`, and the
/// command words on `mosi` when the branch's part takes them.
struct Decoded {
    codes: Vec<u16>,
    commands: Option<Vec<Vec<bool>>>,
}

/// Branch `b`'s conversions in the window (frame 1 on) whose read ends
/// more than `margin` cycles before the run: (the schedule of its frame's
/// mode, shown on `modes`; its index among the branch's conversions in
/// that frame; its channel).
pub fn window_conversions<'a>(
    s: &'a Schedule,
    modes: &[u8],
    b: usize,
    frames: u64,
    margin: u64,
) -> Vec<(&'a Schedule, usize, usize)> {
    in_window(s, modes, b, frames, margin)
        .into_iter()
        .map(|(_, m, k, ch)| (m, k, ch))
        .collect()
}

/// [`window_conversions`] with each conversion's frame first.
fn in_window<'a>(
    s: &'a Schedule,
    modes: &[u8],
    b: usize,
    frames: u64,
    margin: u64,
) -> Vec<(u64, &'a Schedule, usize, usize)> {
    let f = s.grid.frame_cycles;
    let read = s.branches[b].spi.read_cycles;
    let mut out = Vec::new();
    for frame in 1..frames {
        let m = mode_of(s, modes, frame).unwrap_or(s);
        let mine = m
            .instants(frame + 1)
            .filter(|i| i.branch == b && i.cycle / f == frame);
        for (k, i) in mine.enumerate() {
            if i.cycle + read + margin < frames * f {
                out.push((frame, m, k, i.channel));
            }
        }
    }
    out
}

/// The schedule of the mode frame `frame` ran in, as `modes` shows it
/// (`s` itself for a mix without modes); `None` for a mode mix's frame
/// that `modes` does not show.
fn mode_of<'a>(s: &'a Schedule, modes: &[u8], frame: u64) -> Option<&'a Schedule> {
    if s.modes.is_empty() {
        return Some(s);
    }
    modes
        .get(frame as usize)
        .and_then(|&m| s.modes.get(m as usize))
}

/// The word the schedule sends in each of branch `b`'s conversions in the
/// window (in [`window_conversions`]' order): its frame's mode's, except
/// in a frame's last `ahead` conversions (the AD7689's 2), whose words
/// select the next frame's first conversions in the next frame's mode
/// (decided while this frame runs); `None` for those whose next frame is
/// past the run (its mode unknown).
pub fn window_commands(
    s: &Schedule,
    modes: &[u8],
    b: usize,
    frames: u64,
) -> Vec<Option<lut_gen::CommandSent>> {
    let ahead = s.prepared_conversions(b) as usize;
    in_window(s, modes, b, frames, 0)
        .into_iter()
        .map(|(frame, m, k, _)| {
            let words = m.commands_in_frame(b);
            let n = words.len();
            if k + ahead < n {
                return Some(words[k].clone());
            }
            // word `i` selects conversion `i + ahead`: the next frame's
            // conversion `j` is selected by its own table's word `j - ahead`
            let next = mode_of(s, modes, frame + 1)?.commands_in_frame(b);
            let j = k + ahead - n;
            let w = &next[(j + next.len() - ahead % next.len()) % next.len()];
            Some(lut_gen::CommandSent {
                slot: words[k].slot,
                ..w.clone()
            })
        })
        .collect()
}

/// Branch `b`'s decode against the design's samples and, for a converter
/// with a command word, its `mosi` words against the schedule's.
fn check_branch(
    s: &Schedule,
    cap: &SpiCapture,
    frames: u64,
    b: usize,
    decoded: &Decoded,
) -> Result<(), String> {
    let name = &s.branches[b].name;
    let slack = s.mix.branches.iter().map(|b| b.chain as u64).sum::<u64>() + 2;
    let count = |margin: u64| -> usize {
        window_conversions(s, &cap.modes, b, frames, margin)
            .iter()
            .map(|&(m, _, ch)| m.words_of(ch).count())
            .sum()
    };
    let words = &decoded.codes;
    if words.len() != count(0) {
        return Err(format!(
            "branch {name}: sigrok decoded {} words, the schedule has {} conversions",
            words.len(),
            count(0)
        ));
    }
    if let Some(got) = &decoded.commands {
        check_commands(s, &cap.modes, frames, b, got)?;
    }
    // The prepared conversions after reset that fall in the window are
    // read on the wire, never emitted.
    let before = s
        .instants(1)
        .filter(|i| i.branch == b && !s.skipped_at_startup(b, i.cycle))
        .count();
    let prepared = (s.prepared_conversions(b) as usize).saturating_sub(before);
    let words = &words[prepared.min(words.len())..];
    let values: Vec<u16> = cap
        .samples
        .iter()
        .filter(|(c, _)| s.mix.channels.get(*c as usize).map(|c| c.branch) == Some(b))
        .map(|&(_, v)| v)
        .collect();
    if let Some(k) = (0..words.len().min(values.len())).find(|&k| words[k] != values[k]) {
        return Err(format!(
            "branch {name}: word {k}: SPI (sigrok) read {:#06x}, the design emitted {:#06x}",
            words[k], values[k]
        ));
    }
    if values.len() > words.len() || values.len() + prepared < count(slack) {
        return Err(format!(
            "branch {name}: the design emitted {} samples for {} decoded words",
            values.len(),
            words.len()
        ));
    }
    Ok(())
}

/// Branch `b`'s command words as sigrok decoded them from `mosi` (`got`),
/// each the word the schedule sends in that conversion.
fn check_commands(
    s: &Schedule,
    modes: &[u8],
    frames: u64,
    b: usize,
    got: &[Vec<bool>],
) -> Result<(), String> {
    let name = &s.branches[b].name;
    let want = window_commands(s, modes, b, frames);
    let bits = |w: &[bool]| -> String { w.iter().map(|&v| if v { '1' } else { '0' }).collect() };
    if got.len() != want.len() {
        return Err(format!(
            "branch {name}: sigrok decoded {} command words on mosi, the schedule sends {}",
            got.len(),
            want.len()
        ));
    }
    let wrong = (got.iter().zip(&want).enumerate())
        .find_map(|(k, (g, w))| w.as_ref().filter(|w| *g != w.word).map(|w| (k, w)));
    if let Some((k, w)) = wrong {
        return Err(format!(
            "branch {name}: command word {k}: SPI (sigrok) read {} on mosi, the schedule sends {} (selecting {})",
            bits(&got[k]),
            bits(&w.word),
            s.mix.channels[w.selects].name
        ));
    }
    Ok(())
}
