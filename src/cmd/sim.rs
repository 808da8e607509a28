//! `slotforge sim MIX --backend B --frames N [--vcd F --from A --to B] [--json] [--stimulus S] [--samples F.csv] [--link-bytes F.bin] [--rtl FILE.v]`
//!
//! Back ends: model, rusthdl, verilator, icarus (see `engines::Backend`);
//! `--rtl` (verilator, icarus) simulates outside Verilog whose top honours
//! the pin contract (`engines::rtl`); `--netlist FAMILY` the netlist yosys
//! writes for an FPGA family, with its cell models, on the same path
//! (`measure::netlist`).
//!
//! Exit 0: every cycle passed; 1: a divergence or violation; 2: bad input or
//! a missing tool.

use std::path::PathBuf;

use engines::{Backend, SimOptions, Stimulus, VcdOut};

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// model (slot-level), rusthdl (in process), verilator or icarus (the emitted Verilog).
    #[arg(long, default_value = "model", value_parser = super::backend)]
    pub backend: Backend,
    /// Frames to simulate.
    #[arg(long, value_parser = super::whole_number, default_value_t = 2)]
    pub frames: u64,
    /// Write a VCD of the window --from..--to (plus a GTKWave .gtkw beside
    /// it); times in it are exact (each edge rounded once to 1 ps).
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// Write the --vcd window as FST instead (as a name ending in `.fst`
    /// does), through the fst-writer crate; `check` reads it back.
    #[arg(long, requires = "vcd")]
    pub fst: bool,
    /// Start of the VCD window: a frame number, or a time after cycle 0 (the
    /// first cycle after reset) with a unit: 3ms, 250us, 1.5ms.  A window
    /// from 0 also shows the reset.
    #[arg(long, default_value = "0", value_parser = super::bound)]
    pub from: super::Bound,
    /// End (exclusive) of the VCD window, as --from; default: one frame after --from.
    #[arg(long, value_parser = super::bound)]
    pub to: Option<super::Bound>,
    /// ADC input: pattern (unique code per channel and slot), sine (a
    /// channel-specific frequency below its Nyquist limit), sine:HZ (every
    /// channel at HZ, e.g. sine:600 or sine:1.5e3; above Nyquist it aliases),
    /// step or chirp; or a scene of contact: touch:NAMES@FROM-TO presses the
    /// named channels (names or bulk patterns, comma-separated; codes 1/32
    /// below full scale) in frames FROM to TO (exclusive), low (1/64 of full
    /// scale) elsewhere; stroke:NAMES@FROM-TO presses them one after the
    /// other, each for an equal share of the interval.
    #[arg(long, default_value = "pattern")]
    pub stimulus: String,
    /// Write every sample as CSV: `cycle,sampled_s,channel,value` (cycle:
    /// the sample_valid strobe's, from cycle 0, the first after reset;
    /// sampled_s: the conversion's sampling instant in seconds after cycle
    /// 0, rounded once to 1 ps, as `decode` writes it; channel: its name;
    /// value: the ADC code), one row per strobe.  With --backend model the
    /// cycle-level model runs.
    #[arg(long)]
    pub samples: Option<PathBuf>,
    /// Write the bytes the link carried, raw, as a host would have received
    /// them (UART: each character's data byte read off link_tx at the
    /// planned divider; AXI4-Stream: the tdata of each accepted beat), for
    /// `slotforge decode MIX FILE`.  A mix with a [link] only.  With
    /// --backend model the cycle-level model runs.
    #[arg(long, value_name = "FILE")]
    pub link_bytes: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// Simulate this Verilog (verilator, icarus) instead of the emitted one;
    /// its top module must honour the pin contract for the mix.
    #[arg(long, value_name = "FILE.v")]
    pub rtl: Option<PathBuf>,
    /// Simulate the gate-level netlist yosys writes for this FPGA family
    /// (ice40, ecp5, gowin, or a part: ice40-hx8k, ecp5-25k, gw1n-9) with the
    /// family's cell models (verilator, icarus), under the same ADC model
    /// and judge.
    #[arg(long, value_name = "FAMILY", value_parser = super::fpga, conflicts_with = "rtl")]
    pub netlist: Option<lut_gen::Fpga>,
    /// An AXI4-Stream link's slave: `always` (ready in every cycle),
    /// `random` or `random:SEED` (seeded, within the mix's
    /// `link.ready_within`), `worst` (every beat taken in its
    /// `ready_within`-th cycle, the case the FIFO depth is computed for).
    #[arg(long, default_value = "always", value_parser = parse_tready)]
    pub tready: link::ReadyPattern,
    /// A mix with pin-selected modes: drive `mode_sel` with FRAME=MODE
    /// requests, comma-separated (MODE a name or a number; e.g.
    /// `--modes 3=touch,9=rest`): from the first cycle of frame FRAME on the
    /// pin shows MODE, which by the contract runs from frame FRAME + 2.
    /// Before the first request the pin shows 0.  Every back end.
    #[arg(long, value_name = "FRAME=MODE,...")]
    pub modes: Option<String>,
}

/// What is refused before the mix is read: a stimulus that names no
/// channel and is not one, no frames.
fn early_checks(a: &Args) -> Result<(), String> {
    // a scene names channels: it is read once the mix is loaded
    let scene = ["touch:", "stroke:"]
        .iter()
        .any(|p| a.stimulus.starts_with(p));
    if !scene {
        a.stimulus.parse::<Stimulus>()?;
    }
    if a.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    Ok(())
}

/// `--stimulus` (a scene names the mix's channels) and `--modes`.
fn scene_and_modes(a: &Args, s: &lut_gen::Schedule) -> Result<(Stimulus, Vec<(u64, u8)>), String> {
    let stimulus = Stimulus::parse_for(&a.stimulus, s)?;
    let modes = a.modes.as_deref().map(|t| parse_modes(t, s)).transpose()?;
    Ok((stimulus, modes.unwrap_or_default()))
}

/// `--modes FRAME=MODE,...` against the mix's modes.
pub(super) fn parse_modes(text: &str, s: &lut_gen::Schedule) -> Result<Vec<(u64, u8)>, String> {
    let plan = match s.mode_plan() {
        Some(p) if p.select == lut_gen::ModeSelect::Pin => p,
        Some(_) => {
            return Err(format!(
                "--modes {text}: mix `{}` chooses its modes by triggers (select = \"auto\"), not by the mode_sel pin",
                s.mix.name
            ))
        }
        None => return Err(format!("--modes {text}: mix `{}` has no [[mode]] tables", s.mix.name)),
    };
    text.split(',')
        .map(|item| {
            let (f, m) = item.trim().split_once('=').ok_or_else(|| {
                format!(
                    "--modes: `{item}` is not FRAME=MODE (e.g. 3={})",
                    plan.names[plan.names.len() - 1]
                )
            })?;
            let frame: u64 = f
                .trim()
                .parse()
                .map_err(|_| format!("--modes: `{item}`: `{f}` is not a frame number"))?;
            let m = m.trim();
            let mode = plan
                .index(m)
                .or_else(|| m.parse::<usize>().ok().filter(|&n| n < plan.names.len()))
                .ok_or_else(|| {
                    format!(
                        "--modes: `{item}`: no mode `{m}` (the mix's modes: {})",
                        plan.names.join(", ")
                    )
                })?;
            Ok((frame, mode as u8))
        })
        .collect()
}

fn parse_tready(s: &str) -> Result<link::ReadyPattern, String> {
    link::ReadyPattern::parse(s)
        .ok_or_else(|| format!("`{s}`: always, worst, random or random:SEED (SEED > 0)"))
}

/// The run's VCD `vcd` as the FST `fst`, with its own save file and
/// translate file; the VCD and the files named after it are removed.
fn to_fst(
    s: &lut_gen::Schedule,
    vcd: &std::path::Path,
    fst: &std::path::Path,
) -> std::io::Result<()> {
    let r = super::vcd_to_fst(vcd, fst);
    for f in [
        vcd.to_path_buf(),
        vcd.with_extension("gtkw"),
        judge::channels_path(vcd),
    ] {
        let _ = std::fs::remove_file(f);
    }
    r?;
    judge::write_gtkw(&fst.with_extension("gtkw"), fst, s)
}

pub fn run(a: Args) -> u8 {
    let backend = a.backend;
    if let Err(e) = early_checks(&a) {
        eprintln!("error: {e}");
        return 2;
    }
    // The model follows mode switches; the gateware does not yet.
    let load = match backend {
        Backend::Model | Backend::RustHdl | Backend::Verilator | Backend::Icarus => {
            super::load_any_modes
        }
    };
    let s = match load(&a.mix, super::Limits::Contract) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let prepared = scene_and_modes(&a, &s).and_then(|(k, modes)| {
        let (from, to) = window(&a, &s)?;
        let (vcd, fst) = waveform_paths(&a)?;
        samples_path_free(&a)?;
        link_bytes_path_free(&a, &s)?;
        Ok((k, modes, from, to, vcd, fst))
    });
    let (stimulus, modes, from, to, vcd, fst) = match prepared {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let netlist = match netlist_rtl(&a, &s) {
        Ok(n) => n,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let opts = SimOptions {
        stimulus,
        vcd: vcd.clone().map(|path| VcdOut {
            path,
            from,
            to,
            gtkw: true,
        }),
        rtl: netlist
            .as_ref()
            .map(|(d, _)| d.path().join(measure::NETLIST_SIM_FILE))
            .or_else(|| a.rtl.clone()),
        tready: a.tready,
        modes,
        ..SimOptions::default()
    };
    let mut logs = Logs {
        samples: a.samples.is_some().then(judge::SampleLog::new),
        bytes: a
            .link_bytes
            .as_ref()
            .and_then(|_| judge::LinkBytes::new(&s)),
    };
    let report = match simulate(&a, &s, backend, &opts, &mut logs) {
        Ok(mut r) => {
            if let Some((_, f)) = &netlist {
                r.source = format!("{}, {f} netlist", r.source);
            }
            r
        }
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    if let (Some(f), Some(v)) = (&fst, &vcd) {
        if let Err(e) = to_fst(&s, v, f) {
            eprintln!("error: --vcd {}: {e}", f.display());
            return 2;
        }
    }
    if let Err(e) = logs.write(&a, &s) {
        eprintln!("error: {e}");
        return 2;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serializes")
        );
    } else {
        print!("{}", report.summary());
    }
    if report.ok {
        0
    } else {
        1
    }
}

/// `--netlist FAMILY`: yosys' netlist of the emitted gateware with the
/// family's cell models, in a work folder that lives as long as the run.
fn netlist_rtl(
    a: &Args,
    s: &lut_gen::Schedule,
) -> Result<Option<(tempfile::TempDir, lut_gen::Fpga)>, String> {
    let Some(fpga) = a.netlist else {
        return Ok(None);
    };
    if !matches!(a.backend, Backend::Verilator | Backend::Icarus) {
        return Err(format!(
            "--netlist {fpga}: the netlist runs on a Verilog simulator: --backend verilator or icarus, not {}",
            a.backend.name()
        ));
    }
    let dir = tempfile::Builder::new()
        .prefix("slotforge-netlist-")
        .tempdir()
        .map_err(|e| format!("--netlist: a work folder: {e}"))?;
    measure::netlist(s, fpga, dir.path())?;
    Ok(Some((dir, fpga)))
}

/// The VCD window's cycles `[from, to)`, refused when empty or beyond the run.
fn window(a: &Args, s: &lut_gen::Schedule) -> Result<(u64, u64), String> {
    let from = a.from.cycles(s);
    let to = match a.to {
        Some(b) => b.cycles(s),
        None => from + s.grid.frame_cycles,
    };
    if a.vcd.is_some() && to <= from {
        return Err(format!(
            "--to ({to} cycles) must be after --from ({from} cycles)"
        ));
    }
    // A window beyond the run would come out short, after the whole run.
    let run_cycles = a.frames.saturating_mul(s.grid.frame_cycles);
    if a.vcd.is_some() && to > run_cycles {
        return Err(format!(
            "--to ({to} cycles) is beyond the run: {} frame(s) of {} cycles end at cycle {run_cycles}; use --frames {}",
            a.frames,
            s.grid.frame_cycles,
            to.div_ceil(s.grid.frame_cycles)
        ));
    }
    Ok((from, to))
}

/// The VCD the run writes and the FST it becomes (with `--fst` or a
/// `.fst` name): (vcd, fst).
fn waveform_paths(a: &Args) -> Result<(Option<PathBuf>, Option<PathBuf>), String> {
    // A missing folder is refused now, not found missing after the run; the
    // path is made absolute so the .gtkw beside it finds it from anywhere.
    let vcd = (a.vcd.as_deref())
        .map(|p| super::output_file("--vcd", p))
        .transpose()?;
    // FST: the run writes a VCD beside it, converted at the end (in
    // process, through fst-writer).
    let fst = vcd.as_ref().and_then(|v| {
        let named = v.extension().is_some_and(|x| x == "fst");
        (a.fst || named).then(|| v.with_extension("fst"))
    });
    let vcd = match &fst {
        Some(f) => Some(f.with_extension("fst.vcd")),
        None => vcd,
    };
    Ok((vcd, fst))
}

/// `--samples` names a file of its own: not the mix, the waveform or a directory.
fn samples_path_free(a: &Args) -> Result<(), String> {
    let Some(p) = &a.samples else {
        return Ok(());
    };
    let same = |q: &std::path::Path| {
        p == q || matches!((p.canonicalize(), q.canonicalize()), (Ok(x), Ok(y)) if x == y)
    };
    let vcd = a.vcd.as_deref();
    let gtkw = vcd.map(|v| v.with_extension("gtkw"));
    if same(&a.mix) || vcd.is_some_and(same) || gtkw.as_deref().is_some_and(same) {
        return Err(format!(
            "--samples {}: is the mix or the waveform of this run; name another file",
            p.display()
        ));
    }
    super::output_file("--samples", p).map(|_| ())
}

/// `--link-bytes` needs a mix with a link and names a file of its own.
fn link_bytes_path_free(a: &Args, s: &lut_gen::Schedule) -> Result<(), String> {
    let Some(p) = &a.link_bytes else {
        return Ok(());
    };
    if s.mix.link.is_none() {
        return Err(format!(
            "--link-bytes {}: {} has no [link]: its samples leave on the parallel sample port, no line carries bytes (see docs/mix-format.md for a [link] table)",
            p.display(),
            a.mix.display()
        ));
    }
    let same = |q: &std::path::Path| {
        p == q || matches!((p.canonicalize(), q.canonicalize()), (Ok(x), Ok(y)) if x == y)
    };
    let vcd = a.vcd.as_deref();
    let gtkw = vcd.map(|v| v.with_extension("gtkw"));
    let taken = same(&a.mix)
        || vcd.is_some_and(same)
        || gtkw.as_deref().is_some_and(same)
        || a.samples.as_deref().is_some_and(same);
    if taken {
        return Err(format!(
            "--link-bytes {}: is the mix, the waveform or the samples of this run; name another file",
            p.display()
        ));
    }
    super::output_file("--link-bytes", p).map(|_| ())
}

/// What a run logs beside its verdict: its samples (`--samples`) and its
/// link's bytes (`--link-bytes`).
struct Logs {
    samples: Option<judge::SampleLog>,
    bytes: Option<judge::LinkBytes>,
}

impl Logs {
    fn any(&self) -> bool {
        self.samples.is_some() || self.bytes.is_some()
    }

    /// The files asked for, each written whole or not at all.
    fn write(&self, a: &Args, s: &lut_gen::Schedule) -> Result<(), String> {
        if let (Some(p), Some(log)) = (&a.samples, &self.samples) {
            log.write_csv(s, p)
                .map_err(|e| format!("--samples {}: {}", p.display(), lut_gen::write_words(&e)))?;
        }
        if let (Some(p), Some(b)) = (&a.link_bytes, &self.bytes) {
            b.write(p).map_err(|e| {
                format!("--link-bytes {}: {}", p.display(), lut_gen::write_words(&e))
            })?;
        }
        Ok(())
    }
}

impl judge::Observer for Logs {
    fn cycle(&mut self, cycle: u64, rst: bool, pins: &lut_gen::Pins, miso: u64) {
        if let Some(l) = &mut self.samples {
            judge::Observer::cycle(l, cycle, rst, pins, miso);
        }
        if let Some(b) = &mut self.bytes {
            judge::Observer::cycle(b, cycle, rst, pins, miso);
        }
    }
}

impl judge::CycleSink for Logs {
    fn cycle(
        &mut self,
        rst: Option<bool>,
        pins: &lut_gen::Pins,
        xz: &lut_gen::Pins,
        miso: u64,
        miso_xz: u64,
    ) {
        if let Some(l) = &mut self.samples {
            judge::CycleSink::cycle(l, rst, pins, xz, miso, miso_xz);
        }
        if let Some(b) = &mut self.bytes {
            judge::CycleSink::cycle(b, rst, pins, xz, miso, miso_xz);
        }
    }
}

/// The run, with progress shown and every sample and link byte logged into
/// `logs` when `--samples` or `--link-bytes` asks for them.
fn simulate(
    a: &Args,
    s: &lut_gen::Schedule,
    backend: Backend,
    opts: &SimOptions,
    logs: &mut Logs,
) -> Result<judge::Verdict, engines::SimError> {
    // The slot-level model runs hours per second: no progress to show, and
    // an observer would make it run the cycle model instead.
    if backend == Backend::Model && !logs.any() {
        return engines::run(s, backend, a.frames, opts);
    }
    let inner = logs.any().then_some(logs as &mut dyn engines::Tracer);
    let mut p = super::progress::CycleProgress::new(
        a.frames,
        s.grid.frame_cycles,
        a.quiet || a.json,
        inner,
    );
    let r = engines::run_observed(s, backend, a.frames, opts, Some(&mut p));
    p.finish();
    r
}
