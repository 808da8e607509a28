//! The verdict of the independent Icarus testbench (`tests/tb/adc_tb.v`) on
//! its log, shared by `tests/icarus.rs` and `cosim/campaign/tests/mutants.rs`.  It
//! reads only the mix and lut-gen's schedule: nothing from `hdl` or the engines.

use std::collections::BTreeMap;

/// Compares a log of `tests/tb/adc_tb.v` with the schedule: conversions at
/// exactly the schedule's instants on the right channel (decoded from the mux
/// address at the instant), every interval exactly clock/rate, and every
/// sample leaving with the channel and the code the ADC shifted out, in order;
/// a sample of a channel id the mix does not have, or beyond the channel's
/// conversions, fails.  `cycles` is how long the testbench ran.
///
/// Mux settling, physically: a conversion's mux select and enables must have
/// been on the pins for at least the branch's `settle_ns` (in whole cycles,
/// rounded up) at its CS fall, counted from the edge at which they last
/// changed.  Reset cycles count when the pins held their value through them;
/// the first rising edge (a reset edge) counts as a change, since what the
/// pins showed before it (power-up values) is not the design's.  So an
/// instant in the first cycles after a short reset may be missing from the
/// conversions (the design waits for its mux, docs/timing.md "Start-up"),
/// but one that is there must have settled.
pub fn judge(
    mix: &lut_gen::Mix,
    s: &lut_gen::Schedule,
    text: &str,
    cycles: u64,
) -> Result<(), String> {
    struct Conversion {
        cycle: u64,
        channel: usize,
        code: u16,
    }
    let nb = s.branches.len();
    let mut first_device = vec![0u32; nb];
    for b in 1..nb {
        first_device[b] = first_device[b - 1] + s.branches[b - 1].mux_devices;
    }
    let address: BTreeMap<(usize, u32, u32), usize> = s
        .channels
        .iter()
        .enumerate()
        .map(|(c, cs)| ((mix.channels[c].branch, cs.select, cs.device), c))
        .collect();
    let mut conversions: Vec<Vec<Conversion>> = (0..nb).map(|_| Vec::new()).collect();
    let mut samples: Vec<(u64, usize, u16)> = Vec::new();
    // (edge, mux_sel, mux_en) at the first edge and at every change, and
    // the edge that began cycle 0
    let mut mux: Vec<(u64, u64, u64)> = Vec::new();
    let mut edge0: Option<u64> = None;
    for line in text.lines() {
        let f: Vec<u64> = line
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("log line with unknowns: {line:?}"))?;
        match line.split_whitespace().next() {
            Some("CS") if f.len() == 5 => {
                let (b, cycle, sel, en, code) =
                    (f[0] as usize, f[1], f[2] as u32, f[3], f[4] as u16);
                let mine = (en >> first_device[b]) & ((1 << s.branches[b].mux_devices) - 1);
                if mine.count_ones() != 1 {
                    return Err(format!(
                        "cycle {cycle}: branch {b} enables {mine:b}: not exactly one device"
                    ));
                }
                let device = mine.trailing_zeros();
                let channel = *address.get(&(b, sel, device)).ok_or_else(|| {
                    format!("cycle {cycle}: branch {b} samples unused input {device}.{sel}")
                })?;
                conversions[b].push(Conversion {
                    cycle,
                    channel,
                    code,
                });
            }
            Some("SAMPLE") if f.len() == 3 => samples.push((f[0], f[1] as usize, f[2] as u16)),
            Some("MUX") if f.len() == 3 => mux.push((f[0], f[1], f[2])),
            Some("CYCLE0") if f.len() == 1 => edge0 = Some(f[0]),
            _ => return Err(format!("bad log line {line:?}")),
        }
    }
    let edge0 = edge0.ok_or("the log has no CYCLE0 line")?;
    let settle: Vec<u64> = mix
        .branches
        .iter()
        .map(|b| (b.settle_ns as u128 * mix.clock_hz as u128).div_ceil(1_000_000_000) as u64)
        .collect();
    // 0. every conversion's mux had settled (see above)
    for (b, convs) in conversions.iter().enumerate() {
        let lanes = |sel: u64, en: u64| {
            let m = (1u64 << s.branches[b].mux_devices) - 1;
            ((sel >> (3 * b)) & 7, (en >> first_device[b]) & m)
        };
        for c in convs {
            let at = edge0 + c.cycle;
            let mut since = None;
            let mut value = None;
            for &(e, sel, en) in mux.iter().take_while(|m| m.0 <= at) {
                let v = lanes(sel, en);
                if value != Some(v) {
                    since = Some(e);
                    value = Some(v);
                }
            }
            let since = since.ok_or_else(|| format!("cycle {}: no mux value logged", c.cycle))?;
            if at - since < settle[b] {
                return Err(format!(
                    "cycle {}: branch {b} converts on a mux that changed {} cycles before (edge {since}, cycle 0 at edge {edge0}); settling needs {}",
                    c.cycle,
                    at - since,
                    settle[b]
                ));
            }
        }
    }
    // 1. conversions exactly at the schedule's instants, on the right channel
    // (an instant within the settling time of cycle 0 may be skipped)
    let frames = cycles.div_ceil(s.grid.frame_cycles);
    for (b, convs) in conversions.iter().enumerate() {
        let got: Vec<(u64, usize)> = convs.iter().map(|c| (c.cycle, c.channel)).collect();
        let expected: Vec<(u64, usize)> = s
            .instants(frames)
            // the conversion starts its branch's hold-off after the slot tick
            .map(|i| (i.cycle + s.holdoff(i.branch), i.branch, i.channel))
            .filter(|i| i.1 == b && i.0 < cycles - 2)
            .map(|i| (i.0, i.2))
            .filter(|i| i.0 >= settle[b] || got.contains(i))
            .collect();
        if got != expected {
            let k = got
                .iter()
                .zip(&expected)
                .take_while(|(a, b)| a == b)
                .count();
            return Err(format!(
                "branch {b}: conversions differ from the schedule at #{k}: got {:?}, expected {:?} ({} vs {})",
                got.get(k),
                expected.get(k),
                got.len(),
                expected.len()
            ));
        }
    }
    // 2. every interval is exactly clock/rate
    for (c, ch) in mix.channels.iter().enumerate() {
        let times: Vec<u64> = conversions[ch.branch]
            .iter()
            .filter(|x| x.channel == c)
            .map(|x| x.cycle)
            .collect();
        if times.is_empty() {
            return Err(format!("{} never sampled", ch.name));
        }
        for w in times.windows(2) {
            if w[1] - w[0] != mix.clock_hz / ch.rate_hz {
                return Err(format!("{}: interval at cycle {}", ch.name, w[0]));
            }
        }
    }
    // 3. every sample leaves with the channel and the code the ADC shifted out, in order
    // (and every sample is one: an unknown channel id, or more samples of a
    // channel than it had conversions, is a failure)
    let mut per_channel: BTreeMap<usize, Vec<u16>> = BTreeMap::new();
    for (cycle, ch, v) in &samples {
        if *ch >= mix.channels.len() {
            return Err(format!(
                "cycle {cycle}: a sample of channel id {ch}, which the mix does not have ({} channels)",
                mix.channels.len()
            ));
        }
        per_channel.entry(*ch).or_default().push(*v);
    }
    let read = s.branches.iter().map(|b| b.spi.read_cycles).max().unwrap();
    for (c, ch) in mix.channels.iter().enumerate() {
        let shifted: Vec<u16> = conversions[ch.branch]
            .iter()
            .filter(|x| x.channel == c && x.cycle + read + 1 + nb as u64 <= cycles - 2)
            .map(|x| x.code)
            .collect();
        let got = per_channel.get(&c).cloned().unwrap_or_default();
        if got.len() < shifted.len() {
            return Err(format!(
                "{}: {} samples out, {} conversions done",
                ch.name,
                got.len(),
                shifted.len()
            ));
        }
        if got[..shifted.len()] != shifted[..] {
            return Err(format!(
                "{}: sample values differ from the ADC's words",
                ch.name
            ));
        }
        // the samples past those checked above: conversions that ended near
        // the end of the run; there may be no more of them than conversions
        let all: Vec<u16> = conversions[ch.branch]
            .iter()
            .filter(|x| x.channel == c)
            .map(|x| x.code)
            .collect();
        if got.len() > all.len() {
            return Err(format!(
                "{}: {} samples out, more than its {} conversions",
                ch.name,
                got.len(),
                all.len()
            ));
        }
        if got[..] != all[..got.len()] {
            return Err(format!(
                "{}: a late sample's value differs from the ADC's word",
                ch.name
            ));
        }
    }
    Ok(())
}
