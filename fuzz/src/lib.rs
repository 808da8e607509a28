//! Long-running, structure-aware fuzzing of slotforge's two readers of
//! untrusted files: the mix parser (`lut_gen::parse`) and the VCD reader
//! (`judge::check_vcd`).  Outside `make test`: `make fuzz` (docs/fuzzing.md).
//!
//! Inputs are real files (the preset mixes, test fixtures, VCDs written by
//! `slotforge sim`) with 1-4 mutation operators stacked on them; each input
//! runs on a worker thread under `catch_unwind`, watched by a timeout, and
//! every panic or hang is saved for replay.  Input `i` of a run depends only
//! on `(--seed, i)`, so runs are reproducible.

mod mutate;

use std::cell::RefCell;
use std::fmt;
use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::sync::{Arc, Once};
use std::thread;
use std::time::{Duration, Instant};

use fastrand::Rng;
use lut_gen::Schedule;

use mutate::Op;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Mix,
    Vcd,
}

impl Target {
    pub fn name(self) -> &'static str {
        match self {
            Target::Mix => "mix",
            Target::Vcd => "vcd",
        }
    }
    pub fn ext(self) -> &'static str {
        match self {
            Target::Mix => "toml",
            Target::Vcd => "vcd",
        }
    }
    pub(crate) fn ops(self) -> Vec<Op> {
        let specific = match self {
            Target::Mix => mutate::TOML_OPS,
            Target::Vcd => mutate::VCD_OPS,
        };
        mutate::GENERIC.iter().chain(specific).copied().collect()
    }
}

impl std::str::FromStr for Target {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mix" => Ok(Target::Mix),
            "vcd" => Ok(Target::Vcd),
            o => Err(format!("unknown target `{o}` (mix, vcd)")),
        }
    }
}

/// One real file to mutate; VCD seeds carry the schedule of their mix.
pub struct Seed {
    pub path: PathBuf,
    pub bytes: Vec<u8>,
    pub schedule: Option<Arc<Schedule>>,
    /// The mix a VCD seed belongs to.
    pub mix: Option<PathBuf>,
}

/// The workspace root (this crate lives in `<root>/fuzz`).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn files_with_ext(dir: &Path, ext: &str, recurse: bool, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            if recurse {
                files_with_ext(&p, ext, recurse, out);
            }
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

/// Where the mix seeds come from: the presets and every test fixture mix.
pub const MIX_SEED_DIRS: &[&str] = &["mixes", "lut-gen/tests", "hdl/tests/data", "testkit/mixes/"];

/// Where a VCD seed's mix is looked up: `<stem>__<window>.vcd` belongs to `<stem>.toml`.
pub const MIX_DIRS: &[&str] = &["mixes", "testkit/mixes/", "hdl/tests/data"];

/// The mix of a VCD named `<mix>__<anything>.vcd`.
pub fn mix_of_vcd(root: &Path, vcd: &Path) -> Option<PathBuf> {
    let name = vcd.file_name()?.to_str()?;
    let stem = name.split("__").next()?;
    MIX_DIRS
        .iter()
        .map(|d| root.join(d).join(format!("{stem}.toml")))
        .find(|p| p.is_file())
}

/// Loads the seeds of `target` (sorted by path, so runs are reproducible).
pub fn load_seeds(target: Target, root: &Path) -> Result<Vec<Seed>, String> {
    let mut paths = Vec::new();
    match target {
        Target::Mix => {
            for d in MIX_SEED_DIRS {
                files_with_ext(&root.join(d), "toml", true, &mut paths)
            }
        }
        Target::Vcd => {
            files_with_ext(&root.join("fuzz/seeds/vcd"), "vcd", false, &mut paths);
            files_with_ext(
                &root.join("cosim/judge/tests/data/fuzz"),
                "vcd",
                false,
                &mut paths,
            );
        }
    }
    paths.sort();
    paths.dedup();
    let mut seeds = Vec::new();
    for p in paths {
        let bytes = std::fs::read(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        let (schedule, mix) = match target {
            Target::Mix => (None, None),
            Target::Vcd => {
                let Some(m) = mix_of_vcd(root, &p) else {
                    return Err(format!(
                        "{}: no mix `<name>.toml` for this VCD in {} (name VCD seeds `<mix>__<window>.vcd`)",
                        p.display(),
                        MIX_DIRS.join(", ")
                    ));
                };
                let mix = lut_gen::load(&m).map_err(|e| e.to_string())?;
                let s = lut_gen::synthesize(&mix).map_err(|e| format!("{}: {e}", m.display()))?;
                (Some(Arc::new(s)), Some(m))
            }
        };
        seeds.push(Seed {
            path: p,
            bytes,
            schedule,
            mix,
        });
    }
    if seeds.is_empty() {
        return Err(format!("no seeds for target `{}`", target.name()));
    }
    Ok(seeds)
}

/// What one input did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// Parsed (mix) / read and checked with every check passing (VCD).
    Ok,
    /// VCD read in full, and the checker reported divergences or violations.
    Diverged,
    /// A clean error.
    Rejected(String),
}

/// Runs one input against the real API.  `scratch` is a file this worker may overwrite.
pub fn exec(target: Target, input: &[u8], seed: &Seed, scratch: &Path) -> Outcome {
    match target {
        Target::Mix => {
            // Valid UTF-8 goes through `parse`, anything else through `load`
            // (which must reject it cleanly).
            let r = match std::str::from_utf8(input) {
                Ok(text) => lut_gen::parse(Path::new("fuzz.toml"), text),
                Err(_) => {
                    std::fs::write(scratch, input).expect("scratch file");
                    lut_gen::load(scratch)
                }
            };
            match r {
                Ok(m) => {
                    // A validated mix promises whole, representable cycle and
                    // sample counts: use them.
                    let _ = (m.frame_cycles(), m.slice_cycles(), m.slices_per_frame());
                    for c in &m.channels {
                        let _ = m.samples_per_frame(c.rate_hz);
                    }
                    Outcome::Ok
                }
                Err(e) => Outcome::Rejected(e.to_string()),
            }
        }
        Target::Vcd => {
            std::fs::write(scratch, input).expect("scratch file");
            let s = seed.schedule.as_ref().expect("VCD seeds have a schedule");
            match judge::check_vcd(s, scratch, None) {
                Ok(r) if r.ok => Outcome::Ok,
                Ok(_) => Outcome::Diverged,
                Err(e) => Outcome::Rejected(e.to_string()),
            }
        }
    }
}

// ------------------------------------------------------------------ campaign

#[derive(Debug, Clone)]
pub struct Config {
    pub target: Target,
    pub count: u64,
    pub seed: u64,
    pub timeout: Duration,
    /// Where panicking / hanging inputs are written.
    pub crashes: PathBuf,
    /// Print each crash as it is found.
    pub verbose: bool,
    /// Stop after this many hangs (each leaves a thread spinning).
    pub max_hangs: u64,
}

/// How an input broke the code under test.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CrashKind {
    Panic,
    /// No result within the time limit.
    Hang,
}

impl fmt::Display for CrashKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CrashKind::Panic => "panic",
            CrashKind::Hang => "hang",
        })
    }
}

#[derive(Debug, Clone)]
pub struct Crash {
    pub kind: CrashKind,
    pub index: u64,
    pub file: PathBuf,
    pub seed: PathBuf,
    pub ops: Vec<&'static str>,
    pub message: String,
}

#[derive(Debug, Clone, Default)]
pub struct Summary {
    pub target: &'static str,
    pub inputs: u64,
    pub ok: u64,
    pub diverged: u64,
    pub rejected: u64,
    pub panics: u64,
    pub hangs: u64,
    pub elapsed: Duration,
    pub crashes: Vec<Crash>,
    /// The first few rejection messages, to show the mutations reach deep.
    pub sample_errors: Vec<String>,
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let secs = self.elapsed.as_secs_f64();
        write!(
            f,
            "{}: inputs {}, ok {} (of which check failed {}), rejected-with-error {}, panics {}, hangs {}, elapsed {:.1} s, {:.0} inputs/s",
            self.target,
            self.inputs,
            self.ok + self.diverged,
            self.diverged,
            self.rejected,
            self.panics,
            self.hangs,
            secs,
            self.inputs as f64 / secs.max(1e-9)
        )
    }
}

thread_local! {
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

const WORKER: &str = "fuzz-worker";

/// Panics on fuzz workers are recorded quietly; any other thread's go to
/// the default hook.
fn install_quiet_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if thread::current()
                .name()
                .is_some_and(|n| n.starts_with(WORKER))
            {
                LAST_PANIC.with(|p| *p.borrow_mut() = Some(info.to_string()));
            } else {
                default(info)
            }
        }));
    });
}

enum Reply {
    Done(Outcome),
    Panic(String),
}

struct Worker {
    tx: mpsc::Sender<(Vec<u8>, usize)>,
    rx: mpsc::Receiver<Reply>,
    scratch: PathBuf,
}

fn spawn_worker(target: Target, seeds: Arc<Vec<Seed>>, n: u64) -> Worker {
    let (tx, job_rx) = mpsc::channel::<(Vec<u8>, usize)>();
    let (reply_tx, rx) = mpsc::channel();
    let scratch = std::env::temp_dir().join(format!(
        "slotforge-fuzz-{}-{}-{n}.{}",
        std::process::id(),
        target.name(),
        target.ext()
    ));
    let sc = scratch.clone();
    thread::Builder::new()
        .name(format!("{WORKER}-{n}"))
        .spawn(move || {
            for (input, si) in job_rx {
                let seed = &seeds[si];
                let r = catch_unwind(AssertUnwindSafe(|| exec(target, &input, seed, &sc)));
                let reply = match r {
                    Ok(o) => Reply::Done(o),
                    Err(payload) => {
                        Reply::Panic(LAST_PANIC.with(|p| p.borrow_mut().take()).unwrap_or_else(
                            || {
                                payload
                                    .downcast_ref::<&str>()
                                    .map(|s| s.to_string())
                                    .or_else(|| payload.downcast_ref::<String>().cloned())
                                    .unwrap_or_else(|| "(non-string panic)".into())
                            },
                        ))
                    }
                };
                if reply_tx.send(reply).is_err() {
                    break;
                }
            }
        })
        .expect("spawn fuzz worker");
    Worker { tx, rx, scratch }
}

/// FNV-1a, for crash file names.
pub fn hash(b: &[u8]) -> u64 {
    b.iter().fold(0xcbf2_9ce4_8422_2325, |h, &c| {
        (h ^ c as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The input `i` of a run with `seed`: which seed file, the bytes, the operators.
pub fn input(
    target: Target,
    seeds: &[Seed],
    run_seed: u64,
    i: u64,
) -> (usize, Vec<u8>, Vec<&'static str>) {
    // splitmix64 of (seed, i): independent streams per input
    let mut z = run_seed ^ i.wrapping_add(1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    let mut rng = Rng::with_seed(z ^ (z >> 31));
    let si = rng.usize(..seeds.len());
    let (b, ops) = mutate::mutate(&seeds[si].bytes, &target.ops(), &mut rng);
    (si, b, ops)
}

fn save(cfg: &Config, bytes: &[u8]) -> PathBuf {
    let _ = std::fs::create_dir_all(&cfg.crashes);
    let p = cfg.crashes.join(format!(
        "{}-{:016x}.{}",
        cfg.target.name(),
        hash(bytes),
        cfg.target.ext()
    ));
    if let Err(e) = std::fs::write(&p, bytes) {
        eprintln!("cannot save {}: {e}", p.display());
    }
    p
}

/// Runs a campaign: `cfg.count` inputs, each under `cfg.timeout`.
pub fn run(cfg: &Config, seeds: Vec<Seed>) -> Summary {
    install_quiet_hook();
    let seeds = Arc::new(seeds);
    let t0 = Instant::now();
    let mut sum = Summary {
        target: cfg.target.name(),
        ..Summary::default()
    };
    let mut workers = 0;
    let mut w = spawn_worker(cfg.target, seeds.clone(), workers);
    let mut scratches = vec![w.scratch.clone()];
    for i in 0..cfg.count {
        let (si, bytes, ops) = input(cfg.target, &seeds, cfg.seed, i);
        w.tx.send((bytes.clone(), si)).expect("worker alive");
        sum.inputs += 1;
        let (kind, message) = match w.rx.recv_timeout(cfg.timeout) {
            Ok(Reply::Done(Outcome::Ok)) => {
                sum.ok += 1;
                continue;
            }
            Ok(Reply::Done(Outcome::Diverged)) => {
                sum.diverged += 1;
                continue;
            }
            Ok(Reply::Done(Outcome::Rejected(e))) => {
                sum.rejected += 1;
                if sum.sample_errors.len() < 20 {
                    sum.sample_errors.push(e);
                }
                continue;
            }
            Ok(Reply::Panic(m)) => {
                sum.panics += 1;
                (CrashKind::Panic, m)
            }
            Err(_) => {
                sum.hangs += 1;
                // The hung thread cannot be stopped: leave it and start another.
                workers += 1;
                w = spawn_worker(cfg.target, seeds.clone(), workers);
                scratches.push(w.scratch.clone());
                (
                    CrashKind::Hang,
                    format!("no result within {:?}", cfg.timeout),
                )
            }
        };
        let file = save(cfg, &bytes);
        let seed = seeds[si].path.clone();
        if cfg.verbose {
            let mix = seeds[si]
                .mix
                .as_ref()
                .map(|m| format!(" (mix {})", m.display()))
                .unwrap_or_default();
            eprintln!(
                "{kind} at input {i}: {}\n  seed {}{mix}, operators {}\n  {}",
                file.display(),
                seed.display(),
                ops.join("+"),
                message.replace('\n', "\n  ")
            );
            let _ = std::io::stderr().flush();
        }
        sum.crashes.push(Crash {
            kind,
            index: i,
            file,
            seed,
            ops,
            message,
        });
        if sum.hangs >= cfg.max_hangs {
            eprintln!("stopping after {} hang(s)", sum.hangs);
            break;
        }
    }
    sum.elapsed = t0.elapsed();
    for s in scratches {
        let _ = std::fs::remove_file(s);
    }
    sum
}
