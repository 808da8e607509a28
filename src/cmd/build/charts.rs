//! The measurements behind the report's charts, all taken in the build's
//! own run: speed against accuracy of each verification method, a timing
//! diagram of one slice, where scheduling breaks over random mixes, the
//! fault campaign, and the place-and-route estimate.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use cosim::{Backend, SimOptions};
use judge::events::Trace;
use lut_gen::ports::{Layout, Role};
use lut_gen::Schedule;
use report::{draw, Axes, Figure, Section, Series, Table};

use super::frame_seconds;

/// Simulated cycles and wall seconds per method.
#[derive(Debug, Default)]
pub struct Speeds {
    pub runs: Vec<(String, u64, f64)>,
}

impl Speeds {
    pub fn add(&mut self, method: &str, cycles: u64, seconds: f64) {
        self.runs.push((method.into(), cycles, seconds.max(1e-9)));
    }
}

/// A place-and-route estimate.
pub struct Synth {
    pub lcs: u64,
    pub brams: u64,
    pub fmax_mhz: f64,
}

/// yosys `synth_ice40` and nextpnr-ice40 on the emitted Verilog (IO left
/// unconstrained: the estimate does not depend on a board).
pub fn synthesize(s: &Schedule, verilog: &Path, work: &Path) -> Result<Synth, String> {
    use std::process::Command;
    std::fs::create_dir_all(work).map_err(|e| e.to_string())?;
    let top = verilog.join(hdl::VERILOG_FILE);
    let json = work.join("slotforge.json");
    let y = Command::new("yosys")
        .arg("-q")
        .arg("-l")
        .arg(work.join("yosys.log"))
        .arg("-p")
        .arg(format!(
            "read_verilog {}; synth_ice40 -top {} -json {}",
            top.display(),
            lut_gen::ports::TOP_MODULE,
            json.display()
        ))
        .output()
        .map_err(|e| format!("yosys: {e}"))?;
    if !y.status.success() {
        return Err(String::from_utf8_lossy(&y.stderr).into_owned());
    }
    let n = Command::new("nextpnr-ice40")
        .args([
            "--hx8k",
            "--package",
            "ct256",
            "--pcf-allow-unconstrained",
            "--seed",
            "1",
        ])
        .arg("--freq")
        .arg(format!("{}", s.grid.clock_hz as f64 / 1e6))
        .arg("--json")
        .arg(&json)
        .output()
        .map_err(|e| format!("nextpnr-ice40: {e}"))?;
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&n.stdout),
        String::from_utf8_lossy(&n.stderr)
    );
    let _ = std::fs::write(work.join("nextpnr.log"), &log);
    if !n.status.success() {
        return Err(log.lines().rev().take(20).collect::<Vec<_>>().join("\n"));
    }
    // a log without the utilisation lines is an error, never "0 cells"
    let used = |cell: &str| -> Result<u64, String> {
        let key = format!("{cell}:");
        log.lines()
            .filter_map(|l| Some(&l[l.find(&key)? + key.len()..]))
            .filter_map(|r| r.trim().split('/').next()?.trim().parse().ok())
            .next_back()
            .ok_or_else(|| {
                format!("nextpnr's log (synth/nextpnr.log) has no `{cell}` utilisation line")
            })
    };
    let fmax = log
        .lines()
        .filter(|l| l.contains("Max frequency for clock"))
        .filter_map(|l| {
            l.rsplit("': ")
                .next()?
                .split(' ')
                .next()?
                .parse::<f64>()
                .ok()
        })
        .next_back()
        .ok_or("nextpnr reported no Fmax")?;
    Ok(Synth {
        lcs: used("ICESTORM_LC")?,
        brams: used("ICESTORM_RAM")?,
        fmax_mhz: fmax,
    })
}

/// Speed against accuracy of the fault campaign's detectors (its matrix and
/// the timings it measured); the engines' speeds are measured now too.
pub fn speed_accuracy(
    s: &Schedule,
    vcd: &Path,
    speeds: &mut Speeds,
    campaign: Option<&cosim::faults::Campaign>,
) -> Result<(Section, String), String> {
    let g = &s.grid;
    let f = g.frame_cycles;
    // speed
    let n = (1.0 / frame_seconds(s)).ceil().max(10.0) as u64; // >= 1 s of acquisition
    let t = Instant::now();
    let _ = judge::run::run_model(s, n, judge::Stimulus::Pattern, 10);
    speeds.add("model", n * f, t.elapsed().as_secs_f64());
    let t = Instant::now();
    cosim::run(s, Backend::RustHdl, 1, &SimOptions::default()).map_err(|e| e.to_string())?;
    speeds.add("rusthdl", f, t.elapsed().as_secs_f64());
    let icarus = super::tool_present("iverilog");
    if icarus {
        let t = Instant::now();
        cosim::run(s, Backend::Icarus, 1, &SimOptions::default()).map_err(|e| e.to_string())?;
        speeds.add("icarus", f, t.elapsed().as_secs_f64());
    }
    if vcd.exists() {
        let t = Instant::now();
        let r = judge::check_vcd(s, vcd, None).map_err(|e| e.to_string())?;
        speeds.add("check", r.cycles, t.elapsed().as_secs_f64());
    }
    // accuracy: the fault campaign's matrix, each detector's column with
    // the cost measured in the same campaign
    let c = campaign.ok_or("no fault campaign in this run: the chart draws its matrix")?;
    let mut table = Table::new(&[
        "detector",
        "simulated_cycles",
        "wall_seconds",
        "simulated_seconds_per_wall_second",
        "injections_detected",
        "injections",
        "share_detected",
    ]);
    let mut series = Vec::new();
    let mut not_run = Vec::new();
    for col in &c.columns {
        if let Some(why) = &col.not_run {
            not_run.push(format!("{}: {why}", col.detector.name()));
            continue;
        }
        let speed = col.cycles as f64 / g.clock_hz as f64 / col.seconds.max(1e-9);
        table.push(vec![
            col.detector.name().into(),
            col.cycles.to_string(),
            format!("{:.4}", col.seconds),
            format!("{speed:.6}"),
            col.detected.to_string(),
            col.injected.to_string(),
            format!("{:.3}", col.share()),
        ]);
        series.push(Series::scatter(
            col.detector.name(),
            vec![(speed, col.share())],
        ));
    }
    let mut axes = Axes::new(
        "Speed against accuracy of the detectors",
        "simulated seconds per wall second (log)",
        "share of injections detected",
    );
    axes.log_x = true;
    let svg = draw(&axes, &series, 820, 460);
    let engines = speeds
        .runs
        .iter()
        .map(|(m, cycles, secs)| format!("{m} {:.3}x", *cycles as f64 / g.clock_hz as f64 / secs))
        .collect::<Vec<_>>()
        .join(", ");
    let mut para = vec![format!(
        "Each point is one detector of the fault campaign of this run ({:?} target, {} injections at {} sites): its share of injections detected (the matrix's column) against its speed, measured in the same campaign (model and invariants: the checker on a clean run with and without the model; sigrok: its decodes).",
        c.target,
        c.injected,
        c.sites.len()
    )];
    if !not_run.is_empty() {
        para.push(format!("Not drawn: {}.", not_run.join("; ")));
    }
    para.push(format!(
        "Simulation engines in this run, simulated time per wall second: {engines}."
    ));
    let line = table
        .rows
        .iter()
        .map(|r| {
            let v: f64 = r[3].parse().unwrap_or(0.0);
            format!(
                "{} {v:.3}x real time, {} of {} injections",
                r[0], r[4], r[5]
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    Ok((
        Section {
            title: "Speed against accuracy".into(),
            paragraphs: para,
            figures: vec![Figure {
                stem: "speed-accuracy".into(),
                title: "Speed against accuracy".into(),
                caption: "x: simulated seconds per wall second, measured in this run; y: share of the campaign's injections each detector caught".into(),
                svg,
                table,
            }],
            ..Section::default()
        },
        line,
    ))
}

/// A timing diagram of the first slice after reset, per branch (mux select,
/// CS, SCLK) and the sample strobes, from the rust-hdl simulation; and
/// WaveDrom JSON of the first conversion of branch 0.
pub fn timing(s: &Schedule) -> Result<(Section, String), String> {
    let g = &s.grid;
    let slice = g.slots_per_slice * g.slot_cycles;
    let mut trace = Trace::default();
    cosim::run_traced(
        s,
        Backend::RustHdl,
        1,
        &SimOptions::default(),
        Some(&mut trace),
    )
    .map_err(|e| e.to_string())?;
    let z = trace.cycle_zero().ok_or("no cycle after reset")?;
    let cycles = &trace.cycles[z..(z + slice as usize).min(trace.len())];
    let l = Layout::new(s);
    let us = |c: usize| c as f64 * 1e6 / g.clock_hz as f64;
    let mut names = Vec::new();
    let mut series = Vec::new();
    let mut table = Table::new(&["cycle", "time_us", "signal", "value"]);
    let mut row = 0.0;
    let lane = |p: &lut_gen::ports::Pins, r: Role, b: usize| {
        let (hi, lo) = l.lane_bits(r, b);
        ((p.value(r) >> lo) as u64) & ((1u64 << (hi - lo + 1)) - 1)
    };
    let mut add = |name: String, val: &dyn Fn(&lut_gen::ports::Pins) -> u64, scale: f64| {
        let mut pts = Vec::new();
        let mut prev = None;
        for (c, (_, p, _)) in cycles.iter().enumerate() {
            let v = val(p);
            if prev != Some(v) {
                pts.push((us(c), row + 0.8 * (v as f64 / scale)));
                table.push(vec![
                    c.to_string(),
                    format!("{:.6}", us(c)),
                    name.clone(),
                    v.to_string(),
                ]);
                prev = Some(v);
            }
        }
        pts.push((us(cycles.len()), pts.last().map_or(row, |p| p.1)));
        let mut sr = Series::line(&name, pts);
        sr.steps = true;
        series.push(sr);
        names.push(name);
        row += 1.0;
    };
    add(
        Role::SampleValid.name().into(),
        &|p| p.sample_valid as u64,
        1.0,
    );
    for (b, br) in s.branches.iter().enumerate().rev() {
        add(
            format!("{} sclk", br.name),
            &|p| lane(p, Role::Sclk, b),
            1.0,
        );
        add(format!("{} cs_n", br.name), &|p| lane(p, Role::CsN, b), 1.0);
        add(
            format!("{} mux_sel", br.name),
            &|p| lane(p, Role::MuxSel, b),
            7.0,
        );
    }
    let mut axes = Axes::new(
        "One slice after reset, per branch (rust-hdl simulation)",
        "time after reset (us)",
        "",
    );
    axes.y_names = names;
    let svg = draw(&axes, &series, 1000, 120 + 36 * series.len() as u32);
    // WaveDrom: the first conversion of branch 0, one character per SCLK half period
    let spi = s.branches[0].spi;
    let t0 = cycles
        .iter()
        .position(|(_, p, _)| p.cs_n & 1 == 0)
        .ok_or("branch 0 does not convert in the first slice")?;
    let step = spi.sclk_half.max(1) as usize;
    let from = t0.saturating_sub(2 * step);
    let to = (t0 + spi.read_cycles as usize + 4 * step).min(cycles.len());
    let wave = |f: &dyn Fn(&lut_gen::ports::Pins, u64) -> u64| {
        let mut w = String::new();
        let mut prev = None;
        for (_, p, miso) in cycles[from..to].iter().step_by(step) {
            let v = f(p, *miso);
            w.push(if prev == Some(v) {
                '.'
            } else if v == 0 {
                '0'
            } else {
                '1'
            });
            prev = Some(v);
        }
        w
    };
    let mut sel = String::new();
    let mut data = Vec::new();
    let mut prev = None;
    for (_, p, _) in cycles[from..to].iter().step_by(step) {
        let v = lane(p, Role::MuxSel, 0);
        if prev == Some(v) {
            sel.push('.');
        } else {
            sel.push('=');
            data.push(v.to_string());
        }
        prev = Some(v);
    }
    let wd = serde_json::json!({
        "signal": [
            {"name": Role::CsN.key(), "wave": wave(&|p, _| (p.cs_n & 1) as u64)},
            {"name": Role::Sclk.key(), "wave": wave(&|p, _| (p.sclk & 1) as u64)},
            {"name": Role::Miso.key(), "wave": wave(&|_, m| m & 1)},
            {"name": Role::MuxSel.key(), "wave": sel, "data": data},
            {"name": Role::SampleValid.name(), "wave": wave(&|p, _| p.sample_valid as u64)},
        ],
        "head": {"text": format!("{}: first conversion of branch {} (one step = {} clock cycles)", s.mix.name, s.branches[0].name, step)},
        "config": {"hscale": 1},
    });
    let mut text = serde_json::to_string_pretty(&wd).expect("json");
    text.push('\n');
    Ok((
        Section {
            title: "Timing of one slice".into(),
            paragraphs: vec![format!(
                "What the paper's Figure 4 shows, drawn from simulation: for each branch the mux select, CS and SCLK over the first slice ({} slots of {} cycles) after reset, and the merged sample strobes. conversion.wavedrom.json has the first conversion of branch {} for WaveDrom.",
                g.slots_per_slice, g.slot_cycles, s.branches[0].name
            )],
            figures: vec![Figure {
                stem: "timing-slice".into(),
                title: "One slice per branch".into(),
                caption: "steps are the pins' levels; mux_sel is scaled from 0..7".into(),
                svg,
                table,
            }],
            ..Section::default()
        },
        text,
    ))
}

/// A random mix of a family, as TOML text, and its ADC utilization.
fn family_mix(family: &str, seed: u64) -> (String, f64) {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let nb = 1 + next() % 3;
    let mut t = String::from(
        "name = \"r\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 10_000\nslice_us = 1_000\n",
    );
    for b in 0..nb {
        let _ = write!(
            t,
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 8\n"
        );
    }
    let rates: &[u64] = match family {
        // harmonic (and the sync pairs): periods divide one another
        "harmonic" | "sync" => &[100, 500, 1_000, 2_000, 5_000, 10_000],
        // periods that do not: the slot grid must hold several at once
        _ => &[200, 300, 400, 500, 600, 800, 1_200],
    };
    let target = 0.05 + (next() % 1000) as f64 / 1000.0 * 1.1; // utilization aimed at
    let mut demand = 0.0;
    let mut i = 0;
    let cap = nb as f64 * 100_000.0;
    let mut per_branch = vec![0u64; nb as usize];
    while demand / cap < target && i < 64 * nb {
        let b = (next() % nb) as usize;
        if per_branch[b] >= 64 {
            i += 1;
            continue;
        }
        let r = rates[(next() % rates.len() as u64) as usize];
        if family == "sync" && nb >= 2 && next() % 2 == 0 {
            // a pair on two branches, one instant
            let b2 = (b + 1) % nb as usize;
            if per_branch[b2] < 64 {
                let _ = write!(
                    t,
                    "[[channel]]\nname = \"c{i}\"\nbranch = \"b{b}\"\nrate_hz = {r}\nsync = \"g{i}\"\n[[channel]]\nname = \"d{i}\"\nbranch = \"b{b2}\"\nrate_hz = {r}\nsync = \"g{i}\"\n"
                );
                per_branch[b] += 1;
                per_branch[b2] += 1;
                demand += 2.0 * r as f64;
                i += 1;
                continue;
            }
        }
        let _ = write!(
            t,
            "[[channel]]\nname = \"c{i}\"\nbranch = \"b{b}\"\nrate_hz = {r}\n"
        );
        per_branch[b] += 1;
        demand += r as f64;
        i += 1;
    }
    (t, demand / cap)
}

/// Over random mixes of three families: ADC utilization against whether an
/// exact schedule exists, and how long synthesis took.
pub fn schedulability() -> (Section, String) {
    let mut table = Table::new(&["family", "seed", "utilization", "feasible", "synthesis_ms"]);
    let mut series: Vec<Series> = Vec::new();
    let mut counts = Vec::new();
    for family in ["harmonic", "non-harmonic", "sync"] {
        let (mut ok_pts, mut no_pts) = (Vec::new(), Vec::new());
        for seed in 1..=40u64 {
            let (text, util) = family_mix(family, seed);
            let Ok(mix) = lut_gen::parse(Path::new("random.toml"), &text) else {
                continue;
            };
            let t = Instant::now();
            let feasible = lut_gen::synthesize(&mix).is_ok();
            let ms = t.elapsed().as_secs_f64() * 1e3;
            table.push(vec![
                family.into(),
                seed.to_string(),
                format!("{util:.4}"),
                feasible.to_string(),
                format!("{ms:.4}"),
            ]);
            if feasible {
                ok_pts.push((util * 100.0, ms.max(1e-4)));
            } else {
                no_pts.push((util * 100.0, ms.max(1e-4)));
            }
        }
        let best = ok_pts.iter().map(|p| p.0).fold(0.0f64, f64::max);
        let worst = no_pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
        counts.push(format!(
            "{family}: {} of {} feasible, exact schedules up to {best:.0} % utilization{}",
            ok_pts.len(),
            ok_pts.len() + no_pts.len(),
            if worst.is_finite() {
                format!(", the first without one at {worst:.0} %")
            } else {
                String::new()
            }
        ));
        series.push(Series::scatter(
            &format!("{family}, exact schedule"),
            ok_pts,
        ));
        series.push(Series::scatter(&format!("{family}, none"), no_pts));
    }
    let mut axes = Axes::new(
        "Where scheduling breaks: utilization against feasibility and synthesis time",
        "ADC utilization (% of the AD7940s' 100 kSPS)",
        "synthesis time (ms, log)",
    );
    axes.log_y = true;
    let svg = draw(&axes, &series, 900, 480);
    let line = counts.join("; ");
    (
        Section {
            title: "Where scheduling breaks".into(),
            paragraphs: vec![
                format!("Random mixes on 1-3 AD7940 branches (10 ms frame, 1 ms slice) of three families: harmonic rates (100 Hz to 10 kHz, whole samples per 1 ms slice or per 10 ms frame), non-harmonic rates (200, 300, 400, 500, 600, 800 Hz, 1.2 kHz), and sync groups (pairs sampled at one instant on two branches). {line}."),
                "A mix fails when its demand exceeds a branch's ADC, or earlier when no slot grid holds every rate's period exactly (non-harmonic rates) or sync partners cannot share a free slot; the time to decide is the y axis.".into(),
            ],
            figures: vec![Figure {
                stem: "schedulability".into(),
                title: "Where scheduling breaks".into(),
                caption: "each point a random mix; x: demand over the ADCs' throughput; y: time to synthesize (or to prove there is no exact schedule)".into(),
                svg,
                table,
            }],
            ..Section::default()
        },
        line,
    )
}

/// The fault campaign as a table.
pub fn faults_section(c: &cosim::faults::Campaign) -> Section {
    let mut head = vec!["class", "level", "injected"];
    head.extend(c.detectors.iter().map(|d| d.name()));
    head.extend(["undetected", "proved_equivalent"]);
    let mut t = Table::new(&head);
    for k in &c.classes {
        let mut row = vec![k.name.clone(), k.level.into(), k.injected.to_string()];
        for d in &c.detectors {
            row.push(match (k.detected_by.get(d), k.cannot_see.get(d)) {
                (_, Some(why)) => format!("cannot see ({why})"),
                (Some(n), None) => n.to_string(),
                (None, None) => "not run".into(),
            });
        }
        row.push(k.undetected.len().to_string());
        row.push(k.proved_equivalent.len().to_string());
        t.push(row);
    }
    Section {
        title: "Fault campaign".into(),
        paragraphs: vec![
            format!(
                "Target {:?}; sites: {}. {} injections: {} detected, {} undetected, {} proved equivalent. False alarms: {} of {} clean runs over {} random feasible mixes.",
                c.target,
                c.sites
                    .iter()
                    .map(|s| format!("{} (slot {})", s.name, s.slot))
                    .collect::<Vec<_>>()
                    .join(", "),
                c.injected,
                c.detected,
                c.undetected,
                c.proved_equivalent,
                c.false_alarms.rejected,
                c.false_alarms.runs,
                c.false_alarms.mixes
            ),
        ],
        tables: vec![(String::new(), t)],
        ..Section::default()
    }
}

/// Where sampling at `fs` puts a sine of `f` Hz: |f - fs * round(f / fs)|.
fn alias_hz(f: f64, fs: f64) -> f64 {
    (f - fs * (f / fs).round()).abs()
}

/// The strongest frequency (1 Hz steps up to half the sample rate) in a
/// channel's samples: a direct DFT of the mean-free codes.
fn peak_hz(samples: &[(f64, f64)], fs: f64) -> f64 {
    let n = samples.len() as f64;
    if n < 4.0 {
        return 0.0;
    }
    let mean = samples.iter().map(|p| p.1).sum::<f64>() / n;
    let mut best = (0.0, 0.0);
    for f in 1..=(fs / 2.0) as u64 {
        let w = 2.0 * std::f64::consts::PI * f as f64;
        let (mut re, mut im) = (0.0, 0.0);
        for &(t, v) in samples {
            re += (v - mean) * (w * t).cos();
            im -= (v - mean) * (w * t).sin();
        }
        let p = re * re + im * im;
        if p > best.1 {
            best = (f as f64, p);
        }
    }
    best.0
}

/// The paper's Figure 7 from simulation: a sine through the ADC model's
/// quantization, sampled by the gateware at the mix's rates.  600 Hz shows as
/// 400 Hz at 1 kHz and as itself at 2 kHz; a 2 Hz signal keeps its shape at
/// 100 Hz with a tenth of the data of 1 kHz.  `None` when the mix has no
/// channels at those rates.
pub fn figure7(s: &Schedule) -> Result<Option<(Section, String)>, String> {
    let at = |hz: u64| {
        s.channels
            .iter()
            .enumerate()
            .find(|(i, _)| s.mix.channels[*i].rate_hz == hz)
            .map(|(i, _)| i)
    };
    let (Some(c1k), Some(c2k), Some(c100)) = (at(1_000), at(2_000), at(100)) else {
        return Ok(None);
    };
    let backend = if super::tool_present("verilator") {
        Backend::Verilator
    } else {
        Backend::RustHdl
    };
    let g = &s.grid;
    let run = |hz: f64, seconds: f64| -> Result<judge::samples::SampleLog, String> {
        let frames = (seconds / frame_seconds(s)).ceil() as u64;
        let opts = SimOptions {
            stimulus: judge::Stimulus::Sine(Some(hz)),
            ..SimOptions::default()
        };
        let mut log = judge::samples::SampleLog::new();
        let r = cosim::run_observed(s, backend, frames, &opts, Some(&mut log))
            .map_err(|e| e.to_string())?;
        if !r.ok {
            return Err(format!("the sine run fails the checker: {}", r.summary()));
        }
        Ok(log)
    };
    let of = |log: &judge::samples::SampleLog, ch: usize| -> Vec<(f64, f64)> {
        log.samples
            .iter()
            .filter(|x| x.channel as usize == ch)
            .map(|x| (x.cycle as f64 / g.clock_hz as f64, x.value as f64))
            .collect()
    };
    let name = |c: usize| s.mix.channels[c].name.clone();
    // (a) 600 Hz at 1 kHz and 2 kHz, 0.1 s
    let a = run(600.0, 0.1)?;
    let (x1, x2) = (of(&a, c1k), of(&a, c2k));
    let (f1, f2) = (peak_hz(&x1, 1_000.0), peak_hz(&x2, 2_000.0));
    // (b) 2 Hz at 100 Hz and 1 kHz, 1 s
    let b = run(2.0, 1.0)?;
    let (y100, y1k) = (of(&b, c100), of(&b, c1k));
    // shape: the 100 Hz channel's samples, linearly interpolated, against
    // the same channel's signal (the ADC model's code) every millisecond
    let analog = judge::adc::Analog::new(s, judge::Stimulus::Sine(Some(2.0)));
    let truth: Vec<(f64, f64)> = b
        .samples
        .iter()
        .filter(|x| x.channel as usize == c1k)
        .map(|x| {
            let t = x.cycle as f64 / g.clock_hz as f64;
            (t, analog.code(c100 as u64, x.cycle) as f64)
        })
        .collect();
    let amp = {
        let (lo, hi) = truth
            .iter()
            .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
        (hi - lo).max(1.0) / 2.0
    };
    let interp = |t: f64| -> Option<f64> {
        let i = y100.iter().position(|p| p.0 > t)?;
        if i == 0 {
            return None;
        }
        let (a, b) = (y100[i - 1], y100[i]);
        Some(a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0))
    };
    let errs: Vec<f64> = truth
        .iter()
        .filter_map(|p| interp(p.0).map(|v| (v - p.1) / amp))
        .collect();
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len().max(1) as f64).sqrt();
    let saved = 1.0 - y100.len() as f64 / y1k.len().max(1) as f64;
    let fb = peak_hz(&y100, 100.0);
    // the step fails unless each peak is where aliasing puts it (the DFT
    // steps by 1 Hz)
    for (what, got, f, fs) in [
        ("600 Hz at 1 kHz", f1, 600.0, 1_000.0),
        ("600 Hz at 2 kHz", f2, 600.0, 2_000.0),
        ("2 Hz at 100 Hz", fb, 2.0, 100.0),
    ] {
        let want = alias_hz(f, fs);
        if (got - want).abs() > 1.0 {
            return Err(format!(
                "Figure 7: {what} shows as {got:.0} Hz; aliasing puts it at {want:.0} Hz"
            ));
        }
    }

    let ms = |v: &[(f64, f64)], upto: f64| -> Vec<(f64, f64)> {
        v.iter()
            .filter(|p| p.0 <= upto)
            .map(|p| (p.0 * 1e3, p.1))
            .collect()
    };
    let mut table = Table::new(&["stimulus_hz", "channel", "rate_hz", "time_s", "code"]);
    for (hz, ch, rate, pts) in [
        (600, c1k, 1_000, &x1),
        (600, c2k, 2_000, &x2),
        (2, c100, 100, &y100),
        (2, c1k, 1_000, &y1k),
    ] {
        for p in pts.iter() {
            table.push(vec![
                hz.to_string(),
                name(ch),
                rate.to_string(),
                format!("{:.9}", p.0),
                format!("{}", p.1),
            ]);
        }
    }
    let mut sa = Series::line(
        &format!("{} at 1 kHz: shows {f1:.0} Hz", name(c1k)),
        ms(&x1, 0.01),
    );
    sa.points_only = false;
    let sb = Series::line(
        &format!("{} at 2 kHz: shows {f2:.0} Hz", name(c2k)),
        ms(&x2, 0.01),
    );
    let svg_a = draw(
        &Axes::new(
            "A 600 Hz sine sampled at 1 kHz and 2 kHz (first 10 ms)",
            "time (ms)",
            "ADC code",
        ),
        &[sa, sb],
        900,
        380,
    );
    let svg_b = draw(
        &Axes::new(
            "A 2 Hz sine sampled at 100 Hz and 1 kHz (1 s)",
            "time (ms)",
            "ADC code",
        ),
        &[
            Series::line(
                &format!("{} at 1 kHz ({} samples)", name(c1k), y1k.len()),
                ms(&y1k, 1.0),
            ),
            Series::scatter(
                &format!("{} at 100 Hz ({} samples)", name(c100), y100.len()),
                ms(&y100, 1.0),
            ),
        ],
        900,
        380,
    );
    let line = format!(
        "600 Hz shows as {f1:.0} Hz at 1 kHz and {f2:.0} Hz at 2 kHz; 2 Hz at 100 Hz: peak {fb:.0} Hz, {:.0} % less data than 1 kHz, rms shape error {:.1} % of the amplitude",
        saved * 100.0,
        rms * 100.0
    );
    Ok(Some((
        Section {
            title: "Figure 7: sampling rate against reconstruction".into(),
            paragraphs: vec![
                format!("The paper's Figure 7, from simulation ({} back end, the emitted design, codes from the ADC model's quantization of a sine on every channel). {line}.", backend.name()),
                format!("A channel sampled below twice its signal's frequency folds it to |f - fs * round(f / fs)|: measured here, 600 Hz at 1 kHz shows as {f1:.0} Hz (aliasing puts it at {:.0} Hz), at 2 kHz as {f2:.0} Hz ({:.0} Hz), and 2 Hz at 100 Hz as {fb:.0} Hz ({:.0} Hz); this step fails when a peak is more than 1 Hz from there. A slow signal needs no fast rate: at 100 Hz a 2 Hz signal keeps its shape with {:.0} % less data than at 1 kHz.", alias_hz(600.0, 1_000.0), alias_hz(600.0, 2_000.0), alias_hz(2.0, 100.0), saved * 100.0),
            ],
            figures: vec![
                Figure {
                    stem: "figure7-aliasing".into(),
                    title: "600 Hz at 1 kHz and 2 kHz".into(),
                    caption: format!("apparent frequency from a DFT of the samples of 0.1 s: {f1:.0} Hz and {f2:.0} Hz"),
                    svg: svg_a,
                    table: table.clone(),
                },
                Figure {
                    stem: "figure7-slow".into(),
                    title: "2 Hz at 100 Hz and 1 kHz".into(),
                    caption: format!("{:.0} % less data at 100 Hz; the 100 Hz samples, linearly interpolated, differ from that channel's signal taken every millisecond by {:.1} % rms of its amplitude", saved * 100.0, rms * 100.0),
                    svg: svg_b,
                    table,
                },
            ],
            ..Section::default()
        },
        line,
    )))
}
