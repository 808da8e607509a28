//! `slotforge golden MIX [--backend B] [--rtl FILE.v] [--update]`: simulate the mix (or
//! outside Verilog) and
//! compare the run with its golden in `golden/<mix>/`, by signal role.
//!
//! A golden folder holds `events.log` (the decoded event log of the first
//! frames after reset, `judge::events`) and, if `golden.toml` asks for them,
//! waveform windows as VCD with a GTKWave save file each (the reference
//! mix keeps the four windows of the paper's Figure 6).  Windows are
//! compared cycle by cycle on every port, not byte by byte.
//!
//! Exit 0: identical; 1: a difference (first one shown, with a count), or
//! the run itself fails the checker; 2: bad input, a missing golden, a
//! missing tool.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use engines::{Backend, SimOptions};
use judge::{compare_events as compare, EventLog, Trace};
use judge::{write_gtkw, VcdWriter};
use lut_gen::Schedule;
use serde::Deserialize;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix files (TOML), each compared with its own golden.
    #[arg(required = true)]
    pub mix: Vec<PathBuf>,
    /// Which simulator runs the design: verilator or icarus (the emitted
    /// Verilog), rusthdl (in process), or model (the cycle-level reference
    /// model's own pins).
    #[arg(long, default_value = "verilator", value_parser = super::backend)]
    pub backend: Backend,
    /// Simulate this Verilog instead of the emitted design (verilator and
    /// icarus): any top `slotforge_top` that honours the mix's port contract.
    #[arg(long)]
    pub rtl: Option<PathBuf>,
    /// Rewrite the golden from this run and say what changed.
    #[arg(long)]
    pub update: bool,
    /// Where the golden folders are (one per mix, named by the mix's `name`).
    #[arg(long, default_value = "golden")]
    pub dir: PathBuf,
    /// Also write JUnit XML: one test case per mix.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// The scene the run is driven with (a mix with modes switches in it).
    #[command(flatten)]
    pub scene: Scene,
}

/// The scene of a golden run: recorded in the golden's header by
/// `--update`, so a run without these options replays the recorded scene;
/// given, they replace it (a different scene then differs from the golden).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct Scene {
    /// A mix with pin-selected modes: drive `mode_sel` with FRAME=MODE
    /// requests, as `sim --modes` does (e.g. `--modes 2=slow,7=fast`).
    #[arg(long, value_name = "FRAME=MODE,...")]
    pub modes: Option<String>,
    /// The ADC input, as `sim --stimulus` takes it (pattern, sine, step,
    /// chirp, or a scene of contact: touch:NAMES@FROM-TO,
    /// stroke:NAMES@FROM-TO); default pattern.
    #[arg(long)]
    pub stimulus: Option<String>,
}

/// The header lines that record a scene in `events.log`.
const SCENE_MODES: &str = "# scene --modes: ";
const SCENE_STIMULUS: &str = "# scene --stimulus: ";

impl Scene {
    /// The scene recorded in a golden's event log (none: pattern, no requests).
    fn recorded(log: &str) -> Scene {
        let line = |prefix: &str| {
            log.lines()
                .find_map(|l| l.strip_prefix(prefix))
                .map(|v| v.trim().to_string())
        };
        Scene {
            modes: line(SCENE_MODES),
            stimulus: line(SCENE_STIMULUS),
        }
    }

    /// The options given, else the recorded ones, each on its own.
    fn or(&self, recorded: &Scene) -> Scene {
        Scene {
            modes: self.modes.clone().or_else(|| recorded.modes.clone()),
            stimulus: self.stimulus.clone().or_else(|| recorded.stimulus.clone()),
        }
    }

    fn stimulus_text(&self) -> &str {
        self.stimulus.as_deref().unwrap_or("pattern")
    }

    /// The header lines recording it (none for the default scene, so a
    /// golden of a mix without modes reads as before).
    fn header(&self) -> Vec<String> {
        let mut h = Vec::new();
        if let Some(m) = &self.modes {
            h.push(format!("{}{m}", &SCENE_MODES[2..]));
        }
        if let Some(k) = self.stimulus.as_ref().filter(|k| *k != "pattern") {
            h.push(format!("{}{k}", &SCENE_STIMULUS[2..]));
        }
        h
    }

    /// The stimulus and the `mode_sel` requests, resolved against the mix.
    fn resolve(&self, s: &Schedule) -> Result<(engines::Stimulus, Vec<(u64, u8)>), String> {
        let stimulus = engines::Stimulus::parse_for(self.stimulus_text(), s)?;
        let modes = match &self.modes {
            Some(m) => super::sim::parse_modes(m, s)?,
            None => Vec::new(),
        };
        Ok((stimulus, modes))
    }

    /// The options that give this scene, for a command line.
    fn options(&self) -> String {
        let mut o = String::new();
        if let Some(m) = &self.modes {
            o += &format!(" --modes {m}");
        }
        if let Some(k) = &self.stimulus {
            o += &format!(" --stimulus '{k}'");
        }
        o
    }
}

/// `golden/<mix>/golden.toml`: what the golden holds.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    /// Frames the event log covers (default 1).
    #[serde(default = "one")]
    frames: u64,
    #[serde(default)]
    window: Vec<Window>,
}

fn one() -> u64 {
    1
}

/// A waveform window kept as a golden VCD.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Window {
    /// File name in the golden folder (`.vcd`, or `.fst` written through
    /// the `fst-writer` crate; the `.gtkw` goes beside it).
    file: String,
    /// Bounds as for `sim --from/--to`: a frame number or a time (`3ms`).
    from: String,
    to: String,
}

macro_rules! outln {
    ($o:expr, $($a:tt)*) => {{ let _ = writeln!($o.out, $($a)*); }};
}
macro_rules! errln {
    ($o:expr, $($a:tt)*) => {{ let _ = writeln!($o.err, $($a)*); }};
}
macro_rules! errp {
    ($o:expr, $($a:tt)*) => {{ let _ = write!($o.err, $($a)*); }};
}

const EVENTS: &str = "events.log";
const MANIFEST: &str = "golden.toml";
/// Differences listed after the first one.
const SHOWN: usize = 5;

fn load_manifest(path: &Path) -> Result<Manifest, String> {
    if !path.exists() {
        return Ok(Manifest {
            frames: 1,
            window: Vec::new(),
        });
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {}", path.display(), lut_gen::io_words(&e)))?;
    let m: Manifest = toml::from_str(&text).map_err(|e| {
        let line = e
            .span()
            .map(|sp| text[..sp.start].matches('\n').count() + 1)
            .unwrap_or(0);
        format!(
            "{}:{line}: {}",
            path.display(),
            lut_gen::toml_words(e.message(), "")
        )
    })?;
    if m.frames == 0 {
        return Err(format!("{}: `frames` must be at least 1", path.display()));
    }
    for w in &m.window {
        if w.file.contains('/') || !(w.file.ends_with(".vcd") || w.file.ends_with(".fst")) {
            return Err(format!(
                "{}: window file `{}` must be a plain `.vcd` or `.fst` file name",
                path.display(),
                w.file
            ));
        }
    }
    Ok(m)
}

/// A window's run cycles `[k0, k1)` (from the first reset cycle).
fn window_cycles(s: &Schedule, w: &Window, reset: u64, file: &Path) -> Result<(u64, u64), String> {
    let b = |v: &str, field: &str| {
        super::bound(v).map_err(|e| format!("{}: window `{}` {field}: {e}", file.display(), w.file))
    };
    let (from, to) = (b(&w.from, "from")?.cycles(s), b(&w.to, "to")?.cycles(s));
    if to <= from {
        return Err(format!(
            "{}: window `{}` ends ({to} cycles) before it starts ({from})",
            file.display(),
            w.file
        ));
    }
    let v = engines::VcdOut {
        path: file.to_path_buf(),
        from,
        to,
        gtkw: false,
    };
    Ok(v.run_cycles(reset))
}

/// Writes the window `[k0, k1)` of `trace` as a VCD, or as an FST when
/// `fst` (the VCD converted through `fst-writer`).
fn write_window(
    s: &Schedule,
    trace: &Trace,
    k0: u64,
    k1: u64,
    path: &Path,
    fst: bool,
) -> std::io::Result<()> {
    use judge::Observer;
    let vcd = if fst {
        path.with_extension("fst.vcd")
    } else {
        path.to_path_buf()
    };
    let mut w = VcdWriter::create(&vcd, s, k0, k1)?;
    for (k, (rst, p, miso)) in trace.cycles.iter().enumerate().take(k1 as usize) {
        w.cycle(k as u64, *rst, p, *miso);
    }
    w.finish()?;
    if !fst {
        return Ok(());
    }
    let r = super::vcd_to_fst(&vcd, path);
    let _ = std::fs::remove_file(&vcd);
    r
}

/// The cycles of a VCD window as read back by the judge's reader.
fn read_window(s: &Schedule, path: &Path) -> Result<Trace, String> {
    let mut t = Trace::default();
    judge::read_cycles(s, path, None, &mut t).map_err(|e| e.to_string())?;
    Ok(t)
}

/// The first cycle where two windows differ, or `None`.
fn first_window_difference(a: &Trace, b: &Trace) -> Option<String> {
    for (i, (x, y)) in a.cycles.iter().zip(&b.cycles).enumerate() {
        if x != y {
            return Some(format!(
                "window cycle {i}: expected rst={} {} miso={:#b}, actual rst={} {} miso={:#b}",
                x.0,
                pins_text(&x.1),
                x.2,
                y.0,
                pins_text(&y.1),
                y.2
            ));
        }
    }
    (a.len() != b.len()).then(|| format!("{} cycles expected, {} found", a.len(), b.len()))
}

/// A cycle's pins by their port names, as the VCD names them.
fn pins_text(p: &lut_gen::Pins) -> String {
    format!(
        "cs_n={:#b} sclk={:#b} mux_sel={:#x} mux_en={:#b} sample_valid={} sample_channel={} sample_value={}",
        p.cs_n,
        p.sclk,
        p.mux_sel,
        p.mux_en,
        u8::from(p.sample_valid),
        p.sample_channel,
        p.sample_value
    )
}

pub fn run(a: Args) -> u8 {
    if let Err(code) = super::junit::check_writable(a.junit.as_deref()) {
        return code;
    }
    let bar = super::progress::Progress::new(a.mix.len() as u64, "mixes", a.quiet);
    let mut worst = 0;
    let mut cases = Vec::new();
    for mix in &a.mix {
        bar.message(&mix.display().to_string());
        let t = std::time::Instant::now();
        let mut out = Output::default();
        let code = execute(&a, mix, &mut out);
        bar.println_out(&out.out);
        bar.println_err(&out.err);
        bar.inc();
        let first = out
            .out
            .lines()
            .chain(out.err.lines())
            .next()
            .unwrap_or("")
            .to_string();
        cases.push(super::junit::Case {
            name: mix.display().to_string(),
            seconds: t.elapsed().as_secs_f64(),
            outcome: if code == 0 {
                super::junit::Outcome::Passed
            } else {
                super::junit::Outcome::Failed(first, format!("{}{}", out.out, out.err))
            },
        });
        worst = worst.max(code);
    }
    bar.finish();
    if let Some(j) = &a.junit {
        if let Err(e) = super::junit::write(j, "slotforge golden", &cases) {
            eprintln!("error: {e}");
            return 2;
        }
    }
    worst
}

/// What a golden run printed: `out` for stdout, `err` for stderr.
#[derive(Debug, Default)]
pub struct Output {
    pub out: String,
    pub err: String,
}

/// The golden command, its messages collected in `o` (the `build` job
/// puts them in its report).
pub fn execute(a: &Args, mix: &Path, o: &mut Output) -> u8 {
    let s = match super::schedule_on_pins(mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let dir = a.dir.join(&s.mix.name);
    let manifest_path = dir.join(MANIFEST);
    let manifest = match load_manifest(&manifest_path) {
        Ok(m) => m,
        Err(e) => {
            errln!(o, "error: {e}");
            return 2;
        }
    };
    let events_path = dir.join(EVENTS);
    let (golden, scene, (stimulus, modes), other) = match load_golden(a, &s, mix, &events_path, o) {
        Ok(g) => g,
        Err(code) => return code,
    };

    // One run covers the event log and every window.
    let f = s.grid.frame_cycles;
    let opts = SimOptions {
        rtl: a.rtl.clone(),
        stimulus,
        modes,
        ..SimOptions::default()
    };
    let reset = judge::reset_cycles(&s, opts.reset_cycles);
    let windows: Vec<WindowAt> = match (manifest.window.iter())
        .map(|w| Ok((w, window_cycles(&s, w, reset, &manifest_path)?)))
        .collect::<Result<_, String>>()
    {
        Ok(w) => w,
        Err(e) => {
            errln!(o, "error: {e}");
            return 2;
        }
    };
    let frames = windows
        .iter()
        .map(|(_, (_, k1))| (k1 - reset).div_ceil(f))
        .max()
        .unwrap_or(0)
        .max(manifest.frames);
    let mut trace = Trace::default();
    let report = match engines::run_traced(&s, a.backend, frames, &opts, Some(&mut trace)) {
        Ok(r) => r,
        Err(e) => {
            errln!(o, "error: {e}");
            return 2;
        }
    };
    let log = EventLog::from_trace(&s, &trace, manifest.frames * f);
    let who = match &a.rtl {
        Some(r) => format!(
            "golden {} ({}, {})",
            s.mix.name,
            a.backend.name(),
            r.display()
        ),
        None => format!("golden {} ({})", s.mix.name, a.backend.name()),
    };
    if !report.ok {
        errp!(o, "{who}: the run fails the checker:\n{}", report.summary());
    }

    if a.update {
        return update(
            o,
            (&s, &scene),
            &dir,
            golden.as_ref(),
            &log,
            &trace,
            &windows,
            &who,
            report.ok,
        );
    }
    let golden = golden.expect("loaded above");
    if let Some(why) = &other {
        outln!(o, "{who}: DIFFERS from {}: {why}", events_path.display());
    }
    let mut differ = other.is_some();
    differ |= compare_events(o, &who, &s, &golden, &log, &events_path, other.is_some());
    match compare_windows(
        o,
        &who,
        &s,
        &dir,
        &trace,
        (&windows, &update_command(a, mix)),
    ) {
        Ok(d) => differ |= d,
        Err(code) => return code,
    }
    if differ || !report.ok {
        1
    } else {
        0
    }
}

/// The golden's event log ([`load_events`]), the scene this run drives
/// and its stimulus and `mode_sel` requests (`drive`), and how that scene
/// differs from the golden's (`None`: the same).
type Loaded = (
    Option<EventLog>,
    Scene,
    (engines::Stimulus, Vec<(u64, u8)>),
    Option<String>,
);

fn load_golden(
    a: &Args,
    s: &Schedule,
    mix: &Path,
    events_path: &Path,
    o: &mut Output,
) -> Result<Loaded, u8> {
    let (golden, recorded) = load_events(a, s, mix, events_path, o)?;
    // the scene given, else the one the golden was recorded under
    let scene = a.scene.or(&recorded);
    let k = scene.resolve(s).map_err(|e| {
        errln!(o, "error: {e}");
        2u8
    })?;
    let other = golden
        .as_ref()
        .and_then(|_| scene_differs(s, &recorded, &scene, &k));
    Ok((golden, scene, k, other))
}

/// How `scene`, resolved as `k`, differs from the one the golden was
/// `recorded` under (`None`: the same stimulus and the same requests,
/// however written): a run under another scene is never "the same".
fn scene_differs(
    s: &Schedule,
    recorded: &Scene,
    scene: &Scene,
    k: &(engines::Stimulus, Vec<(u64, u8)>),
) -> Option<String> {
    if recorded.resolve(s).as_ref() == Ok(k) {
        return None;
    }
    Some(format!(
        "the golden was recorded under{}; this run drives{}",
        or_default(&recorded.options()),
        or_default(&scene.options())
    ))
}

/// The golden event log at `events_path` and the scene it was recorded
/// under: `None` when `--update` records a new one; a missing or
/// unreadable one is an error (printed: exit 2).
fn load_events(
    a: &Args,
    s: &Schedule,
    mix: &Path,
    events_path: &Path,
    o: &mut Output,
) -> Result<(Option<EventLog>, Scene), u8> {
    if !events_path.exists() {
        if a.update {
            return Ok((None, Scene::default()));
        }
        errln!(
            o,
            "error: no golden for mix `{}`: {} does not exist (record one with `{}`)",
            s.mix.name,
            events_path.display(),
            update_command(a, mix)
        );
        return Err(2);
    }
    let text = match std::fs::read_to_string(events_path) {
        Ok(t) => t,
        Err(e) => {
            let why = lut_gen::io_words(&e);
            errln!(o, "error: {}: cannot read: {why}", events_path.display());
            return Err(2);
        }
    };
    let recorded = Scene::recorded(&text);
    match EventLog::parse(&text) {
        Ok(l) => Ok((Some(l), recorded)),
        Err(e) if a.update => {
            errln!(o, "note: {}: {e}; replacing it", events_path.display());
            Ok((None, recorded))
        }
        Err(e) => {
            errln!(o, "error: {}: {e}", events_path.display());
            Err(2)
        }
    }
}

/// This run's event log against the golden's, the first differences
/// listed: whether they differ.
fn compare_events(
    o: &mut Output,
    who: &str,
    s: &Schedule,
    golden: &EventLog,
    log: &EventLog,
    events_path: &Path,
    other_scene: bool,
) -> bool {
    let cmp = compare(golden, log, SHOWN + 1);
    let mut differ = false;
    if cmp.same() && other_scene {
        outln!(
            o,
            "  its {} events over {} cycles are alike; the scenes differ",
            log.events.len(),
            log.cycles
        );
    } else if cmp.same() {
        outln!(
            o,
            "{who}: same as {}: {} events over {} cycles",
            events_path.display(),
            log.events.len(),
            log.cycles
        );
    } else {
        differ = true;
        outln!(
            o,
            "{who}: DIFFERS from {}: {} event(s) differ",
            events_path.display(),
            cmp.count
        );
        if cmp.expected_cycles != cmp.actual_cycles {
            outln!(
                o,
                "  the golden covers {} cycles, this run {}",
                cmp.expected_cycles,
                cmp.actual_cycles
            );
        }
        for (i, d) in cmp.first.iter().enumerate().take(SHOWN) {
            let what = if i == 0 { "first" } else { "then " };
            outln!(o, "  {what}: {}", d.describe(s));
        }
    }
    differ
}

/// A golden's window and the run's cycles `[from, to)` it covers.
type WindowAt<'a> = (&'a Window, (u64, u64));

/// This run's waveform windows against the golden's, cycle by cycle:
/// whether any differs, or the exit code of an error (printed).
fn compare_windows(
    o: &mut Output,
    who: &str,
    s: &Schedule,
    dir: &Path,
    trace: &Trace,
    (windows, redo): (&[WindowAt], &str),
) -> Result<bool, u8> {
    let tmp = match tempfile::tempdir() {
        Ok(t) => t,
        Err(e) => {
            errln!(o, "error: temporary directory: {e}");
            return Err(2);
        }
    };
    let mut differ = false;
    for (w, (k0, k1)) in windows {
        let gold = dir.join(&w.file);
        // This run's window as VCD: the reader compares cycles, whatever the golden's format.
        let new = tmp.path().join(&w.file).with_extension("vcd");
        if let Err(e) = write_window(s, trace, *k0, *k1, &new, false) {
            errln!(o, "error: {}: {e}", new.display());
            return Err(2);
        }
        let expected = match read_window(s, &gold) {
            Ok(t) => t,
            Err(e) => {
                errln!(o, "error: golden window {e} (re-record with `{redo}`)");
                return Err(2);
            }
        };
        let actual = match read_window(s, &new) {
            Ok(t) => t,
            Err(e) => {
                errln!(o, "error: this run's window {}: {e}", w.file);
                return Err(2);
            }
        };
        match first_window_difference(&expected, &actual) {
            None => outln!(o, "{who}: window {} same ({} cycles)", w.file, actual.len()),
            Some(d) => {
                differ = true;
                outln!(o, "{who}: window {} DIFFERS: {d}", w.file);
            }
        }
    }
    Ok(differ)
}

#[allow(clippy::too_many_arguments)]
fn update(
    o: &mut Output,
    (s, scene): (&Schedule, &Scene),
    dir: &Path,
    old: Option<&EventLog>,
    log: &EventLog,
    trace: &Trace,
    windows: &[(&Window, (u64, u64))],
    who: &str,
    ok: bool,
) -> u8 {
    if !ok {
        errln!(
            o,
            "{who}: not recording a golden from a run that fails the checker"
        );
        return 1;
    }
    match old {
        None => outln!(
            o,
            "{who}: new golden: {} events over {} cycles",
            log.events.len(),
            log.cycles
        ),
        Some(old) => {
            let cmp = compare(old, log, SHOWN);
            if cmp.same() {
                outln!(o, "{who}: unchanged ({} events)", log.events.len());
            } else {
                outln!(o, "{who}: {} event(s) changed", cmp.count);
                for d in &cmp.first {
                    outln!(o, "  {}", d.describe(s));
                }
            }
        }
    }
    // nothing run-specific (path, back end): every simulator must give this file
    let mut header = vec![format!(
        "recorded by `slotforge golden --update` ({} stimulus, {} reset cycles); change it only that way",
        scene.stimulus_text(),
        trace.cycle_zero().unwrap_or(0)
    )];
    // the scene a run without options replays
    header.extend(scene.header());
    let text = log.render(s, &header);
    if let Err(code) = super::write_files(dir, &[(EVENTS, text)]) {
        return code;
    }
    for (w, (k0, k1)) in windows {
        let path = dir.join(&w.file);
        let tmp = dir.join(format!(".{}.tmp", w.file));
        if let Err(e) = write_window(s, trace, *k0, *k1, &tmp, w.file.ends_with(".fst"))
            .and_then(|()| std::fs::rename(&tmp, &path))
        {
            errln!(o, "error: {}: {e}", path.display());
            return 2;
        }
        // the .gtkw names the VCD beside it, so the folder can move
        let name = Path::new(path.file_name().expect("a file name"));
        if let Err(e) = write_gtkw(&path.with_extension("gtkw"), name, s) {
            errln!(o, "error: {}: {e}", path.display());
            return 2;
        }
        outln!(o, "{who}: window {} written ({} cycles)", w.file, k1 - k0);
    }
    0
}

/// A scene's options in words: none is the default scene.
fn or_default(options: &str) -> String {
    if options.is_empty() {
        " the default scene (pattern, no mode requests)".into()
    } else {
        options.to_string()
    }
}

/// The command that records `mix`'s golden with the options the user gave
/// (back end, Verilog, folder), so the hint works as printed.
fn update_command(a: &Args, mix: &Path) -> String {
    let quote = |p: &Path| {
        let t = p.display().to_string();
        if t.contains(|c: char| c.is_whitespace() || "'\"$`\\".contains(c)) {
            format!("'{}'", t.replace('\'', "'\\''"))
        } else {
            t
        }
    };
    let mut cmd = format!(
        "slotforge golden {} --backend {}",
        quote(mix),
        a.backend.name()
    );
    if let Some(rtl) = &a.rtl {
        cmd += &format!(" --rtl {}", quote(rtl));
    }
    cmd += &a.scene.options();
    if a.dir != Path::new("golden") {
        cmd += &format!(" --dir {}", quote(&a.dir));
    }
    cmd + " --update"
}
